#include "core/report/html_payload.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace surfinspect {
namespace {

struct Cloud {
  PointCloud points;
  std::vector<float> deviation;
};

Cloud RandomCloud(std::size_t n, uint32_t seed) {
  Cloud c;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> x(-150, 150), y(-60, 60), z(0, 40), d(-0.8f, 0.8f);
  for (std::size_t i = 0; i < n; ++i) {
    c.points.points.emplace_back(x(rng), y(rng), z(rng));
    c.deviation.push_back(i % 97 == 0 ? NAN : d(rng));
  }
  c.points.width = static_cast<uint32_t>(n);
  c.points.height = 1;
  return c;
}

TEST(HtmlPayload, RoundTripWithinTheQuantisationError) {
  Cloud c = RandomCloud(20000, 1);
  c.points.points[5] = Eigen::Vector3f::Constant(NAN);  // no coordinates: not shown
  const DeviationPalette palette = MakeDeviationPalette(0.3, 1.0);
  auto p = BuildHtmlPayload(c.points, c.deviation, palette, nullptr);
  ASSERT_TRUE(p.ok()) << p.status();
  EXPECT_FALSE(p->thinned);
  EXPECT_EQ(p->input_points, 20000u);
  EXPECT_EQ(p->finite_points, 19999u);
  ASSERT_EQ(p->positions.size(), 19999u);
  ASSERT_EQ(p->source.size(), 19999u);
  // The stated bounds: half a step per axis, half a deviation step.
  const Eigen::Vector3d half = p->positions.step / 2 * (1 + 1e-9);
  const double half_dev = p->deviation_step_mm / 2 * (1 + 1e-6);
  EXPECT_LE(p->positions.step.maxCoeff(), 300.0 / 65535 * 1.001);
  for (std::size_t i = 0; i < p->source.size(); ++i) {
    const uint32_t src = p->source[i];
    EXPECT_NE(src, 5u);
    const Eigen::Vector3d err =
        (p->positions.Decode(i) - c.points.points[src].cast<double>()).cwiseAbs();
    ASSERT_TRUE((err.array() <= half.array() + 1e-6).all()) << i << ": " << err.transpose();
    const float d = c.deviation[src];
    if (std::isnan(d)) {
      EXPECT_EQ(p->deviation[i], kDeviationMissing);
      EXPECT_TRUE(std::isnan(p->DecodeDeviation(i)));
      EXPECT_EQ(p->palette_index[i], kPaletteUnmatched);
    } else {
      ASSERT_LE(std::abs(p->DecodeDeviation(i) - d), half_dev) << i;
      EXPECT_EQ(p->palette_index[i], PaletteIndex(palette, d));
    }
  }
}

TEST(HtmlPayload, ThinningKeepsTheCapAndThePeak) {
  Cloud c = RandomCloud(200000, 2);
  c.deviation[123456] = -2.5f;  // the deepest point of the part
  PayloadSettings s;
  s.max_points = 30000;
  auto p = BuildHtmlPayload(c.points, c.deviation, MakeDeviationPalette(0.3, 1.0), nullptr, s);
  ASSERT_TRUE(p.ok()) << p.status();
  EXPECT_TRUE(p->thinned);
  EXPECT_LE(p->positions.size(), s.max_points);
  EXPECT_GE(p->positions.size(), s.max_points / 2);
  EXPECT_GT(p->cell_mm, 0);
  EXPECT_NE(std::find(p->source.begin(), p->source.end(), 123456u), p->source.end());
  double lowest = 0;
  for (std::size_t i = 0; i < p->deviation.size(); ++i)
    if (p->deviation[i] != kDeviationMissing) lowest = std::min(lowest, p->DecodeDeviation(i));
  EXPECT_NEAR(lowest, -2.5, p->deviation_step_mm);
}

// The viewer draws a prefix as its preview: a raster-scanned sheet's first
// eighth, in payload order, reaches every part of the sheet.
TEST(HtmlPayload, EveryPrefixIsAnEvenPreview) {
  Cloud c;
  for (int j = 0; j < 200; ++j)
    for (int i = 0; i < 300; ++i) {
      c.points.points.emplace_back(i * 0.5f, j * 0.5f, 0.01f * i);
      c.deviation.push_back(0.0f);
    }
  c.points.width = 300;
  c.points.height = 200;
  auto p = BuildHtmlPayload(c.points, c.deviation, MakeDeviationPalette(0.3, 1.0), nullptr);
  ASSERT_TRUE(p.ok()) << p.status();
  ASSERT_EQ(p->source.size(), 60000u);
  int quadrant[4] = {0, 0, 0, 0};
  for (std::size_t i = 0; i < 60000 / 8; ++i) {
    const Eigen::Vector3d q = p->positions.Decode(i);
    ++quadrant[(q.x() >= 75.0) + 2 * (q.y() >= 50.0)];
  }
  for (int count : quadrant) EXPECT_NEAR(count, 60000 / 32, 60000 / 32 / 10);
}

TEST(HtmlPayload, MeshIsQuantisedInItsOwnBox) {
  Cloud c = RandomCloud(10, 3);
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {100, 0, 0}, {0, 50, 10}};
  mesh.triangles = {{0, 1, 2}};
  auto p = BuildHtmlPayload(c.points, c.deviation, MakeDeviationPalette(0.3, 1.0), &mesh);
  ASSERT_TRUE(p.ok());
  ASSERT_EQ(p->mesh_vertices.size(), 3u);
  EXPECT_EQ(p->mesh_triangles, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_NEAR((p->mesh_vertices.Decode(2) - Eigen::Vector3d(0, 50, 10)).norm(), 0, 1e-3);
  PayloadSettings small;
  small.max_mesh_triangles = 0;
  auto q = BuildHtmlPayload(c.points, c.deviation, MakeDeviationPalette(0.3, 1.0), &mesh, small);
  ASSERT_TRUE(q.ok());
  EXPECT_TRUE(q->mesh_omitted);
  EXPECT_TRUE(q->mesh_triangles.empty());
}

TEST(HtmlPayload, RefusesMismatchedSizes) {
  Cloud c = RandomCloud(10, 4);
  c.deviation.pop_back();
  auto p = BuildHtmlPayload(c.points, c.deviation, MakeDeviationPalette(0.3, 1.0), nullptr);
  EXPECT_EQ(p.status().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace surfinspect
