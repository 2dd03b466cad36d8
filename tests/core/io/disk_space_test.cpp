#include "core/io/disk_space.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "core/io/atomic_file.h"
#include "tests/support/small_file_system.h"

namespace surfinspect {
namespace {

using testing::FillWithZeros;
using testing::SmallFileSystem;

TEST(DiskSpace, AFullTmpfsIsToldFromOtherWriteFailures) {
  std::string why;
  const auto fs = SmallFileSystem::Mount(8 << 20, &why);
  if (!fs) GTEST_SKIP() << why;
  auto space = DiskSpaceOf(fs->path());
  ASSERT_TRUE(space.ok()) << space.status();
  EXPECT_EQ(space->total_bytes, uint64_t{8} << 20);
  EXPECT_GT(space->free_bytes, uint64_t{7} << 20);
  // A folder not made yet is on its parent's file system.
  EXPECT_EQ(DiskSpaceOf(fs->File("results/part-1"))->total_bytes, uint64_t{8} << 20);

  const absl::Status other = absl::DataLossError("short write to x.ply");
  EXPECT_EQ(AsDiskFull(other, fs->path()), other) << "space is left: not a full disk";

  FillWithZeros(fs->File("filler"), uint64_t{16} << 20);
  EXPECT_LT(DiskSpaceOf(fs->path())->free_bytes, kFullDiskSlackBytes);
  const absl::Status write =
      WriteStringAtomically(fs->File("report.json"), std::string(1 << 20, 'x'));
  ASSERT_FALSE(write.ok());
  const absl::Status full = AsDiskFull(write, fs->File("results"));
  EXPECT_TRUE(IsDiskFull(full)) << full;
  EXPECT_NE(full.message().find(fs->path()), std::string::npos) << full;
  EXPECT_NE(full.message().find("MiB free"), std::string::npos) << full;
  EXPECT_EQ(AsDiskFull(full, fs->path()), full) << "said once";
  EXPECT_FALSE(IsDiskFull(absl::ResourceExhaustedError("too many calls")));
}

TEST(DiskSpace, ENOSPCInTheMessageIsAFullDiskAnywhere) {
  const absl::Status st = AsDiskFull(absl::InternalError("cannot write x: No space left on device"),
                                     ::testing::TempDir());
  EXPECT_TRUE(IsDiskFull(st)) << st;
}

}  // namespace
}  // namespace surfinspect
