// client/agent/disk_guard.cpp: cell.json's "disk", the room a part needs on
// a real (tmpfs) file system, and the metrics file.
#include "client/agent/disk_guard.h"

#include <gtest/gtest.h>

#include "tests/support/small_file_system.h"

namespace surfinspect::client {
namespace {

CellConfig CellWith(const std::string& disk_json) {
  CellConfig c;
  c.path = "cell.json";
  c.raw = nlohmann::json::parse(disk_json);
  return c;
}

TEST(DiskGuard, TheReserveIsReadAndBadValuesAreNamed) {
  EXPECT_EQ(DiskConfigOf(CellWith("{}"))->reserve_mb, 512);
  EXPECT_EQ(DiskConfigOf(CellWith(R"({"disk": {"reserve_mb": 64}})"))->reserve_mb, 64);
  for (const char* bad : {R"({"disk": {"reserve_mb": -1}})", R"({"disk": {"reserve_mb": "1G"}})",
                          R"({"disk": {"reserve": 1}})", R"({"disk": 3})"}) {
    const auto c = DiskConfigOf(CellWith(bad));
    EXPECT_EQ(c.status().code(), absl::StatusCode::kInvalidArgument) << bad;
    EXPECT_NE(c.status().message().find("cell.json: disk"), std::string::npos) << c.status();
  }
}

TEST(DiskGuard, APartNeedsTheLargestSetSoFarPlusTheReserve) {
  std::string why;
  const auto small = testing::SmallFileSystem::Mount(16 << 20, &why);
  if (!small) GTEST_SKIP() << why;
  DiskGuard guard({small->File("results"), "/"}, DiskConfig{4});
  EXPECT_TRUE(guard.Check().ok()) << "16 MiB free, 4 MiB reserve, no set written yet";
  guard.SetWritten(14 << 20);
  guard.SetWritten(2 << 20);
  EXPECT_EQ(guard.need_bytes(), uint64_t{14} << 20) << "the largest";
  const absl::Status full = guard.Check();
  EXPECT_TRUE(absl::IsResourceExhausted(full)) << full;
  EXPECT_NE(full.message().find(small->File("results")), std::string::npos) << full;
  EXPECT_NE(full.message().find("14.0 MiB plus the reserve of 4.0 MiB"), std::string::npos) << full;
  guard.SetFailed(15 << 20);
  EXPECT_GT(guard.need_bytes(), uint64_t{15} << 20) << "more than the failed set had";
  const std::vector<FolderSpace> space = guard.Space();
  ASSERT_EQ(space.size(), 2u);
  EXPECT_GT(space[0].free_bytes, uint64_t{15} << 20);
  EXPECT_LE(space[0].free_bytes, uint64_t{16} << 20);
}

TEST(DiskGuard, TheMetricsSayFullAndEachFoldersFreeBytes) {
  const std::string m = DiskMetrics("cell-a", true, {{"/r", 123}, {"/a", 0}});
  EXPECT_NE(m.find("surfinspect_agent_disk_full{cell=\"cell-a\"} 1\n"), std::string::npos) << m;
  EXPECT_NE(m.find("surfinspect_agent_disk_free_bytes{cell=\"cell-a\",folder=\"/r\"} 123\n"),
            std::string::npos)
      << m;
  EXPECT_NE(DiskMetrics("c", false, {}).find("surfinspect_agent_disk_full{cell=\"c\"} 0\n"),
            std::string::npos);
}

}  // namespace
}  // namespace surfinspect::client
