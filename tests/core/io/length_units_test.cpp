// LengthUnit (core/io/length_units.cpp): names both ways, the factors by
// definition, and scaling that leaves millimetres bit for bit.
#include "core/io/length_units.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

namespace surfinspect {
namespace {

TEST(LengthUnits, NamesAndFactorsByDefinition) {
  const struct {
    const char* name;
    double mm;
  } rows[] = {{"mm", 1}, {"cm", 10}, {"m", 1000}, {"in", 25.4}};
  for (const auto& r : rows) {
    const absl::StatusOr<LengthUnit> u = ParseLengthUnit(r.name);
    ASSERT_TRUE(u.ok()) << u.status();
    EXPECT_STREQ(LengthUnitName(*u), r.name);
    EXPECT_EQ(MillimetresPer(*u), r.mm);
  }
  for (const char* bad : {"", "MM", "inch", "metre", "um"}) {
    const absl::StatusOr<LengthUnit> u = ParseLengthUnit(bad);
    EXPECT_EQ(u.status().code(), absl::StatusCode::kInvalidArgument) << bad;
    EXPECT_NE(u.status().message().find("mm, cm, m or in"), std::string::npos);
  }
}

TEST(LengthUnits, AnUnstatedUnitIsAssumedMillimetres) {
  const absl::StatusOr<InputUnit> none = InputUnitOf("");
  ASSERT_TRUE(none.ok());
  EXPECT_FALSE(none->stated);
  EXPECT_EQ(none->unit, LengthUnit::kMillimetre);
  const absl::StatusOr<InputUnit> m = InputUnitOf("m");
  ASSERT_TRUE(m.ok());
  EXPECT_TRUE(m->stated);
  EXPECT_EQ(m->unit, LengthUnit::kMetre);
  EXPECT_FALSE(InputUnitOf("yd").ok());
}

TEST(LengthUnits, ScalingRoundsEachCoordinateOnceAndKeepsMillimetresAndNaN) {
  PointCloud c = PointCloud::Organized(3, 1);
  c.points[0] = {0.1234567f, -2.5f, 1e-3f};
  c.points[2] = {-0.f, 3.3333333f, 7.f};  // points[1] stays NaN
  PointCloud mm = c;
  ScaleToMillimetres(LengthUnit::kMillimetre, &mm);
  EXPECT_EQ(0, std::memcmp(mm.points.data(), c.points.data(), c.size() * 12));
  PointCloud inch = c;
  ScaleToMillimetres(LengthUnit::kInch, &inch);
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(inch.points[0][a], static_cast<float>(static_cast<double>(c.points[0][a]) * 25.4));
    EXPECT_TRUE(std::isnan(inch.points[1][a]));
  }
  EXPECT_TRUE(std::signbit(inch.points[2].x()));
  TriangleMesh mesh;
  mesh.vertices = {{1, 2, 3}, {0.5f, 0, 0}, {0, 0.25f, 0}};
  mesh.triangles = {{0, 1, 2}};
  ScaleToMillimetres(LengthUnit::kMetre, &mesh);
  EXPECT_EQ(mesh.vertices[0], Eigen::Vector3f(1000, 2000, 3000));
  EXPECT_EQ(mesh.vertices[2], Eigen::Vector3f(0, 250, 0));
}

}  // namespace
}  // namespace surfinspect
