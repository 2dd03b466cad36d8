#include "core/history/trend.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_replace.h"

namespace surfinspect {
namespace {

nlohmann::json Num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nullptr; }

nlohmann::json LimitsJson(const ControlLimits& l) {
  return {{"center_mm", Num(l.center)}, {"lower_mm", Num(l.lower)}, {"upper_mm", Num(l.upper)}};
}

// One value a part's characteristic charts, with its tolerance.
struct Charted {
  const char* quantity;
  double value_mm, lower_mm, upper_mm;
};

// A hole's sizes are charted as deviations from nominal (as every other
// series is, against the band the plan gives, known even on parts where the
// hole was not measured); its true position against its zone alone, since
// a position has no lower limit.
std::vector<Charted> ChartedValues(const CharacteristicRecord& c) {
  if (c.type != "hole" && c.type != "slot")
    return {{"deviation", c.value_mm, c.lower_mm, c.upper_mm}};
  const bool slot = c.type == "slot";
  std::vector<Charted> out = {
      {slot ? "width" : "diameter", c.size_deviation_mm, c.lower_mm, c.upper_mm}};
  if (slot) out.push_back({"length", c.length_deviation_mm, c.length_lower_mm, c.length_upper_mm});
  out.push_back({"true_position", c.true_position_mm, -std::numeric_limits<double>::infinity(),
                 c.position_tolerance_mm});
  return out;
}

CharacteristicTrend Analyse(CharacteristicTrend c) {
  if (c.values_mm.size() >= 2 && c.lower_mm < c.upper_mm)
    if (auto spc = ComputeSpc(c.values_mm, c.lower_mm, c.upper_mm); spc.ok()) {
      c.spc = *std::move(spc);
      c.violations =
          WesternElectricViolations(c.values_mm, c.spc->individuals.center, c.spc->sigma_within_mm);
    }
  if (c.values_mm.size() >= 3)
    if (auto line = FitDriftLine(c.values_mm); line.ok()) c.drift = *line;
  return c;
}

nlohmann::json CharacteristicJson(const CharacteristicTrend& c) {
  const bool s = c.spc.has_value(), d = c.drift.has_value();
  nlohmann::json violations = nlohmann::json::array();
  for (const RuleViolation& v : c.violations)
    violations.push_back({{"rule", v.rule}, {"part_id", c.part_ids[v.index]}});
  return {{"name", c.name},
          {"type", c.type},
          {"quantity", c.quantity},
          {"n", c.values_mm.size()},
          {"tolerance_mm", {{"lower", Num(c.lower_mm)}, {"upper", Num(c.upper_mm)}}},
          {"mean_mm", s ? Num(c.spc->mean_mm) : nullptr},
          {"sigma_within_mm", s ? Num(c.spc->sigma_within_mm) : nullptr},
          {"sigma_overall_mm", s ? Num(c.spc->sigma_overall_mm) : nullptr},
          {"cp", s ? Num(c.spc->cp) : nullptr},
          {"cpk", s ? Num(c.spc->cpk) : nullptr},
          {"pp", s ? Num(c.spc->pp) : nullptr},
          {"ppk", s ? Num(c.spc->ppk) : nullptr},
          {"individuals_limits", s ? LimitsJson(c.spc->individuals) : nullptr},
          {"moving_range_limits", s ? LimitsJson(c.spc->moving_range) : nullptr},
          {"slope_mm_per_part", d ? Num(c.drift->slope_mm_per_part) : nullptr},
          {"slope_ci_mm_per_part",
           d ? nlohmann::json{Num(c.drift->ci_lower), Num(c.drift->ci_upper)} : nullptr},
          {"violations", violations},
          {"part_ids", c.part_ids},
          {"values_mm", c.values_mm}};
}

}  // namespace

std::string QuantityText(const std::string& quantity) {
  return absl::StrReplaceAll(quantity, {{"_", " "}});
}

std::string TrendLabel(const CharacteristicTrend& c) {
  return c.quantity == "deviation" ? c.name : absl::StrCat(c.name, " ", QuantityText(c.quantity));
}

absl::StatusOr<Trend> ComputeTrend(const std::vector<PartRecord>& parts,
                                   const std::string& characteristic) {
  if (parts.empty()) return absl::NotFoundError("no parts selected");
  Trend trend;
  std::vector<CharacteristicTrend> series;
  std::map<std::pair<std::string, std::string>, std::size_t> index;  // (name, quantity)
  std::vector<std::string> names;                                    // in first-seen order
  for (const PartRecord& p : parts) {
    trend.part_ids.push_back(p.part_id);
    for (const CharacteristicRecord& c : p.characteristics) {
      if (std::find(names.begin(), names.end(), c.name) == names.end()) names.push_back(c.name);
      for (const Charted& v : ChartedValues(c)) {
        auto [it, fresh] = index.emplace(std::make_pair(c.name, v.quantity), series.size());
        if (fresh) {
          series.emplace_back();
          series.back().name = c.name;
          series.back().type = c.type;
          series.back().quantity = v.quantity;
        }
        CharacteristicTrend& s = series[it->second];
        s.lower_mm = v.lower_mm;
        s.upper_mm = v.upper_mm;
        if (!std::isfinite(v.value_mm)) continue;
        s.part_ids.push_back(p.part_id);
        s.values_mm.push_back(v.value_mm);
      }
    }
  }
  if (!characteristic.empty() &&
      std::find(names.begin(), names.end(), characteristic) == names.end())
    return absl::NotFoundError(absl::StrCat(
        "unknown characteristic '", characteristic,
        "'; the selected parts have: ", names.empty() ? "none" : absl::StrJoin(names, ", ")));
  for (CharacteristicTrend& s : series)
    if (characteristic.empty() || s.name == characteristic)
      trend.characteristics.push_back(Analyse(std::move(s)));
  trend.map = ComputeTrendMap(parts);
  return trend;
}

nlohmann::json TrendJson(const Trend& trend, const nlohmann::json& selection) {
  nlohmann::json chars = nlohmann::json::array();
  for (const CharacteristicTrend& c : trend.characteristics) chars.push_back(CharacteristicJson(c));
  nlohmann::json triangles = nlohmann::json::array();
  for (const TriangleTrend& t : trend.map.triangles)
    triangles.push_back({t.triangle_id, t.parts, Num(t.mean_mm), Num(t.sigma_mm)});
  nlohmann::json largest = nullptr;
  if (trend.map.largest >= 0) {
    const TriangleTrend& t = trend.map.triangles[trend.map.largest];
    largest = {{"triangle_id", t.triangle_id},
               {"parts", t.parts},
               {"mean_mm", Num(t.mean_mm)},
               {"sigma_mm", Num(t.sigma_mm)}};
  }
  return {{"schema", kTrendSchema},
          {"units", "mm"},
          {"selection", selection},
          {"parts", trend.part_ids.size()},
          {"part_ids", trend.part_ids},
          {"characteristics", chars},
          {"trend_map",
           {{"parts", trend.map.parts},
            {"num_triangles", trend.map.num_triangles},
            {"largest", largest},
            {"columns", {"triangle_id", "parts", "mean_mm", "sigma_mm"}},
            {"triangles", triangles}}}};
}

}  // namespace surfinspect
