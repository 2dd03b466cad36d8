// core/report/section_plot.cpp: the in-plane basis, the exaggeration rule
// and every drawn point against the header's formulas written out here.
#include "core/report/section_plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace surfinspect {
namespace {

void Append(const Eigen::Vector3d& v, std::vector<double>& out) {
  out.insert(out.end(), {v.x(), v.y(), v.z()});
}

// A section in the plane through `point` with normal `n`: a curve of 60 mm
// (an arc in the plane) and whiskers along an in-plane direction.
ReportSection Section(const Eigen::Vector3d& point, const Eigen::Vector3d& n, ToleranceBand band) {
  ReportSection s;
  s.name = "S";
  s.point_mm = point;
  s.normal = n;
  s.tolerance = band;
  const Eigen::Vector3d a = n.unitOrthogonal(), b = n.cross(a);
  ReportPolyline& line = s.polylines.emplace_back();
  for (int i = 0; i <= 30; ++i)
    Append(point + (2.0 * i - 30) * a + 0.01 * (i - 15) * (i - 15) * b, line.xyz_mm);
  for (int i = 0; i < 7; ++i) {
    Append(point + (10.0 * i - 30) * a + 0.3 * b, s.whiskers.at_mm);
    Append((b + 0.1 * i * a).normalized(), s.whiskers.direction);
    s.whiskers.deviation_mm.push_back(-0.3 + 0.1 * i);
  }
  return s;
}

TEST(SectionPlot, TheBasisKeepsZUpAndSeesThePlaneFromItsNormal) {
  const DeviationPalette palette = MakeDeviationPalette(0.1, 0.5);
  struct Case {
    Eigen::Vector3d n, right, up;
  };
  const Case cases[] = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                        {{0, 1, 0}, {-1, 0, 0}, {0, 0, 1}},
                        {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}}};
  for (const Case& c : cases) {
    const SectionPlot plot = MakeSectionPlot(Section({0, 0, 0}, c.n, {-0.1, 0.1}), palette);
    EXPECT_LT((plot.right - c.right).norm(), 1e-15) << c.n.transpose();
    EXPECT_LT((plot.up - c.up).norm(), 1e-15) << c.n.transpose();
  }
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int k = 0; k < 50; ++k) {
    const Eigen::Vector3d n = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    const SectionPlot plot = MakeSectionPlot(Section({1, 2, 3}, n, {-0.1, 0.1}), palette);
    EXPECT_NEAR(plot.right.norm(), 1, 1e-12);
    EXPECT_NEAR(plot.up.norm(), 1, 1e-12);
    EXPECT_NEAR(plot.right.dot(plot.up), 0, 1e-12);
    EXPECT_LT((plot.right.cross(plot.up) - n).norm(), 1e-12) << "seen from the normal's side";
    // up is the first of z, y, x at >= 30 degrees from the normal.
    const int axis = std::abs(n.z()) <= std::sqrt(0.75)   ? 2
                     : std::abs(n.y()) <= std::sqrt(0.75) ? 1
                                                          : 0;
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(axis);
    EXPECT_LT((plot.up - (e - e.dot(n) * n).normalized()).norm(), 1e-12) << k;
  }
}

TEST(SectionPlot, EveryDrawnPointIsItsPartPointProjected) {
  const DeviationPalette palette = MakeDeviationPalette(0.1, 0.5);
  const Eigen::Vector3d origin(5, -3, 60), n = Eigen::Vector3d(1, 0.2, -0.1).normalized();
  const ReportSection s = Section(origin, n, {-0.15, 0.25});
  const SectionPlot plot = MakeSectionPlot(s, palette);
  // The curve spans 60 mm (its sag is 2.25 mm): 0.05 * 60 / 0.4 = 7.5 -> 5.
  EXPECT_EQ(plot.exaggeration, 5);
  auto project = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector2d((p - origin).dot(plot.right), (p - origin).dot(plot.up));
  };
  ASSERT_EQ(plot.curve.size(), 1u);
  ASSERT_EQ(plot.curve[0].size(), 31u);
  for (std::size_t i = 0; i < 31; ++i)
    EXPECT_LT((plot.curve[0][i] - project(s.polylines[0].vertex(i))).norm(), 1e-12);
  ASSERT_EQ(plot.whiskers.size(), 7u);
  ASSERT_EQ(plot.band.size(), 7u);
  for (std::size_t i = 0; i < 7; ++i) {
    const Eigen::Vector3d at(s.whiskers.at_mm[3 * i], s.whiskers.at_mm[3 * i + 1],
                             s.whiskers.at_mm[3 * i + 2]);
    const Eigen::Vector3d dir(s.whiskers.direction[3 * i], s.whiskers.direction[3 * i + 1],
                              s.whiskers.direction[3 * i + 2]);
    const double dev = s.whiskers.deviation_mm[i];
    EXPECT_LT((plot.whiskers[i].foot - project(at)).norm(), 1e-12);
    EXPECT_LT((plot.whiskers[i].tip - project(at + 5 * dev * dir)).norm(), 1e-12) << i;
    // In the plane the whisker is k * |dev| long (its direction is in the plane).
    EXPECT_NEAR((plot.whiskers[i].tip - plot.whiskers[i].foot).norm(), 5 * std::abs(dev), 1e-12);
    EXPECT_LT((plot.band[i].lower - project(at - 5 * 0.15 * dir)).norm(), 1e-12);
    EXPECT_LT((plot.band[i].upper - project(at + 5 * 0.25 * dir)).norm(), 1e-12);
    const Rgb c = palette.colors[PaletteIndex(palette, static_cast<float>(dev))];
    EXPECT_TRUE(plot.whiskers[i].color.r == c.r && plot.whiskers[i].color.g == c.g &&
                plot.whiskers[i].color.b == c.b);
  }
  // The bounds hold everything drawn.
  for (const auto& w : plot.whiskers)
    for (const Eigen::Vector2d& p : {w.foot, w.tip})
      EXPECT_TRUE((p.array() >= plot.min.array() - 1e-12).all() &&
                  (p.array() <= plot.max.array() + 1e-12).all());
  EXPECT_EQ(SectionPlotCaption(s, plot).rfind("whiskers x 5, band -0.150..+0.250 mm", 0), 0u)
      << SectionPlotCaption(s, plot);
}

TEST(SectionPlot, TheExaggerationIsOneTwoOrFiveTimesAPowerOfTen) {
  const DeviationPalette palette = MakeDeviationPalette(0.1, 0.5);
  // Curve extent 60 mm: 0.05 * 60 / width.
  const std::pair<double, double> cases[] = {
      {0.3, 10},     // 10 exactly
      {0.06, 50},    // 50 exactly
      {0.2, 10},     // 15
      {1.0, 2},      // 3
      {20, 0.1},     // 0.15
      {0.001, 2000}  // 3000
  };
  for (const auto& [width, k] : cases) {
    const SectionPlot plot =
        MakeSectionPlot(Section({0, 0, 0}, {1, 0, 0}, {-width / 2, width / 2}), palette);
    EXPECT_DOUBLE_EQ(plot.exaggeration, k) << width;
  }
  // Without a band, twice the largest |deviation| (0.3 mm) stands in.
  const SectionPlot unsaid = MakeSectionPlot(Section({0, 0, 0}, {1, 0, 0}, {NAN, NAN}), palette);
  EXPECT_DOUBLE_EQ(unsaid.exaggeration, 5);
  EXPECT_TRUE(unsaid.band.empty());
  EXPECT_NE(
      SectionPlotCaption(Section({0, 0, 0}, {1, 0, 0}, {NAN, NAN}), unsaid).find("band not said"),
      std::string::npos);
}

TEST(SectionPlot, AnEmptyCutDrawsNothingAndTheTitleComesFromTheCharacteristic) {
  const DeviationPalette palette = MakeDeviationPalette(0.1, 0.5);
  ReportSection empty;
  empty.name = "E";
  EXPECT_TRUE(MakeSectionPlot(empty, palette).empty());
  InspectionReport report;
  ReportCharacteristic c;
  c.name = "E";
  c.type = "section";
  c.verdict = "fail";
  c.points = 42;
  c.min_mm = -0.2;
  c.max_mm = 0.125;
  c.mean_mm = 0.01;
  report.characteristics = {c};
  EXPECT_EQ(SectionPlotTitle(report, empty),
            "E: fail, 42 points, min -0.200, max +0.125, mean +0.010 mm");
  report.characteristics[0].type = "region";  // a region of the same name is not it
  EXPECT_EQ(SectionPlotTitle(report, empty), "E");
}

}  // namespace
}  // namespace surfinspect
