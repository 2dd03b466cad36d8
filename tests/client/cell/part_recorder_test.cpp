// Recording parts from their files: errormap.ply read back exactly, the
// triangle summary by matching again equal to the in-process triangle ids,
// the catch-up that records each missing part once.
#include "client/cell/part_recorder.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "core/history/triangle_summary.h"
#include "core/io/atomic_file.h"
#include "core/report/error_map_output.h"
#include "tests/support/temp_dir.h"
#include "tests/support/test_meshes.h"

namespace surfinspect::client {
namespace {
namespace fs = std::filesystem;
using surfinspect::testing::TempDir;

const char kReport[] = R"({"verdict": "pass", "defects": [], "characteristics": [
  {"name": "surface", "type": "surface", "verdict": "pass", "mean_mm": 0.01, "points": 10,
   "tolerance_mm": {"lower": -0.3, "upper": 0.3}}]})";

// Points 0.02 mm above a 10 x 10 mm sheet of 4 x 4 cells (32 triangles),
// with one far point (unmatched) and one invalid point.
struct Sheet {
  Sheet() {
    mesh =
        surfinspect::testing::HeightField(0, 10, 0, 10, 5, 5, [](double, double) { return 0.0; });
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<float> u(0.1f, 9.9f);
    for (int i = 0; i < 500; ++i) cloud.points.push_back({u(rng), u(rng), 0.02f});
    cloud.points.push_back({5, 5, 50});
    cloud.points.push_back({NAN, 0, 0});
    cloud.width = cloud.points.size();
    cloud.height = 1;
    index = *MeshIndex::Build(mesh);
    BatchQuerySettings q;
    q.max_distance_mm = 5;  // the recorder's context below
    auto closest = QueryClosest(*index, cloud, Eigen::Isometry3d::Identity(), q);
    for (const ClosestPoint& c : *closest) {
      result.triangle_id.push_back(c.triangle_id);
      result.deviation_mm.push_back(c.matched() ? 0.02f : NAN);
    }
    result.tolerance_mm = 0.1;
    result.color_range_mm = 0.3;
  }
  TriangleMesh mesh;
  PointCloud cloud;
  std::shared_ptr<const MeshIndex> index;
  ErrorMapResult result;
};

RecordContext Context(const Sheet& s) {
  RecordContext c;
  c.cell = "cell-1";
  c.part = s.index;
  c.max_distance_mm = 5;
  return c;
}

void WritePart(const Sheet& s, const std::string& dir) {
  fs::create_directories(dir);
  ASSERT_TRUE(WriteErrorMapPly(dir + "/errormap.ply", s.cloud, s.result, "world").ok());
  ASSERT_TRUE(WriteStringAtomically(dir + "/report.json", kReport).ok());
}

TEST(PartRecorder, ErrorMapPlyReadsBackExactly) {
  Sheet s;
  TempDir dir;
  WritePart(s, dir.path());
  PointCloud back;
  std::vector<float> dev;
  ASSERT_TRUE(ReadErrorMapPly(dir.File("errormap.ply"), &back, &dev).ok());
  ASSERT_EQ(back.size(), s.cloud.size() - 1);  // the invalid point is not written
  for (std::size_t i = 0; i < back.size(); ++i) {
    EXPECT_EQ(back.points[i], s.cloud.points[i]);
    EXPECT_EQ(std::isnan(dev[i]), std::isnan(s.result.deviation_mm[i]));
  }
  surfinspect::testing::WriteBytes(dir.File("bad.ply"), "ply\nformat ascii 1.0\nend_header\n");
  const absl::Status st = ReadErrorMapPly(dir.File("bad.ply"), &back, &dev);
  EXPECT_NE(st.message().find("bad.ply"), std::string::npos) << st;
}

TEST(PartRecorder, MatchingAgainEqualsTheInProcessTriangles) {
  Sheet s;
  TempDir dir;
  WritePart(s, dir.path());
  auto from_files = PartRecordFromFiles(Context(s), "p1", dir.path());
  ASSERT_TRUE(from_files.ok()) << from_files.status();
  auto in_process = SummarizeByTriangle(s.result.triangle_id, s.result.deviation_mm, 32);
  ASSERT_TRUE(in_process.ok());
  ASSERT_EQ(from_files->triangles.size(), in_process->size());
  for (std::size_t i = 0; i < in_process->size(); ++i) {
    EXPECT_EQ(from_files->triangles[i].triangle_id, (*in_process)[i].triangle_id);
    EXPECT_EQ(from_files->triangles[i].count, (*in_process)[i].count);
    EXPECT_EQ(from_files->triangles[i].mean_mm, (*in_process)[i].mean_mm);
  }
  EXPECT_EQ(from_files->num_triangles, 32u);
  EXPECT_EQ(from_files->verdict, "pass");
  EXPECT_EQ(from_files->cell, "cell-1");
  EXPECT_NE(from_files->files_json.find("errormap.ply"), std::string::npos);
  EXPECT_EQ(from_files->inspected_utc.size(), std::string("2026-12-01T11:39:48.123456Z").size());
}

TEST(PartRecorder, CatchUpRecordsEachMissingPartOnce) {
  Sheet s;
  TempDir dir;
  for (const char* id : {"a", "b", "c"}) WritePart(s, dir.File("results/") + id);
  fs::create_directories(dir.File("results/unfinished"));  // no report.json yet: not a part
  fs::create_directories(dir.File("results/broken"));
  surfinspect::testing::WriteBytes(dir.File("results/broken/report.json"), "{");
  auto store = OpenResultsStore(dir.File("results/results.db"));
  ASSERT_TRUE(store.ok());
  ASSERT_TRUE(*RecordPartFromFiles(**store, Context(s), "b", dir.File("results/b")));
  std::vector<std::string> skipped;
  auto n = CatchUpFromFiles(**store, Context(s), dir.File("results"), &skipped);
  ASSERT_TRUE(n.ok()) << n.status();
  EXPECT_EQ(*n, 2);  // a and c; b was there
  ASSERT_EQ(skipped.size(), 1u);
  EXPECT_NE(skipped[0].find("broken"), std::string::npos);
  EXPECT_EQ(*CatchUpFromFiles(**store, Context(s), dir.File("results")), 0);
  EXPECT_EQ((*store)->Load({})->size(), 3u);
}

TEST(PartRecorder, PlanHashIsSha256OfThePlan) {
  EXPECT_EQ(PlanHash(nlohmann::json::object()),  // sha256("{}")
            "44136fa355b3678a1146ad16f7e8649e94fb4fc21fe77e8310c060f61caaff8a");
}

}  // namespace
}  // namespace surfinspect::client
