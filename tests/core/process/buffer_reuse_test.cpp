#include "core/process/buffer_reuse.h"

#include <gtest/gtest.h>
#include <malloc.h>

#include <cstdlib>
#include <cstring>

#include "tests/support/sanitizer.h"

namespace surfinspect {
namespace {

// glibc's chunk header: the size word before the user pointer, whose bit 1
// (IS_MMAPPED) marks a block mapped on its own. Read per block, so a
// process-wide counter that other threads (a previous test's TBB workers
// finishing their tasks) may move at the same moment does not enter.
bool MappedOnItsOwn(const void* p) {
  std::size_t size_word;
  std::memcpy(&size_word, static_cast<const char*>(p) - sizeof size_word, sizeof size_word);
  return (size_word & 2) != 0;
}

// A 9.4 MB cloud buffer must come from the heap, and a freed one must stay
// there: the next buffer of that size gets the same pages.
TEST(BufferReuse, CloudSizedBuffersComeFromTheHeapAndStay) {
  if (testing::kAddressSanitizer) GTEST_SKIP() << "AddressSanitizer's malloc is not glibc's";
  ASSERT_TRUE(ReuseFreedLargeBuffers());
  const std::size_t cloud_bytes = 1024 * 768 * 12;
  void* a = std::malloc(cloud_bytes);
  ASSERT_NE(a, nullptr);
  std::memset(a, 1, cloud_bytes);
  EXPECT_FALSE(MappedOnItsOwn(a)) << "a cloud-sized buffer was mapped separately";
  std::free(a);
  void* b = std::malloc(cloud_bytes);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b, a) << "the freed buffer was not reused";
  std::free(b);
  // Above the limit glibc still maps (and returns) a block it cannot serve
  // from the heap. Earlier tests may leave up to the trim threshold (256
  // MiB) free there, which a block just above the limit would come from.
  void* huge = std::malloc(std::size_t{320} << 20);
  ASSERT_NE(huge, nullptr);
  EXPECT_TRUE(MappedOnItsOwn(huge));
  std::free(huge);
}

}  // namespace
}  // namespace surfinspect
