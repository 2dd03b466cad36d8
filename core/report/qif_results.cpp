#include "core/report/qif_results.h"

#include <openssl/evp.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <ctime>
#include <pugixml.hpp>
#include <sstream>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/io/atomic_file.h"
#include "core/report/report_content.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

// Fixed QIF ids; characteristic k uses kFirstCharacteristicId + 4k .. + 3.
constexpr int kStandardId = 1, kDeviceId = 2, kPartId = 3, kResultsId = 4, kComponentId = 5;
constexpr int kFirstCharacteristicId = 10;

// Shortest text that reads back as the same double (as report.json's).
std::string Num(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

pugi::xml_node Text(pugi::xml_node parent, const char* name, const std::string& text) {
  pugi::xml_node n = parent.append_child(name);
  n.text().set(text.c_str());
  return n;
}

pugi::xml_node Counted(pugi::xml_node parent, const char* name, std::size_t n) {
  pugi::xml_node node = parent.append_child(name);
  node.append_attribute("n").set_value(static_cast<unsigned long long>(n));
  return node;
}

pugi::xml_node WithId(pugi::xml_node parent, const char* name, int id) {
  pugi::xml_node node = parent.append_child(name);
  node.append_attribute("id").set_value(id);
  return node;
}

// One QIF characteristic. A surface, region, section or point is one; a
// hole is two (its diameter and its position) and a slot three (width,
// length, position), each with its own band and status, so that a quality
// system sees which of them failed.
struct QifCharacteristic {
  enum class Family { kProfile, kSize, kPosition };
  Family family = Family::kProfile;
  std::string kind;             // the QIF elements' prefix: "SurfaceProfile", "Diameter", ...
  std::string name;             // the report's name; a hole's parts add " diameter" etc.
  std::string status;           // PASS, FAIL or INDETERMINATE
  std::string description;      // the report's reason
  double lower = 0, upper = 0;  // profile and size: the band; position: upper = the zone
  double target = NAN;          // size: the nominal, known when measured
  bool has_values = false;
  double value = 0, worst_positive = 0, worst_negative = 0;  // the worst: profiles only
  int size_index = -1;  // position: the index of its hole's size characteristic
  // A line profile (a section): the normal of the plane its curve lies in.
  Eigen::Vector3d plane_normal = Eigen::Vector3d::Constant(NAN);
};

std::string Upper(const std::string& verdict) { return verdict == "pass" ? "PASS" : "FAIL"; }

// A characteristic's status; QIF's CharacteristicStatusEnum has no "not
// measured", and INDETERMINATE is what a characteristic seen over too little
// of its area is (Characteristics.xsd).
std::string CharacteristicStatus(const std::string& verdict) {
  return verdict == "not_measured" ? "INDETERMINATE" : Upper(verdict);
}

// A surface or region is a surface profile of its points; a section a line
// profile in its plane (report.json's "sections" carries the plane; a report
// without it, from before sections were written, keeps the surface
// profile); a comparison point and a trim-edge point are point profiles.
absl::Status AddProfile(const ReportCharacteristic& c, const std::string& where,
                        const std::vector<ReportSection>& sections,
                        std::vector<QifCharacteristic>& out) {
  QifCharacteristic q;
  // A trim-edge point is one offset: a point profile whose worst values are
  // that offset.
  const bool edge = c.type == "edge_point";
  q.kind = c.has_value() ? "PointProfile" : "SurfaceProfile";
  for (const ReportSection& s : sections)
    if (c.type == "section" && s.name == c.name && s.normal.norm() > 0) {
      q.kind = "LineProfile";
      q.plane_normal = s.normal.normalized();
    }
  q.name = c.name;
  q.status = CharacteristicStatus(c.verdict);
  q.description = c.reason;
  q.lower = c.tolerance.lower_mm;
  q.upper = c.tolerance.upper_mm;
  q.has_values = edge ? std::isfinite(c.value_mm) : c.points > 0 && std::isfinite(c.min_mm);
  if (q.has_values) {
    q.worst_negative = edge ? c.value_mm : c.min_mm;
    q.worst_positive = edge ? c.value_mm : c.max_mm;
    // A surface profile's value is the zone width 2 max(|min|, |max|).
    q.value = c.has_value() ? c.value_mm : 2.0 * std::max(std::abs(c.min_mm), std::abs(c.max_mm));
    if (!std::isfinite(q.worst_positive) || !std::isfinite(q.value))
      return absl::InvalidArgumentError(absl::StrCat(where, ": points without values"));
  }
  out.push_back(std::move(q));
  return absl::OkStatus();
}

// A size of a hole (diameter, a slot's width or length) against its band.
QifCharacteristic Size(const ReportCharacteristic& c, const char* kind, const char* what,
                       const ToleranceBand& band, double measured_mm, double deviation_mm,
                       const std::string& verdict) {
  QifCharacteristic q;
  q.family = QifCharacteristic::Family::kSize;
  q.kind = kind;
  q.name = absl::StrCat(c.name, " ", what);
  q.status = CharacteristicStatus(verdict);
  q.description = c.reason;
  q.lower = band.lower_mm;
  q.upper = band.upper_mm;
  q.has_values = c.measured() && std::isfinite(measured_mm) && std::isfinite(deviation_mm);
  if (q.has_values) {
    q.value = measured_mm;
    // The plan's nominal, without the subtraction's last-bit error.
    q.target = std::round((measured_mm - deviation_mm) * 1e9) / 1e9;
  }
  return q;
}

// A hole: its size(s), then its true position against the diametral zone.
absl::Status AddHole(const ReportCharacteristic& c, const std::string& where,
                     std::vector<QifCharacteristic>& out) {
  const bool slot = c.type == "slot";
  if (!(c.position_tolerance_mm > 0))
    return absl::InvalidArgumentError(absl::StrCat(where, ".position_tolerance_mm: missing"));
  if (slot && !(c.length_tolerance.lower_mm <= c.length_tolerance.upper_mm))
    return absl::InvalidArgumentError(absl::StrCat(where, ".length_tolerance_mm: missing"));
  const HoleVerdicts v = HoleVerdictsOf(c);
  const int size_index = static_cast<int>(out.size());
  out.push_back(Size(c, slot ? "Width" : "Diameter", slot ? "width" : "diameter", c.tolerance,
                     c.measured_diameter_mm, c.diameter_deviation_mm, v.size));
  if (slot)
    out.push_back(Size(c, "Length", "length", c.length_tolerance, c.measured_length_mm,
                       c.length_deviation_mm, v.length));
  QifCharacteristic q;
  q.family = QifCharacteristic::Family::kPosition;
  q.kind = "Position";
  q.name = absl::StrCat(c.name, " position");
  q.status = CharacteristicStatus(v.position);
  q.description = c.reason;
  q.upper = c.position_tolerance_mm;
  q.has_values = c.measured() && std::isfinite(c.true_position_mm);
  q.value = c.true_position_mm;
  q.size_index = size_index;
  out.push_back(std::move(q));
  return absl::OkStatus();
}

absl::Status AddCharacteristic(const ReportCharacteristic& c, std::size_t k,
                               const std::vector<ReportSection>& sections,
                               std::vector<QifCharacteristic>& out) {
  const std::string where = absl::StrCat("report.characteristics[", k, "]");
  if (!std::isfinite(c.tolerance.lower_mm) || !std::isfinite(c.tolerance.upper_mm))
    return absl::InvalidArgumentError(absl::StrCat(where, ".tolerance_mm: missing"));
  if (c.verdict != "pass" && c.verdict != "fail" && c.verdict != "not_measured")
    return absl::InvalidArgumentError(absl::StrCat(where, ".verdict: not pass/fail/not_measured"));
  if (c.is_hole()) return AddHole(c, where, out);
  if (c.type != "surface" && c.type != "region" && c.type != "point" && c.type != "section" &&
      c.type != "edge_point")
    return absl::InvalidArgumentError(absl::StrCat(where, ".type: unknown \"", c.type, "\""));
  return AddProfile(c, where, sections, out);
}

absl::StatusOr<std::vector<QifCharacteristic>> ReadCharacteristics(const InspectionReport& report) {
  std::vector<QifCharacteristic> out;
  for (std::size_t k = 0; k < report.characteristics.size(); ++k)
    RETURN_IF_ERROR(AddCharacteristic(report.characteristics[k], k, report.sections, out));
  return out;
}

std::string ModelOf(const QifContext& ctx) {
  return ctx.part_model.empty() ? absl::StrCat("part of cell ", ctx.cell) : ctx.part_model;
}

void AddPreamble(pugi::xml_node doc, const QifContext& ctx) {
  Text(doc, "QPId", QifUuid(absl::StrCat("document/", ctx.cell, "/", ctx.part_id)));
  if (!ctx.time_created.empty()) Text(doc.append_child("Version"), "TimeCreated", ctx.time_created);
  pugi::xml_node app = doc.append_child("Header").append_child("Application");
  Text(app, "Name", "surfinspect");
  Text(app, "Organization", "surfinspect");
  // Profile tolerances as ISO 1101 defines them (zone of uniform width).
  pugi::xml_node std_ = WithId(Counted(doc, "StandardsDefinitions", 1), "Standard", kStandardId);
  Text(std_.append_child("Organization"), "StandardsOrganizationEnum", "ISO");
  Text(std_, "Designator", "1101");
  Text(std_, "Year", "2017");
  pugi::xml_node unit = doc.append_child("FileUnits").append_child("PrimaryUnits");
  unit = unit.append_child("LinearUnit");
  Text(unit, "SIUnitName", "meter");
  Text(unit, "UnitName", "mm");
  Text(unit.append_child("UnitConversion"), "Factor", "0.001");
  pugi::xml_node device =
      WithId(Counted(doc.append_child("MeasurementResources"), "MeasurementDevices", 1),
             "MeasurementDevice", kDeviceId);
  Text(device, "Name", ctx.cell);
  Text(device, "Description", ctx.sensor);
  const std::string model = ModelOf(ctx);
  pugi::xml_node part = WithId(Counted(doc.append_child("Product"), "PartSet", 1), "Part", kPartId);
  part.append_attribute("label").set_value(model.c_str());
  Text(part, "UUID", QifUuid(absl::StrCat("part/", model)));
  if (!ctx.part_model.empty()) Text(part, "ModelNumber", ctx.part_model);
}

int IdOf(std::size_t k) { return kFirstCharacteristicId + 4 * static_cast<int>(k); }

// The definition's tolerance. A profile's zone width, with an unequal
// band's upper limit as OuterDisposition (the XSD: "the upper tolerance
// limit when the tolerance zone is expressed as a bi-directional
// tolerance"); a size's band as signed deviations (DefinedAsLimit false); a
// position's zone diameter, regardless of feature size, circular in the
// hole's plane (the report measures the centre in one plane).
void AddTolerance(pugi::xml_node def, const QifCharacteristic& c) {
  using Family = QifCharacteristic::Family;
  if (c.family == Family::kProfile) {
    Text(def, "ToleranceValue", Num(c.upper - c.lower));
    if (c.lower != -c.upper) Text(def, "OuterDisposition", Num(c.upper));
  } else if (c.family == Family::kSize) {
    pugi::xml_node tol = def.append_child("Tolerance");
    Text(tol, "MaxValue", Num(c.upper));
    Text(tol, "MinValue", Num(c.lower));
    Text(tol, "DefinedAsLimit", "false");
  } else {
    Text(def, "ToleranceValue", Num(c.upper));
    Text(def, "MaterialCondition", "REGARDLESS");
    Text(def, "SizeCharacteristicDefinitionId", std::to_string(IdOf(c.size_index)));
    Text(def.append_child("ZoneShape").append_child("DiametricalZone"), "Dimensionality",
         "TWODIMENSIONAL");
  }
}

void AddCharacteristics(pugi::xml_node doc, const std::vector<QifCharacteristic>& cs,
                        const std::string& model) {
  pugi::xml_node root = doc.append_child("Characteristics");
  Text(root, "FormalStandardId", std::to_string(kStandardId));
  pugi::xml_node defs = Counted(root, "CharacteristicDefinitions", cs.size());
  pugi::xml_node noms = Counted(root, "CharacteristicNominals", cs.size());
  pugi::xml_node items = Counted(root, "CharacteristicItems", cs.size());
  for (std::size_t k = 0; k < cs.size(); ++k) {
    const QifCharacteristic& c = cs[k];
    const int id = IdOf(k);
    AddTolerance(WithId(defs, (c.kind + "CharacteristicDefinition").c_str(), id), c);
    pugi::xml_node nom = WithId(noms, (c.kind + "CharacteristicNominal").c_str(), id + 1);
    Text(nom, "CharacteristicDefinitionId", std::to_string(id));
    Text(nom, "Name", c.name);
    if (std::isfinite(c.target)) Text(nom, "TargetValue", Num(c.target));
    if (c.plane_normal.allFinite())  // after the base type's elements (Characteristics.xsd)
      Text(nom, "Vector",
           absl::StrCat(Num(c.plane_normal.x()), " ", Num(c.plane_normal.y()), " ",
                        Num(c.plane_normal.z())));
    pugi::xml_node item = WithId(items, (c.kind + "CharacteristicItem").c_str(), id + 2);
    Text(item, "Name", c.name);
    pugi::xml_node designator = item.append_child("CharacteristicDesignator");
    Text(designator, "Designator", c.name);
    Text(designator, "UUID", QifUuid(absl::StrCat("characteristic/", model, "/", c.name)));
    Text(item, "CharacteristicNominalId", std::to_string(id + 1));
  }
}

void AddMeasurement(pugi::xml_node list, const QifCharacteristic& c, int id) {
  pugi::xml_node m = WithId(list, (c.kind + "CharacteristicMeasurement").c_str(), id + 3);
  if (!c.description.empty()) Text(m, "Description", c.description);
  Text(m.append_child("Status"), "CharacteristicStatusEnum", c.status);
  Text(m, "CharacteristicItemId", std::to_string(id + 2));
  Text(m, "ActualComponentId", std::to_string(kComponentId));
  Text(Counted(m, "MeasurementDeviceIds", 1), "Id", std::to_string(kDeviceId));
  if (!c.has_values) return;
  Text(m, "Value", Num(c.value));
  if (c.family != QifCharacteristic::Family::kProfile) return;
  Text(m, "WorstPositiveDeviation", Num(c.worst_positive));
  Text(m, "WorstNegativeDeviation", Num(c.worst_negative));
}

void AddResults(pugi::xml_node doc, const std::vector<QifCharacteristic>& cs,
                const std::string& verdict, const QifContext& ctx) {
  pugi::xml_node results = doc.append_child("Results");
  pugi::xml_node mr =
      WithId(Counted(results, "MeasurementResultsSet", 1), "MeasurementResults", kResultsId);
  Text(mr, "ThisResultsInstanceQPId",
       QifUuid(absl::StrCat("results/", ctx.cell, "/", ctx.part_id)));
  pugi::xml_node file =
      Counted(mr, "ExternalFileReferences", 1).append_child("ExternalFileReference");
  Text(file, "URI", ctx.points_uri);
  Text(file.append_child("FileSpec"), "OtherFileSpec",
       absl::StrCat("PLY 1.0 binary_little_endian: vertex x y z (float, mm, ", ctx.points_frame,
                    " frame), deviation (float, mm, signed, NaN unmatched), red green blue "
                    "(uchar)"));
  Text(file, "Description",
       absl::StrCat("measured points of part ", ctx.part_id,
                    " with their signed deviation from "
                    "the CAD surface (",
                    ctx.points_count, " points)"));
  pugi::xml_node list =
      Counted(mr.append_child("MeasuredCharacteristics"), "CharacteristicMeasurements", cs.size());
  for (std::size_t k = 0; k < cs.size(); ++k) AddMeasurement(list, cs[k], IdOf(k));
  Text(mr.append_child("InspectionStatus"), "InspectionStatusEnum", Upper(verdict));
  Text(Counted(mr, "ActualComponentIds", 1), "Id", std::to_string(kComponentId));
  pugi::xml_node component =
      WithId(Counted(Counted(results, "ActualComponentSets", 1), "ActualComponentSet", 1),
             "ActualComponent", kComponentId);
  Text(component, "SerialNumber", ctx.part_id);
  Text(component.append_child("Status"), "InspectionStatusEnum", Upper(verdict));
}

}  // namespace

absl::StatusOr<std::string> QifResultsXml(const InspectionReport& report, const QifContext& ctx) {
  if (ctx.part_id.empty()) return absl::InvalidArgumentError("QIF: no part id");
  if (ctx.cell.empty()) return absl::InvalidArgumentError("QIF: no cell name");
  if (report.schema != kReportSchema)
    return absl::InvalidArgumentError(absl::StrCat("report: schema is not ", kReportSchema));
  const std::string& verdict = report.verdict;
  if (verdict != "pass" && verdict != "fail")
    return absl::InvalidArgumentError("report.verdict: not pass/fail");
  ASSIGN_OR_RETURN(auto cs, ReadCharacteristics(report));
  pugi::xml_document xml;
  pugi::xml_node decl = xml.append_child(pugi::node_declaration);
  decl.append_attribute("version").set_value("1.0");
  decl.append_attribute("encoding").set_value("UTF-8");
  pugi::xml_node doc = xml.append_child("QIFDocument");
  doc.append_attribute("xmlns").set_value("http://qifstandards.org/xsd/qif3");
  doc.append_attribute("versionQIF").set_value("3.0.0");
  doc.append_attribute("idMax").set_value(IdOf(cs.size()));
  AddPreamble(doc, ctx);
  AddCharacteristics(doc, cs, ModelOf(ctx));
  AddResults(doc, cs, verdict, ctx);
  std::ostringstream out;
  xml.save(out, "  ", pugi::format_default, pugi::encoding_utf8);
  return out.str();
}

absl::Status WriteQifResults(const std::string& path, const InspectionReport& report,
                             const QifContext& context) {
  ASSIGN_OR_RETURN(auto xml, QifResultsXml(report, context));
  return WriteStringAtomically(path, xml);
}

std::string QifUuid(const std::string& name) {
  // surfinspect's namespace, 859d64b9-8cdd-567b-928d-af9223f36229: the version-5 UUID of
  // "surfinspect" in RFC 4122's URL namespace (6ba7b811-9dad-11d1-80b4-00c04fd430c8).
  static const unsigned char kNamespace[16] = {0x85, 0x9d, 0x64, 0xb9, 0x8c, 0xdd, 0x56, 0x7b,
                                               0x92, 0x8d, 0xaf, 0x92, 0x23, 0xf3, 0x62, 0x29};
  std::string input(reinterpret_cast<const char*>(kNamespace), 16);
  input += name;
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int len = 0;
  EVP_Digest(input.data(), input.size(), digest, &len, EVP_sha1(), nullptr);
  digest[6] = static_cast<unsigned char>((digest[6] & 0x0F) | 0x50);  // version 5
  digest[8] = static_cast<unsigned char>((digest[8] & 0x3F) | 0x80);  // RFC 4122 variant
  std::string out;
  for (int i = 0; i < 16; ++i) {
    if (i == 4 || i == 6 || i == 8 || i == 10) out += '-';
    out += absl::StrFormat("%02x", digest[i]);
  }
  return out;
}

std::string QifTimeNow() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

}  // namespace surfinspect
