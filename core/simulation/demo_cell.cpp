#include "core/simulation/demo_cell.h"

#include <cmath>
#include <random>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/plan/cad_holes.h"
#include "core/plan/inspection_plan.h"
#include "core/types/transform.h"

namespace surfinspect {
namespace {

void AddBox(TriangleMesh& m, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  const auto base = static_cast<uint32_t>(m.vertices.size());
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(),
                            i & 4 ? hi.z() : lo.z());
  const Triangle faces[12] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                              {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  for (const auto& f : faces) m.triangles.push_back({base + f[0], base + f[1], base + f[2]});
}

Eigen::Isometry3d Pose(const Eigen::Vector3d& t, double yaw_deg) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  p.translation() = t;
  return p;
}

// A small rigid perturbation of exactly `mm` and `deg` in random directions.
Eigen::Isometry3d Perturb(std::mt19937_64& rng, double mm, double deg) {
  std::normal_distribution<double> g;
  const Eigen::Vector3d axis = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
  const Eigen::Vector3d dir = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
  Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
  d.linear() = Eigen::AngleAxisd(deg * M_PI / 180, axis).toRotationMatrix();
  d.translation() = mm * dir;
  return d;
}

}  // namespace

void AddUvSphere(TriangleMesh& m, const Eigen::Vector3d& c, double r, int slices, int stacks) {
  const auto base = static_cast<uint32_t>(m.vertices.size());
  m.vertices.push_back((c + Eigen::Vector3d(0, 0, r)).cast<float>());  // north pole
  for (int s = 1; s < stacks; ++s) {
    const double phi = M_PI * s / stacks;
    for (int k = 0; k < slices; ++k) {
      const double th = 2 * M_PI * k / slices;
      m.vertices.push_back((c + r * Eigen::Vector3d(std::sin(phi) * std::cos(th),
                                                    std::sin(phi) * std::sin(th), std::cos(phi)))
                               .cast<float>());
    }
  }
  m.vertices.push_back((c - Eigen::Vector3d(0, 0, r)).cast<float>());  // south pole
  const uint32_t south = static_cast<uint32_t>(m.vertices.size() - 1);
  auto ring = [&](int s, int k) { return base + 1 + uint32_t((s - 1) * slices + (k % slices)); };
  for (int k = 0; k < slices; ++k) m.triangles.push_back({base, ring(1, k), ring(1, k + 1)});
  for (int s = 1; s + 1 < stacks; ++s)
    for (int k = 0; k < slices; ++k) {
      m.triangles.push_back({ring(s, k), ring(s + 1, k), ring(s + 1, k + 1)});
      m.triangles.push_back({ring(s, k), ring(s + 1, k + 1), ring(s, k + 1)});
    }
  for (int k = 0; k < slices; ++k)
    m.triangles.push_back({south, ring(stacks - 1, k + 1), ring(stacks - 1, k)});
}

TriangleMesh MakeGaugeMesh() {
  // Stepped plate (x-normal step faces) and three spheres of different radii
  // at asymmetric spots: together they pin all six degrees of freedom.
  TriangleMesh m;
  AddBox(m, {-80, -60, -10}, {80, 60, 0});
  AddBox(m, {10, -55, 0}, {75, 55, 15});  // inset: no edge shared with the plate
  AddUvSphere(m, {-45, -25, 12}, 12, 48, 24);
  AddUvSphere(m, {-30, 30, 18}, 18, 48, 24);
  AddUvSphere(m, {45, 5, 15 + 20}, 20, 48, 24);
  return m;
}

DemoCell MakeDemoCell(const DemoCellOptions& o) {
  DemoCell cell;
  cell.part_length_mm = o.part_length_mm;
  cell.features = DemoPillarFeatures();
  cell.part = MakePillarMesh(o.part_length_mm, cell.features);
  cell.gauge = MakeGaugeMesh();
  cell.world_from_part = Pose({600, 100, 5}, 3.0);
  std::mt19937_64 rng(o.seed);
  const double xs[5] = {-0.4, -0.2, 0.0, 0.2, 0.4};
  const double tilt_deg[5][2] = {{12, -8}, {-10, 5}, {6, 10}, {-12, -6}, {10, 8}};
  for (int v = 0; v < 5; ++v) {
    const double x = xs[v] * o.part_length_mm;
    const Eigen::Vector3d target_part(x, 0, PillarRidgeZ(x, o.part_length_mm));
    const Eigen::Vector3d target = cell.world_from_part * target_part;
    const Eigen::Vector3d dir =
        (Eigen::AngleAxisd(tilt_deg[v][0] * M_PI / 180, Eigen::Vector3d::UnitX()) *
         Eigen::AngleAxisd(tilt_deg[v][1] * M_PI / 180, Eigen::Vector3d::UnitY()) *
         Eigen::Vector3d::UnitZ());
    DemoViewpoint vp;
    vp.name = absl::StrCat("v", v + 1);
    vp.world_from_sensor = LookAt(target + 400.0 * dir, target,
                                  cell.world_from_part.linear() * -Eigen::Vector3d::UnitY());
    vp.nominal_world_from_sensor =
        vp.world_from_sensor * Perturb(rng, o.nominal_error_mm, o.nominal_error_deg);
    // The gauge is surveyed where the optical axis meets z = 20 mm.
    const Eigen::Vector3d eye = vp.world_from_sensor.translation();
    const Eigen::Vector3d axis = vp.world_from_sensor.linear().col(2);
    const double s = (20.0 - eye.z()) / axis.z();
    const Eigen::Vector3d on_table = eye + s * axis;
    vp.world_from_gauge = Pose({on_table.x(), on_table.y(), 0.0}, 15.0 * v - 20.0);
    cell.viewpoints.push_back(vp);
  }
  return cell;
}

std::vector<DemoPart> MakeDemoParts(const DemoCell& cell, int count, uint64_t scan_seed) {
  std::mt19937_64 rng(scan_seed + 7);
  std::uniform_real_distribution<double> ux(-0.45, 0.45), uy(-18, 18), udepth(0.05, 0.5),
      uradius(3, 8);
  const Bounds3 bounds = ComputeBounds(cell.part);
  const double length = bounds.max.x() - bounds.min.x();
  std::vector<DemoPart> parts;
  for (int k = 1; k <= count; ++k) {
    DemoPart part;
    part.number = k;
    part.part_id = absl::StrFormat("part-%03d", k);
    for (int d = 0; d < 3; ++d) {
      SurfaceDefect defect;
      const double x = ux(rng) * length;
      defect.center_in_part = {x, uy(rng), PillarRidgeZ(x, length)};
      defect.radius_mm = uradius(rng);
      defect.depth_mm = (d == 2 ? -1 : 1) * udepth(rng);  // two dents and a bump
      part.defects.push_back(defect);
    }
    parts.push_back(std::move(part));
  }
  return parts;
}

absl::StatusOr<SimulatedScan> SimulateDemoGaugeScan(const DemoCell& cell, std::size_t v,
                                                    const ScanOptions& scan) {
  const DemoViewpoint& vp = cell.viewpoints.at(v);
  ScanOptions gauge_opt = scan;
  gauge_opt.defects.clear();
  gauge_opt.seed = scan.seed * 1000 + v;
  return SimulateScan(cell.gauge, vp.world_from_gauge, vp.world_from_sensor, cell.intrinsics,
                      gauge_opt);
}

nlohmann::json DemoRpsAlignment(const DemoCell& cell) {
  const nlohmann::json holes = PlanHolesJson(ListHoles(cell.part), 0.3);
  const auto near = [&](double x, double y) {
    std::string best;
    double d = INFINITY;
    for (const nlohmann::json& h : holes["holes"]) {
      const double e =
          std::hypot(h["position_mm"][0].get<double>() - x, h["position_mm"][1].get<double>() - y);
      if (e < d) d = e, best = h["name"];
    }
    return best;
  };
  const double len = cell.part_length_mm;
  const auto at = [&](double x, double y, double below) {
    return nlohmann::json{x, y, PillarRidgeZ(x, len) - below};
  };
  return {{"mode", "rps"},
          {"references",
           {{{"name", "A1"}, {"hole", near(-110, 0)}},
            {{"name", "A2"}, {"hole", near(35, 10)}},
            {{"name", "B1"}, {"position_mm", at(-70, 15, 0)}},
            {{"name", "B2"}, {"position_mm", at(110, -15, 0)}},
            {{"name", "C1"}, {"position_mm", at(-120, 65, 60)}},
            {{"name", "C2"}, {"position_mm", at(120, -65, 60)}}}}};
}

absl::StatusOr<SimulatedScan> SimulateDemoPartScan(const DemoCell& cell, const DemoPart& part,
                                                   std::size_t v, const ScanOptions& scan) {
  const DemoViewpoint& vp = cell.viewpoints.at(v);
  ScanOptions opt = scan;
  opt.defects.insert(opt.defects.end(), part.defects.begin(), part.defects.end());
  opt.seed = scan.seed * 7919 + part.number * 100 + v;
  const Eigen::Isometry3d placed = cell.world_from_part * part.in_fixture;
  if (!part.manufactured)
    return SimulateScan(cell.part, placed, vp.world_from_sensor, cell.intrinsics, opt);
  const TriangleMesh made = MakePillarMesh(cell.part_length_mm, *part.manufactured);
  return SimulateScan(made, placed, vp.world_from_sensor, cell.intrinsics, opt);
}

}  // namespace surfinspect
