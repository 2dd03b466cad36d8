#include "core/io/length_units.h"

#include "absl/strings/str_cat.h"

namespace surfinspect {

namespace {

struct UnitRow {
  LengthUnit unit;
  const char* name;
  double mm;
};
// The inch is 25.4 mm exactly (International Yard and Pound Agreement, 1959).
constexpr UnitRow kUnits[] = {{LengthUnit::kMillimetre, "mm", 1.0},
                              {LengthUnit::kCentimetre, "cm", 10.0},
                              {LengthUnit::kMetre, "m", 1000.0},
                              {LengthUnit::kInch, "in", 25.4}};

const UnitRow& RowOf(LengthUnit unit) {
  for (const UnitRow& r : kUnits)
    if (r.unit == unit) return r;
  return kUnits[0];
}

}  // namespace

absl::StatusOr<LengthUnit> ParseLengthUnit(std::string_view name) {
  for (const UnitRow& r : kUnits)
    if (name == r.name) return r.unit;
  return absl::InvalidArgumentError(
      absl::StrCat("unknown length unit \"", std::string(name), "\" (mm, cm, m or in)"));
}

const char* LengthUnitName(LengthUnit unit) { return RowOf(unit).name; }
double MillimetresPer(LengthUnit unit) { return RowOf(unit).mm; }

absl::StatusOr<InputUnit> InputUnitOf(std::string_view name) {
  if (name.empty()) return InputUnit{};
  absl::StatusOr<LengthUnit> unit = ParseLengthUnit(name);
  if (!unit.ok()) return unit.status();
  return InputUnit{*unit, true};
}

void ScaleToMillimetres(LengthUnit unit, std::vector<Eigen::Vector3f>* points) {
  if (unit == LengthUnit::kMillimetre) return;
  const double k = MillimetresPer(unit);
  for (Eigen::Vector3f& p : *points) p = (p.cast<double>() * k).cast<float>();
}
void ScaleToMillimetres(LengthUnit unit, PointCloud* cloud) {
  ScaleToMillimetres(unit, &cloud->points);
}
void ScaleToMillimetres(LengthUnit unit, TriangleMesh* mesh) {
  ScaleToMillimetres(unit, &mesh->vertices);
}

}  // namespace surfinspect
