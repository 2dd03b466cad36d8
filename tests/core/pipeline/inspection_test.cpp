// InspectPart end to end on the simulated demo part: two views with known
// poses (the simulator's), a planted dent and planted pulses, so every step
// of the result is checked against the simulator's per-pixel truth.
#include "core/pipeline/inspection.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <tuple>

#include "core/pipeline/inspection_report.h"
#include "core/report/error_map_png.h"
#include "core/simulation/demo_cell.h"
#include "core/simulation/scan_simulator.h"
#include "core/types/transform.h"
#include "tests/support/png_decode.h"

namespace surfinspect {
namespace {

using Eigen::Vector3d;

constexpr double kDentDepthMm = 0.25;
constexpr double kDentRadiusMm = 6;

struct Event {
  InspectionStage stage;
  std::string view;
  std::size_t points;
  bool operator==(const Event& o) const {
    return std::tie(stage, view, points) == std::tie(o.stage, o.view, o.points);
  }
};

std::ostream& operator<<(std::ostream& os, const Event& e) {
  return os << "(" << static_cast<int>(e.stage) << ", '" << e.view << "', " << e.points << ")";
}

class Inspection : public ::testing::Test {
 protected:
  // The scans and one full inspection are shared by the tests (a few
  // hundred ms of ray casting and distance queries).
  static void SetUpTestSuite() {
    cell_ = new DemoCell(MakeDemoCell());
    auto index = MeshIndex::Build(cell_->part);
    ASSERT_TRUE(index.ok()) << index.status();
    index_ = index->release();
    // The dent centre: the CAD ridge point below (-40, 3).
    const Bounds3 b = ComputeBounds(cell_->part);
    const ClosestPoint top = index_->Closest(Vector3d(-40, 3, b.max.z() + 5));
    ASSERT_TRUE(top.matched());
    ASSERT_GT(top.normal.z(), 0.99) << "on the top ridge";
    dent_in_part_ = new Vector3d(top.point);
    dent_normal_ = new Vector3d(top.normal);
    SurfaceDefect dent;
    dent.center_in_part = top.point;
    dent.depth_mm = kDentDepthMm;
    dent.radius_mm = kDentRadiusMm;

    const Vector3d centre_world = cell_->world_from_part * top.point;
    const Vector3d up_world = cell_->world_from_part.linear() * top.normal;
    const std::vector<std::pair<std::string, Eigen::Isometry3d>> poses = {
        {"above-dent", LookAt(centre_world + 400 * up_world + Vector3d(7, 3, 0), centre_world)},
        {cell_->viewpoints[2].name, cell_->viewpoints[2].world_from_sensor}};
    scans_ = new std::vector<SimulatedScan>;
    views_ = new std::vector<ViewScan>;
    for (std::size_t k = 0; k < poses.size(); ++k) {
      ScanOptions opt;  // noise-free, so the dent depth is exact
      opt.pulse_fraction = 0.003;
      opt.defects = {dent};
      opt.seed = 100 + k;
      auto scan = SimulateScan(cell_->part, cell_->world_from_part, poses[k].second,
                               cell_->intrinsics, opt);
      ASSERT_TRUE(scan.ok()) << scan.status();
      ASSERT_GT(scan->pulses, 100u);
      views_->push_back({poses[k].first, scan->cloud_in_sensor, poses[k].second});
      scans_->push_back(*std::move(scan));
    }
    events_ = new std::vector<Event>;
    auto result = InspectPart(*index_, cell_->world_from_part, *views_, settings(),
                              [](InspectionStage stage, const std::string& view, std::size_t n) {
                                events_->push_back({stage, view, n});
                              });
    ASSERT_TRUE(result.ok()) << result.status();
    result_ = new InspectionResult(*std::move(result));
  }

  static void TearDownTestSuite() {
    delete result_;
    delete events_;
    delete views_;
    delete scans_;
    delete dent_normal_;
    delete dent_in_part_;
    delete index_;
    delete cell_;
  }

  static InspectionSettings settings() {
    InspectionSettings s;
    s.error_map.tolerance_mm = 0.05;
    return s;
  }

  static DemoCell* cell_;
  static MeshIndex* index_;
  static Vector3d* dent_in_part_;
  static Vector3d* dent_normal_;
  static std::vector<SimulatedScan>* scans_;
  static std::vector<ViewScan>* views_;
  static std::vector<Event>* events_;
  static InspectionResult* result_;
};

DemoCell* Inspection::cell_ = nullptr;
MeshIndex* Inspection::index_ = nullptr;
Vector3d* Inspection::dent_in_part_ = nullptr;
Vector3d* Inspection::dent_normal_ = nullptr;
std::vector<SimulatedScan>* Inspection::scans_ = nullptr;
std::vector<ViewScan>* Inspection::views_ = nullptr;
std::vector<Event>* Inspection::events_ = nullptr;
InspectionResult* Inspection::result_ = nullptr;

TEST_F(Inspection, EveryMergedPointTracesBackToItsViewAndPixel) {
  ASSERT_TRUE(result_);
  const MergedCloud& m = result_->merged;
  EXPECT_EQ(m.view_names, (std::vector<std::string>{"above-dent", (*views_)[1].name}));
  const std::size_t n = m.cloud_in_world.size();
  ASSERT_EQ(m.view_id.size(), n);
  ASSERT_EQ(m.grid_index.size(), n);
  ASSERT_EQ(m.points_per_view.size(), 2u);
  EXPECT_EQ(m.points_per_view[0] + m.points_per_view[1], n);
  std::vector<std::size_t> per_view(2, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const uint16_t v = m.view_id[i];
    ASSERT_LT(v, 2u);
    ++per_view[v];
    const SimulatedScan& scan = (*scans_)[v];
    const uint32_t pixel = m.grid_index[i];
    ASSERT_LT(pixel, scan.cloud_in_sensor.size());
    // world = world_from_sensor * the measured point in the sensor frame.
    const Vector3d expected =
        (*views_)[v].world_from_sensor * scan.cloud_in_sensor.points[pixel].cast<double>();
    ASSERT_LT((m.cloud_in_world.points[i].cast<double>() - expected).norm(), 1e-3) << i;
  }
  EXPECT_EQ(per_view, m.points_per_view);
}

TEST_F(Inspection, TheFilterRemovesThePlantedPulsesAndKeepsTheSurface) {
  ASSERT_TRUE(result_);
  const MergedCloud& m = result_->merged;
  for (std::size_t v = 0; v < 2; ++v) {
    const SimulatedScan& scan = (*scans_)[v];
    std::vector<bool> kept(scan.labels.size(), false);
    for (std::size_t i = 0; i < m.view_id.size(); ++i) {
      if (m.view_id[i] != v) continue;
      kept[m.grid_index[i]] = true;
      // A pulse is displaced 2-20 mm along its ray. One that survives has
      // landed within the link distance of the surface (a grazing ray), so
      // it stays linked to its neighbours; every other one is removed.
      if (scan.labels[m.grid_index[i]] == PixelLabel::kPulse) {
        EXPECT_LT(std::abs(result_->error_map.deviation_mm[i]),
                  settings().filter_settings.link_distance_mm)
            << "view " << v << " pixel " << m.grid_index[i];
      }
    }
    std::size_t pulses_kept = 0, surface = 0, surface_kept = 0, dent = 0, dent_kept = 0;
    for (std::size_t p = 0; p < kept.size(); ++p) {
      const PixelLabel label = scan.labels[p];
      pulses_kept += label == PixelLabel::kPulse && kept[p] ? 1 : 0;
      if (label == PixelLabel::kGood || label == PixelLabel::kDefect) {
        ++surface;
        surface_kept += kept[p] ? 1 : 0;
      }
      if (label == PixelLabel::kDefect) {
        ++dent;
        dent_kept += kept[p] ? 1 : 0;
      }
    }
    // Seen: 5 of 1490 and 3 of 1590 kept.
    EXPECT_LE(pulses_kept, 0.01 * scan.pulses) << "view " << v << " of " << scan.pulses;
    EXPECT_GE(surface_kept, 0.99 * surface) << "view " << v;
    if (v == 0) {
      EXPECT_GT(dent, 1000u) << "the first view looks at the dent";
    }
    EXPECT_GE(dent_kept, 0.999 * dent) << "view " << v;

    const ViewOutcome& outcome = result_->views[v];
    EXPECT_EQ(outcome.name, (*views_)[v].name);
    EXPECT_EQ(outcome.valid_points, scan.cloud_in_sensor.CountValid());
    EXPECT_GE(outcome.removed_points, scan.pulses);
    EXPECT_EQ(outcome.valid_points - outcome.removed_points, m.points_per_view[v]);
  }
}

TEST_F(Inspection, TheErrorMapRecoversThePlantedDent) {
  ASSERT_TRUE(result_);
  const MergedCloud& m = result_->merged;
  const ErrorMapResult& map = result_->error_map;
  ASSERT_EQ(map.deviation_mm.size(), m.cloud_in_world.size());
  EXPECT_EQ(map.stats.count, m.cloud_in_world.size());
  // The merged point nearest the dent axis, from either view.
  const Eigen::Isometry3d part_from_world = cell_->world_from_part.inverse();
  std::size_t best = SIZE_MAX;
  double best_r = INFINITY;
  std::size_t compared = 0;
  double deepest_surface_mm = INFINITY;  // over the good and dent pixels
  for (std::size_t i = 0; i < m.cloud_in_world.size(); ++i) {
    const Vector3d q = part_from_world * m.cloud_in_world.points[i].cast<double>() - *dent_in_part_;
    const double radial = (q - q.dot(*dent_normal_) * *dent_normal_).norm();
    if (radial < best_r) best_r = radial, best = i;
    // Across the whole dent the map follows the simulator's truth.
    const SimulatedScan& scan = (*scans_)[m.view_id[i]];
    const PixelLabel label = scan.labels[m.grid_index[i]];
    if (label == PixelLabel::kGood || label == PixelLabel::kDefect)
      deepest_surface_mm = std::min<double>(deepest_surface_mm, map.deviation_mm[i]);
    if (label != PixelLabel::kDefect) continue;
    ASSERT_NEAR(map.deviation_mm[i], scan.true_deviation_mm[m.grid_index[i]], 1e-4) << i;
    ++compared;
  }
  EXPECT_GT(compared, 1000u);
  ASSERT_NE(best, SIZE_MAX);
  EXPECT_LT(best_r, 0.3);
  EXPECT_NEAR(map.deviation_mm[best], -kDentDepthMm, 0.005);
  EXPECT_NEAR(deepest_surface_mm, -kDentDepthMm, 0.005) << "the dent is the deepest point";
  EXPECT_FALSE(map.verdict.pass) << "a 0.25 mm dent is outside +-0.05 mm";
  EXPECT_GT(map.verdict.below, 100u);
}

TEST_F(Inspection, ProgressArrivesInStageOrderWithTheCounts) {
  ASSERT_TRUE(result_);
  const MergedCloud& m = result_->merged;
  const std::string& a = m.view_names[0];
  const std::string& b = m.view_names[1];
  const std::vector<Event> expected = {
      {InspectionStage::kViewFiltered, a, m.points_per_view[0]},
      {InspectionStage::kViewFiltered, b, m.points_per_view[1]},
      {InspectionStage::kViewRegistered, a, m.points_per_view[0]},
      {InspectionStage::kViewRegistered, b, m.points_per_view[1]},
      {InspectionStage::kErrorMap, "", result_->error_map.stats.matched},
  };
  EXPECT_EQ(*events_, expected);
  EXPECT_GT(result_->error_map.stats.matched, 0.99 * m.cloud_in_world.size());
}

TEST_F(Inspection, WithoutTheFilterThePulsesReachTheErrorMap) {
  ASSERT_TRUE(result_);
  InspectionSettings s = settings();
  s.filter = false;
  std::vector<Event> events;
  auto r = InspectPart(*index_, cell_->world_from_part, *views_, s,
                       [&](InspectionStage stage, const std::string& view, std::size_t n) {
                         events.push_back({stage, view, n});
                       });
  ASSERT_TRUE(r.ok()) << r.status();
  std::size_t pulses = 0;
  for (std::size_t i = 0; i < r->merged.view_id.size(); ++i)
    pulses += (*scans_)[r->merged.view_id[i]].labels[r->merged.grid_index[i]] == PixelLabel::kPulse;
  EXPECT_EQ(pulses, (*scans_)[0].pulses + (*scans_)[1].pulses);
  for (const ViewOutcome& v : r->views) EXPECT_EQ(v.removed_points, 0u);
  ASSERT_EQ(events.size(), 3u) << "no kViewFiltered events";
  EXPECT_EQ(events[0].stage, InspectionStage::kViewRegistered);
  EXPECT_EQ(events[2].stage, InspectionStage::kErrorMap);
}

TEST_F(Inspection, CancelEndsTheCallWithCancelled) {
  ASSERT_TRUE(result_);
  std::atomic<bool> cancel{true};
  for (bool filter : {true, false}) {
    InspectionSettings s = settings();
    s.filter = filter;
    std::vector<InspectionStage> stages;
    auto r = InspectPart(
        *index_, cell_->world_from_part, *views_, s,
        [&](InspectionStage stage, const std::string&, std::size_t) { stages.push_back(stage); },
        &cancel);
    EXPECT_EQ(r.status().code(), absl::StatusCode::kCancelled) << "filter " << filter;
    for (InspectionStage st : stages) EXPECT_NE(st, InspectionStage::kErrorMap);
  }
  // Raised from the progress callback once the views are registered: the
  // error map is not computed.
  std::atomic<bool> later{false};
  std::vector<InspectionStage> stages;
  auto r = InspectPart(
      *index_, cell_->world_from_part, *views_, settings(),
      [&](InspectionStage stage, const std::string&, std::size_t) {
        stages.push_back(stage);
        if (stage == InspectionStage::kViewRegistered) later = true;
      },
      &later);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kCancelled);
  ASSERT_FALSE(stages.empty());
  EXPECT_EQ(stages.back(), InspectionStage::kViewRegistered) << "no kErrorMap";
}

TEST_F(Inspection, NoViewsOrABadPoseIsInvalidArgument) {
  ASSERT_TRUE(result_);
  EXPECT_EQ(InspectPart(*index_, cell_->world_from_part, {}, settings()).status().code(),
            absl::StatusCode::kInvalidArgument);
  std::vector<ViewScan> scaled = {(*views_)[0]};
  scaled[0].world_from_sensor.linear() *= 1.01;  // not rigid
  InspectionSettings s = settings();
  s.filter = false;
  EXPECT_EQ(InspectPart(*index_, cell_->world_from_part, scaled, s).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST_F(Inspection, ReportTextIsTheErrorMapJsonIndentedWithANewline) {
  ASSERT_TRUE(result_);
  const ErrorMapSettings es = settings().error_map;
  const std::string text = ErrorMapReportText(result_->error_map, es, result_->plan);
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\n');
  EXPECT_EQ(text.substr(0, 5), "{\n  \"") << "two-space indentation";
  const nlohmann::json parsed = nlohmann::json::parse(text);
  EXPECT_EQ(parsed, EncodeReport(MakeInspectionReport(result_->error_map, es, result_->plan)));
  EXPECT_EQ(parsed["points"]["matched"], result_->error_map.stats.matched);
  EXPECT_EQ(parsed["tolerance"]["verdict"], "fail");
}

TEST_F(Inspection, PngBytesAreTheMapDrawnInThePartFrame) {
  ASSERT_TRUE(result_);
  auto bytes = ErrorMapPngBytes(result_->merged.cloud_in_world, cell_->world_from_part,
                                result_->error_map, cell_->part, result_->plan);
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  const RgbImage decoded = testing::DecodePng(*bytes);
  ASSERT_GT(decoded.width, 0u);
  // The same picture rendered here from the cloud mapped into the part frame.
  PointCloud in_part = PointCloud::Unorganized({});
  const Eigen::Isometry3d part_from_world = cell_->world_from_part.inverse();
  for (const auto& p : result_->merged.cloud_in_world.points)
    in_part.points.push_back((part_from_world * p.cast<double>()).cast<float>());
  in_part.width = static_cast<uint32_t>(in_part.points.size());
  ErrorMapPngOptions options;
  options.defects = &result_->plan.defects.defects;
  options.part_pass = result_->plan.pass();
  auto expected = RenderErrorMap(in_part, result_->error_map, ComputeBounds(cell_->part), options);
  ASSERT_TRUE(expected.ok()) << expected.status();
  EXPECT_EQ(decoded.width, expected->width);
  EXPECT_EQ(decoded.height, expected->height);
  EXPECT_TRUE(decoded.pixels == expected->pixels);
}

}  // namespace
}  // namespace surfinspect
