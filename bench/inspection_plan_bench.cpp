// The cost of an inspection plan next to the error map it judges: a ~2 M-point
// organized scan of the demo pillar (2048 x 1536 sensor, noise 0.015 mm,
// two planted dents), its error map, then a plan of 20 regions and 50
// comparison points (resolution and the one-pass characteristics), and
// defect detection on the same map. Goal: the characteristics add at most
// 15% to the error map. Then a drawing's features on a pillar with 20
// holes: the holes, 10 sections and coverage, each timed through
// EvaluatePlan against the same plan without them; goal: together at most
// 15% of the error map. Each step is timed best of 3 (the plans with
// features best of 7: their cost is a difference of two times), 2 threads.
//
//   build/bin/inspection_plan_bench
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>

#include "core/plan/cad_holes.h"
#include "core/plan/characteristics.h"
#include "core/plan/coverage.h"
#include "core/plan/defects.h"
#include "core/plan/inspection_plan.h"
#include "core/plan/plan_evaluation.h"
#include "core/plan/surface_neighbourhood.h"
#include "core/simulation/demo_cell.h"
#include "core/simulation/pillar.h"
#include "core/types/transform.h"

namespace {

using namespace surfinspect;

// The least of n wall times: this machine's other work only ever adds.
double BestOf(int n, const std::function<void()>& f) {
  double best = 1e30;
  for (int k = 0; k < n; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best,
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

// The demo cell's part seen from its top viewpoint, and its error map
// (timed best of 3, 2 threads).
struct MappedView {
  SimulatedScan scan;
  PointCloud cloud;  // world frame
  ErrorMapResult em;
  double map_seconds = 0;
  Eigen::Isometry3d part_from_sensor;
};
absl::StatusOr<MappedView> MapTopView(const DemoCell& cell, const SensorIntrinsics& in,
                                      const ScanOptions& opt) {
  const DemoViewpoint& vp = cell.viewpoints[2];
  auto scan = SimulateScan(cell.part, cell.world_from_part, vp.world_from_sensor, in, opt);
  if (!scan.ok()) return scan.status();
  MappedView v{*std::move(scan), {}, {}, 0, cell.world_from_part.inverse() * vp.world_from_sensor};
  v.cloud = TransformCloud(v.scan.cloud_in_sensor, vp.world_from_sensor);
  auto index = MeshIndex::Build(cell.part);
  if (!index.ok()) return index.status();
  ErrorMapSettings es;
  es.threads = 2;
  absl::StatusOr<ErrorMapResult> em;
  v.map_seconds =
      BestOf(3, [&] { em = ComputeErrorMap(**index, v.cloud, cell.world_from_part, es); });
  if (!em.ok()) return em.status();
  v.em = *std::move(em);
  return v;
}

InspectionPlan TwentyRegionsFiftyPoints() {
  InspectionPlan plan;
  plan.tolerance = {-0.1, 0.1};
  for (int k = 0; k < 20; ++k) {  // 15 mm slices along x, each 30 mm long: every triangle in two
    PlanRegion r;
    r.name = "slice" + std::to_string(k);
    r.select.box_min_mm = {-150 + 15.0 * k - 15, -80, -10};
    r.select.box_max_mm = {-150 + 15.0 * k + 15, 80, 80};
    r.tolerance = ToleranceBand{-0.05, 0.15};
    plan.regions.push_back(r);
  }
  for (int k = 0; k < 50; ++k) {
    const double x = -120 + 240.0 * k / 49;
    ComparisonPoint p;
    p.name = "P" + std::to_string(k);
    p.position_mm = {x, (k % 5 - 2) * 8.0, 60.0 - 3.0 * (x / 150) * (x / 150)};
    p.radius_mm = 2.0;
    plan.points.push_back(p);
  }
  return plan;
}

// 12 holes in the top, 8 in the flanges, 5-12 mm.
PillarFeatures TwentyHoles() {
  PillarFeatures f;
  for (int k = 0; k < 12; ++k)
    f.holes.push_back({-132 + 24.0 * k, k % 2 ? 9.0 : -9.0, 5.0 + (k % 4) * 2, 0});
  for (int k = 0; k < 8; ++k)
    f.holes.push_back({-120 + 34.0 * k, k % 2 ? 63.4 : -63.4, 6.0 + (k % 3) * 3, 0});
  return f;
}

// The part's holes, 10 sections across x, and a least coverage, each
// switched on by its flag.
nlohmann::json DrawingPlan(const TriangleMesh& part, bool holes, bool sections, bool coverage) {
  nlohmann::json plan = {{"tolerance_mm", {{"lower", -0.3}, {"upper", 0.3}}},
                         {"min_coverage", coverage ? 0.5 : 0.0}};
  if (holes) plan["holes"] = PlanHolesJson(ListHoles(part), 0.3)["holes"];
  if (sections)
    for (int k = 0; k < 10; ++k)
      plan["sections"].push_back({{"name", "X" + std::to_string(k)},
                                  {"point_mm", {-135 + 30.0 * k, 0, 0}},
                                  {"normal", {1, 0, 0}},
                                  {"width_mm", 1.0}});
  return plan;
}

// The drawing's plan on a 20-hole pillar seen by the 2048 x 1536 sensor
// from the demo's top viewpoint: each feature's time over the plan without
// features, in % of the error map.
int RunDrawingPlan(const SensorIntrinsics& in, const ScanOptions& opt) {
  DemoCell cell = MakeDemoCell();
  cell.part = MakePillarMesh(cell.part_length_mm, TwentyHoles());
  auto view = MapTopView(cell, in, opt);
  if (!view.ok()) return std::fprintf(stderr, "%s\n", view.status().ToString().c_str()), 1;
  const PointCloud& cloud = view->cloud;
  const ErrorMapResult* em = &view->em;
  const double t_map = view->map_seconds;
  ErrorMapSettings es;
  const std::vector<PlanView> views = {
      {"top", &view->scan.cloud_in_sensor, view->part_from_sensor}};
  const auto time_plan = [&](bool holes, bool sections, bool coverage, std::size_t* measured) {
    auto plan =
        ParsePlanWithDefaults(DrawingPlan(cell.part, holes, sections, coverage), cell.part, es);
    if (!plan.ok()) return std::fprintf(stderr, "%s\n", plan.status().ToString().c_str()), -1.0;
    absl::StatusOr<PlanOutcome> out;
    const double t =
        BestOf(7, [&] { out = EvaluatePlan(*em, cloud, cell.part, *plan, 2, nullptr, views); });
    if (!out.ok()) return std::fprintf(stderr, "%s\n", out.status().ToString().c_str()), -1.0;
    if (measured)
      for (const auto& c : out->characteristics.characteristics)
        *measured += c.is_hole() && c.measured;
    return t;
  };
  std::size_t holes_measured = 0;
  const double base = time_plan(false, false, false, nullptr);
  const double holes = time_plan(true, false, false, &holes_measured) - base;
  const double sections = time_plan(false, true, false, nullptr) - base;
  const double coverage = time_plan(false, false, true, nullptr) - base;
  const double all = time_plan(true, true, true, nullptr) - base;
  std::printf("\ndrawing plan: 20-hole pillar, %zu points, %zu matched, %zu triangles\n",
              cloud.size(), em->stats.matched, cell.part.num_triangles());
  std::printf("error map          %8.1f ms\n", 1e3 * t_map);
  std::printf(
      "20 holes           %8.1f ms  %5.1f%% of the error map (%zu measured from this view)\n",
      1e3 * holes, 100 * holes / t_map, holes_measured);
  std::printf("10 sections        %8.1f ms  %5.1f%% of the error map\n", 1e3 * sections,
              100 * sections / t_map);
  std::printf("coverage           %8.1f ms  %5.1f%% of the error map\n", 1e3 * coverage,
              100 * coverage / t_map);
  std::printf("all three          %8.1f ms  %5.1f%% of the error map (goal 15%%)\n", 1e3 * all,
              100 * all / t_map);
  return 0;
}

int Run() {
  const DemoCell cell = MakeDemoCell();
  SensorIntrinsics in = cell.intrinsics;
  in.width = 2048;
  in.height = 1536;
  ScanOptions opt;
  opt.noise_sigma_mm = 0.015;
  opt.defects = {{{-40, 5, 59.8}, 5, 0.2}, {{50, -8, 59.7}, 4, -0.1}};
  auto view = MapTopView(cell, in, opt);
  if (!view.ok()) return std::fprintf(stderr, "%s\n", view.status().ToString().c_str()), 1;
  const PointCloud& cloud = view->cloud;
  const ErrorMapResult* em = &view->em;
  const double t_map = view->map_seconds;
  const double matched = static_cast<double>(em->stats.matched);

  const InspectionPlan plan = TwentyRegionsFiftyPoints();
  absl::StatusOr<ResolvedInspectionPlan> rp;
  const double t_resolve = BestOf(3, [&] { rp = ResolveInspectionPlan(plan, cell.part); });
  if (!rp.ok()) return 1;
  CharacteristicsSettings cs;
  cs.threads = 2;
  absl::StatusOr<CharacteristicsResult> ch;
  const double t_char = BestOf(3, [&] { ch = ComputeCharacteristics(*em, *rp, 0, cs); });
  if (!ch.ok()) return 1;
  DefectRules rules;
  rules.threshold_mm = 0.03;
  DefectSettings ds;
  ds.threads = 2;
  absl::StatusOr<DefectsResult> defects;
  const double t_defects =
      BestOf(3, [&] { defects = FindDefects(*em, cloud, cell.part, rules, &*rp, ds); });
  if (!defects.ok()) return 1;
  absl::StatusOr<CoverageResult> coverage;
  CoverageSettings cov;
  cov.threads = 2;
  const double t_coverage = BestOf(3, [&] {
    cov.distance_mm = kCoverageSpacings * EstimateSurfaceSpacing(*em, cloud);
    coverage = ComputeCoverage(*em, cell.part, *rp, cov);
  });
  if (!coverage.ok()) return 1;

  std::printf("%zu points, %.0f matched, %zu triangles\n", cloud.size(), matched,
              cell.part.num_triangles());
  std::printf("error map          %8.1f ms  %6.1f ns/matched point\n", 1e3 * t_map,
              1e9 * t_map / matched);
  std::printf("plan resolution    %8.2f ms  (once per plan and mesh)\n", 1e3 * t_resolve);
  std::printf("characteristics    %8.1f ms  %6.1f ns/matched point  %5.1f%% of the error map\n",
              1e3 * t_char, 1e9 * t_char / matched, 100 * t_char / t_map);
  std::printf("  (resolution included: %.1f%%)\n", 100 * (t_char + t_resolve) / t_map);
  std::printf(
      "defect detection   %8.1f ms  %6.1f ns/matched point  %5.1f%% of the error map,"
      " %zu defects\n",
      1e3 * t_defects, 1e9 * t_defects / matched, 100 * t_defects / t_map, defects->defects.size());
  std::printf(
      "coverage           %8.1f ms  %6.1f ns/matched point  %5.1f%% of the error map,"
      " %.1f%% of the surface within %.2f mm\n",
      1e3 * t_coverage, 1e9 * t_coverage / matched, 100 * t_coverage / t_map,
      100 * coverage->surface, coverage->distance_mm);
  for (const Defect& d : defects->defects)
    std::printf("  defect %d %s at (%.2f, %.2f, %.2f) peak %.4f mm area %.1f mm2\n", d.id,
                DefectKindName(d.kind), d.centroid_mm.x(), d.centroid_mm.y(), d.centroid_mm.z(),
                d.peak_mm, d.area_mm2);
  return RunDrawingPlan(in, opt);
}

}  // namespace

int main() { return Run(); }
