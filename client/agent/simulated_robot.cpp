#include "client/agent/simulated_robot.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <optional>
#include <random>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "client/cell/cell_part.h"
#include "core/io/atomic_file.h"
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"
#include "core/io/io_transform.h"
#include "core/plan/cad_holes.h"
#include "core/simulation/hole_changes.h"
#include "core/simulation/scan_simulator.h"
#include "core/types/status_macros.h"

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

// The scanner's imperfections: noise 0.015 mm, 0.3% pulses, stripes at
// depth jumps, unless cell.json's optional "simulation" block says otherwise.
ScanOptions ScanOptionsOf(const CellConfig& cell) {
  ScanOptions opt;
  opt.noise_sigma_mm = 0.015;
  opt.pulse_fraction = 0.003;
  opt.stripes = true;
  if (cell.raw.contains("simulation") && cell.raw["simulation"].is_object()) {
    const auto& s = cell.raw["simulation"];
    opt.noise_sigma_mm = s.value("noise_sigma_mm", opt.noise_sigma_mm);
    opt.pulse_fraction = s.value("pulse_fraction", opt.pulse_fraction);
    opt.stripes = s.value("stripes", opt.stripes);
  }
  return opt;
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

// Where a drift's bump sits, part frame (x, y).
Eigen::Vector2d DriftCenterXY(const TriangleMesh& part, const SurfaceDrift& drift) {
  const Bounds3 b = ComputeBounds(part);
  return drift.center_xy.value_or(Eigen::Vector2d(0.5 * (b.min.x() + b.max.x()), 0.0));
}

// An area the random defects stay out of (the drift's bump, so that the
// drift is observed alone); radius 0 = none.
struct KeepClear {
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  double radius_mm = 0;
};

// Two defects on the ridge's top (a bump, then a dent); their truth as JSON.
nlohmann::json PlantDefects(const TriangleMesh& part, std::mt19937_64& rng, ScanOptions* opt,
                            const KeepClear& clear = {}) {
  const Bounds3 b = ComputeBounds(part);
  std::uniform_real_distribution<double> ux(b.min.x() + 0.1 * (b.max.x() - b.min.x()),
                                            b.max.x() - 0.1 * (b.max.x() - b.min.x()));
  std::uniform_real_distribution<double> uy(-18, 18), udepth(0.05, 0.5), uradius(3, 8);
  nlohmann::json defects = nlohmann::json::array();
  for (int d = 0; d < 2; ++d) {
    SurfaceDefect defect;
    double x = ux(rng), y = uy(rng);
    defect.radius_mm = uradius(rng);
    for (int tries = 0; tries < 100 && (Eigen::Vector2d(x, y) - clear.xy).norm() <
                                           clear.radius_mm + 2 * defect.radius_mm;
         ++tries)
      x = ux(rng), y = uy(rng);
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

// The drift's bump on part k, added to the scan; its truth as JSON.
nlohmann::json PlantDrift(const TriangleMesh& part, const SurfaceDrift& drift, int k,
                          ScanOptions* opt) {
  const Bounds3 b = ComputeBounds(part);
  const Eigen::Vector2d xy = DriftCenterXY(part, drift);
  SurfaceDefect bump;
  bump.center_in_part = {xy.x(), xy.y(), HighestFacetZ(part, xy.x(), xy.y(), b.max.z())};
  bump.radius_mm = drift.radius_mm;
  bump.depth_mm = -drift.HeightAt(k);  // a depth < 0 is a bump
  if (bump.depth_mm != 0) opt->defects.push_back(bump);
  const Eigen::Vector3d& c = bump.center_in_part;
  return {{"spec", drift.spec},
          {"kind", drift.kind == SurfaceDrift::Kind::kBow ? "bow" : "shift"},
          {"part_index", k},
          {"center_in_part", {c.x(), c.y(), c.z()}},
          {"radius_mm", bump.radius_mm},
          {"height_mm", drift.HeightAt(k)}};
}

// Scans one part at every viewpoint into DIR, then truth.json, then DONE.
absl::Status DropPart(const CellConfig& cell, const TriangleMesh& part, const fs::path& dir,
                      ScanOptions opt, const nlohmann::json& truth, uint64_t seed, int n,
                      const RobotDrift& drift, const Eigen::Isometry3d& in_fixture) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return absl::PermissionDeniedError(dir.string() + ": " + ec.message());
  const SensorIntrinsics intrinsics = IntrinsicsOf(cell);
  for (std::size_t v = 0; v < cell.viewpoints.size(); ++v) {
    const CellViewpoint& vp = cell.viewpoints[v];
    opt.seed = seed * 1000003 + n * 101 + v;
    auto scan = SimulateScan(part, cell.world_from_part * in_fixture, DriftedPose(cell, vp, drift),
                             intrinsics, opt);
    if (!scan.ok()) return scan.status();
    if (auto st = WritePointCloud((dir / (vp.name + ".pcd")).string(), scan->cloud_in_sensor);
        !st.ok())
      return st;
  }
  if (auto st = WriteStringAtomically((dir / "truth.json").string(), truth.dump(2) + "\n");
      !st.ok())
    return st;
  return WriteStringAtomically((dir / "DONE").string(), "");
}

// The part made with the CAD's first hole moved `mm` along +x in its plane.
struct MadePart {
  TriangleMesh mesh;
  nlohmann::json truth;
};
absl::StatusOr<MadePart> ShiftFirstHole(const TriangleMesh& cad, double mm) {
  const std::vector<CadHole> holes = ListHoles(cad);
  if (holes.empty()) return absl::InvalidArgumentError("--hole-shift: the part has no hole");
  const Eigen::Vector3d& a = holes[0].axis;
  const Eigen::Vector3d shift = mm * (Eigen::Vector3d::UnitX() - a.x() * a).normalized();
  MadePart made;
  ASSIGN_OR_RETURN(made.mesh, ChangeHoles(cad, {{0, shift, 0}}));
  const Eigen::Vector3d& c = holes[0].position_mm;
  made.truth = nlohmann::json::array({{{"cad_position_mm", {c.x(), c.y(), c.z()}},
                                       {"shift_mm", {shift.x(), shift.y(), shift.z()}},
                                       {"true_position_mm", 2 * mm}}});
  return made;
}

// "X,Y,R" after a spec's second colon.
absl::Status ParsePlace(const std::string& spec, const std::string& text, SurfaceDrift* d) {
  std::vector<std::string> xyr = absl::StrSplit(text, ',');
  double x = 0, y = 0, r = 0;
  if (xyr.size() != 3 || !absl::SimpleAtod(xyr[0], &x) || !absl::SimpleAtod(xyr[1], &y) ||
      !absl::SimpleAtod(xyr[2], &r) || !(r > 0))
    return absl::InvalidArgumentError(absl::StrCat(
        "--drift ", spec, ": the place must be X,Y,R in mm with R > 0, got '", text, "'"));
  d->center_xy = Eigen::Vector2d(x, y);
  d->radius_mm = r;
  return absl::OkStatus();
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
  ScanOptions opt = ScanOptionsOf(cell);
  opt.seed = seed * 1000003 + std::hash<std::string>{}(vp.name) % 1000;
  ASSIGN_OR_RETURN(auto scan, SimulateScan(gauge, vp.world_from_gauge, DriftedPose(cell, vp, drift),
                                           IntrinsicsOf(cell), opt));
  return std::move(scan.cloud_in_sensor);
}

double SurfaceDrift::HeightAt(int k) const {
  switch (kind) {
    case Kind::kBow:
      return amount_mm * k;
    case Kind::kShift:
      return k + 1 >= from_part ? amount_mm : 0.0;
    case Kind::kNone:
      break;
  }
  return 0.0;
}

absl::StatusOr<SurfaceDrift> ParseSurfaceDrift(const std::string& spec) {
  SurfaceDrift d;
  d.spec = spec;
  std::vector<std::string> parts = absl::StrSplit(spec, absl::MaxSplits(':', 2));
  const auto bad = [&](const std::string& why) {
    return absl::InvalidArgumentError(
        absl::StrCat("--drift ", spec, ": ", why,
                     " (expected bow:RATE_MM[:X,Y,R] or shift:AMOUNT_MM@PART[:X,Y,R])"));
  };
  if (parts.size() < 2) return bad("no amount");
  std::vector<std::string> amount = absl::StrSplit(parts[1], '@');
  if (!absl::SimpleAtod(amount[0], &d.amount_mm) || !std::isfinite(d.amount_mm))
    return bad("the amount is not a number");
  if (parts[0] == "bow") {
    d.kind = SurfaceDrift::Kind::kBow;
    if (amount.size() != 1) return bad("a bow has no @PART");
  } else if (parts[0] == "shift") {
    d.kind = SurfaceDrift::Kind::kShift;
    if (amount.size() != 2 || !absl::SimpleAtoi(amount[1], &d.from_part) || d.from_part < 1)
      return bad("a shift needs @PART, the first part (1-based) with the step");
  } else {
    return bad("unknown kind '" + parts[0] + "'");
  }
  if (parts.size() == 3) RETURN_IF_ERROR(ParsePlace(spec, parts[2], &d));
  return d;
}

Eigen::Isometry3d RandomFixtureError(std::mt19937_64& rng, double mm) {
  std::normal_distribution<double> g(0, 1);
  std::uniform_real_distribution<double> u(0, 1);
  const Eigen::Vector3d dir(g(rng), g(rng), g(rng)), axis(g(rng), g(rng), g(rng));
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translate(mm * u(rng) * dir.normalized());
  t.rotate(Eigen::AngleAxisd(mm / 2 * u(rng) * M_PI / 180, axis.normalized()));
  return t;
}

nlohmann::json FixtureTruth(const Eigen::Isometry3d& in_fixture) {
  nlohmann::json matrix = nlohmann::json::array();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) matrix.push_back(in_fixture.matrix()(r, c));
  const Eigen::Vector3d t = in_fixture.translation();
  return {{"in_fixture", matrix},
          {"translation_mm", {t.x(), t.y(), t.z()}},
          {"rotation_deg", Eigen::AngleAxisd(in_fixture.linear()).angle() * 180 / M_PI}};
}

absl::StatusOr<std::vector<std::string>> SimulateParts(const CellConfig& cell,
                                                       const std::string& inbox, int count,
                                                       uint64_t seed, const SurfaceDrift& drift,
                                                       const RobotDrift& robot,
                                                       double hole_shift_mm,
                                                       double fixture_error_mm) {
  ASSIGN_OR_RETURN(auto part, ReadCellPartMesh(cell));
  std::optional<MadePart> shifted;
  if (hole_shift_mm > 0) {
    ASSIGN_OR_RETURN(shifted, ShiftFirstHole(part, hole_shift_mm));
  }
  std::mt19937_64 rng(seed);
  std::vector<std::string> ids;
  for (int k = 0, n = 1; k < count; ++n) {
    const std::string id = absl::StrFormat("sim-%04d-%04d", seed % 10000, n);
    if (fs::exists(fs::path(inbox) / id)) continue;
    ++k;
    ScanOptions opt = ScanOptionsOf(cell);
    KeepClear clear;
    if (drift.kind != SurfaceDrift::Kind::kNone)
      clear = {DriftCenterXY(part, drift), drift.radius_mm};
    nlohmann::json truth = {{"defects", PlantDefects(part, rng, &opt, clear)}};
    if (drift.kind != SurfaceDrift::Kind::kNone)
      truth["drift"] = PlantDrift(part, drift, k - 1, &opt);
    const bool shift = shifted && k % 3 == 0;
    if (shift) truth["holes"] = shifted->truth;
    const Eigen::Isometry3d in_fixture = fixture_error_mm > 0
                                             ? RandomFixtureError(rng, fixture_error_mm)
                                             : Eigen::Isometry3d::Identity();
    if (fixture_error_mm > 0) truth["fixture"] = FixtureTruth(in_fixture);
    RETURN_IF_ERROR(DropPart(cell, shift ? shifted->mesh : part, fs::path(inbox) / id, opt, truth,
                             seed, n, robot, in_fixture));
    ids.push_back(id);
  }
  return ids;
}

}  // namespace surfinspect::client
