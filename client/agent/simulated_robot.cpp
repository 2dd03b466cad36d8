#include "client/agent/simulated_robot.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <random>

#include "absl/strings/str_format.h"
#include "core/io/atomic_file.h"
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"
#include "core/io/io_transform.h"
#include "core/simulation/scan_simulator.h"

namespace surfinspect::client {
namespace fs = std::filesystem;
namespace {

SensorIntrinsics IntrinsicsOf(const CellConfig& cell) {
  SensorIntrinsics intrinsics;
  if (cell.raw.contains("sensor")) {
    const auto& s = cell.raw["sensor"];
    intrinsics.width = s.value("width", intrinsics.width);
    intrinsics.height = s.value("height", intrinsics.height);
    intrinsics.horizontal_fov_deg = s.value("horizontal_fov_deg", intrinsics.horizontal_fov_deg);
    intrinsics.min_range_mm = s.value("min_range_mm", intrinsics.min_range_mm);
    intrinsics.max_range_mm = s.value("max_range_mm", intrinsics.max_range_mm);
  }
  return intrinsics;
}

// Height of the highest facet above (x, y), by a vertical probe of the mesh;
// `top` when none is above.
double HighestFacetZ(const TriangleMesh& part, double x, double y, double top) {
  for (const auto& t : part.triangles) {
    const Eigen::Vector3d a = part.vertices[t[0]].cast<double>(),
                          bb = part.vertices[t[1]].cast<double>(),
                          c = part.vertices[t[2]].cast<double>();
    const Eigen::Vector3d n = (bb - a).cross(c - a);
    if (std::abs(n.z()) < 1e-9) continue;
    const double z = a.z() - (n.x() * (x - a.x()) + n.y() * (y - a.y())) / n.z();
    const Eigen::Vector3d p(x, y, z);
    const bool inside = (bb - a).cross(p - a).z() * n.z() >= 0 &&
                        (c - bb).cross(p - bb).z() * n.z() >= 0 &&
                        (a - c).cross(p - c).z() * n.z() >= 0;
    if (inside) top = z;
  }
  return top;
}

// The robot really stands at the demo's true pose when the cell says so.
Eigen::Isometry3d TruePose(const CellConfig& cell, const CellViewpoint& vp) {
  Eigen::Isometry3d pose = vp.world_from_sensor.value_or(vp.nominal_world_from_sensor);
  for (const auto& jv : cell.raw["viewpoints"])
    if (jv.value("name", "") == vp.name && jv.contains("simulation_truth_world_from_sensor"))
      if (auto t = TransformFromJsonValue(jv["simulation_truth_world_from_sensor"], "truth");
          t.ok())
        pose = *t;
  return pose;
}

// TruePose, moved by the drift when it is this viewpoint's.
Eigen::Isometry3d DriftedPose(const CellConfig& cell, const CellViewpoint& vp,
                              const RobotDrift& drift) {
  Eigen::Isometry3d pose = TruePose(cell, vp);
  if (drift.view != vp.name || drift.mm == 0) return pose;
  std::mt19937_64 rng(drift.seed);
  std::normal_distribution<double> g;
  const Eigen::Vector3d dir = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
  pose.pretranslate(drift.mm * dir);
  return pose;
}

ScanOptions RobotScanOptions() {
  ScanOptions opt;
  opt.noise_sigma_mm = 0.015;
  opt.pulse_fraction = 0.003;
  opt.stripes = true;
  return opt;
}

// Two defects on the ridge's top (a bump, then a dent); their truth as JSON.
nlohmann::json PlantDefects(const TriangleMesh& part, std::mt19937_64& rng, ScanOptions* opt) {
  const Bounds3 b = ComputeBounds(part);
  std::uniform_real_distribution<double> ux(b.min.x() + 0.1 * (b.max.x() - b.min.x()),
                                            b.max.x() - 0.1 * (b.max.x() - b.min.x()));
  std::uniform_real_distribution<double> uy(-18, 18), udepth(0.05, 0.5), uradius(3, 8);
  nlohmann::json defects = nlohmann::json::array();
  for (int d = 0; d < 2; ++d) {
    SurfaceDefect defect;
    const double x = ux(rng), y = uy(rng);
    defect.radius_mm = uradius(rng);
    defect.depth_mm = (d == 1 ? -1 : 1) * udepth(rng);
    const double top = HighestFacetZ(part, x, y, b.max.z());
    defect.center_in_part = {x, y, top};
    opt->defects.push_back(defect);
    defects.push_back({{"center_in_part", {x, y, top}},
                       {"radius_mm", defect.radius_mm},
                       {"depth_mm", defect.depth_mm}});
  }
  return defects;
}

// Scans one part at every viewpoint into DIR, then truth.json, then DONE.
absl::Status DropPart(const CellConfig& cell, const TriangleMesh& part, const fs::path& dir,
                      ScanOptions opt, const nlohmann::json& defects, uint64_t seed, int n,
                      const RobotDrift& drift) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return absl::PermissionDeniedError(dir.string() + ": " + ec.message());
  const SensorIntrinsics intrinsics = IntrinsicsOf(cell);
  for (std::size_t v = 0; v < cell.viewpoints.size(); ++v) {
    const CellViewpoint& vp = cell.viewpoints[v];
    opt.seed = seed * 1000003 + n * 101 + v;
    auto scan =
        SimulateScan(part, cell.world_from_part, DriftedPose(cell, vp, drift), intrinsics, opt);
    if (!scan.ok()) return scan.status();
    if (auto st = WritePointCloud((dir / (vp.name + ".pcd")).string(), scan->cloud_in_sensor);
        !st.ok())
      return st;
  }
  if (auto st = WriteStringAtomically((dir / "truth.json").string(),
                                      nlohmann::json{{"defects", defects}}.dump(2) + "\n");
      !st.ok())
    return st;
  return WriteStringAtomically((dir / "DONE").string(), "");
}

}  // namespace

absl::StatusOr<RobotDrift> ParseRobotDrift(const std::string& text) {
  RobotDrift d;
  const auto colon = text.rfind(':');
  char* end = nullptr;
  if (colon != std::string::npos && colon > 0) d.mm = std::strtod(text.c_str() + colon + 1, &end);
  if (colon == std::string::npos || colon == 0 || end == text.c_str() + colon + 1 || *end != 0 ||
      !(d.mm >= 0) || !std::isfinite(d.mm))
    return absl::InvalidArgumentError("--robot-drift " + text + ": expected VIEW:MM, e.g. v2:0.02");
  d.view = text.substr(0, colon);
  return d;
}

absl::StatusOr<PointCloud> SimulateGaugeScan(const CellConfig& cell, const TriangleMesh& gauge,
                                             const CellViewpoint& vp, const RobotDrift& drift,
                                             uint64_t seed) {
  ScanOptions opt = RobotScanOptions();
  opt.seed = seed * 1000003 + std::hash<std::string>{}(vp.name) % 1000;
  auto scan = SimulateScan(gauge, vp.world_from_gauge, DriftedPose(cell, vp, drift),
                           IntrinsicsOf(cell), opt);
  if (!scan.ok()) return scan.status();
  return std::move(scan->cloud_in_sensor);
}

absl::StatusOr<std::vector<std::string>> SimulateParts(const CellConfig& cell,
                                                       const std::string& inbox, int count,
                                                       uint64_t seed) {
  return SimulateParts(cell, inbox, count, seed, RobotDrift{});
}

absl::StatusOr<std::vector<std::string>> SimulateParts(const CellConfig& cell,
                                                       const std::string& inbox, int count,
                                                       uint64_t seed, const RobotDrift& drift) {
  auto part = ReadMesh(cell.part_mesh);
  if (!part.ok()) return part.status();
  std::mt19937_64 rng(seed);
  std::vector<std::string> ids;
  for (int k = 0, n = 1; k < count; ++n) {
    const std::string id = absl::StrFormat("sim-%04d-%04d", seed % 10000, n);
    if (fs::exists(fs::path(inbox) / id)) continue;
    ++k;
    ScanOptions opt = RobotScanOptions();
    const nlohmann::json defects = PlantDefects(*part, rng, &opt);
    if (auto st = DropPart(cell, *part, fs::path(inbox) / id, opt, defects, seed, n, drift);
        !st.ok())
      return st;
    ids.push_back(id);
  }
  return ids;
}

}  // namespace surfinspect::client
