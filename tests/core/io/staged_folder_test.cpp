#include "core/io/staged_folder.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>

#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

namespace fs = std::filesystem;
using testing::ReadBytes;
using testing::TempDir;
using testing::WriteBytes;

std::set<std::string> Names(const std::string& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

TEST(StagedFolder, NothingAppearsUntilCommitThenTheWholeSet) {
  TempDir dir;
  const std::string target = dir.File("part-1");
  {
    auto staged = StagedFolder::Begin(target);
    ASSERT_TRUE(staged.ok()) << staged.status();
    EXPECT_EQ(fs::path(staged->path()).parent_path(), fs::path(dir.File(".partial")));
    WriteBytes(staged->path() + "/errormap.ply", "ply");
    WriteBytes(staged->path() + "/report.json", "{}");
    EXPECT_FALSE(fs::exists(target)) << "a reader sees no set in the making";
    EXPECT_EQ(staged->Bytes(), 5u);
    ASSERT_TRUE(staged->Commit("report.json").ok());
    EXPECT_EQ(Names(target), (std::set<std::string>{"errormap.ply", "report.json"}));
  }
  EXPECT_EQ(Names(dir.path()), std::set<std::string>{"part-1"}) << "the empty .partial goes too";
}

TEST(StagedFolder, AnAbandonedSetLeavesNothing) {
  TempDir dir;
  {
    auto staged = StagedFolder::Begin(dir.File("part-1"));
    ASSERT_TRUE(staged.ok());
    WriteBytes(staged->path() + "/errormap.ply", "half");
  }  // e.g. the PDF writer failed: no Commit
  EXPECT_FALSE(fs::exists(dir.File("part-1")));
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(StagedFolder, ATrailingSlashNamesTheSameFolder) {
  TempDir dir;
  auto staged = StagedFolder::Begin(dir.File("part-1/"));
  ASSERT_TRUE(staged.ok());
  WriteBytes(staged->path() + "/report.json", "{}");
  ASSERT_TRUE(staged->Commit("report.json").ok());
  EXPECT_EQ(ReadBytes(dir.File("part-1/report.json")), "{}");
  for (const char* no_name : {"", "/", "..", "a/.."})
    EXPECT_FALSE(StagedFolder::Begin(no_name).ok()) << no_name;
}

TEST(StagedFolder, AFolderHoldingOtherFilesKeepsThemAndGetsTheSetReportLast) {
  TempDir dir;
  const std::string target = dir.File("out");
  fs::create_directories(target);
  WriteBytes(target + "/notes.txt", "mine");
  WriteBytes(target + "/report.json", "old");
  auto staged = StagedFolder::Begin(target);
  ASSERT_TRUE(staged.ok());
  WriteBytes(staged->path() + "/report.json", "new");
  WriteBytes(staged->path() + "/report.pdf", "pdf");
  ASSERT_TRUE(staged->Commit("report.json").ok());
  EXPECT_EQ(Names(target), (std::set<std::string>{"notes.txt", "report.json", "report.pdf"}));
  EXPECT_EQ(ReadBytes(target + "/report.json"), "new");
  EXPECT_EQ(ReadBytes(target + "/notes.txt"), "mine");
}

TEST(StagedFolder, AnEmptyFolderIsReplacedAndAFileIsRefused) {
  TempDir dir;
  fs::create_directories(dir.File("empty"));
  auto staged = StagedFolder::Begin(dir.File("empty"));
  ASSERT_TRUE(staged.ok());
  WriteBytes(staged->path() + "/report.json", "{}");
  ASSERT_TRUE(staged->Commit("report.json").ok());
  EXPECT_EQ(Names(dir.File("empty")), std::set<std::string>{"report.json"});

  WriteBytes(dir.File("file"), "x");
  auto onto_file = StagedFolder::Begin(dir.File("file"));
  ASSERT_TRUE(onto_file.ok());
  const absl::Status st = onto_file->Commit("report.json");
  EXPECT_TRUE(absl::IsFailedPrecondition(st)) << st;
  EXPECT_EQ(ReadBytes(dir.File("file")), "x");
}

TEST(StagedFolder, LeftoversOfKilledWritersAreRemovedAndNamed) {
  TempDir dir;
  fs::create_directories(dir.File(".partial/part-7.4242.0"));
  WriteBytes(dir.File(".partial/part-7.4242.0/report.json"), "{}");
  fs::create_directories(dir.File("part-8"));  // a finished set stays
  auto removed = RemoveStagingLeftovers(dir.path());
  ASSERT_TRUE(removed.ok()) << removed.status();
  EXPECT_EQ(*removed, std::vector<std::string>{"part-7.4242.0"});
  EXPECT_TRUE(fs::is_empty(dir.File(".partial")));
  EXPECT_TRUE(fs::exists(dir.File("part-8")));
  auto none = RemoveStagingLeftovers(dir.File("part-8"));
  ASSERT_TRUE(none.ok());
  EXPECT_TRUE(none->empty());
}

}  // namespace
}  // namespace surfinspect
