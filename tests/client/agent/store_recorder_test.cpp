// The agent's store listener: a store that cannot be reached fails no part
// and is caught up with once it can; a restart records what a killed agent
// left on disk, once.
#include "client/agent/store_recorder.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "core/io/atomic_file.h"
#include "tests/support/temp_dir.h"

namespace surfinspect::client {
namespace {
namespace fs = std::filesystem;
using surfinspect::testing::TempDir;

void WriteReport(const std::string& dir) {
  fs::create_directories(dir);
  ASSERT_TRUE(WriteStringAtomically(dir + "/report.json",
                                    R"({"verdict": "pass", "characteristics": [{"name": "s",
      "type": "surface", "mean_mm": 0.01, "tolerance_mm": {"lower": -1, "upper": 1}}]})")
                  .ok());
}

RecordContext Context() {
  RecordContext c;
  c.cell = "c1";  // no part mesh: no triangle summary
  return c;
}

TEST(StoreRecorder, UnreachableStoreIsCaughtUpLater) {
  TempDir dir;
  const std::string results = dir.File("results");
  const std::string db = dir.File("later/results.db");  // its folder is not there yet
  std::vector<std::string> errors;
  StoreRecorder recorder(db, Context(), results,
                         [&](const std::string& m) { errors.push_back(m); });
  EXPECT_FALSE(recorder.CatchUp().ok());
  WriteReport(results + "/p1");
  recorder.OnStored("p1", results + "/p1");
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("p1: not recorded"), std::string::npos) << errors[0];
  EXPECT_NE(errors[0].find("recorded later"), std::string::npos) << errors[0];
  EXPECT_TRUE(recorder.behind());
  fs::create_directories(dir.File("later"));
  WriteReport(results + "/p2");
  recorder.OnStored("p2", results + "/p2");
  EXPECT_FALSE(recorder.behind());
  EXPECT_EQ(recorder.recorded(), 2);
  auto store = OpenResultsStore(db);
  EXPECT_EQ((*store)->Load({})->size(), 2u);
}

TEST(StoreRecorder, RestartRecordsWhatAKilledAgentLeftOnDiskOnce) {
  TempDir dir;
  const std::string results = dir.File("results");
  const std::string db = results + "/results.db";
  fs::create_directories(results);
  {
    StoreRecorder first(db, Context(), results, [](const std::string&) {});
    ASSERT_TRUE(first.CatchUp().ok());
    WriteReport(results + "/p1");
    first.OnStored("p1", results + "/p1");
    // p2's results reach the disk, then the agent dies before telling the store.
    WriteReport(results + "/p2");
  }
  StoreRecorder restarted(db, Context(), results, [](const std::string&) {});
  ASSERT_TRUE(restarted.CatchUp().ok());
  EXPECT_EQ(restarted.recorded(), 1);
  restarted.OnStored("p2", results + "/p2");  // the restart finds p2 in the inbox too
  EXPECT_EQ(restarted.recorded(), 1);
  auto store = OpenResultsStore(db);
  EXPECT_EQ((*store)->Load({})->size(), 2u);
}

}  // namespace
}  // namespace surfinspect::client
