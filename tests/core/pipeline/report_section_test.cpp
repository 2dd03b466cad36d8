// core/pipeline/report_section.cpp and the "sections" of report.json: the
// plane found from a real cut against the plane that cut it, each cut
// matched to its characteristic by plan order, numbers rounded to 1 um, and
// the codec's round trip (struct and bytes) with and without sections.
#include "core/pipeline/report_section.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

#include "core/pipeline/inspection_report.h"
#include "core/plan/section.h"
#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

// An error map of one point per triangle, at its centroid, deviation a
// smooth function of the position: what CutSection reads.
ErrorMapResult CentroidMap(const TriangleMesh& mesh) {
  ErrorMapResult em;
  for (uint32_t t = 0; t < mesh.num_triangles(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Eigen::Vector3f c =
        (mesh.vertices[tri[0]] + mesh.vertices[tri[1]] + mesh.vertices[tri[2]]) / 3.0f;
    em.closest_point.push_back(c);
    em.triangle_id.push_back(t);
    em.deviation_mm.push_back(0.1f * std::sin(0.3f * c.x()) + 0.02f * c.y() / 20.0f);
  }
  return em;
}

SectionCut Cut(const TriangleMesh& mesh, const ErrorMapResult& em, const Eigen::Vector3d& point,
               const Eigen::Vector3d& normal, double width = 2.0) {
  absl::StatusOr<SectionCut> cut = CutSection(mesh, em, {point, normal, width});
  EXPECT_TRUE(cut.ok()) << cut.status();
  return cut.ok() ? *std::move(cut) : SectionCut{};
}

TEST(ReportSection, ThePlaneOfARealCutIsThePlaneThatCutIt) {
  const TriangleMesh sphere = testing::Icosphere(20, 3);
  const ErrorMapResult em = CentroidMap(sphere);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d n = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    const Eigen::Vector3d p = 10 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    const Eigen::Vector3d point = p - (p.dot(n) - 8 * u(rng)) * n;  // |offset| < 8 < radius
    const SectionCut cut = Cut(sphere, em, point, n);
    ASSERT_FALSE(cut.polylines.empty()) << trial;
    const CutPlane plane = PlaneOfCut(cut);
    // The sign rule: the largest component positive.
    Eigen::Index largest = 0;
    n.cwiseAbs().maxCoeff(&largest);
    const Eigen::Vector3d expected = n[largest] > 0 ? n : Eigen::Vector3d(-n);
    EXPECT_LT((plane.normal - expected).norm(), 1e-9) << trial;
    EXPECT_NEAR((plane.point_mm - point).dot(n), 0, 1e-9) << "on the plane, trial " << trial;
  }
}

TEST(ReportSection, AStraightCutTakesItsNormalFromTheWhiskers) {
  // The flat square z = 0 cut by x = 30.5: a straight line along y; the
  // whiskers (face normal +z) fix the plane x = const.
  const TriangleMesh square = testing::FlatSquare();
  const ErrorMapResult em = CentroidMap(square);
  const SectionCut cut = Cut(square, em, {30.5, 0, 0}, {1, 0, 0}, 10.0);
  ASSERT_EQ(cut.polylines.size(), 1u);
  ASSERT_FALSE(cut.whiskers.empty());
  const CutPlane plane = PlaneOfCut(cut);
  EXPECT_LT((plane.normal - Eigen::Vector3d::UnitX()).norm(), 1e-12);
  EXPECT_NEAR(plane.point_mm.x(), 30.5, 1e-12);
  // Without whiskers the line alone: a unit normal across it.
  SectionCut bare = cut;
  bare.whiskers.clear();
  const CutPlane line = PlaneOfCut(bare);
  EXPECT_NEAR(line.normal.norm(), 1, 1e-12);
  EXPECT_NEAR(line.normal.y(), 0, 1e-12) << "orthogonal to the line along y";
  EXPECT_EQ(PlaneOfCut(SectionCut{}).normal, Eigen::Vector3d::Zero());
}

// A plan outcome whose characteristics interleave two sections with others.
PlanOutcome OutcomeWithSections() {
  PlanOutcome out;
  const char* names[] = {"surface", "ridge", "A", "P1", "B <&>"};
  const CharacteristicType types[] = {CharacteristicType::kSurface, CharacteristicType::kRegion,
                                      CharacteristicType::kSection, CharacteristicType::kPoint,
                                      CharacteristicType::kSection};
  for (int k = 0; k < 5; ++k) {
    CharacteristicResult c;
    c.name = names[k];
    c.type = types[k];
    c.tolerance = {-0.1 * (k + 1), 0.05 * (k + 1)};
    c.pass = true;
    out.characteristics.characteristics.push_back(c);
  }
  SectionCut a;
  a.polylines = {{{1.23456789, -0.0004, 2}, {1.5, 2.0004999, -3.00049}},
                 {{0, 0, 0}, {0, 1, 0}, {0, 1, 1}}};
  a.whiskers = {{{1.2344, 0.5, 2.9996}, {0, 0.6, 0.8}, 0.0125f},
                {{1.1, 0.7, 3}, {0, -1, 0}, -0.25049f}};
  SectionCut b;  // an empty cut: no curve, no whiskers
  out.sections = {a, b};
  return out;
}

TEST(ReportSection, EachCutTakesItsCharacteristicsNameAndBandRoundedToAMicrometre) {
  const std::vector<ReportSection> s = ReportSectionsOf(OutcomeWithSections());
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].name, "A");
  EXPECT_EQ(s[0].tolerance.lower_mm, -0.1 * 3);
  EXPECT_EQ(s[0].tolerance.upper_mm, 0.05 * 3);
  EXPECT_EQ(s[1].name, "B <&>");
  EXPECT_EQ(s[1].tolerance.upper_mm, 0.05 * 5);
  ASSERT_EQ(s[0].polylines.size(), 2u);
  EXPECT_EQ(s[0].polylines[0].xyz_mm, (std::vector<double>{1.235, 0.0, 2, 1.5, 2.0, -3.0}));
  EXPECT_FALSE(std::signbit(s[0].polylines[0].xyz_mm[1])) << "-0.0004 rounds to +0";
  EXPECT_EQ(s[0].polylines[1].size(), 3u);
  EXPECT_EQ(s[0].whiskers.at_mm, (std::vector<double>{1.234, 0.5, 3.0, 1.1, 0.7, 3}));
  EXPECT_EQ(s[0].whiskers.direction, (std::vector<double>{0, 0.6, 0.8, 0, -1, 0}));
  EXPECT_EQ(s[0].whiskers.deviation_mm, (std::vector<double>{0.013, -0.25}));
  EXPECT_EQ(s[1].polylines.size(), 0u);
  EXPECT_EQ(s[1].whiskers.size(), 0u);
  EXPECT_EQ(s[1].normal, Eigen::Vector3d::Zero()) << "nothing to find the plane from";
}

TEST(ReportSection, TheReportCarriesSectionsAndRoundTripsStructAndBytes) {
  ErrorMapResult map;
  map.tolerance_mm = 0.1;
  map.color_range_mm = 0.5;
  InspectionReport report = MakeInspectionReport(map, {}, OutcomeWithSections());
  ASSERT_EQ(report.sections.size(), 2u);
  const std::string text = ReportText(report);
  const nlohmann::json j = nlohmann::json::parse(text);
  ASSERT_TRUE(j.contains("sections"));
  const nlohmann::json& a = j["sections"][0];
  EXPECT_EQ(a["name"], "A");
  EXPECT_EQ(a["tolerance_mm"], (nlohmann::json{{"lower", -0.1 * 3}, {"upper", 0.05 * 3}}));
  EXPECT_EQ(a["polylines"][0]["xyz_mm"].dump(), "[1.235,0.0,2.0,1.5,2.0,-3.0]");
  EXPECT_EQ(a["whiskers"]["deviation_mm"].dump(), "[0.013,-0.25]");
  EXPECT_EQ(a["whiskers"]["at_mm"].size(), 6u);
  EXPECT_EQ(a["normal"].size(), 3u);
  // decode(encode(x)) is x, and encoding it again gives the same bytes.
  const absl::StatusOr<InspectionReport> back = ParseReport(text);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(ReportText(*back), text);
  ASSERT_EQ(back->sections.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    const ReportSection &x = report.sections[k], &y = back->sections[k];
    EXPECT_EQ(y.name, x.name);
    EXPECT_EQ(y.point_mm, x.point_mm);
    EXPECT_EQ(y.normal, x.normal);
    EXPECT_EQ(y.tolerance.lower_mm, x.tolerance.lower_mm);
    ASSERT_EQ(y.polylines.size(), x.polylines.size());
    for (std::size_t i = 0; i < x.polylines.size(); ++i)
      EXPECT_EQ(y.polylines[i].xyz_mm, x.polylines[i].xyz_mm);
    EXPECT_EQ(y.whiskers.at_mm, x.whiskers.at_mm);
    EXPECT_EQ(y.whiskers.direction, x.whiskers.direction);
    EXPECT_EQ(y.whiskers.deviation_mm, x.whiskers.deviation_mm);
  }
  // The codec itself is exact: unrounded numbers come back bit for bit.
  report.sections[0].whiskers.deviation_mm[0] = 0.1 + 0.2;
  report.sections[0].polylines[0].xyz_mm[0] = 1.0 / 3.0;
  const absl::StatusOr<InspectionReport> exact = DecodeReport(EncodeReport(report));
  ASSERT_TRUE(exact.ok());
  EXPECT_EQ(exact->sections[0].whiskers.deviation_mm[0], 0.1 + 0.2);
  EXPECT_EQ(exact->sections[0].polylines[0].xyz_mm[0], 1.0 / 3.0);
}

TEST(ReportSection, AReportWithoutSectionsHasNoKeyAndDecodesToNone) {
  ErrorMapResult map;
  PlanOutcome outcome = OutcomeWithSections();
  outcome.sections.clear();
  const nlohmann::json j = EncodeReport(MakeInspectionReport(map, {}, outcome));
  EXPECT_FALSE(j.contains("sections"));
  const absl::StatusOr<InspectionReport> back = DecodeReport(j);
  ASSERT_TRUE(back.ok());
  EXPECT_TRUE(back->sections.empty());
  EXPECT_EQ(EncodeReport(*back), j);
}

TEST(ReportSection, DecodingNamesTheBadSectionField) {
  ErrorMapResult map;
  const nlohmann::json good = EncodeReport(MakeInspectionReport(map, {}, OutcomeWithSections()));
  struct Case {
    std::function<void(nlohmann::json&)> spoil;
    std::string message;
  };
  const std::vector<Case> cases = {
      {[](nlohmann::json& j) { j["sections"][0]["polylines"][1]["xyz_mm"].push_back(1.0); },
       "report.sections[0].polylines[1].xyz_mm: not x, y, z triples"},
      {[](nlohmann::json& j) { j["sections"][0]["whiskers"]["deviation_mm"].push_back(0.1); },
       "report.sections[0].whiskers: at_mm and direction must hold x, y, z per deviation_mm"},
      {[](nlohmann::json& j) { j["sections"][1].erase("name"); },
       "report.sections[1].name: missing"},
      {[](nlohmann::json& j) {
         j["sections"][0]["normal"] = {1, 0};
       },
       "report.sections[0].normal: not three numbers"},
      {[](nlohmann::json& j) { j["sections"][0]["whiskers"]["at_mm"][2] = "x"; },
       "report.sections[0].whiskers.at_mm: not a list of numbers"},
      {[](nlohmann::json& j) { j["sections"] = 1; }, "report.sections: not an array"},
  };
  for (const Case& k : cases) {
    nlohmann::json bad = good;
    k.spoil(bad);
    const absl::StatusOr<InspectionReport> r = DecodeReport(bad);
    ASSERT_FALSE(r.ok()) << k.message;
    EXPECT_EQ(r.status().code(), absl::StatusCode::kDataLoss);
    EXPECT_EQ(r.status().message(), k.message);
  }
}

}  // namespace
}  // namespace surfinspect
