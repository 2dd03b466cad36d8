#include "core/io/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "core/io/disk_space.h"
#include "tests/support/small_file_system.h"
#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

namespace fs = std::filesystem;
using testing::ReadBytes;
using testing::TempDir;
using testing::WriteBytes;

std::set<std::string> FilesIn(const std::string& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

TEST(AtomicFile, WritesTheBytesAndReplacesTheOldFileWhole) {
  TempDir dir;
  const std::string path = dir.File("report.json");
  const std::string binary("a\0b\xff\n", 5);
  ASSERT_TRUE(WriteStringAtomically(path, binary).ok());
  EXPECT_EQ(ReadBytes(path), binary);
  ASSERT_TRUE(WriteStringAtomically(path, std::string(1000, 'x')).ok());
  ASSERT_TRUE(WriteStringAtomically(path, "short").ok());
  EXPECT_EQ(ReadBytes(path), "short") << "no tail of the longer old file";
  EXPECT_EQ(FilesIn(dir.path()), std::set<std::string>{"report.json"});
}

TEST(AtomicFile, TheTemporaryFileSitsBesideTheTargetWithItsExtension) {
  TempDir dir;
  const std::string path = dir.File("map.ply");
  WriteBytes(path, "old");
  std::string seen_tmp;
  const absl::Status st = WriteFileAtomically(path, [&](const std::string& tmp) {
    seen_tmp = tmp;
    EXPECT_EQ(ReadBytes(path), "old") << "the target is untouched while writing";
    WriteBytes(tmp, "new");
    return absl::OkStatus();
  });
  ASSERT_TRUE(st.ok()) << st;
  EXPECT_NE(seen_tmp, path);
  EXPECT_EQ(fs::path(seen_tmp).parent_path(), fs::path(path).parent_path());
  EXPECT_EQ(fs::path(seen_tmp).extension(), ".ply");
  EXPECT_FALSE(fs::exists(seen_tmp)) << "renamed over the target";
  EXPECT_EQ(ReadBytes(path), "new");
}

TEST(AtomicFile, AFailedWriterLeavesTheTargetAndNoTemporaryFile) {
  TempDir dir;
  const std::string path = dir.File("cloud.pcd");
  WriteBytes(path, "the old, complete file");
  std::string seen_tmp;
  const absl::Status st = WriteFileAtomically(path, [&](const std::string& tmp) {
    seen_tmp = tmp;
    WriteBytes(tmp, "half of the ne");  // then the writer fails
    return absl::DataLossError("disk full");
  });
  EXPECT_EQ(st.code(), absl::StatusCode::kDataLoss);
  EXPECT_EQ(st.message(), "disk full") << "the writer's status is returned as is";
  EXPECT_FALSE(seen_tmp.empty());
  EXPECT_FALSE(fs::exists(seen_tmp));
  EXPECT_EQ(ReadBytes(path), "the old, complete file");
  EXPECT_EQ(FilesIn(dir.path()), std::set<std::string>{"cloud.pcd"});
}

TEST(AtomicFile, AWriterOnAFullDiskIsToldAsAFullDiskWhateverItSaid) {
  std::string why;
  const auto small = testing::SmallFileSystem::Mount(1 << 20, &why);
  if (!small) GTEST_SKIP() << why;
  const absl::Status st =
      WriteFileAtomically(small->File("map.ply"), [](const std::string& tmp) -> absl::Status {
        std::ofstream out(tmp, std::ios::binary);
        out << std::string(2 << 20, 'x');  // more than fits; the writer's own words say nothing
        out.close();
        return out ? absl::OkStatus() : absl::DataLossError("write failed: " + tmp);
      });
  EXPECT_TRUE(IsDiskFull(st)) << st;
  EXPECT_NE(st.message().find("write failed"), std::string::npos) << "the writer's words kept";
  EXPECT_TRUE(FilesIn(small->path()).empty()) << "no temporary file";
}

TEST(AtomicFile, AWriterThatCreatesNothingCannotBeRenamed) {
  TempDir dir;
  const std::string path = dir.File("x.csv");
  WriteBytes(path, "kept");
  const absl::Status st =
      WriteFileAtomically(path, [](const std::string&) { return absl::OkStatus(); });
  EXPECT_EQ(st.code(), absl::StatusCode::kInternal);
  EXPECT_NE(st.message().find("cannot rename"), std::string::npos) << st;
  EXPECT_EQ(ReadBytes(path), "kept");
  EXPECT_EQ(FilesIn(dir.path()), std::set<std::string>{"x.csv"});
}

TEST(AtomicFile, AMissingDirectoryIsAnErrorAndCreatesNothing) {
  TempDir dir;
  const std::string path = dir.File("no/such/dir/out.png");
  const absl::Status st = WriteStringAtomically(path, "bytes");
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find(dir.File("no/such/dir/out")), std::string::npos) << st;
  EXPECT_TRUE(FilesIn(dir.path()).empty());
}

TEST(AtomicFile, ReadFileToStringReadsEveryByte) {
  TempDir dir;
  std::string bytes;
  for (int i = 0; i < 70000; ++i) bytes += static_cast<char>(i * 7 % 256);
  WriteBytes(dir.File("b.bin"), bytes);
  auto got = ReadFileToString(dir.File("b.bin"));
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(*got, bytes);
  WriteBytes(dir.File("empty"), "");
  auto empty = ReadFileToString(dir.File("empty"));
  ASSERT_TRUE(empty.ok());
  EXPECT_TRUE(empty->empty());
}

TEST(AtomicFile, ReadFileToStringHonoursTheLimitAndNamesMissingFiles) {
  TempDir dir;
  WriteBytes(dir.File("100"), std::string(100, 'a'));
  EXPECT_TRUE(ReadFileToString(dir.File("100"), 100).ok()) << "the limit is inclusive";
  auto over = ReadFileToString(dir.File("100"), 99);
  EXPECT_EQ(over.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(over.status().message().find("100 bytes exceeds the limit of 99"), std::string::npos)
      << over.status();

  auto missing = ReadFileToString(dir.File("absent.stl"));
  EXPECT_EQ(missing.status().code(), absl::StatusCode::kNotFound);
  EXPECT_NE(missing.status().message().find(dir.File("absent.stl")), std::string::npos)
      << missing.status();
  EXPECT_FALSE(ReadFileToString(dir.path()).ok()) << "a directory is not a file";
}

}  // namespace
}  // namespace surfinspect
