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

// One report characteristic, read and checked.
struct Characteristic {
  std::string name, type, verdict, reason;
  double lower = 0, upper = 0;
  bool has_values = false;  // points > 0: min/max (and value for points) exist
  double min_mm = 0, max_mm = 0, value_mm = 0;
  // A section is a surface profile of its slab here: QIF's LineProfile
  // needs the plane's normal, which the report does not carry yet.
  const char* qif_kind() const { return type == "point" ? "PointProfile" : "SurfaceProfile"; }
};

absl::StatusOr<Characteristic> ReadCharacteristic(const ReportCharacteristic& c, std::size_t k) {
  const std::string where = absl::StrCat("report.characteristics[", k, "]");
  Characteristic out;
  out.name = c.name;
  out.type = c.type;
  out.verdict = c.verdict;
  out.reason = c.reason;
  out.lower = c.tolerance.lower_mm;
  out.upper = c.tolerance.upper_mm;
  out.has_values = c.points > 0 && std::isfinite(c.min_mm);
  if (out.has_values) {
    out.min_mm = c.min_mm;
    out.max_mm = c.max_mm;
    if (out.type == "point") out.value_mm = c.value_mm;
    if (!std::isfinite(out.max_mm) || !std::isfinite(out.value_mm))
      return absl::InvalidArgumentError(absl::StrCat(where, ": points without values"));
  }
  if (!std::isfinite(out.lower) || !std::isfinite(out.upper))
    return absl::InvalidArgumentError(absl::StrCat(where, ".tolerance_mm: missing"));
  if (out.type != "surface" && out.type != "region" && out.type != "point" && out.type != "section")
    return absl::InvalidArgumentError(absl::StrCat(where, ".type: unknown \"", out.type, "\""));
  if (out.verdict != "pass" && out.verdict != "fail" && out.verdict != "not_measured")
    return absl::InvalidArgumentError(absl::StrCat(where, ".verdict: not pass/fail/not_measured"));
  return out;
}

absl::StatusOr<std::vector<Characteristic>> ReadCharacteristics(const InspectionReport& report) {
  std::vector<Characteristic> out;
  for (std::size_t k = 0; k < report.characteristics.size(); ++k) {
    ASSIGN_OR_RETURN(auto c, ReadCharacteristic(report.characteristics[k], k));
    out.push_back(std::move(c));
  }
  return out;
}

std::string ModelOf(const QifContext& ctx) {
  return ctx.part_model.empty() ? absl::StrCat("part of cell ", ctx.cell) : ctx.part_model;
}

const char* Upper(const std::string& verdict) { return verdict == "pass" ? "PASS" : "FAIL"; }

// A characteristic's status; QIF's CharacteristicStatusEnum has no "not
// measured", and INDETERMINATE is what a characteristic seen over too little
// of its area is (Characteristics.xsd).
const char* CharacteristicStatus(const std::string& verdict) {
  return verdict == "not_measured" ? "INDETERMINATE" : Upper(verdict);
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

void AddCharacteristics(pugi::xml_node doc, const std::vector<Characteristic>& cs,
                        const std::string& model) {
  pugi::xml_node root = doc.append_child("Characteristics");
  Text(root, "FormalStandardId", std::to_string(kStandardId));
  pugi::xml_node defs = Counted(root, "CharacteristicDefinitions", cs.size());
  pugi::xml_node noms = Counted(root, "CharacteristicNominals", cs.size());
  pugi::xml_node items = Counted(root, "CharacteristicItems", cs.size());
  for (std::size_t k = 0; k < cs.size(); ++k) {
    const Characteristic& c = cs[k];
    const int id = kFirstCharacteristicId + 4 * static_cast<int>(k);
    const std::string kind = c.qif_kind();
    pugi::xml_node def = WithId(defs, (kind + "CharacteristicDefinition").c_str(), id);
    Text(def, "ToleranceValue", Num(c.upper - c.lower));
    if (c.lower != -c.upper) Text(def, "OuterDisposition", Num(c.upper));
    pugi::xml_node nom = WithId(noms, (kind + "CharacteristicNominal").c_str(), id + 1);
    Text(nom, "CharacteristicDefinitionId", std::to_string(id));
    Text(nom, "Name", c.name);
    pugi::xml_node item = WithId(items, (kind + "CharacteristicItem").c_str(), id + 2);
    Text(item, "Name", c.name);
    pugi::xml_node designator = item.append_child("CharacteristicDesignator");
    Text(designator, "Designator", c.name);
    Text(designator, "UUID", QifUuid(absl::StrCat("characteristic/", model, "/", c.name)));
    Text(item, "CharacteristicNominalId", std::to_string(id + 1));
  }
}

void AddMeasurement(pugi::xml_node list, const Characteristic& c, int id) {
  pugi::xml_node m =
      WithId(list, (std::string(c.qif_kind()) + "CharacteristicMeasurement").c_str(), id + 3);
  if (!c.reason.empty()) Text(m, "Description", c.reason);
  Text(m.append_child("Status"), "CharacteristicStatusEnum", CharacteristicStatus(c.verdict));
  Text(m, "CharacteristicItemId", std::to_string(id + 2));
  Text(m, "ActualComponentId", std::to_string(kComponentId));
  Text(Counted(m, "MeasurementDeviceIds", 1), "Id", std::to_string(kDeviceId));
  if (!c.has_values) return;
  const double value =
      c.type == "point" ? c.value_mm : 2.0 * std::max(std::abs(c.min_mm), std::abs(c.max_mm));
  Text(m, "Value", Num(value));
  Text(m, "WorstPositiveDeviation", Num(c.max_mm));
  Text(m, "WorstNegativeDeviation", Num(c.min_mm));
}

void AddResults(pugi::xml_node doc, const std::vector<Characteristic>& cs,
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
  for (std::size_t k = 0; k < cs.size(); ++k)
    AddMeasurement(list, cs[k], kFirstCharacteristicId + 4 * static_cast<int>(k));
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
  doc.append_attribute("idMax").set_value(kFirstCharacteristicId + 4 * static_cast<int>(cs.size()));
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
