#include "core/process/buffer_reuse.h"

#include <gtest/gtest.h>
#include <malloc.h>

#include <cstdlib>
#include <cstring>

#include "tests/support/sanitizer.h"

namespace surfinspect {
namespace {

// A 9.4 MB cloud buffer must come from the heap (hblkhd counts the bytes of
// separately mapped blocks), and a freed one must stay there for reuse.
TEST(BufferReuse, CloudSizedBuffersComeFromTheHeapAndStay) {
  if (testing::kAddressSanitizer) GTEST_SKIP() << "AddressSanitizer's malloc is not glibc's";
  ASSERT_TRUE(ReuseFreedLargeBuffers());
  const std::size_t cloud_bytes = 1024 * 768 * 12;
  const std::size_t mapped_before = mallinfo2().hblkhd;
  void* a = std::malloc(cloud_bytes);
  ASSERT_NE(a, nullptr);
  std::memset(a, 1, cloud_bytes);
  EXPECT_EQ(mallinfo2().hblkhd, mapped_before) << "a cloud-sized buffer was mapped separately";
  const std::size_t free_before = mallinfo2().fordblks;
  std::free(a);
  // Freed and not trimmed: the heap holds it for the next buffer.
  EXPECT_GE(mallinfo2().fordblks, free_before + cloud_bytes);
  // Above the limit glibc still maps (and returns) the block.
  void* huge = std::malloc(kHeapBufferLimitBytes + (1 << 20));
  ASSERT_NE(huge, nullptr);
  EXPECT_GT(mallinfo2().hblkhd, mapped_before);
  std::free(huge);
}

}  // namespace
}  // namespace surfinspect
