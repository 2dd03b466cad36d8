#include "client/cell/demo_cell_files.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <system_error>

#include "absl/strings/str_cat.h"
#include "core/io/atomic_file.h"
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"
#include "core/io/io_transform.h"
#include "core/plan/inspection_plan.h"
#include "core/simulation/acceptance_artefacts.h"
#include "core/types/status_macros.h"

namespace surfinspect::client {
namespace {

absl::Status MakeDirectory(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::create_directories(path, ec); ec)
    return absl::PermissionDeniedError(absl::StrCat(path, ": ", ec.message()));
  return absl::OkStatus();
}

// Writes the gauge scans; returns cell.json's "viewpoints" array.
absl::StatusOr<nlohmann::json> WriteGaugeScans(const std::string& dir, const DemoCell& cell,
                                               const ScanOptions& scan) {
  nlohmann::json views = nlohmann::json::array();
  for (std::size_t v = 0; v < cell.viewpoints.size(); ++v) {
    const DemoViewpoint& vp = cell.viewpoints[v];
    ASSIGN_OR_RETURN(auto gauge_scan, SimulateDemoGaugeScan(cell, v, scan));
    const std::string gauge_path = absl::StrCat("gauge_scans/", vp.name, ".pcd");
    RETURN_IF_ERROR(WritePointCloud(dir + "/" + gauge_path, gauge_scan.cloud_in_sensor));
    views.push_back(
        {{"name", vp.name},
         {"nominal_world_from_sensor", TransformToJsonValue(vp.nominal_world_from_sensor)},
         {"world_from_gauge", TransformToJsonValue(vp.world_from_gauge)},
         {"gauge_scan", gauge_path},
         {"simulation_truth_world_from_sensor", TransformToJsonValue(vp.world_from_sensor)}});
  }
  return views;
}

// The outlier pixels of one production scan, as truth/PART/VIEW.json holds them.
nlohmann::json ScanTruth(const std::string& part_id, const std::string& view,
                         const SimulatedScan& scan) {
  nlohmann::json pulses = nlohmann::json::array(), stripes = nlohmann::json::array();
  for (std::size_t i = 0; i < scan.labels.size(); ++i) {
    if (scan.labels[i] == PixelLabel::kPulse) pulses.push_back(i);
    if (scan.labels[i] == PixelLabel::kStripe) stripes.push_back(i);
  }
  return {{"part_id", part_id},        {"viewpoint", view},
          {"valid_points", scan.hits}, {"pulse_pixels", pulses},
          {"stripe_pixels", stripes},  {"defect_pixels", scan.defect_pixels}};
}

// Writes one part's scans and truth; returns its entry of truth/parts.json.
absl::StatusOr<nlohmann::json> WritePart(const std::string& dir, const DemoCell& cell,
                                         const DemoPart& part, const ScanOptions& scan) {
  nlohmann::json defects = nlohmann::json::array();
  for (const SurfaceDefect& d : part.defects)
    defects.push_back(
        {{"center_in_part", {d.center_in_part.x(), d.center_in_part.y(), d.center_in_part.z()}},
         {"radius_mm", d.radius_mm},
         {"depth_mm", d.depth_mm}});
  for (const char* sub : {"/scans/", "/truth/"})
    RETURN_IF_ERROR(MakeDirectory(absl::StrCat(dir, sub, part.part_id)));
  nlohmann::json scans = nlohmann::json::object();
  for (std::size_t v = 0; v < cell.viewpoints.size(); ++v) {
    const std::string& view = cell.viewpoints[v].name;
    ASSIGN_OR_RETURN(auto s, SimulateDemoPartScan(cell, part, v, scan));
    const std::string path = absl::StrCat("scans/", part.part_id, "/", view, ".pcd");
    RETURN_IF_ERROR(WritePointCloud(dir + "/" + path, s.cloud_in_sensor));
    if (auto st =
            WriteStringAtomically(absl::StrCat(dir, "/truth/", part.part_id, "/", view, ".json"),
                                  ScanTruth(part.part_id, view, s).dump());
        !st.ok())
      return st;
    scans[view] = path;
  }
  return nlohmann::json{{"part_id", part.part_id}, {"defects", defects}, {"scans", scans}};
}

// The highest vertex of the part at the station nearest x: the ridge's top.
double RidgeTopZ(const TriangleMesh& part, double x) {
  double best_dx = INFINITY, z = -INFINITY;
  for (const Eigen::Vector3f& v : part.vertices) {
    const double dx = std::abs(v.x() - x);
    if (dx < best_dx - 1e-9) best_dx = dx, z = v.z();
    if (std::abs(dx - best_dx) <= 1e-9) z = std::max(z, double{v.z()});
  }
  return z;
}

// plan.json (docs/inspection-plan.md): the top ridge, where the parts are
// judged, as a region with a tighter band than the cell's +-0.3 mm; three
// comparison points along it; a section across it at x = 0 (a 1 mm slab,
// the ridge's band); defect detection with the threshold chosen
// for the scans' noise (sigma 0.015 mm: 0.03 mm is ~7 sigma of the local
// median); and every hole and slot the CAD has (ListHoles), H1.. and S1..
// in its order, with a 0.3 mm true-position zone; the ridge's trim edge at
// +x within +-0.5 mm. The surface keeps the cell's tolerance_mm.
nlohmann::json PlanJson(const DemoCell& cell) {
  const Bounds3 b = ComputeBounds(cell.part);
  nlohmann::json holes = PlanHolesJson(ListHoles(cell.part), 0.3);
  nlohmann::json points = nlohmann::json::array();
  for (const auto& [name, x] : {std::pair<const char*, double>{"ridge-left", -100.0},
                                {"ridge-centre", 0.0},
                                {"ridge-right", 100.0}})
    points.push_back({{"name", name},
                      {"position_mm", {x, 0.0, RidgeTopZ(cell.part, x)}},
                      {"normal", {0, 0, 1}},
                      {"radius_mm", 3.0},
                      {"tolerance_mm", {{"lower", -0.1}, {"upper", 0.1}}}});
  return {
      {"schema", "surfinspect.plan/1"},
      {"regions",
       {{{"name", "ridge"},
         {"select", {{"box_mm", {{b.min.x(), -25.0, 50.0}, {b.max.x(), 25.0, b.max.z() + 10}}}}},
         {"tolerance_mm", {{"lower", -0.15}, {"upper", 0.15}}},
         {"allowed_fraction_outside", 0.001}}}},
      {"points", points},
      {"sections",
       {{{"name", "ridge-x0"},
         {"point_mm", {0.0, 0.0, 0.0}},
         {"normal", {1, 0, 0}},
         {"width_mm", 1.0},
         {"region", "ridge"},
         {"tolerance_mm", {{"lower", -0.15}, {"upper", 0.15}}},
         {"allowed_fraction_outside", 0.001}}}},
      {"holes", holes["holes"]},
      {"slots", holes["slots"]},
      {"edge_points",
       {{{"name", "trim-x+"},
         {"position_mm", {b.max.x(), 0.0, RidgeTopZ(cell.part, b.max.x())}},
         {"tolerance_mm", {{"lower", -0.5}, {"upper", 0.5}}}}}},
      {"defects", {{"threshold_mm", 0.03}, {"min_area_mm2", 3.0}}}};
}

nlohmann::json CellJson(const DemoCell& cell, nlohmann::json views) {
  return {{"units", "mm"},
          {"part",
           {{"mesh", "part.stl"}, {"world_from_part", TransformToJsonValue(cell.world_from_part)}}},
          {"gauge", {{"mesh", "gauge.stl"}}},
          {"sensor",
           {{"width", cell.intrinsics.width},
            {"height", cell.intrinsics.height},
            {"horizontal_fov_deg", cell.intrinsics.horizontal_fov_deg},
            {"min_range_mm", cell.intrinsics.min_range_mm},
            {"max_range_mm", cell.intrinsics.max_range_mm}}},
          {"viewpoints", std::move(views)},
          // Stamped sheet metal: +-0.3 mm, and 0.1% of the points may fall
          // outside (unfiltered speckle at shadow edges) before a part fails.
          {"tolerance_mm", 0.3},
          {"plan", "plan.json"},
          {"error_map", {{"allowed_fraction_outside", 0.001}, {"max_distance_mm", 5.0}}}};
}

// One scan of an acceptance measurement from its viewpoint's true pose.
absl::Status WriteAcceptanceScan(const std::string& dir, const DemoCell& cell,
                                 const AcceptanceScene& scene, const std::string& name,
                                 const std::string& view, const ScanOptions& scan) {
  ASSIGN_OR_RETURN(auto v, ViewIndex(cell, view));
  ASSIGN_OR_RETURN(auto s, SimulateAcceptanceScan(cell, scene, name,
                                                  cell.viewpoints[v].world_from_sensor, scan));
  const std::string sub = absl::StrCat(dir, "/acceptance/scans/", name);
  RETURN_IF_ERROR(MakeDirectory(sub));
  return WritePointCloud(absl::StrCat(sub, "/", view, ".pcd"), s.cloud_in_sensor,
                         PcdEncoding::kBinaryCompressed);
}

// DIR/acceptance/: every measurement's scans, then artefacts.json with the
// simulated truth of each figure beside the calibrated values.
absl::Status WriteAcceptance(const std::string& dir, const DemoCell& cell,
                             const ScanOptions& scan) {
  const AcceptanceScene scene = MakeDemoAcceptance(cell);
  const Artefacts& a = scene.artefacts;
  std::vector<std::pair<std::string, std::string>> scans;
  for (const auto& m : a.spheres) scans.emplace_back(m.name, m.at.view);
  for (const auto& b : a.ball_bar) {
    scans.emplace_back(b.name, b.a.view);
    if (b.cross_view()) scans.emplace_back(b.name, b.b.view);
  }
  for (const auto& p : a.plates) scans.emplace_back(p.name, p.at.view);
  for (const auto& [name, view] : scans)
    RETURN_IF_ERROR(WriteAcceptanceScan(dir, cell, scene, name, view, scan));
  nlohmann::json j = ArtefactsToJson(a);
  j["simulation_truth"] = {
      {"sphere_diameter_mm", scene.true_sphere_diameter_mm},
      {"ball_bar_length_mm", scene.true_length_mm},
      {"PS_mm", scene.true_sphere_diameter_mm - a.sphere_diameter_mm},
      {"SD_mm", scene.true_length_mm - a.ball_bar_length_mm},
      {"PF_mm_form", 0.0},
      {"F_mm_form", scene.true_flatness_mm},
      {"note", "PF and F of noisy scans also hold the sensor noise, as the guideline intends"}};
  return WriteStringAtomically(dir + "/acceptance/artefacts.json", j.dump(2) + "\n");
}

}  // namespace

absl::Status WriteDemoCell(const std::string& dir, const DemoCell& cell,
                           const DemoWriteOptions& options) {
  for (const char* sub : {"", "/gauge_scans", "/scans", "/truth"})
    RETURN_IF_ERROR(MakeDirectory(dir + sub));
  RETURN_IF_ERROR(WriteMesh(dir + "/part.stl", cell.part));
  RETURN_IF_ERROR(WriteMesh(dir + "/gauge.stl", cell.gauge));
  ASSIGN_OR_RETURN(auto views, WriteGaugeScans(dir, cell, options.scan));
  nlohmann::json parts = nlohmann::json::array();
  for (const DemoPart& part : MakeDemoParts(cell, options.parts, options.scan.seed)) {
    ASSIGN_OR_RETURN(auto entry, WritePart(dir, cell, part, options.scan));
    parts.push_back(std::move(entry));
  }
  RETURN_IF_ERROR(WriteStringAtomically(dir + "/plan.json", PlanJson(cell).dump(2) + "\n"));
  if (auto st = WriteStringAtomically(dir + "/cell.json",
                                      CellJson(cell, std::move(views)).dump(2) + "\n");
      !st.ok())
    return st;
  if (auto st =
          WriteStringAtomically(dir + "/truth/parts.json", nlohmann::json(parts).dump(2) + "\n");
      !st.ok())
    return st;
  return options.acceptance ? WriteAcceptance(dir, cell, options.scan) : absl::OkStatus();
}

}  // namespace surfinspect::client
