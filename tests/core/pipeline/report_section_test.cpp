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

TEST(ReportSection, ThePlaneIsThePlansAsCut) {
  const TriangleMesh sphere = testing::Icosphere(20, 3);
  const ErrorMapResult em = CentroidMap(sphere);
  PlanOutcome outcome;
  outcome.sections = {Cut(sphere, em, {1, 2, 3}, {0, 0, -2})};
  const std::vector<ReportSection> s = ReportSectionsOf(outcome);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].point_mm, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(s[0].normal, Eigen::Vector3d(0, 0, -1)) << "unit, the plan's sign";
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
  EXPECT_EQ(s[1].normal, Eigen::Vector3d::UnitX()) << "an empty cut keeps its plane";
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
