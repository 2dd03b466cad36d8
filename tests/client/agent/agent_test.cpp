// The cell-agent's decisions against a fake Inspect and a fake clock: every
// test runs in milliseconds, with real folders in a temporary directory.
#include "client/agent/agent.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/io/io_point_cloud.h"
#include "proto/convert.h"
#include "tests/support/small_file_system.h"
#include "tests/support/temp_dir.h"

namespace surfinspect::client {
namespace {
namespace fs = std::filesystem;
using surfinspect::testing::ReadBytes;
using surfinspect::testing::TempDir;
using surfinspect::testing::WriteBytes;

// A small valid result, as the server sends it: 3 merged points, their
// deviations, and a report with the fields the part outputs need.
v1::InspectResult OkResult(const std::string& id) {
  v1::InspectResult r;
  r.set_part_id(id);
  r.set_verdict("pass");
  r.set_report_json(R"({"tolerance": {"band_mm": 0.3, "verdict": "pass"}, "color_range_mm": 1.0,)"
                    R"( "statistics": {"min_mm": -0.125, "max_mm": 0.25}})");
  r.set_png("not really a png");
  wire::CloudToProto(PointCloud::Unorganized({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}),
                     r.mutable_merged());
  r.set_deviations(wire::PackFloats({-0.125f, 0.0f, 0.25f}));
  return r;
}

class AgentTest : public ::testing::Test {
 protected:
  void SetUp() override {
    layout_ = ResolveLayout({tmp_.path(), "", "", "", ""});
    ASSERT_TRUE(PrepareDirectories(layout_).ok());
    CellViewpoint vp;
    vp.name = "v1";
    vp.world_from_sensor = Eigen::Isometry3d::Identity();
    cell_.viewpoints.push_back(vp);
    hooks_.sleep = [this](double s, const std::atomic<bool>&) {
      sleeps_.push_back(s);
      // A loop that never ends a test is a failure, not a hang.
      if (stop_in_sleep_ || sleeps_.size() >= 100) stop_.store(true);
    };
    hooks_.inspect = [this](const v1::PartHeader& header, const std::vector<ViewScan>& views) {
      EXPECT_EQ(views.size(), 1u);
      EXPECT_TRUE(header.return_deviations());
      ++calls_;
      absl::StatusOr<v1::InspectResult> r = OkResult(header.part_id());
      if (!answers_.empty()) {
        r = answers_.front();
        answers_.erase(answers_.begin());
      }
      return r;
    };
    settings_.backoff = {0.5, 15.0, 0};
  }

  // INBOX/<id>/v1.pcd + DONE, as a scanner drops a part.
  void DropPart(const std::string& id) {
    const fs::path dir = fs::path(layout_.inbox) / id;
    fs::create_directories(dir);
    ASSERT_TRUE(WritePointCloud((dir / "v1.pcd").string(),
                                PointCloud::Unorganized({{0, 0, 400}, {1, 0, 400}, {0, 1, 400}}))
                    .ok());
    WriteBytes((dir / "DONE").string(), "");
  }

  CellAgent Agent() { return CellAgent(cell_, layout_, settings_, hooks_, 7); }
  bool InInbox(const std::string& id) const { return fs::exists(fs::path(layout_.inbox) / id); }

  TempDir tmp_;
  InboxLayout layout_;
  CellConfig cell_;
  AgentSettings settings_;
  AgentHooks hooks_;
  std::vector<absl::StatusOr<v1::InspectResult>> answers_;  // then OK
  std::vector<double> sleeps_;
  std::atomic<bool> stop_{false};
  bool stop_in_sleep_ = false;
  int calls_ = 0;
};

TEST_F(AgentTest, UnavailableTwiceThenOkIsDoneAfterThreeCalls) {
  DropPart("p1");
  answers_ = {absl::UnavailableError("down"), absl::UnavailableError("down")};
  CellAgent agent = Agent();
  const PartReport r = agent.ProcessPart("p1", stop_);
  EXPECT_EQ(r.outcome, PartOutcome::kDone) << r.message;
  EXPECT_EQ(r.inspect_calls, 3);
  EXPECT_EQ(calls_, 3);
  ASSERT_EQ(sleeps_.size(), 2u);  // backoff waited twice, within the full-jitter caps
  EXPECT_LE(sleeps_[0], 0.5);
  EXPECT_LE(sleeps_[1], 1.0);
  EXPECT_EQ(r.verdict, "pass");
  EXPECT_DOUBLE_EQ(r.max_mm, 0.25);
  EXPECT_DOUBLE_EQ(r.min_mm, -0.125);
  // The cell's outputs (the defaults: all but the CSV), and no other file;
  // the fake server's report has no plan, so no result.qif.
  for (const PartFileEntry& e : PartFileCatalogue())
    EXPECT_EQ(fs::exists(fs::path(layout_.results) / "p1" / e.file_name),
              cell_.outputs.Has(e.file) && e.file != PartFile::kQif)
        << e.file_name;
  EXPECT_FALSE(InInbox("p1"));
  EXPECT_TRUE(fs::exists(fs::path(layout_.archive) / "p1" / "v1.pcd"));
}

TEST_F(AgentTest, ThePartGetsTheFilesTheCellsOutputsName) {
  cell_.outputs = PartFileSet::All();
  cell_.outputs.Set(PartFile::kPdf, false);
  DropPart("p1");
  CellAgent agent = Agent();
  ASSERT_EQ(agent.ProcessPart("p1", stop_).outcome, PartOutcome::kDone);
  for (const PartFileEntry& e : PartFileCatalogue())
    EXPECT_EQ(fs::exists(fs::path(layout_.results) / "p1" / e.file_name),
              e.file != PartFile::kPdf && e.file != PartFile::kQif)
        << e.file_name;
}

TEST_F(AgentTest, ReportHtmlCarriesTheCellAndTheMeshReadOnce) {
  cell_.name = "cell-7";
  cell_.part_mesh = tmp_.path() + "/part.off";
  WriteBytes(cell_.part_mesh, "OFF\n3 1 0\n0 0 0\n10 0 0\n0 10 0\n3 0 1 2\n");
  DropPart("p1");
  DropPart("p2");
  CellAgent agent = Agent();
  EXPECT_EQ(agent.ProcessPart("p1", stop_).outcome, PartOutcome::kDone);
  fs::remove(cell_.part_mesh);  // read once: the second part still has it
  EXPECT_EQ(agent.ProcessPart("p2", stop_).outcome, PartOutcome::kDone);
  for (const char* id : {"p1", "p2"}) {
    const std::string html = ReadBytes((fs::path(layout_.results) / id / "report.html").string());
    EXPECT_NE(html.find("\"triangles\":1"), std::string::npos) << id;
    EXPECT_NE(html.find("cell cell-7"), std::string::npos) << id;
  }
}

TEST_F(AgentTest, InvalidArgumentGoesToQuarantineWithErrorTxt) {
  DropPart("p1");
  answers_ = {absl::InvalidArgumentError("scan v1: width is 0")};
  CellAgent agent = Agent();
  const PartReport r = agent.ProcessPart("p1", stop_);
  EXPECT_EQ(r.outcome, PartOutcome::kQuarantined);
  EXPECT_EQ(r.message, "INVALID_ARGUMENT: scan v1: width is 0");
  EXPECT_EQ(calls_, 1);
  EXPECT_TRUE(sleeps_.empty());
  EXPECT_EQ(ReadBytes((fs::path(layout_.quarantine) / "p1" / "error.txt").string()),
            "INVALID_ARGUMENT: scan v1: width is 0\n");
  EXPECT_FALSE(InInbox("p1"));
  EXPECT_FALSE(fs::exists(fs::path(layout_.results) / "p1"));
}

TEST_F(AgentTest, StopDuringBackoffLeavesThePartInTheInbox) {
  DropPart("p1");
  answers_ = {absl::UnavailableError("down")};
  stop_in_sleep_ = true;
  CellAgent agent = Agent();
  const PartReport r = agent.ProcessPart("p1", stop_);
  EXPECT_EQ(r.outcome, PartOutcome::kStopped);
  EXPECT_EQ(calls_, 1);  // no call after the stop
  EXPECT_EQ(sleeps_.size(), 1u);
  EXPECT_TRUE(InInbox("p1"));
  EXPECT_FALSE(fs::exists(fs::path(layout_.results) / "p1"));
  EXPECT_FALSE(fs::exists(layout_.archive));
  EXPECT_FALSE(fs::exists(layout_.quarantine));
}

TEST_F(AgentTest, RetriesExhaustedLeaveThePartForLater) {
  DropPart("p1");
  settings_.backoff.max_attempts = 2;
  answers_ = {absl::UnavailableError("down"), absl::DeadlineExceededError("slow")};
  CellAgent agent = Agent();
  const PartReport r = agent.ProcessPart("p1", stop_);
  EXPECT_EQ(r.outcome, PartOutcome::kRetryLater);
  EXPECT_NE(r.message.find("slow"), std::string::npos) << r.message;
  EXPECT_EQ(calls_, 2);
  EXPECT_EQ(sleeps_.size(), 1u);
  EXPECT_TRUE(InInbox("p1"));
}

TEST_F(AgentTest, PartWithResultsOnDiskIsArchivedWithoutACall) {
  DropPart("p1");
  fs::create_directories(fs::path(layout_.results) / "p1");
  WriteBytes((fs::path(layout_.results) / "p1" / "report.json").string(), "{}");
  CellAgent agent = Agent();
  const PartReport r = agent.ProcessPart("p1", stop_);
  EXPECT_EQ(r.outcome, PartOutcome::kArchivedWithoutCall);
  EXPECT_EQ(calls_, 0);
  EXPECT_TRUE(fs::exists(fs::path(layout_.archive) / "p1" / "v1.pcd"));
  EXPECT_EQ(ReadBytes((fs::path(layout_.results) / "p1" / "report.json").string()), "{}");
}

// Listeners hear of a part once its results are on disk, whether it was just
// inspected or a restart found its results; never of a quarantined part.
TEST_F(AgentTest, ListenersHearStartedAndStoredPartsOnly) {
  std::vector<std::string> heard;
  hooks_.on_started.push_back([&](const std::string& id) { heard.push_back("started " + id); });
  hooks_.on_stored.push_back([&](const std::string& id, const std::string& dir) {
    EXPECT_TRUE(fs::exists(fs::path(dir) / "report.json")) << dir;
    heard.push_back("stored " + id);
  });
  answers_ = {absl::InvalidArgumentError("bad scan")};
  DropPart("p0");
  DropPart("p1");
  DropPart("p2");
  fs::create_directories(fs::path(layout_.results) / "p2");
  WriteBytes((fs::path(layout_.results) / "p2" / "report.json").string(), "{}");
  CellAgent agent = Agent();
  EXPECT_EQ(agent.ProcessPart("p0", stop_).outcome, PartOutcome::kQuarantined);
  EXPECT_EQ(agent.ProcessPart("p1", stop_).outcome, PartOutcome::kDone);
  EXPECT_EQ(agent.ProcessPart("p2", stop_).outcome, PartOutcome::kArchivedWithoutCall);
  EXPECT_EQ(heard,
            (std::vector<std::string>{"started p0", "started p1", "stored p1", "stored p2"}));
}

TEST_F(AgentTest, ArchiveNameCollisionKeepsBothParts) {
  const fs::path earlier = fs::path(layout_.archive) / "p1";
  fs::create_directories(earlier);
  WriteBytes((earlier / "earlier.txt").string(), "first p1");
  DropPart("p1");
  CellAgent agent = Agent();
  const PartReport r = agent.ProcessPart("p1", stop_);
  EXPECT_EQ(r.outcome, PartOutcome::kDone) << r.message;
  EXPECT_TRUE(r.message.empty()) << r.message;
  EXPECT_EQ(ReadBytes((earlier / "earlier.txt").string()), "first p1");
  EXPECT_FALSE(fs::exists(earlier / "v1.pcd"));
  EXPECT_TRUE(fs::exists(fs::path(layout_.archive) / "p1.1" / "v1.pcd"));
  EXPECT_TRUE(fs::exists(fs::path(layout_.archive) / "p1.1" / "DONE"));
  EXPECT_FALSE(InInbox("p1"));
}

// The quarantine folder cannot be created (a regular file is in its way):
// the part is reported, left in the inbox, never sent again, and the loop
// waits a poll interval between passes instead of spinning.
TEST_F(AgentTest, FailedQuarantineIsReportedRetriedLaterAndNeverResent) {
  WriteBytes(layout_.quarantine, "a file where the quarantine folder should be");
  DropPart("p1");
  // The same verdict however often it is asked.
  answers_.assign(8, absl::InvalidArgumentError("bad settings"));
  CellAgent agent = Agent();
  const PartReport first = agent.ProcessPart("p1", stop_);
  EXPECT_EQ(first.outcome, PartOutcome::kRetryLater);
  EXPECT_NE(first.message.find("cannot quarantine (INVALID_ARGUMENT: bad settings)"),
            std::string::npos)
      << first.message;
  EXPECT_NE(first.message.find(layout_.quarantine), std::string::npos) << first.message;
  EXPECT_TRUE(InInbox("p1"));
  EXPECT_EQ(calls_, 1);

  std::vector<PartReport> reports;
  const RunSummary s = agent.Run(stop_, [&](const PartReport& r) {
    reports.push_back(r);
    if (reports.size() == 4) stop_.store(true);
  });
  ASSERT_EQ(reports.size(), 4u);
  for (const auto& r : reports) EXPECT_EQ(r.outcome, PartOutcome::kRetryLater);
  EXPECT_EQ(calls_, 1);           // never re-sent
  EXPECT_EQ(sleeps_.size(), 3u);  // one poll wait between passes: no spin
  for (double w : sleeps_) EXPECT_EQ(w, settings_.poll_s);
  EXPECT_EQ(s.quarantined, 0);  // not counted as quarantined
  EXPECT_TRUE(InInbox("p1"));

  // Once the folder can be made, the part moves with the first verdict.
  fs::remove(layout_.quarantine);
  stop_.store(false);
  const PartReport last = agent.ProcessPart("p1", stop_);
  EXPECT_EQ(last.outcome, PartOutcome::kQuarantined);
  EXPECT_EQ(calls_, 1);
  EXPECT_EQ(ReadBytes((fs::path(layout_.quarantine) / "p1" / "error.txt").string()),
            "INVALID_ARGUMENT: bad settings\n");
  EXPECT_FALSE(InInbox("p1"));
}

TEST_F(AgentTest, FailedArchiveOfAPartWithResultsWaitsForThePoll) {
  WriteBytes(layout_.archive, "a file where the archive folder should be");
  DropPart("p1");
  settings_.once = true;
  CellAgent agent = Agent();
  std::vector<PartReport> reports;
  const RunSummary s = agent.Run(stop_, [&](const PartReport& r) { reports.push_back(r); });
  // Sent once, results written; the archive fails, so the next pass tries
  // again without a call and, making no progress, ends the --once run.
  ASSERT_EQ(reports.size(), 2u);
  EXPECT_EQ(reports[0].outcome, PartOutcome::kDone);
  EXPECT_FALSE(reports[0].message.empty());
  EXPECT_EQ(reports[1].outcome, PartOutcome::kRetryLater);
  EXPECT_EQ(calls_, 1);
  EXPECT_EQ(s.done, 1);
  EXPECT_TRUE(InInbox("p1"));
  EXPECT_TRUE(fs::exists(fs::path(layout_.results) / "p1" / "report.json"));
}

TEST_F(AgentTest, CorruptScanIsQuarantinedWithoutACall) {
  DropPart("p1");
  const std::string scan = (fs::path(layout_.inbox) / "p1" / "v1.pcd").string();
  const std::string bytes = ReadBytes(scan);
  // Keep the header and the first of the three points (PCL pads the file).
  const std::size_t data = bytes.find("DATA binary\n");
  ASSERT_NE(data, std::string::npos);
  WriteBytes(scan, bytes.substr(0, data + 12 + 12));
  CellAgent agent = Agent();
  const PartReport r = agent.ProcessPart("p1", stop_);
  EXPECT_EQ(r.outcome, PartOutcome::kQuarantined);
  EXPECT_EQ(calls_, 0);
  EXPECT_NE(r.message.find("truncated"), std::string::npos) << r.message;
  EXPECT_EQ(ReadBytes((fs::path(layout_.quarantine) / "p1" / "error.txt").string()),
            r.message + "\n");
}

TEST_F(AgentTest, InvalidIdAndMissingScansAreQuarantined) {
  DropPart("p 1");
  fs::create_directories(fs::path(layout_.inbox) / "p2");
  WriteBytes((fs::path(layout_.inbox) / "p2" / "DONE").string(), "");
  CellAgent agent = Agent();
  EXPECT_EQ(agent.ProcessPart("p 1", stop_).outcome, PartOutcome::kQuarantined);
  const PartReport r = agent.ProcessPart("p2", stop_);
  EXPECT_EQ(r.outcome, PartOutcome::kQuarantined);
  EXPECT_NE(r.message.find("no <viewpoint>.pcd"), std::string::npos);
  EXPECT_EQ(calls_, 0);
}

TEST_F(AgentTest, UncalibratedViewpointStopsTheRun) {
  cell_.viewpoints[0].world_from_sensor.reset();
  DropPart("p1");
  CellAgent agent = Agent();
  std::vector<PartReport> reports;
  const RunSummary s = agent.Run(stop_, [&](const PartReport& r) { reports.push_back(r); });
  EXPECT_TRUE(s.config_error);
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_EQ(reports[0].outcome, PartOutcome::kConfigError);
  EXPECT_EQ(calls_, 0);
  EXPECT_TRUE(InInbox("p1"));
}

TEST_F(AgentTest, OnceRunProcessesTheInboxAndReturns) {
  DropPart("a");
  DropPart("b");
  settings_.once = true;
  answers_ = {OkResult("a"), absl::FailedPreconditionError("gauge too far")};
  CellAgent agent = Agent();
  const RunSummary s = agent.Run(stop_, {});
  EXPECT_EQ(s.done, 1);
  EXPECT_EQ(s.pass, 1);
  EXPECT_EQ(s.quarantined, 1);
  EXPECT_EQ(calls_, 2);
  EXPECT_TRUE(CompleteParts(layout_.inbox).empty());
  EXPECT_TRUE(sleeps_.empty());
}

TEST_F(AgentTest, AFullDiskPausesWithThePartsInTheInboxAndResumesWhenSpaceReturns) {
  std::string why;
  const auto small = surfinspect::testing::SmallFileSystem::Mount(16 << 20, &why);
  if (!small) GTEST_SKIP() << why;
  layout_.results = small->File("results");
  ASSERT_TRUE(PrepareDirectories(layout_).ok());
  surfinspect::testing::FillWithZeros(small->File("filler"), uint64_t{32} << 20);
  DiskGuard disk({layout_.results}, DiskConfig{0});
  std::vector<std::string> told;
  hooks_.disk = &disk;
  hooks_.on_disk.push_back([&told](const std::string& reason) { told.push_back(reason); });
  settings_.once = true;
  DropPart("p1");
  DropPart("p2");
  CellAgent agent = Agent();
  agent.Run(stop_, {});
  EXPECT_EQ(calls_, 1) << "the first part found the disk full; the second was not sent";
  ASSERT_EQ(told.size(), 1u);
  EXPECT_NE(told[0].find("no space left"), std::string::npos) << told[0];
  EXPECT_TRUE(InInbox("p1") && InInbox("p2"));
  EXPECT_FALSE(fs::exists(fs::path(layout_.results) / "p1")) << "no half-written set";
  agent.Run(stop_, {});  // still full: paused, nothing sent, nothing told again
  EXPECT_EQ(calls_, 1);
  EXPECT_EQ(told.size(), 1u);
  fs::remove(small->File("filler"));
  const RunSummary s = agent.Run(stop_, {});
  EXPECT_EQ(s.done, 2);
  ASSERT_EQ(told.size(), 2u);
  EXPECT_EQ(told[1], "") << "resumed";
  EXPECT_TRUE(HasResults(layout_, "p1") && HasResults(layout_, "p2"));
  EXPECT_GT(disk.need_bytes(), 0u) << "a part's set size is known now";
}

TEST_F(AgentTest, UnfinishedSetsAreRemovedAndFinishedOnesKept) {
  fs::create_directories(fs::path(layout_.results) / ".partial" / "p1.123.0");
  WriteBytes((fs::path(layout_.results) / ".partial" / "p1.123.0" / "report.json").string(), "{}");
  fs::create_directories(fs::path(layout_.results) / "p2");  // written in place, then killed
  WriteBytes((fs::path(layout_.results) / "p2" / "errormap.ply").string(), "half");
  fs::create_directories(fs::path(layout_.results) / "p3");
  WriteBytes((fs::path(layout_.results) / "p3" / "report.json").string(), "{}");
  WriteBytes((fs::path(layout_.results) / "results.db").string(), "");
  auto removed = RemoveUnfinishedSets(layout_.results);
  ASSERT_TRUE(removed.ok()) << removed.status();
  EXPECT_EQ(*removed, (std::vector<std::string>{"p1.123.0", "p2"}));
  EXPECT_TRUE(HasResults(layout_, "p3"));
  EXPECT_TRUE(fs::exists(fs::path(layout_.results) / "results.db"));
  EXPECT_FALSE(fs::exists(fs::path(layout_.results) / "p2"));
}

TEST(AgentLayoutTest, ArchiveAndQuarantineDefaultBesideTheInbox) {
  const InboxLayout l = ResolveLayout({"", "/data/inbox", "/data/results", "", ""});
  EXPECT_EQ(l.inbox, "/data/inbox");
  EXPECT_EQ(l.results, "/data/results");
  EXPECT_EQ(l.archive, "/data/archive");
  EXPECT_EQ(l.quarantine, "/data/quarantine");
  const InboxLayout slash = ResolveLayout({"", "/data/in/", "", "", ""});
  EXPECT_EQ(slash.archive, "/data/archive");
  EXPECT_EQ(slash.results, "results");
  const InboxLayout rel = ResolveLayout({"", "", "", "", ""});
  EXPECT_EQ(rel.inbox, "inbox");
  EXPECT_EQ(rel.archive, (fs::current_path() / "archive").string());
}

TEST(AgentLayoutTest, CellDirSetsTheDefaultsAndExplicitFoldersWin) {
  const InboxLayout l = ResolveLayout({"/cell", "", "", "", ""});
  EXPECT_EQ(l.inbox, "/cell/inbox");
  EXPECT_EQ(l.results, "/cell/results");
  EXPECT_EQ(l.archive, "/cell/archive");
  EXPECT_EQ(l.quarantine, "/cell/quarantine");
  const InboxLayout mixed = ResolveLayout({"/cell", "/scanner/in", "", "", "/bad"});
  EXPECT_EQ(mixed.inbox, "/scanner/in");
  EXPECT_EQ(mixed.results, "/cell/results");
  EXPECT_EQ(mixed.archive, "/cell/archive");
  EXPECT_EQ(mixed.quarantine, "/bad");
}

TEST(AgentLayoutTest, PrepareDirectoriesNamesTheFolderAndTheError) {
  TempDir tmp;
  WriteBytes(tmp.File("file"), "x");
  const InboxLayout l =
      ResolveLayout({"", tmp.File("inbox"), tmp.File("file") + "/results", "", ""});
  const absl::Status st = PrepareDirectories(l);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find(tmp.File("file") + "/results"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("Not a directory"), std::string::npos) << st.message();
}

}  // namespace
}  // namespace surfinspect::client
