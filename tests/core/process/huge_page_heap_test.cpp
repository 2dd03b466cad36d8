// core/process/huge_page_heap.cpp: after the call, cloud-sized buffers from
// the main thread and from another thread lie in a mapping the kernel
// marks for huge pages ("hg" in /proc/self/smaps). Each case runs in a
// child process (a death test that exits), since the setting is
// process-wide and this test binary's other tests must not get it.
#include "core/process/huge_page_heap.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "core/process/buffer_reuse.h"
#include "tests/support/sanitizer.h"

namespace surfinspect {
namespace {

// The VmFlags line of the mapping that holds `p`, or "" if none does.
std::string VmFlagsOf(const void* p) {
  const auto at = reinterpret_cast<uintptr_t>(p);
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream head(line);
    if (head >> std::hex >> lo >> dash >> hi && dash == '-') inside = lo <= at && at < hi;
    if (inside && line.rfind("VmFlags:", 0) == 0) return line;
  }
  return "";
}

// Past its first 2 MiB (the heap's reserve starts at the first huge-page
// boundary, which may fall inside the first buffer), to its last byte.
bool MarkedHuge(const void* buffer, std::size_t bytes) {
  for (std::size_t at : {std::size_t{2} << 20, bytes / 2, bytes - 1})
    if (VmFlagsOf(static_cast<const char*>(buffer) + at).find(" hg") == std::string::npos)
      return false;
  return true;
}

// Exit codes: 0 all marked, 2 the call refused, 3 main thread's buffer not
// marked, 4 another thread's buffer not marked.
[[noreturn]] void CheckInChild() {
  ReuseFreedLargeBuffers();
  if (!BackHeapWithHugePages(std::size_t{256} << 20)) std::_Exit(2);
  const std::size_t cloud_bytes = 1024 * 768 * 12;
  void* main_buffer = std::malloc(cloud_bytes);
  std::memset(main_buffer, 1, cloud_bytes);
  if (!MarkedHuge(main_buffer, cloud_bytes)) std::_Exit(3);
  void* worker_buffer = nullptr;
  std::thread([&] {
    worker_buffer = std::malloc(cloud_bytes);
    std::memset(worker_buffer, 2, cloud_bytes);
  }).join();
  if (!MarkedHuge(worker_buffer, cloud_bytes)) std::_Exit(4);
  std::_Exit(0);
}

TEST(HugePageHeap, BuffersOfEveryThreadAreMarkedForHugePages) {
  if (testing::kAddressSanitizer) GTEST_SKIP() << "AddressSanitizer's malloc is not glibc's";
  if (!std::ifstream("/sys/kernel/mm/transparent_hugepage/enabled"))
    GTEST_SKIP() << "this kernel has no transparent huge pages";
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(CheckInChild(), ::testing::ExitedWithCode(0), "");
}

TEST(HugePageHeap, RefusesAReserveOutsideItsRange) {
  // Both refusals return before any setting changes, so they run here.
  EXPECT_FALSE(BackHeapWithHugePages(4096));
  EXPECT_FALSE(BackHeapWithHugePages(std::size_t{4} << 30));
}

}  // namespace
}  // namespace surfinspect
