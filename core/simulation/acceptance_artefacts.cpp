#include "core/simulation/acceptance_artefacts.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace surfinspect {
namespace {

// 512 x 256 facets: sag r (1 - cos(pi / 512)) = 0.24 µm at r = 12.5 mm.
constexpr int kSlices = 512, kStacks = 256;

struct BarPlacement {
  const char* name;
  const char* view_a;
  const char* view_b;
  Eigen::Vector3d a, b;  // part frame, mm; b is rescaled to the bar's length
};

// Same-view positions first, then four that need two viewpoints: no single
// view sees both spheres whole (checked by projecting each sphere into every
// view; tests/core/simulation/acceptance_artefacts_test.cpp counts points).
const BarPlacement kBar[] = {
    {"bb-1", "v3", "v3", {-100, 0, 50}, {100, 0, 50}},
    {"bb-2", "v3", "v3", {-80, -60, 50}, {80, 60, 50}},
    {"bb-3", "v2", "v2", {-140, 50, 50}, {20, -70, 50}},
    {"bb-4", "v4", "v4", {-30, 0, 10}, {150, 0, 97.18}},
    {"bb-5", "v1", "v3", {-190, 0, 50}, {10, 0, 50}},
    {"bb-6", "v2", "v4", {-140, -40, 50}, {53.19, -91.76, 50}},
    {"bb-7", "v1", "v5", {-180, 40, 50}, {13.19, 91.76, 50}},
    {"bb-8", "v2", "v5", {-150, -20, 50}, {23.2, 80, 50}},
};

Eigen::Vector3d Rounded(const Eigen::Vector3d& v) {
  return {std::round(v.x()), std::round(v.y()), std::round(v.z())};
}

Eigen::Isometry3d Translation(const Eigen::Vector3d& t) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.translation() = t;
  return p;
}

void AddSpheres(const DemoCell& cell, const AcceptanceArtefactOptions& o, AcceptanceScene& s) {
  auto sphere = std::make_shared<TriangleMesh>();
  AddUvSphere(*sphere, Eigen::Vector3d::Zero(), 0.5 * s.true_sphere_diameter_mm, kSlices, kStacks);
  const std::pair<const char*, double> at[] = {{"v1", -120}, {"v3", 0}, {"v5", 120}};
  int k = 1;
  for (const auto& [view, x] : at) {
    const Eigen::Vector3d c = cell.world_from_part * Eigen::Vector3d(x, 0, 50);
    const std::string name = absl::StrCat("sphere-", k++);
    s.objects[name] = {sphere, Translation(c), {}, {c}};
    s.artefacts.spheres.push_back({name, {view, Rounded(c)}});
  }
  s.artefacts.sphere_diameter_mm = o.sphere_diameter_mm;
  s.artefacts.sphere_diameter_u_mm = 0.0002;
}

void AddBallBar(const DemoCell& cell, const AcceptanceArtefactOptions& o, AcceptanceScene& s) {
  const double half = 0.5 * s.true_length_mm;
  auto bar = std::make_shared<TriangleMesh>();
  AddUvSphere(*bar, Eigen::Vector3d(-half, 0, 0), 0.5 * o.sphere_diameter_mm, kSlices, kStacks);
  AddUvSphere(*bar, Eigen::Vector3d(half, 0, 0), 0.5 * o.sphere_diameter_mm, kSlices, kStacks);
  for (const BarPlacement& p : kBar) {
    const Eigen::Vector3d a = cell.world_from_part * p.a;
    const Eigen::Vector3d dir = (cell.world_from_part.linear() * (p.b - p.a)).normalized();
    const Eigen::Vector3d b = a + s.true_length_mm * dir;
    Eigen::Isometry3d pose = Translation(0.5 * (a + b));
    pose.linear() =
        Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitX(), dir).toRotationMatrix();
    s.objects[p.name] = {bar, pose, {}, {a, b}};
    s.artefacts.ball_bar.push_back({p.name, {p.view_a, Rounded(a)}, {p.view_b, Rounded(b)}});
  }
  s.artefacts.ball_bar_length_mm = o.length_mm;
  s.artefacts.ball_bar_length_u_mm = 0.0005;
  s.artefacts.ball_bar_sphere_diameter_mm = o.sphere_diameter_mm;
}

// A 150 x 110 x 8 mm plate, top face at z = 0 of its frame, tilted 4 deg
// about x, its top centre at (0, 0, 40) in the part's frame.
void AddPlate(const DemoCell& cell, const AcceptanceArtefactOptions& o, AcceptanceScene& s) {
  auto plate = std::make_shared<TriangleMesh>();
  const float x = 75, y = 55, z = 8;
  for (int i = 0; i < 8; ++i)
    plate->vertices.emplace_back(i & 1 ? x : -x, i & 2 ? y : -y, i & 4 ? 0.0f : -z);
  const Triangle faces[12] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                              {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  for (const auto& f : faces) plate->triangles.push_back(f);
  Eigen::Isometry3d pose = cell.world_from_part * Translation({0, 0, 40});
  pose.rotate(Eigen::AngleAxisd(4.0 * M_PI / 180, Eigen::Vector3d::UnitX()));
  SurfaceDefect dent;
  dent.center_in_part = Eigen::Vector3d::Zero();
  dent.radius_mm = 30;  // Gaussian sigma 15 mm
  dent.depth_mm = o.plate_dent_mm;
  const double radius = 45;
  PlateMeasurement m;
  m.name = "plate-1";
  m.at = {"v3", Rounded(pose.translation())};
  m.normal = pose.linear().col(2);
  m.radius_mm = radius;
  // The LS plane of a centred radial dent is flat; the range over the disc
  // is depth (1 - exp(-R^2 / (2 sigma^2))).
  const double sigma = 0.5 * dent.radius_mm;
  s.true_flatness_mm = o.plate_dent_mm * (1 - std::exp(-radius * radius / (2 * sigma * sigma)));
  s.objects[m.name] = {plate, pose, {dent}, {}};
  s.artefacts.plates.push_back(m);
  s.artefacts.plate_flatness_u_mm = 0.0002;
}

}  // namespace

AcceptanceScene MakeDemoAcceptance(const DemoCell& cell, const AcceptanceArtefactOptions& o) {
  AcceptanceScene s;
  s.true_sphere_diameter_mm = o.sphere_diameter_mm + o.sphere_error_mm;
  s.true_length_mm = o.length_mm + o.length_error_mm;
  AddSpheres(cell, o, s);
  AddBallBar(cell, o, s);
  AddPlate(cell, o, s);
  s.artefacts.mpe = o.mpe;
  return s;
}

absl::StatusOr<std::size_t> ViewIndex(const DemoCell& cell, const std::string& view) {
  for (std::size_t v = 0; v < cell.viewpoints.size(); ++v)
    if (cell.viewpoints[v].name == view) return v;
  return absl::NotFoundError(absl::StrCat("no viewpoint ", view, " in the cell"));
}

absl::StatusOr<SimulatedScan> SimulateAcceptanceScan(const DemoCell& cell,
                                                     const AcceptanceScene& scene,
                                                     const std::string& name,
                                                     const Eigen::Isometry3d& world_from_sensor,
                                                     const ScanOptions& scan) {
  const auto it = scene.objects.find(name);
  if (it == scene.objects.end())
    return absl::NotFoundError(absl::StrCat("no acceptance measurement ", name));
  ScanOptions opt = scan;
  opt.defects = it->second.defects;
  uint64_t h = 1469598103934665603ull;  // FNV-1a of the name: a seed per measurement
  for (char c : name) h = (h ^ uint8_t(c)) * 1099511628211ull;
  opt.seed = scan.seed * 1000003 + (h % 1000003) +
             uint64_t(std::llround(1e3 * world_from_sensor.translation().norm()));
  return SimulateScan(*it->second.mesh, it->second.world_from_object, world_from_sensor,
                      cell.intrinsics, opt);
}

}  // namespace surfinspect
