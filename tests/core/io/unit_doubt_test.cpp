// The unit plausibility rules (core/io/unit_doubt.cpp) on PCL's real Kinect
// and stereo clouds, which are in metres, read as they are and scaled to
// millimetres; on meshes in both units; and on each rule's edge.
#include "core/io/unit_doubt.h"

#include <gtest/gtest.h>

#include "core/io/io_point_cloud.h"
#include "core/io/length_units.h"
#include "tests/support/real_data.h"
#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

constexpr const char* kRealClouds[] = {"clouds/table_scene_mug_stereo_textured.pcd",
                                       "clouds/pairwise__capture0001.pcd"};

UnitSubject Cloud(const PointCloud& c, bool stated = false) {
  return {"cloud c.pcd", "--cloud-units", ExtentOf(c), stated};
}
UnitSubject Mesh(const TriangleMesh& m, bool stated = false) {
  return {"mesh m.stl", "--mesh-units", ExtentOf(m), stated};
}

// A square grid of n x n points `size` wide, in the plane z = 400 size/300.
PointCloud Grid(int n, double size) {
  PointCloud c = PointCloud::Organized(n, n);
  for (int i = 0; i < n * n; ++i)
    c.points[i] =
        Eigen::Vector3d(size * (i % n) / n, size * (i / n) / n, size * 4 / 3).cast<float>();
  return c;
}

TEST(UnitDoubt, RealCloudsInMetresAreDoubtedAndTheSameInMillimetresAreNot) {
  for (const char* name : kRealClouds) {
    SKIP_WITHOUT_REAL_DATA(name);
    absl::StatusOr<PointCloud> cloud = ReadPointCloud(testing::RealData(name));
    ASSERT_TRUE(cloud.ok()) << cloud.status();
    const std::string doubt = SizeDoubt(Cloud(*cloud));
    EXPECT_NE(doubt.find("look like metres"), std::string::npos) << name << ": " << doubt;
    EXPECT_NE(doubt.find("--cloud-units m"), std::string::npos) << doubt;
    EXPECT_EQ(SizeDoubt(Cloud(*cloud, /*stated=*/true)), "") << name;
    ScaleToMillimetres(LengthUnit::kMetre, &*cloud);
    EXPECT_EQ(SizeDoubt(Cloud(*cloud)), "") << name;
    EXPECT_TRUE(UnitDoubts(Cloud(*cloud), nullptr).empty()) << name;
  }
}

TEST(UnitDoubt, TheSizeRuleNeedsEnoughItemsUnderFiveMillimetres) {
  // 32 x 32 = 1024 points: enough; 31 x 31 = 961: too few to judge.
  EXPECT_NE(SizeDoubt(Cloud(Grid(32, 0.3))), "");
  EXPECT_EQ(SizeDoubt(Cloud(Grid(31, 0.3))), "");
  // The diagonal of a grid `size` wide (z constant) is about 1.4 size.
  EXPECT_NE(SizeDoubt(Cloud(Grid(40, kSmallestPartMm / 2))), "");
  EXPECT_EQ(SizeDoubt(Cloud(Grid(40, kSmallestPartMm))), "");
  // A mesh: 100 triangles or more.
  const TriangleMesh sphere_m = testing::Icosphere(0.05, 2);  // 320 triangles, 0.1 across
  ASSERT_GE(sphere_m.num_triangles(), kMinTrianglesForSize);
  EXPECT_NE(SizeDoubt(Mesh(sphere_m)).find("320 triangles"), std::string::npos);
  const TriangleMesh box_m = testing::Box({0, 0, 0}, {0.3, 0.2, 0.1});  // 12 triangles
  EXPECT_EQ(SizeDoubt(Mesh(box_m)), "");
}

TEST(UnitDoubt, TheRatioRuleCatchesAMeshInMetresTooSmallForTheSizeRule) {
  const TriangleMesh box_m = testing::Box({0, 0, 0}, {0.3, 0.2, 0.1});
  const PointCloud scan_mm = Grid(40, 250);
  const UnitSubject mesh_m = Mesh(box_m);
  const std::vector<std::string> doubts = UnitDoubts(Cloud(scan_mm), &mesh_m);
  ASSERT_EQ(doubts.size(), 1u);
  EXPECT_NE(doubts[0].find("--mesh-units"), std::string::npos) << doubts[0];
  // The same in millimetres, or with the mesh's unit stated as mm: the cloud's is named.
  TriangleMesh box_mm = box_m;
  ScaleToMillimetres(LengthUnit::kMetre, &box_mm);
  const UnitSubject mesh_mm = Mesh(box_mm);
  EXPECT_TRUE(UnitDoubts(Cloud(scan_mm), &mesh_mm).empty());
  const UnitSubject stated = Mesh(box_m, true);
  const std::string d = RatioDoubt(Cloud(scan_mm), stated);
  EXPECT_NE(d.find("--cloud-units"), std::string::npos) << d;
  EXPECT_EQ(RatioDoubt(Cloud(scan_mm, true), stated), "");
  // A single view of a large part is far smaller than it, but not 200 times.
  const TriangleMesh car = testing::Box({0, 0, 0}, {4000, 1800, 1400});
  const UnitSubject car_mm = Mesh(car);
  EXPECT_TRUE(UnitDoubts(Cloud(Grid(40, 60)), &car_mm).empty());
}

TEST(UnitDoubt, BothFilesInMetresAreEachDoubtedOnce) {
  const TriangleMesh sphere_m = testing::Icosphere(0.08, 2);
  const UnitSubject mesh = Mesh(sphere_m);
  const std::vector<std::string> doubts = UnitDoubts(Cloud(Grid(40, 0.15)), &mesh);
  ASSERT_EQ(doubts.size(), 2u);
  EXPECT_NE(doubts[0].find("cloud c.pcd"), std::string::npos);
  EXPECT_NE(doubts[1].find("mesh m.stl"), std::string::npos);
}

}  // namespace
}  // namespace surfinspect
