// client/jobs/errormap_job.cpp: the errormap command as a library, in-process
// on a plane with a raised patch: the files asked for and no others, the
// report's numbers, and bad input refused before anything is written.
#include "client/jobs/errormap_job.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "client/cell/part_files.h"
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"
#include "tests/support/temp_dir.h"
#include "tests/support/test_meshes.h"

namespace surfinspect::client {
namespace {

namespace fs = std::filesystem;

// A 100 x 100 mm plane (part.stl) and a 40 x 30 organized scan of it
// (scan.pcd): every point 0.01 mm above, those of the first 8 columns 0.5 mm.
struct Files {
  testing::TempDir dir;
  Files() {
    EXPECT_TRUE(WriteMesh(dir.File("part.stl"), testing::FlatSquare()).ok());
    PointCloud cloud = PointCloud::Organized(40, 30);
    for (uint32_t r = 0; r < 30; ++r)
      for (uint32_t c = 0; c < 40; ++c)
        cloud.points[r * 40 + c] = {10.f + 2 * c, 10.f + 2 * r, c < 8 ? 0.5f : 0.01f};
    EXPECT_TRUE(WritePointCloud(dir.File("scan.pcd"), cloud).ok());
  }
  ErrorMapJob Job() const {
    ErrorMapJob job;
    job.cloud = dir.File("scan.pcd");
    job.mesh = dir.File("part.stl");
    job.ply = dir.File("out/map.ply");
    job.settings.tolerance_mm = 0.1;
    return job;
  }
};

std::vector<std::string> Listing(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(ErrorMapJob, WritesTheFilesAskedForAndReportsTheNumbers) {
  Files f;
  fs::create_directories(f.dir.File("out"));
  ErrorMapJob job = f.Job();
  job.report = f.dir.File("out/r.json");
  job.png = f.dir.File("out/m.png");
  job.qif = f.dir.File("out/r.qif");
  std::vector<std::string> logged;
  auto r = RunErrorMapJob(job, nullptr, nullptr,
                          [&](const std::string& line) { logged.push_back(line); });
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(Listing(f.dir.File("out")),
            (std::vector<std::string>{"m.png", "map.ply", "r.json", "r.qif"}));
  EXPECT_EQ(r->part_id, "scan");
  EXPECT_EQ(r->report.stats.matched, 1200u);
  EXPECT_EQ(r->report.tolerance.above, 240u);  // the 8 raised columns
  EXPECT_EQ(r->report.verdict, "fail");
  ASSERT_TRUE(r->report.timing.total_seconds.has_value());
  ASSERT_TRUE(r->report.inputs.has_value());
  EXPECT_EQ(r->report.inputs->cloud, job.cloud);
  // report.json is the report the job returns.
  auto written = ParseReport(testing::ReadBytes(job.report));
  ASSERT_TRUE(written.ok()) << written.status();
  EXPECT_EQ(ReportText(*written), ReportText(r->report));
  EXPECT_FALSE(logged.empty());
}

TEST(ErrorMapJob, ABadPlanIsRefusedBeforeAnyFileIsWritten) {
  Files f;
  testing::WriteBytes(f.dir.File("plan.json"), R"({"regions": [{"name": "r"}]})");
  ErrorMapJob job = f.Job();
  job.plan = f.dir.File("plan.json");
  job.report = f.dir.File("out/r.json");
  auto r = RunErrorMapJob(job, nullptr, nullptr);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("regions[0]"), std::string::npos) << r.status();
  EXPECT_FALSE(fs::exists(f.dir.File("out")));
  job.plan.clear();
  job.settings.tolerance_mm = -1;
  EXPECT_EQ(RunErrorMapJob(job, nullptr, nullptr).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_FALSE(fs::exists(f.dir.File("out")));
}

TEST(ErrorMapJob, AFileThatCannotBeWrittenIsTheError) {
  Files f;
  fs::create_directories(f.dir.File("out"));
  ErrorMapJob job = f.Job();
  job.pdf = f.dir.File("no/such/folder/r.pdf");
  auto r = RunErrorMapJob(job, nullptr, nullptr);
  EXPECT_FALSE(r.ok());
  job.pdf.clear();
  job.cloud = f.dir.File("missing.pcd");
  r = RunErrorMapJob(job, nullptr, nullptr);
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("missing.pcd"), std::string::npos) << r.status();
}

}  // namespace
}  // namespace surfinspect::client
