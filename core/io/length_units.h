// The length units a cloud or mesh file may be written in. Everything inside
// surfinspect is millimetres; a file in another unit is scaled once, right
// after it is read, and the unit it was read in is recorded in the report.
// A unit the user did not state is "assumed" millimetres, and only then does
// the plausibility rule (unit_doubt.h) look at the file's size.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "core/types/point_cloud.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

enum class LengthUnit { kMillimetre, kCentimetre, kMetre, kInch };

// "mm", "cm", "m" or "in"; anything else is InvalidArgument naming them.
absl::StatusOr<LengthUnit> ParseLengthUnit(std::string_view name);
const char* LengthUnitName(LengthUnit unit);  // "mm", "cm", "m", "in"
double MillimetresPer(LengthUnit unit);       // 1, 10, 1000, 25.4 (exact, by definition)

// A file's unit as the user gave it: stated, or millimetres assumed.
struct InputUnit {
  LengthUnit unit = LengthUnit::kMillimetre;
  bool stated = false;
};
// "" = assumed millimetres, else the stated unit's name.
absl::StatusOr<InputUnit> InputUnitOf(std::string_view name);

// Coordinates times MillimetresPer(unit), each rounded once to float; a
// millimetre input is left as it is (bit for bit), NaN stays NaN.
void ScaleToMillimetres(LengthUnit unit, std::vector<Eigen::Vector3f>* points);
void ScaleToMillimetres(LengthUnit unit, PointCloud* cloud);
void ScaleToMillimetres(LengthUnit unit, TriangleMesh* mesh);

}  // namespace surfinspect
