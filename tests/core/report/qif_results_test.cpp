// core/report/qif_results.cpp: the QIF document read back with pugixml
// against the report it came from, the name-based UUIDs against Python's
// uuid.uuid5, and (where the QIF 3.0 schemas are beside the checkout) the
// document validated by xmllint.
#include "core/report/qif_results.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <pugixml.hpp>
#include <string>
#include <vector>

#include "core/pipeline/inspection_report.h"
#include "core/types/status_macros.h"
#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

using nlohmann::json;

json Characteristic(const std::string& name, const std::string& type, const std::string& verdict,
                    double lower, double upper, int points, double min_mm, double max_mm) {
  json c = {{"name", name},
            {"type", type},
            {"verdict", verdict},
            {"reason", verdict + ": because"},
            {"tolerance_mm", {{"lower", lower}, {"upper", upper}}},
            {"points", points}};
  c["min_mm"] = points > 0 ? json(min_mm) : json(nullptr);
  c["max_mm"] = points > 0 ? json(max_mm) : json(nullptr);
  if (type == "point") c["value_mm"] = points > 0 ? json((min_mm + max_mm) / 2) : json(nullptr);
  return c;
}

json Report() {
  json r = {{"schema", "surfinspect.report/2"}, {"verdict", "fail"}};
  r["characteristics"] = {
      Characteristic("surface", "surface", "pass", -0.3, 0.3, 1000, -0.41, 0.12),
      Characteristic("ridge", "region", "fail", -0.05, 0.15, 200, -0.02, 0.31),
      Characteristic("P1", "point", "pass", -0.1, 0.1, 12, -0.03, 0.01),
      Characteristic("P2", "point", "fail", -0.1, 0.1, 0, 0, 0)};
  return r;
}

// A failed hole (inside its diameter band, outside its position zone), a
// passing slot and a hole not measured, after the report's surface.
json HoleReport() {
  json r = Report();
  r["characteristics"] = {r["characteristics"][0], json::parse(R"({
      "name": "H1", "type": "hole", "verdict": "fail", "reason": "fail: true position",
      "tolerance_mm": {"lower": -0.1, "upper": 0.1}, "points": 180,
      "measured_position_mm": [10.1, 20.0, 5.0], "position_deviation_mm": [0.155, 0, 0],
      "true_position_mm": 0.31, "position_tolerance_mm": 0.3, "measured_diameter_mm": 8.012,
      "diameter_deviation_mm": 0.012, "form_mm": 0.02, "arc_coverage_deg": 351,
      "pixel_pitch_mm": 0.25})"),
                          json::parse(R"({
      "name": "S1", "type": "slot", "verdict": "pass", "reason": "pass",
      "tolerance_mm": {"lower": -0.1, "upper": 0.1}, "points": 300,
      "measured_position_mm": [40, 20, 5], "position_deviation_mm": [0.06, 0, 0],
      "true_position_mm": 0.12, "position_tolerance_mm": 0.2, "measured_width_mm": 6.05,
      "width_deviation_mm": 0.05, "measured_length_mm": 14.1, "length_deviation_mm": 0.1,
      "length_tolerance_mm": {"lower": -0.2, "upper": 0.3}, "arc_coverage_deg": 360})"),
                          json::parse(R"({
      "name": "H9", "type": "hole", "verdict": "not_measured",
      "reason": "not measured: edge seen over 120 deg", "points": 0,
      "tolerance_mm": {"lower": -0.1, "upper": 0.1}, "position_tolerance_mm": 0.2,
      "measured_position_mm": null, "true_position_mm": null, "measured_diameter_mm": null,
      "arc_coverage_deg": 120})")};
  return r;
}

// The surface and a section across x, with its plane in "sections".
json SectionReport() {
  json r = Report();
  r["characteristics"] = {r["characteristics"][0],
                          Characteristic("X0", "section", "pass", -0.2, 0.2, 80, -0.05, 0.07)};
  r["sections"] = json::parse(R"([{"name": "X0", "point_mm": [12, 0, 0], "normal": [0, 0.6, 0.8],
      "tolerance_mm": {"lower": -0.2, "upper": 0.2}, "polylines": [{"xyz_mm": [12, -5, 0, 12, 5, 0]}],
      "whiskers": {"at_mm": [], "direction": [], "deviation_mm": []}}])");
  return r;
}

// The QIF of a report.json text, as a part's files are made: parsed, then mapped.
absl::StatusOr<std::string> XmlOf(const std::string& report_json, const QifContext& context) {
  ASSIGN_OR_RETURN(InspectionReport report, ParseReport(report_json));
  return QifResultsXml(report, context);
}

QifContext Context() {
  QifContext c;
  c.part_id = "part-0007";
  c.cell = "cell-a";
  c.part_model = "part.obj";
  c.points_count = 1234;
  c.time_created = "2026-12-01T10:00:00Z";
  return c;
}

pugi::xml_node ById(const pugi::xml_document& doc, const std::string& id) {
  return doc.find_node([&](pugi::xml_node n) { return id == n.attribute("id").value(); });
}

TEST(QifResults, EveryCharacteristicReadsBackAsTheReportSays) {
  const json report = Report();
  auto xml = XmlOf(report.dump(), Context());
  ASSERT_TRUE(xml.ok()) << xml.status();
  pugi::xml_document doc;
  ASSERT_TRUE(doc.load_string(xml->c_str()));
  const pugi::xml_node root = doc.child("QIFDocument");
  EXPECT_STREQ(root.attribute("versionQIF").value(), "3.0.0");
  const pugi::xml_node results =
      root.child("Results").child("MeasurementResultsSet").child("MeasurementResults");
  EXPECT_STREQ(results.child("InspectionStatus").child_value("InspectionStatusEnum"), "FAIL");
  EXPECT_STREQ(root.select_node("//ActualComponent/SerialNumber").node().child_value(),
               "part-0007");
  EXPECT_STREQ(
      results.select_node("ExternalFileReferences/ExternalFileReference/URI").node().child_value(),
      "errormap.ply");
  const pugi::xml_node list =
      results.child("MeasuredCharacteristics").child("CharacteristicMeasurements");
  ASSERT_EQ(list.attribute("n").as_int(), 4);
  int k = 0;
  for (pugi::xml_node m : list.children()) {
    const json& c = report["characteristics"][k];
    SCOPED_TRACE(c["name"].get<std::string>());
    const std::string kind = c["type"] == "point" ? "PointProfile" : "SurfaceProfile";
    EXPECT_EQ(m.name(), kind + "CharacteristicMeasurement");
    EXPECT_EQ(m.attribute("id").as_int(), 13 + 4 * k);  // stable: from the plan's order
    EXPECT_EQ(m.child("Status").child_value("CharacteristicStatusEnum"),
              std::string(c["verdict"] == "pass" ? "PASS" : "FAIL"));
    // Item -> nominal -> definition: name and tolerance.
    const pugi::xml_node item = ById(doc, m.child_value("CharacteristicItemId"));
    EXPECT_EQ(item.child_value("Name"), c["name"].get<std::string>());
    const pugi::xml_node nominal = ById(doc, item.child_value("CharacteristicNominalId"));
    const pugi::xml_node def = ById(doc, nominal.child_value("CharacteristicDefinitionId"));
    const double lower = c["tolerance_mm"]["lower"], upper = c["tolerance_mm"]["upper"];
    EXPECT_EQ(def.child("ToleranceValue").text().as_double(), upper - lower);
    EXPECT_EQ(!def.child("OuterDisposition").empty(), lower != -upper);
    if (lower != -upper) {
      EXPECT_EQ(def.child("OuterDisposition").text().as_double(), upper);
    }
    if (c["points"] == 0) {
      EXPECT_TRUE(m.child("Value").empty());
    } else {
      const double min = c["min_mm"], max = c["max_mm"];
      const double value = c["type"] == "point" ? c["value_mm"].get<double>()
                                                : 2 * std::max(std::abs(min), std::abs(max));
      EXPECT_EQ(m.child("Value").text().as_double(), value);  // exact: shortest round-trip text
      EXPECT_EQ(m.child("WorstPositiveDeviation").text().as_double(), max);
      EXPECT_EQ(m.child("WorstNegativeDeviation").text().as_double(), min);
    }
    ++k;
  }
  EXPECT_EQ(k, 4);
}

pugi::xml_node Measurement(const pugi::xml_document& doc, const std::string& name) {
  for (pugi::xpath_node n : doc.select_nodes("//CharacteristicMeasurements/*")) {
    const pugi::xml_node item = ById(doc, n.node().child_value("CharacteristicItemId"));
    if (item.child_value("Name") == name) return n.node();
  }
  return {};
}

// The definition behind a measurement: measurement -> item -> nominal -> definition.
pugi::xml_node DefinitionOf(const pugi::xml_document& doc, pugi::xml_node m) {
  const pugi::xml_node item = ById(doc, m.child_value("CharacteristicItemId"));
  const pugi::xml_node nominal = ById(doc, item.child_value("CharacteristicNominalId"));
  return ById(doc, nominal.child_value("CharacteristicDefinitionId"));
}

std::string NominalTarget(const pugi::xml_document& doc, pugi::xml_node m) {
  const pugi::xml_node item = ById(doc, m.child_value("CharacteristicItemId"));
  return ById(doc, item.child_value("CharacteristicNominalId")).child_value("TargetValue");
}

TEST(QifResults, HolesAreDiameterAndPositionSlotsWidthLengthAndPosition) {
  auto xml = XmlOf(HoleReport().dump(), Context());
  ASSERT_TRUE(xml.ok()) << xml.status();
  pugi::xml_document doc;
  ASSERT_TRUE(doc.load_string(xml->c_str()));
  const pugi::xml_node list = doc.select_node("//CharacteristicMeasurements").node();
  ASSERT_EQ(list.attribute("n").as_int(), 1 + 2 + 3 + 2);
  std::vector<std::string> kinds;
  for (pugi::xml_node m : list.children()) kinds.push_back(m.name());
  EXPECT_EQ(kinds,
            (std::vector<std::string>{
                "SurfaceProfileCharacteristicMeasurement", "DiameterCharacteristicMeasurement",
                "PositionCharacteristicMeasurement", "WidthCharacteristicMeasurement",
                "LengthCharacteristicMeasurement", "PositionCharacteristicMeasurement",
                "DiameterCharacteristicMeasurement", "PositionCharacteristicMeasurement"}));
  // H1: the diameter is inside its band, the true position outside its zone.
  const pugi::xml_node d = Measurement(doc, "H1 diameter"), p = Measurement(doc, "H1 position");
  ASSERT_TRUE(d && p);
  EXPECT_STREQ(d.child("Status").child_value("CharacteristicStatusEnum"), "PASS");
  EXPECT_STREQ(p.child("Status").child_value("CharacteristicStatusEnum"), "FAIL");
  EXPECT_EQ(d.child("Value").text().as_double(), 8.012);
  EXPECT_EQ(NominalTarget(doc, d), "8");
  EXPECT_EQ(p.child("Value").text().as_double(), 0.31);
  const pugi::xml_node ddef = DefinitionOf(doc, d), pdef = DefinitionOf(doc, p);
  EXPECT_EQ(ddef.select_node("Tolerance/MaxValue").node().text().as_double(), 0.1);
  EXPECT_EQ(ddef.select_node("Tolerance/MinValue").node().text().as_double(), -0.1);
  EXPECT_STREQ(ddef.select_node("Tolerance/DefinedAsLimit").node().child_value(), "false");
  EXPECT_EQ(pdef.child("ToleranceValue").text().as_double(), 0.3);
  EXPECT_STREQ(pdef.child_value("SizeCharacteristicDefinitionId"), ddef.attribute("id").value());
  EXPECT_FALSE(pdef.select_node("ZoneShape/DiametricalZone").node().empty());
  // S1: width, length (its own band) and position, all passing.
  const pugi::xml_node w = Measurement(doc, "S1 width"), l = Measurement(doc, "S1 length");
  ASSERT_TRUE(w && l);
  EXPECT_EQ(w.child("Value").text().as_double(), 6.05);
  EXPECT_EQ(NominalTarget(doc, w), "6");
  EXPECT_EQ(l.child("Value").text().as_double(), 14.1);
  EXPECT_EQ(NominalTarget(doc, l), "14");
  EXPECT_EQ(DefinitionOf(doc, l).select_node("Tolerance/MaxValue").node().text().as_double(), 0.3);
  for (const char* name : {"S1 width", "S1 length", "S1 position"})
    EXPECT_STREQ(Measurement(doc, name).child("Status").child_value("CharacteristicStatusEnum"),
                 "PASS")
        << name;
  // H9: not measured, so INDETERMINATE without a value or a nominal size.
  for (const char* name : {"H9 diameter", "H9 position"}) {
    const pugi::xml_node m = Measurement(doc, name);
    ASSERT_TRUE(m) << name;
    EXPECT_STREQ(m.child("Status").child_value("CharacteristicStatusEnum"), "INDETERMINATE");
    EXPECT_TRUE(m.child("Value").empty()) << name;
    EXPECT_EQ(NominalTarget(doc, m), "") << name;
  }
}

// A section is a line profile whose nominal names the plane's normal; one
// whose plane the report does not carry stays a surface profile.
TEST(QifResults, ASectionIsALineProfileInItsPlane) {
  json report = SectionReport();
  auto xml = XmlOf(report.dump(), Context());
  ASSERT_TRUE(xml.ok()) << xml.status();
  pugi::xml_document doc;
  ASSERT_TRUE(doc.load_string(xml->c_str()));
  const pugi::xml_node nominal = doc.find_node(
      [](pugi::xml_node n) { return std::string(n.name()) == "LineProfileCharacteristicNominal"; });
  ASSERT_TRUE(nominal) << *xml;
  EXPECT_STREQ(nominal.child_value("Name"), "X0");
  EXPECT_STREQ(nominal.child_value("Vector"), "0 0.6 0.8");
  EXPECT_NE(xml->find("<LineProfileCharacteristicMeasurement"), std::string::npos);
  EXPECT_NE(xml->find("<LineProfileCharacteristicDefinition"), std::string::npos);
  report.erase("sections");
  auto without = XmlOf(report.dump(), Context());
  ASSERT_TRUE(without.ok());
  EXPECT_EQ(without->find("LineProfile"), std::string::npos);
  EXPECT_NE(without->find("<SurfaceProfileCharacteristicNominal id=\"15\""), std::string::npos)
      << "X0, the second characteristic (ids 14..17), as a surface profile";
}

TEST(QifResults, AHoleWithoutItsZoneIsNamed) {
  json r = HoleReport();
  r["characteristics"][1].erase("position_tolerance_mm");
  EXPECT_NE(XmlOf(r.dump(), Context()).status().message().find("characteristics[1]"),
            std::string::npos);
}

TEST(QifResults, SameInputGivesTheSameBytesAndStableCharacteristicUuids) {
  auto a = XmlOf(Report().dump(), Context());
  auto b = XmlOf(Report().dump(), Context());
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(*a, *b);
  QifContext other = Context();
  other.part_id = "part-0008";
  auto c = XmlOf(Report().dump(), other);
  ASSERT_TRUE(c.ok());
  pugi::xml_document da, dc;
  ASSERT_TRUE(da.load_string(a->c_str()) && dc.load_string(c->c_str()));
  // Another part: another document id, the same characteristic identities.
  EXPECT_STRNE(da.child("QIFDocument").child_value("QPId"),
               dc.child("QIFDocument").child_value("QPId"));
  EXPECT_STREQ(da.select_node("//CharacteristicDesignator/UUID").node().child_value(),
               dc.select_node("//CharacteristicDesignator/UUID").node().child_value());
}

TEST(QifResults, UuidIsRfc4122Version5) {
  // python3: uuid.uuid5(uuid.uuid5(uuid.NAMESPACE_URL, "surfinspect"), NAME)
  EXPECT_EQ(QifUuid("x"), "3436e54d-bdf5-522e-ac85-876dda827267");
  EXPECT_EQ(QifUuid("characteristic/part.obj/ridge"), "793b274c-43fb-5ffc-9c60-3cc8ee01a4af");
}

TEST(QifResults, BadInputIsNamed) {
  EXPECT_NE(XmlOf("not json", Context()).status().message().find("JSON"), std::string::npos);
  json r = Report();
  r["schema"] = "surfinspect.report/1";
  EXPECT_NE(XmlOf(r.dump(), Context()).status().message().find("schema"), std::string::npos);
  r = Report();
  r["characteristics"][1].erase("tolerance_mm");
  EXPECT_NE(XmlOf(r.dump(), Context()).status().message().find("characteristics[1]"),
            std::string::npos);
  QifContext no_part = Context();
  no_part.part_id.clear();
  EXPECT_EQ(XmlOf(Report().dump(), no_part).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(QifResults, ValidatesAgainstTheQif3Schema) {
  const std::filesystem::path xsd = std::filesystem::path(SURFINSPECT_SOURCE_DIR) /
                                    "../shared/qif-3.0/QIFApplications/QIFDocument.xsd";
  if (!std::filesystem::exists(xsd))
    GTEST_SKIP() << "SKIPPED: no QIF 3.0 schemas at " << xsd << " (see docs/integration.md)";
  if (std::system("command -v xmllint >/dev/null") != 0) GTEST_SKIP() << "SKIPPED: no xmllint";
  testing::TempDir dir;
  json only_surface = Report();
  only_surface["characteristics"] = {only_surface["characteristics"][0]};
  only_surface["verdict"] = "pass";
  for (const json& report : {Report(), only_surface, HoleReport(), SectionReport()}) {
    const std::string path = dir.path() + "/r.qif";
    ASSERT_TRUE(WriteQifResults(path, *ParseReport(report.dump()), Context()).ok());
    const std::string cmd =
        "xmllint --noout --nonet --schema '" + xsd.string() + "' '" + path + "' 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << report.dump();
  }
}

}  // namespace
}  // namespace surfinspect
