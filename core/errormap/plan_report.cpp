#include "core/errormap/plan_report.h"

#include <cmath>

namespace surfinspect {
namespace {

nlohmann::json NumberOrNull(double v) { return std::isfinite(v) ? nlohmann::json(v) : nullptr; }

}  // namespace

nlohmann::json CharacteristicsJson(const CharacteristicsResult& result) {
  nlohmann::json list = nlohmann::json::array();
  for (const CharacteristicResult& c : result.characteristics) {
    nlohmann::json j = {
        {"name", c.name},
        {"type", CharacteristicTypeName(c.type)},
        {"verdict", c.pass ? "pass" : "fail"},
        {"reason", c.reason},
        {"tolerance_mm", {{"lower", c.tolerance.lower_mm}, {"upper", c.tolerance.upper_mm}}},
        {"points", c.points},
        {"min_mm", NumberOrNull(c.min_mm)},
        {"max_mm", NumberOrNull(c.max_mm)},
        {"mean_mm", NumberOrNull(c.mean_mm)},
        {"stddev_mm", NumberOrNull(c.stddev_mm)},
        {"rms_mm", NumberOrNull(c.rms_mm)},
        {"fraction_within", NumberOrNull(c.fraction_within)}};
    if (c.type == CharacteristicType::kPoint)
      j["value_mm"] = NumberOrNull(c.value_mm);
    else
      j["allowed_fraction_outside"] = c.allowed_fraction_outside;
    list.push_back(std::move(j));
  }
  return list;
}

nlohmann::json DefectsJson(const DefectsResult& result) {
  nlohmann::json list = nlohmann::json::array();
  for (const Defect& d : result.defects)
    list.push_back({{"id", d.id},
                    {"kind", DefectKindName(d.kind)},
                    {"centroid_mm", {d.centroid_mm.x(), d.centroid_mm.y(), d.centroid_mm.z()}},
                    {"area_mm2", d.area_mm2},
                    {"extent_mm", d.extent_mm},
                    {"peak_mm", d.peak_mm},
                    {"points", d.points},
                    {"region", d.region}});
  return list;
}

}  // namespace surfinspect
