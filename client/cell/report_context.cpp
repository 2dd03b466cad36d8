#include "client/cell/report_context.h"

namespace surfinspect::client {

std::vector<ViewpointCalibration> ViewpointCalibrations(const CellConfig& cell) {
  std::vector<ViewpointCalibration> out;
  const nlohmann::json& raw = cell.raw.is_object() && cell.raw.contains("viewpoints")
                                  ? cell.raw["viewpoints"]
                                  : nlohmann::json();
  for (const CellViewpoint& vp : cell.viewpoints) {
    ViewpointCalibration v;
    v.name = vp.name;
    v.calibrated = vp.world_from_sensor.has_value();
    if (raw.is_array())
      for (const nlohmann::json& r : raw)
        if (r.is_object() && r.value("name", std::string()) == vp.name && r.contains("calibration"))
          v.quality = r["calibration"];
    out.push_back(std::move(v));
  }
  return out;
}

}  // namespace surfinspect::client
