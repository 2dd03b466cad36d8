#include "proto/convert.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>

#include "core/pipeline/inspection_report.h"

namespace surfinspect::wire {
namespace {

std::string Bytes(const PointCloud& c) {
  return std::string(reinterpret_cast<const char*>(c.points.data()), c.size() * 12);
}

PointCloud Grid(uint32_t w, uint32_t h) {
  PointCloud c = PointCloud::Organized(w, h);
  for (std::size_t i = 0; i < c.size(); ++i)
    if (i % 7 != 3) c.points[i] = Eigen::Vector3f(float(i), -0.5f * float(i), 1e3f + float(i % 13));
  return c;  // every 7th point stays NaN
}

// Chunks of any size, including ones that split a point's 12 bytes, give
// the cloud the one-message path gives, bit for bit (NaN holes included).
TEST(CloudAssembler, ChunksOfAnySizeGiveTheSameCloud) {
  const PointCloud want = Grid(33, 17);
  const std::string bytes = Bytes(want);
  for (std::size_t chunk :
       {std::size_t{1}, std::size_t{5}, std::size_t{12}, std::size_t{1000}, bytes.size()}) {
    CloudAssembler a;
    a.Start(33, 17);
    EXPECT_EQ(a.expected_bytes(), bytes.size());
    for (std::size_t off = 0; off < bytes.size(); off += chunk) {
      EXPECT_FALSE(a.complete());
      ASSERT_TRUE(a.Add(bytes.substr(off, chunk), "view").ok());
    }
    ASSERT_TRUE(a.complete());
    auto got = a.Take("view");
    ASSERT_TRUE(got.ok()) << got.status();
    EXPECT_EQ(got->width, 33u);
    EXPECT_EQ(got->height, 17u);
    EXPECT_EQ(Bytes(*got), bytes);
    EXPECT_EQ(a.received_bytes(), 0u) << "Take empties the assembler";
  }
}

TEST(CloudAssembler, OverrunAndInfinityAreInvalidAndNamed) {
  CloudAssembler a;
  a.Start(2, 1);
  EXPECT_TRUE(a.Add(std::string(20, '\0'), "view 'top'").ok());
  const absl::Status over = a.Add(std::string(5, '\0'), "view 'top'");
  EXPECT_EQ(over.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(over.message().find("view 'top'"), absl::string_view::npos) << over.message();
  EXPECT_EQ(a.received_bytes(), 20u) << "a refused chunk is not half-copied";

  EXPECT_EQ(a.Take("view 'top'").status().code(), absl::StatusCode::kInvalidArgument)
      << "an incomplete cloud is not handed out";

  // An infinity is caught by the chunk that completes its point, even when
  // the point's bytes are split across chunks.
  PointCloud bad = Grid(3, 1);
  bad.points[1].y() = INFINITY;
  const std::string bytes = Bytes(bad);
  a.Start(3, 1);
  ASSERT_TRUE(a.Add(bytes.substr(0, 18), "view 'top'").ok());
  const absl::Status inf = a.Add(bytes.substr(18, 6), "view 'top'");
  EXPECT_EQ(inf.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(inf.message().find("point 1 has an infinite coordinate"), absl::string_view::npos)
      << inf.message();
}

std::string Hex(const std::string& bytes) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (unsigned char b : bytes) {
    out += digits[b >> 4];
    out += digits[b & 15];
  }
  return out;
}

// Little-endian bytes written out by hand; an Unpack inverts its Pack and
// drops a trailing partial element.
TEST(PackedArrays, AreLittleEndianAndRoundTrip) {
  EXPECT_EQ(Hex(PackUint16({1, 0x0203, 0xffff})), "01000302ffff");
  EXPECT_EQ(Hex(PackUint32({1, 0x01020304u, 70000})), "010000000403020170110100");
  EXPECT_EQ(Hex(PackFloats({1.0f, -2.5f})), "0000803f000020c0");
  EXPECT_EQ(UnpackUint16(std::string("\x01\x00\x03\x02\xff", 5)),
            (std::vector<uint16_t>{1, 0x0203}));
  EXPECT_EQ(UnpackUint32(PackUint32({7, 0xdeadbeefu})), (std::vector<uint32_t>{7, 0xdeadbeefu}));
  EXPECT_EQ(UnpackFloats(PackFloats({0.5f, 3.25f})), (std::vector<float>{0.5f, 3.25f}));
  EXPECT_TRUE(UnpackUint16("").empty());
  EXPECT_EQ(PackUint32({}), "");
}

TEST(FilterResultToProto, CloudStatsAndOneMaskBytePerPoint) {
  const PointCloud filtered = Grid(2, 2);
  LinkClusteringResult r;
  r.kept_mask = {1, 0, 0, 1};
  r.input_points = 4;
  r.valid_points = 3;
  r.kept = 2;
  r.removed = 1;
  r.largest_cluster = 2;
  r.clusters.resize(2);
  r.clusters[0].kept = true;
  v1::FilterResponse msg;
  FilterResultToProto(filtered, r, &msg);
  EXPECT_EQ(msg.kept_mask(), std::string("\x01\x00\x00\x01", 4));
  EXPECT_EQ(msg.stats().valid_points(), 3u);
  EXPECT_EQ(msg.stats().kept(), 2u);
  EXPECT_EQ(msg.stats().removed(), 1u);
  EXPECT_EQ(msg.stats().clusters(), 2u);
  EXPECT_EQ(msg.stats().removed_clusters(), 1u);
  EXPECT_EQ(msg.cloud().width(), 2u);
  EXPECT_EQ(msg.cloud().xyz(), Bytes(filtered));
}

TEST(MergedCloudToProto, PacksViewAndGridIndicesPerPoint) {
  MergedCloud m;
  m.cloud_in_world = PointCloud::Unorganized({{1, 2, 3}, {4, 5, 6}, {7, 8, 9}});
  m.view_id = {0, 1, 1};
  m.grid_index = {5, 0, 70000};
  m.view_names = {"v1", "v2"};
  m.points_per_view = {1, 2};
  v1::RegisterResponse msg;
  MergedCloudToProto(m, &msg);
  EXPECT_EQ(Hex(msg.view_index()), "000001000100");
  EXPECT_EQ(Hex(msg.grid_index()), "050000000000000070110100");
  EXPECT_EQ(UnpackUint16(msg.view_index()), m.view_id);
  EXPECT_EQ(UnpackUint32(msg.grid_index()), m.grid_index);
  ASSERT_EQ(msg.points_per_view_size(), 2);
  EXPECT_EQ(msg.points_per_view(0), 1u);
  EXPECT_EQ(msg.points_per_view(1), 2u);
  auto merged = CloudFromProto(msg.merged(), "merged", Limits{});
  ASSERT_TRUE(merged.ok()) << merged.status();
  EXPECT_EQ(Bytes(*merged), Bytes(m.cloud_in_world));
  EXPECT_FALSE(msg.has_best_fit_correction()) << "the caller's";
}

ErrorMapResult SmallMap(bool pass) {
  ErrorMapResult map;
  map.deviation_mm = {0.01f, NAN, -0.02f};
  map.stats.count = 3;
  map.stats.valid = 3;
  map.stats.matched = 2;
  map.verdict.pass = pass;
  map.verdict.reason = pass ? "all within" : "too many outside";
  map.tolerance_mm = 0.1;
  return map;
}

// The part verdict of a plan outcome.
PlanOutcome Outcome(bool pass) {
  PlanOutcome o;
  o.characteristics.pass = pass;
  return o;
}

TEST(ErrorMapToProto, ReportVerdictAndDeviationsOnlyWhenAsked) {
  const ErrorMapSettings settings;
  v1::ErrorMapResponse with;
  ErrorMapToProto(SmallMap(true), settings, Outcome(true), true, &with);
  EXPECT_EQ(with.verdict(), "pass");
  EXPECT_EQ(with.report_json(), ErrorMapReportText(SmallMap(true), settings, Outcome(true)));
  EXPECT_EQ(with.deviations(), PackFloats(SmallMap(true).deviation_mm));
  v1::ErrorMapResponse without;
  ErrorMapToProto(SmallMap(false), settings, Outcome(false), false, &without);
  EXPECT_EQ(without.verdict(), "fail");
  EXPECT_TRUE(without.deviations().empty());
  EXPECT_TRUE(without.png().empty()) << "the caller's";
}

TEST(ErrorMapToProto, TheTypedAlignmentIsTheReportsAndUnsetWhenCalibrated) {
  const ErrorMapSettings settings;
  v1::ErrorMapResponse calibrated;
  ErrorMapToProto(SmallMap(true), settings, Outcome(true), false, &calibrated);
  EXPECT_FALSE(calibrated.has_alignment());
  PlanOutcome o = Outcome(false);
  o.alignment.mode = AlignmentMode::kRps;
  o.alignment.aligned = true;
  o.alignment.x << 0.1, 0, 0, 0, 0, 0.002;
  o.alignment.correction = RigidMotion(o.alignment.x).transform();
  o.alignment.correction_mm = 0.3;
  o.alignment.within_max_correction = false;
  o.alignment.references = {
      {"B1", "surface", true, {1, 2, 3}, {1, 2, 3.1}, {{0, 0, 1}}, {0.1}, {0.001}, 40, ""}};
  v1::ErrorMapResponse msg;
  ErrorMapToProto(SmallMap(true), settings, o, false, &msg);
  ASSERT_TRUE(msg.has_alignment());
  const auto report = nlohmann::json::parse(msg.report_json())["alignment"];
  const v1::AlignmentResult& a = msg.alignment();
  EXPECT_EQ(a.mode(), report["mode"]);
  EXPECT_EQ(a.within_max_correction(), report["within_max_correction"]);
  EXPECT_EQ(a.correction_mm(), report["correction_mm"]);
  ASSERT_EQ(a.matrix_size(), 16);
  for (int k = 0; k < 16; ++k) EXPECT_EQ(a.matrix(k), report["matrix"][k]);
  ASSERT_EQ(a.references_size(), 1);
  EXPECT_EQ(a.references(0).points(), 40u);
  EXPECT_EQ(a.references(0).locked(0).before_mm(),
            report["references"][0]["locked"][0]["before_mm"]);
  EXPECT_EQ(msg.part_verdict(), v1::VERDICT_FAIL);
}

TEST(InspectionResultToProto, PartIdVerdictReportViewsAndOptionalDeviations) {
  InspectionResult r;
  r.error_map = SmallMap(false);
  r.merged.cloud_in_world = PointCloud::Unorganized({{1, 2, 3}, {4, 5, 6}, {7, 8, 9}});
  r.views = {{"top", 1200, 7}, {"side", 800, 0}};
  r.plan = Outcome(false);
  ErrorMapSettings settings;
  settings.tolerance_mm = 0.25;
  v1::InspectResult msg;
  InspectionResultToProto("part-7", r, settings, true, &msg);
  EXPECT_EQ(msg.part_id(), "part-7");
  EXPECT_EQ(msg.verdict(), "fail");
  EXPECT_EQ(msg.report_json(), ErrorMapReportText(r.error_map, settings, r.plan));
  ASSERT_EQ(msg.views_size(), 2);
  EXPECT_EQ(msg.views(0).name(), "top");
  EXPECT_EQ(msg.views(0).valid_points(), 1200u);
  EXPECT_EQ(msg.views(0).removed_points(), 7u);
  EXPECT_EQ(msg.views(1).name(), "side");
  EXPECT_EQ(msg.views(1).valid_points(), 800u);
  EXPECT_EQ(msg.deviations(), PackFloats(r.error_map.deviation_mm));
  EXPECT_EQ(msg.merged().xyz(), Bytes(r.merged.cloud_in_world));

  v1::InspectResult lean;
  InspectionResultToProto("part-7", r, settings, false, &lean);
  EXPECT_TRUE(lean.deviations().empty());
  EXPECT_FALSE(lean.has_merged());
  EXPECT_EQ(lean.views_size(), 2);
}

TEST(StageToProto, EveryCoreStageHasItsWireStage) {
  EXPECT_EQ(StageToProto(InspectionStage::kViewFiltered), v1::Progress::STAGE_VIEW_FILTERED);
  EXPECT_EQ(StageToProto(InspectionStage::kViewRegistered), v1::Progress::STAGE_VIEW_REGISTERED);
  EXPECT_EQ(StageToProto(InspectionStage::kErrorMap), v1::Progress::STAGE_ERROR_MAP);
}

}  // namespace
}  // namespace surfinspect::wire

namespace surfinspect::wire {
namespace {

TEST(MeshFromProto, AnEmptyMeshIsRefusedBeforeAnyCopy) {
  v1::InlineMesh msg;
  Limits limits;
  EXPECT_EQ(MeshFromProto(msg, "part.inline", limits).status().code(),
            absl::StatusCode::kInvalidArgument);
  msg.mutable_vertices()->assign(36, '\0');  // three vertices, no triangle
  auto m = MeshFromProto(msg, "part.inline", limits);
  ASSERT_EQ(m.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(m.status().message().find("part.inline"), std::string::npos) << m.status();
  msg.clear_vertices();
  msg.mutable_triangles()->assign(12, '\0');  // a triangle, no vertices
  EXPECT_EQ(MeshFromProto(msg, "part.inline", limits).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace surfinspect::wire

namespace surfinspect::wire {
namespace {

TEST(PlanProto, RoundTripsEveryFieldAndUnsetBandsTakeTheSettings) {
  InspectionPlan plan;
  plan.tolerance = {-0.05, 0.15};
  plan.allowed_fraction_outside = 0.01;
  plan.min_coverage = 0.75;
  plan.coverage_distance_mm = 1.5;
  plan.allow_not_measured = true;
  PlanRegion box{"box", {}, ToleranceBand{-0.2, 0.1}, 0.5, 0.6};
  box.select.box_min_mm = {-1, -2, -3};
  box.select.box_max_mm = {4, 5, 6};
  PlanRegion tris{"tris", {}, {}, 0, {}};
  tris.select.kind = RegionSelector::Kind::kTriangles;
  tris.select.triangles = {0, 7, 3};
  PlanRegion group{"group", {}, {}, 0, {}};
  group.select.kind = RegionSelector::Kind::kGroup;
  group.select.group = "flange";
  plan.regions = {box, tris, group};
  plan.points = {{"P1", {1, 2, 3}, {0, 0, 1}, 2.5, ToleranceBand{-0.1, 0.3}, 0.4},
                 {"P2", {4, 5, 6}, {}, 2.0, {}, {}}};
  plan.points[0].direction = {0, 0.6, 0.8};
  PlanSection section;
  section.name = "S1";
  section.point_mm = {1, 2, 3};
  section.normal = {0, 1, 0};
  section.width_mm = 0.5;
  section.region = "box";
  section.tolerance = ToleranceBand{-0.2, 0.3};
  section.allowed_fraction_outside = 0.01;
  plan.sections = {section};
  plan.defects = DefectRules{0.03, 4.0, 2};
  v1::InspectionPlan msg;
  PlanToProto(plan, &msg);
  auto back = PlanFromProto(msg, {}, "plan");
  ASSERT_TRUE(back.ok()) << back.status();
  v1::InspectionPlan again;
  PlanToProto(*back, &again);
  EXPECT_EQ(msg.SerializeAsString(), again.SerializeAsString());
  EXPECT_EQ(back->regions[1].select.triangles, tris.select.triangles);
  EXPECT_EQ(back->regions[2].select.group, "flange");
  EXPECT_FALSE(back->points[1].tolerance.has_value());
  EXPECT_EQ(*back->defects->max_count, 2);
  EXPECT_EQ(back->tolerance.upper_mm, 0.15);
  EXPECT_EQ(back->min_coverage, 0.75);
  EXPECT_EQ(back->coverage_distance_mm, 1.5);
  EXPECT_TRUE(back->allow_not_measured);
  EXPECT_EQ(*back->regions[0].min_coverage, 0.6);
  EXPECT_FALSE(back->regions[1].min_coverage.has_value());
  EXPECT_EQ(*back->points[0].min_coverage, 0.4);
  EXPECT_EQ(back->points[0].direction, Eigen::Vector3d(0, 0.6, 0.8));
  EXPECT_EQ(back->points[1].direction, Eigen::Vector3d::Zero());
  ASSERT_EQ(back->sections.size(), 1u);
  EXPECT_EQ(back->sections[0].region, "box");
  EXPECT_EQ(back->sections[0].width_mm, 0.5);
  EXPECT_EQ(back->sections[0].tolerance->upper_mm, 0.3);
  // An empty message: the surface against +-tolerance_mm, no defects.
  ErrorMapSettings s;
  s.tolerance_mm = 0.3;
  s.allowed_fraction_outside = 0.001;
  auto empty = PlanFromProto(v1::InspectionPlan{}, s, "plan");
  ASSERT_TRUE(empty.ok());
  EXPECT_EQ(empty->tolerance.lower_mm, -0.3);
  EXPECT_EQ(empty->tolerance.upper_mm, 0.3);
  EXPECT_EQ(empty->allowed_fraction_outside, 0.001);
  EXPECT_EQ(empty->min_coverage, kDefaultMinCoverage) << "a plan's default, as in the JSON";
  EXPECT_FALSE(empty->allow_not_measured);
  EXPECT_FALSE(empty->defects.has_value());
}

TEST(PlanProto, AlignmentRoundTripsAndTheCalibratedFrameIsUnset) {
  InspectionPlan plan;
  plan.alignment.mode = AlignmentMode::kRps;
  plan.alignment.references = {{"A1", "H1", Eigen::Vector3d::Zero(), 3.0},
                               {"B1", "", {1, 2, 3}, 4.5}};
  plan.alignment.max_correction_mm = 1.25;
  v1::InspectionPlan msg;
  PlanToProto(plan, &msg);
  EXPECT_EQ(msg.alignment().mode(), v1::ALIGNMENT_MODE_RPS);
  auto back = PlanFromProto(msg, {}, "plan");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->alignment.mode, AlignmentMode::kRps);
  ASSERT_EQ(back->alignment.references.size(), 2u);
  EXPECT_EQ(back->alignment.references[0].hole, "H1");
  EXPECT_EQ(back->alignment.references[1].position_mm, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(back->alignment.references[1].radius_mm, 4.5);
  EXPECT_EQ(back->alignment.max_correction_mm, 1.25);
  EXPECT_EQ(back->alignment.max_correction_deg, 1.0);
  plan.alignment = PlanAlignment{};
  plan.alignment.mode = AlignmentMode::kBestFit;
  plan.alignment.regions = {"ridge"};
  plan.alignment.locked.tz = plan.alignment.locked.rx = true;
  PlanToProto(plan, &msg);
  back = PlanFromProto(msg, {}, "plan");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->alignment.regions, std::vector<std::string>{"ridge"});
  EXPECT_TRUE(back->alignment.locked.tz && back->alignment.locked.rx);
  EXPECT_EQ(back->alignment.locked.FreeCount(), 4);
  msg.mutable_alignment()->add_locked("up");
  EXPECT_EQ(PlanFromProto(msg, {}, "part.plan").status().message(),
            "part.plan.alignment.locked[2]: must be one of tx, ty, tz, rx, ry, rz");
  PlanToProto(InspectionPlan{}, &msg);
  EXPECT_FALSE(msg.has_alignment()) << "the calibrated frame keeps the message as it was";
}

TEST(PlanProto, ShapesAreCheckedNamingTheField) {
  v1::InspectionPlan msg;
  msg.add_regions()->set_name("r");
  EXPECT_EQ(PlanFromProto(msg, {}, "part.plan").status().message(),
            "part.plan.regions[0].select: needs exactly one selector (box_mm, triangles, group)");
  msg.Clear();
  v1::ComparisonPoint* p = msg.add_points();
  p->add_position_mm(1);
  EXPECT_EQ(PlanFromProto(msg, {}, "plan").status().message(),
            "plan.points[0].position_mm: must be 3 numbers");
  for (double v : {1.0, 2.0}) p->add_position_mm(v);
  for (double v : {0.0, 0.0, 0.0}) p->add_normal(v);
  EXPECT_EQ(PlanFromProto(msg, {}, "plan").status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(OutcomeProto, TypedResultsAndBackToCore) {
  PlanOutcome o;
  CharacteristicResult c;
  c.name = "ridge";
  c.type = CharacteristicType::kRegion;
  c.pass = false;
  c.reason = "fail: 3% outside";
  c.tolerance = {-0.15, 0.15};
  c.points = 10;
  c.mean_mm = 0.01;
  o.characteristics.characteristics = {c};
  Defect d;
  d.id = 1;
  d.kind = DefectKind::kBump;
  d.centroid_mm = {1, 2, 3};
  d.peak_mm = 0.2;
  d.region = "ridge";
  o.defects.defects = {d};
  v1::ErrorMapResponse msg;
  ErrorMapToProto(SmallMap(true), {}, o, false, &msg);
  EXPECT_EQ(msg.part_verdict(), v1::VERDICT_FAIL);
  EXPECT_EQ(msg.verdict(), "fail");
  EXPECT_EQ(msg.statistics().tolerance_verdict(), v1::VERDICT_PASS);
  EXPECT_EQ(msg.statistics().matched(), 2u);
  ASSERT_EQ(msg.characteristics_size(), 1);
  EXPECT_EQ(msg.characteristics(0).type(), v1::CHARACTERISTIC_REGION);
  EXPECT_TRUE(std::isnan(msg.characteristics(0).value_mm()));
  EXPECT_EQ(msg.defects(0).kind(), v1::DEFECT_BUMP);
  const CharacteristicsResult back = CharacteristicsFromProto(msg.characteristics());
  EXPECT_EQ(CharacteristicsJson(back), CharacteristicsJson(o.characteristics));
  EXPECT_EQ(back.failed, 1u);
  EXPECT_EQ(DefectsJson(DefectsFromProto(msg.defects())), DefectsJson(o.defects));
}

}  // namespace
}  // namespace surfinspect::wire
