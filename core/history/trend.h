// The process trend over the parts of a selection: per characteristic and
// quantity its series (the charted value per part: a comparison point's
// value_mm, a region's, a section's or the surface's mean_mm; of a hole its
// diameter's deviation from nominal and its true position, of a slot its
// width's and length's deviations and its true position), SPC (spc.h), the Western Electric
// rules (western_electric.h) and the drift line (drift_line.h); and the
// trend map per CAD triangle (trend_map.h). TrendJson is trend.json's one
// writer (docs in README.md, "Part history and the process trend").
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/history/drift_line.h"
#include "core/history/results_store.h"
#include "core/history/spc.h"
#include "core/history/trend_map.h"
#include "core/history/western_electric.h"

namespace surfinspect {

inline constexpr char kTrendSchema[] = "surfinspect.trend/1";

struct CharacteristicTrend {
  std::string name, type;
  // What is charted: "deviation" (surface, region, section, point);
  // "diameter", "width" or "length" (a hole's or slot's size, as its
  // deviation from nominal); "true_position" (no lower limit: -infinity).
  std::string quantity = "deviation";
  double lower_mm = NAN, upper_mm = NAN;  // the tolerance of the newest part
  std::vector<std::string> part_ids;      // parts with a finite value, in order
  std::vector<double> values_mm;
  std::optional<SpcResult> spc;           // with 2 values or more
  std::optional<DriftLine> drift;         // with 3 values or more
  std::vector<RuleViolation> violations;  // indices into values_mm
};

struct Trend {
  std::vector<std::string> part_ids;  // every selected part, in order
  std::vector<CharacteristicTrend> characteristics;
  TrendMap map;
};

// A quantity as people read it: "true position" for "true_position".
std::string QuantityText(const std::string& quantity);
// "H1 diameter" for a hole's quantity, the name alone for a deviation: how
// a series is named where one line holds it (the CLI's table).
std::string TrendLabel(const CharacteristicTrend& c);

// `characteristic` empty = all, in the order the parts list them (a hole
// with its quantities in the order above); a name takes all of its
// quantities. Fails on
// no parts, or on a characteristic none of the parts has (naming the ones
// they have).
absl::StatusOr<Trend> ComputeTrend(const std::vector<PartRecord>& parts,
                                   const std::string& characteristic = "");

// trend.json; `selection` is echoed as given.
nlohmann::json TrendJson(const Trend& trend, const nlohmann::json& selection);

}  // namespace surfinspect
