// client/agent/retention.cpp: cell.json's "retention" and the prune it
// drives, on real folders with set ages.
#include "client/agent/retention.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "tests/support/temp_dir.h"

namespace surfinspect::client {
namespace {
namespace fs = std::filesystem;
using surfinspect::testing::TempDir;
using surfinspect::testing::WriteBytes;

CellConfig CellWith(const std::string& json) {
  CellConfig c;
  c.path = "cell.json";
  c.raw = nlohmann::json::parse(json);
  return c;
}

class RetentionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    layout_ = {dir_.File("inbox"), dir_.File("results"), dir_.File("archive"), dir_.File("q")};
    now_ = std::chrono::system_clock::now();
    for (int i = 1; i <= 6; ++i) AddPart(Id(i), 7 - i);  // p1 six days old ... p6 one day
  }
  static std::string Id(int i) { return "p" + std::to_string(i); }
  // A finished set `days_old` days ago, and its archived scans.
  void AddPart(const std::string& id, int days_old) {
    const fs::path r = fs::path(layout_.results) / id, a = fs::path(layout_.archive) / id;
    fs::create_directories(r);
    fs::create_directories(a);
    for (const char* name : {"errormap.ply", "report.html", "report.pdf", "result.qif"})
      WriteBytes((r / name).string(), std::string(1000, 'x'));
    WriteBytes((r / "report.json").string(), "{}");
    WriteBytes((a / "v1.pcd").string(), std::string(1000, 'x'));
    const auto when = fs::file_time_type::clock::now() - std::chrono::hours(24 * days_old);
    fs::last_write_time(r / "report.json", when);
    fs::last_write_time(a, when);
  }
  bool Has(const std::string& id, const char* file) const {
    return fs::exists(fs::path(layout_.results) / id / file);
  }

  TempDir dir_;
  InboxLayout layout_;
  std::chrono::system_clock::time_point now_;
};

TEST_F(RetentionTest, HeavyFilesBeyondTheNewestPartsGoAndTheRecordStays) {
  RetentionConfig rule;
  rule.heavy.parts = 2;
  const SettledFn settled = [](const std::string& id) { return id != "p2"; };
  auto r = Prune(layout_, rule, settled, now_);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->heavy, 3);  // p1, p3, p4; p2 is not yet recorded or delivered
  EXPECT_EQ(r->unsettled, 1);
  EXPECT_EQ(r->bytes, 6000u);
  for (int i : {1, 3, 4}) {
    EXPECT_FALSE(Has(Id(i), "errormap.ply") || Has(Id(i), "report.html")) << i;
    EXPECT_TRUE(Has(Id(i), "report.json") && Has(Id(i), "report.pdf") && Has(Id(i), "result.qif"));
  }
  for (int i : {2, 5, 6}) EXPECT_TRUE(Has(Id(i), "errormap.ply") && Has(Id(i), "report.html")) << i;
  EXPECT_NE(PruneText(*r).find("1 due but kept"), std::string::npos) << PruneText(*r);
  auto again = Prune(layout_, rule, settled, now_);
  EXPECT_EQ(again->heavy, 0) << "nothing left to prune";
}

TEST_F(RetentionTest, OldResultsFoldersAndArchivedScansBeyondTheirSizeGo) {
  RetentionConfig rule;
  rule.light.days = 4.5;     // p1 (6 days) and p2 (5 days)
  rule.archive.gb = 2.5e-6;  // 2,500 bytes: the newest two archived parts
  auto r = Prune(layout_, rule, {}, now_);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->light, 2);
  EXPECT_EQ(r->archive, 4);
  EXPECT_FALSE(fs::exists(fs::path(layout_.results) / "p1"));
  EXPECT_FALSE(fs::exists(fs::path(layout_.results) / "p2"));
  EXPECT_TRUE(Has("p3", "errormap.ply"));
  for (int i = 1; i <= 6; ++i)
    EXPECT_EQ(fs::exists(fs::path(layout_.archive) / Id(i)), i >= 5) << i;
}

TEST_F(RetentionTest, NoRuleKeepsEverything) {
  auto r = Prune(layout_, RetentionConfig{}, {}, now_);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->heavy + r->light + r->archive, 0);
  EXPECT_TRUE(Has("p1", "errormap.ply"));
}

TEST(RetentionConfig, TheRuleIsReadAndBadValuesAreNamed) {
  auto c = RetentionConfigOf(
      CellWith(R"({"retention": {"heavy": {"parts": 50, "gb": 2.5}, "archive": {"days": 14}}})"));
  ASSERT_TRUE(c.ok()) << c.status();
  EXPECT_EQ(c->heavy.parts, 50);
  EXPECT_EQ(c->heavy.gb, 2.5);
  EXPECT_EQ(c->archive.days, 14);
  EXPECT_FALSE(c->light.any());
  EXPECT_FALSE(RetentionConfigOf(CellWith("{}"))->any());
  for (const char* bad :
       {R"({"retention": {"raw": {"days": 1}}})", R"({"retention": {"heavy": {"weeks": 1}}})",
        R"({"retention": {"heavy": {"days": -1}}})", R"({"retention": {"heavy": {"parts": 2.5}}})",
        R"({"retention": {"light": "forever"}})", R"({"retention": []})"}) {
    const auto bad_config = RetentionConfigOf(CellWith(bad));
    EXPECT_EQ(bad_config.status().code(), absl::StatusCode::kInvalidArgument) << bad;
    EXPECT_NE(bad_config.status().message().find("cell.json: retention"), std::string::npos)
        << bad_config.status();
  }
}

}  // namespace
}  // namespace surfinspect::client
