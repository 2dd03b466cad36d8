// The JSON objects of an inspection plan's results, as report.json
// ("schema": "surfinspect.report/2") holds them; docs/inspection-plan.md
// lists the fields. Millimetres, part frame; a number that does not exist
// (the statistics of a characteristic without points, a comparison point's
// value with no point near it) is null.
#pragma once

#include <nlohmann/json.hpp>

#include "core/errormap/characteristics.h"
#include "core/errormap/defects.h"

namespace surfinspect {

// [{name, type, verdict, reason, tolerance_mm: {lower, upper}, points,
//   min_mm, max_mm, mean_mm, stddev_mm, rms_mm, fraction_within}, ...];
// points also carry value_mm, surface and regions allowed_fraction_outside.
nlohmann::json CharacteristicsJson(const CharacteristicsResult& result);

// [{id, kind, centroid_mm: [x, y, z], area_mm2, extent_mm, peak_mm, points,
//   region}, ...]; region is "" outside every region.
nlohmann::json DefectsJson(const DefectsResult& result);

}  // namespace surfinspect
