// The parent side of a STEP import: the real worker on real files, the
// cache, and a worker that hangs or crashes (scripts in its place).
#include "core/cad/cad_import.h"

#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

#include "core/distance/mesh_index.h"
#include "tests/core/cad/cad_test_files.h"
#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

using testing::RealCad;
using testing::TempDir;

class CadImport : public ::testing::Test {
 protected:
  void SetUp() override { ::setenv("SURFINSPECT_CAD_WORKER", SURFINSPECT_CAD_WORKER_BIN, 1); }
  void TearDown() override { ::unsetenv("SURFINSPECT_CAD_WORKER"); }
  // A script standing in for the worker.
  void FakeWorker(const std::string& body) {
    const std::string path = dir.File("fake-worker");
    testing::WriteBytes(path, "#!/bin/sh\n" + body + "\n");
    ::chmod(path.c_str(), 0755);
    ::setenv("SURFINSPECT_CAD_WORKER", path.c_str(), 1);
  }
  TempDir dir;
};

TEST_F(CadImport, InchAndMillimetreCubesGiveTheSameMesh) {
  SKIP_WITHOUT_REAL_CAD();
  const auto inch = ImportCad(RealCad("cube-in.step"), {}, dir.File("cache"));
  const auto mm = ImportCad(RealCad("cube-mm.step"), {}, dir.File("cache"));
  ASSERT_TRUE(inch.ok()) << inch.status();
  ASSERT_TRUE(mm.ok()) << mm.status();
  EXPECT_EQ(inch->report.declared_unit, "INCH");
  EXPECT_EQ(mm->report.declared_unit, "MILLIMETRE");
  ASSERT_EQ(inch->mesh.num_triangles(), mm->mesh.num_triangles());
  // The same nodes, in whatever order the triangles first use them.
  const auto sorted = [](std::vector<Eigen::Vector3f> v) {
    std::sort(v.begin(), v.end(), [](const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
      return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
    });
    return v;
  };
  const std::vector<Eigen::Vector3f> a = sorted(inch->mesh.vertices), b = sorted(mm->mesh.vertices);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(a[i][k], b[i][k], 1e-9 * std::max(1.0f, std::abs(b[i][k])));
  // The same surface: Delaunay may take either diagonal of a square face
  // (four nodes on one circle), so each mesh's triangles are checked to lie
  // on the other, at their corners and centroids, to 1e-9 of the size.
  for (const auto* pair : {&*inch, &*mm}) {
    const TriangleMesh& a = pair->mesh;
    const TriangleMesh& b = pair == &*inch ? mm->mesh : inch->mesh;
    const auto index = MeshIndex::Build(b);
    ASSERT_TRUE(index.ok()) << index.status();
    for (const auto& t : a.triangles) {
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      for (uint32_t v : t) {
        EXPECT_LE((*index)->Closest(a.vertices[v].cast<double>()).distance_mm, 1e-9 * 1000);
        centroid += a.vertices[v].cast<double>() / 3;
      }
      EXPECT_LE((*index)->Closest(centroid).distance_mm, 1e-9 * 1000);
    }
  }
  EXPECT_NEAR(mm->report.bounds_mm.max.x() - mm->report.bounds_mm.min.x(), 1000, 1e-6);
}

TEST_F(CadImport, TheSecondImportIsServedFromTheCacheWithoutTheWorker) {
  SKIP_WITHOUT_REAL_CAD();
  const auto first = ImportCad(RealCad("bug3883_xr2-ct-214_l-bracket.stp"), {}, dir.File("c"));
  ASSERT_TRUE(first.ok()) << first.status();
  EXPECT_FALSE(first->from_cache);
  ::setenv("SURFINSPECT_CAD_WORKER", "/nonexistent/worker", 1);
  const auto second = ImportCad(RealCad("bug3883_xr2-ct-214_l-bracket.stp"), {}, dir.File("c"));
  ASSERT_TRUE(second.ok()) << second.status();
  EXPECT_TRUE(second->from_cache);
  EXPECT_EQ(second->mesh.triangles, first->mesh.triangles);
  EXPECT_EQ(second->groups.names, first->groups.names);
  EXPECT_EQ(second->report.source_sha256, first->report.source_sha256);
  // Another tolerance is another entry: the (missing) worker is asked.
  CadSettings finer;
  finer.tessellation.chord_tolerance_mm = 0.005;
  EXPECT_EQ(
      ImportCad(RealCad("bug3883_xr2-ct-214_l-bracket.stp"), finer, dir.File("c")).status().code(),
      absl::StatusCode::kNotFound);
}

TEST_F(CadImport, ATruncatedFileIsAClearError) {
  SKIP_WITHOUT_REAL_CAD();
  const std::string bytes = testing::ReadBytes(RealCad("nist_ctc_01_asme1_ap242-e1.stp"));
  testing::WriteBytes(dir.File("cut.stp"), bytes.substr(0, bytes.size() / 3));
  const auto r = ImportCad(dir.File("cut.stp"), {}, dir.File("cache"));
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument) << r.status();
  EXPECT_NE(r.status().message().find("cut.stp"), std::string::npos) << r.status();
}

TEST_F(CadImport, AHangingWorkerIsStoppedWithinTheLimit) {
  testing::WriteBytes(dir.File("part.step"), "ISO-10303-21;\n");
  FakeWorker("exec sleep 60");
  CadSettings s;
  s.limits.seconds = 1;
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = ImportCad(dir.File("part.step"), s, dir.File("cache"));
  EXPECT_EQ(r.status().code(), absl::StatusCode::kDeadlineExceeded) << r.status();
  EXPECT_NE(r.status().message().find("took longer than 1 s"), std::string::npos);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 15);
}

TEST_F(CadImport, ACrashingWorkerIsNamedAndLeavesNoCacheEntry) {
  testing::WriteBytes(dir.File("part.step"), "ISO-10303-21;\n");
  FakeWorker("echo 'half a mesh' > \"$4\"; kill -SEGV $$");
  const auto r = ImportCad(dir.File("part.step"), {}, dir.File("cache"));
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInternal) << r.status();
  EXPECT_NE(r.status().message().find("crashed"), std::string::npos);
  for (const auto& e : std::filesystem::directory_iterator(dir.File("cache")))
    EXPECT_NE(e.path().extension(), ".json") << e.path();
}

TEST_F(CadImport, TheRealWorkerRunsOutOfItsMemoryLimitAsAnError) {
  SKIP_WITHOUT_REAL_CAD();
  CadSettings s;
  // Enough to load OCCT, not enough for its threads' stacks and arenas.
  s.limits.memory_mb = 100;
  const auto r = ImportCad(RealCad("nist_ctc_01_asme1_ap242-e1.stp"), s, dir.File("cache"));
  EXPECT_EQ(r.status().code(), absl::StatusCode::kResourceExhausted) << r.status();
  EXPECT_NE(r.status().message().find("100 MB memory limit"), std::string::npos) << r.status();
}

TEST(CadCacheKey, DependsOnTheFileAndEverySettingThatChangesTheMesh) {
  const TessellationSettings base;
  TessellationSettings chord = base, angle = base, body = base;
  chord.chord_tolerance_mm = 0.02;
  angle.angular_tolerance_deg = 10;
  body.body = "b";
  const std::string k = CadCacheKey("abc", base);
  EXPECT_EQ(k, CadCacheKey("abc", base));
  for (const std::string& other : {CadCacheKey("abd", base), CadCacheKey("abc", chord),
                                   CadCacheKey("abc", angle), CadCacheKey("abc", body)})
    EXPECT_NE(k, other);
}

}  // namespace
}  // namespace surfinspect
