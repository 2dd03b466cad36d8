// proto/convert.h: the results of each stage, and the Inspect stream's
// progress.
#include "core/pipeline/inspection_report.h"
#include "core/types/status_macros.h"
#include "proto/convert.h"
#include "proto/convert_helpers.h"

namespace surfinspect::wire {

void FilterStatsToProto(const LinkClusteringResult& r, v1::FilterStats* msg) {
  msg->set_input_points(r.input_points);
  msg->set_valid_points(r.valid_points);
  msg->set_kept(r.kept);
  msg->set_removed(r.removed);
  msg->set_clusters(r.clusters.size());
  msg->set_largest_cluster(r.largest_cluster);
  uint64_t removed_clusters = 0;
  for (const ClusterInfo& k : r.clusters) removed_clusters += k.kept ? 0 : 1;
  msg->set_removed_clusters(removed_clusters);
}

void CalibrationToProto(const CalibrationResult& r, v1::CalibrateResponse* msg) {
  TransformToProto(r.world_from_sensor, msg->mutable_world_from_sensor());
  TransformToProto(r.gauge_from_sensor, msg->mutable_gauge_from_sensor());
  v1::CalibrationQuality* q = msg->mutable_quality();
  q->set_rms_mm(r.rms_mm);
  q->set_iterations(static_cast<uint32_t>(r.icp.iterations));
  q->set_converged(r.icp.converged);
  q->set_stop_reason(ToString(r.icp.stop_reason));
  q->set_inlier_fraction(r.inlier_fraction);
  q->set_sigma_translation_um(r.sigma_translation_um);
  q->set_sigma_rotation_deg(r.sigma_rotation_deg);
  q->set_degenerate(r.degenerate);
  q->set_degeneracy_ratio(r.degeneracy_ratio);
  q->set_residual_p50_mm(r.residual_p50_mm);
  q->set_residual_p95_mm(r.residual_p95_mm);
  q->set_residual_p99_mm(r.residual_p99_mm);
  q->set_filtered_points(r.filtered_points);
  for (double c : r.icp.cost_history) q->add_cost_history(c);
  for (const auto& w : r.warnings) q->add_warnings(w);
}

void FilterResultToProto(const PointCloud& filtered, const LinkClusteringResult& r,
                         v1::FilterResponse* msg) {
  CloudToProto(filtered, msg->mutable_cloud());
  FilterStatsToProto(r, msg->mutable_stats());
  msg->set_kept_mask(std::string(r.kept_mask.begin(), r.kept_mask.end()));
}

void MergedCloudToProto(const MergedCloud& merged, v1::RegisterResponse* msg) {
  CloudToProto(merged.cloud_in_world, msg->mutable_merged());
  msg->set_view_index(PackUint16(merged.view_id));
  msg->set_grid_index(PackUint32(merged.grid_index));
  msg->clear_points_per_view();
  for (std::size_t n : merged.points_per_view) msg->add_points_per_view(n);
}

namespace {

v1::Verdict VerdictOf(bool pass) { return pass ? v1::VERDICT_PASS : v1::VERDICT_FAIL; }

void StatisticsToProto(const ErrorMapResult& map, v1::ErrorMapStatistics* msg) {
  const ErrorMapStats& s = map.stats;
  msg->set_count(s.count);
  msg->set_valid(s.valid);
  msg->set_matched(s.matched);
  msg->set_min_mm(s.min_mm);
  msg->set_max_mm(s.max_mm);
  msg->set_mean_mm(s.mean_mm);
  msg->set_stddev_mm(s.stddev_mm);
  msg->set_rms_mm(s.rms_mm);
  msg->set_p1_mm(s.p1_mm);
  msg->set_p5_mm(s.p5_mm);
  msg->set_p50_mm(s.p50_mm);
  msg->set_p95_mm(s.p95_mm);
  msg->set_p99_mm(s.p99_mm);
  msg->set_within(map.verdict.within);
  msg->set_above(map.verdict.above);
  msg->set_below(map.verdict.below);
  msg->set_fraction_within(map.verdict.fraction_within);
  msg->set_tolerance_verdict(VerdictOf(map.verdict.pass));
}

v1::CharacteristicType TypeToProto(CharacteristicType t) {
  switch (t) {
    case CharacteristicType::kSurface:
      return v1::CHARACTERISTIC_SURFACE;
    case CharacteristicType::kRegion:
      return v1::CHARACTERISTIC_REGION;
    case CharacteristicType::kPoint:
      return v1::CHARACTERISTIC_POINT;
    case CharacteristicType::kSection:
      return v1::CHARACTERISTIC_SECTION;
    case CharacteristicType::kHole:
      return v1::CHARACTERISTIC_HOLE;
    case CharacteristicType::kSlot:
      return v1::CHARACTERISTIC_SLOT;
    case CharacteristicType::kEdgePoint:
      return v1::CHARACTERISTIC_EDGE_POINT;
  }
  return v1::CHARACTERISTIC_TYPE_UNSPECIFIED;
}

void HoleToProto(const CharacteristicResult& c, v1::HoleResult* msg) {
  const HoleMeasurement& h = c.hole;
  Vector3ToProto(h.measured_position_mm, msg->mutable_measured_position_mm());
  Vector3ToProto(h.position_deviation_mm, msg->mutable_position_deviation_mm());
  msg->set_true_position_mm(h.true_position_mm);
  msg->set_position_tolerance_mm(c.position_tolerance_mm);
  msg->set_measured_diameter_mm(h.diameter_mm);
  msg->set_diameter_deviation_mm(h.diameter_deviation_mm);
  msg->set_measured_length_mm(h.length_mm);
  msg->set_length_deviation_mm(h.length_deviation_mm);
  BandToProto(c.length_tolerance, msg->mutable_length_tolerance_mm());
  msg->set_form_mm(h.form_mm);
  msg->set_arc_coverage_deg(h.arc_coverage_deg);
  msg->set_pixel_pitch_mm(h.pixel_pitch_mm);
}

void HoleFromProto(const v1::HoleResult& m, CharacteristicResult* c) {
  HoleMeasurement& h = c->hole;
  auto vec = [](const google::protobuf::RepeatedField<double>& v) {
    return v.size() == 3 ? Eigen::Vector3d(v[0], v[1], v[2]) : Eigen::Vector3d::Constant(NAN);
  };
  h.measured = c->measured;
  h.measured_position_mm = vec(m.measured_position_mm());
  h.position_deviation_mm = vec(m.position_deviation_mm());
  h.true_position_mm = m.true_position_mm();
  c->position_tolerance_mm = m.position_tolerance_mm();
  h.diameter_mm = m.measured_diameter_mm();
  h.diameter_deviation_mm = m.diameter_deviation_mm();
  h.length_mm = m.measured_length_mm();
  h.length_deviation_mm = m.length_deviation_mm();
  c->length_tolerance = BandFromProto(m.length_tolerance_mm());
  h.form_mm = m.form_mm();
  h.arc_coverage_deg = m.arc_coverage_deg();
  h.pixel_pitch_mm = m.pixel_pitch_mm();
  h.edge_points = c->points;
}

void CharacteristicToProto(const CharacteristicResult& c, v1::CharacteristicResult* msg) {
  msg->set_name(c.name);
  msg->set_type(TypeToProto(c.type));
  msg->set_verdict(c.pass       ? v1::VERDICT_PASS
                   : c.measured ? v1::VERDICT_FAIL
                                : v1::VERDICT_NOT_MEASURED);
  msg->set_reason(c.reason);
  BandToProto(c.tolerance, msg->mutable_tolerance_mm());
  msg->set_points(c.points);
  msg->set_min_mm(c.min_mm);
  msg->set_max_mm(c.max_mm);
  msg->set_mean_mm(c.mean_mm);
  msg->set_stddev_mm(c.stddev_mm);
  msg->set_rms_mm(c.rms_mm);
  msg->set_fraction_within(c.fraction_within);
  msg->set_value_mm(c.value_mm);
  msg->set_allowed_fraction_outside(c.allowed_fraction_outside);
  msg->set_coverage(c.coverage);
  msg->set_min_coverage(c.min_coverage);
  if (c.is_hole()) HoleToProto(c, msg->mutable_hole());
}

void DefectToProto(const Defect& d, v1::DefectResult* msg) {
  msg->set_id(d.id);
  msg->set_kind(d.kind == DefectKind::kDent ? v1::DEFECT_DENT : v1::DEFECT_BUMP);
  Vector3ToProto(d.centroid_mm, msg->mutable_centroid_mm());
  msg->set_area_mm2(d.area_mm2);
  msg->set_extent_mm(d.extent_mm);
  msg->set_peak_mm(d.peak_mm);
  msg->set_peak_fitted(d.peak_fitted);
  msg->set_measured_extreme_mm(d.measured_extreme_mm);
  msg->set_noise_mm(d.noise_mm);
  msg->set_points(d.points);
  msg->set_region(d.region);
}

// report.json's alignment, typed: made from the report's struct, so the
// two cannot differ.
void AlignmentToProto(const ReportAlignment& a, v1::AlignmentResult* msg) {
  msg->set_mode(a.mode);
  msg->set_aligned(a.aligned);
  msg->set_failure(a.failure);
  msg->set_note(a.note);
  for (double m : a.matrix) msg->add_matrix(m);
  Vector3ToProto(a.translation_mm, msg->mutable_translation_mm());
  Vector3ToProto(a.rotation_deg, msg->mutable_rotation_deg());
  msg->set_correction_mm(a.correction_mm);
  msg->set_correction_deg(a.correction_deg);
  msg->set_max_correction_mm(a.max_correction_mm);
  msg->set_max_correction_deg(a.max_correction_deg);
  msg->set_within_max_correction(a.within_max_correction);
  msg->set_rms_before_mm(a.rms_before_mm);
  msg->set_rms_after_mm(a.rms_after_mm);
  msg->set_dofs(a.dofs);
  for (const std::string& l : a.locked) msg->add_locked(l);
  msg->set_points_used(a.points_used);
  msg->set_inliers(a.inliers);
  msg->set_iterations(a.iterations);
  msg->set_converged(a.converged);
  for (const ReportAlignmentReference& r : a.references) {
    v1::AlignmentReferenceResult* m = msg->add_references();
    m->set_name(r.name);
    m->set_kind(r.kind);
    m->set_measured(r.measured);
    Vector3ToProto(r.nominal_mm, m->mutable_nominal_mm());
    Vector3ToProto(r.measured_mm, m->mutable_measured_mm());
    m->set_points(r.points);
    for (const ReportLockedDirection& d : r.locked) {
      v1::AlignmentLockedDirection* x = m->add_locked();
      Vector3ToProto(d.direction, x->mutable_direction());
      x->set_before_mm(d.before_mm);
      x->set_after_mm(d.after_mm);
    }
  }
}

// ErrorMapResponse and InspectResult carry the same typed fields.
template <typename Msg>
void OutcomeToProto(const ErrorMapResult& map, const PlanOutcome& outcome, Msg* msg) {
  msg->set_part_verdict(VerdictOf(outcome.pass()));
  StatisticsToProto(map, msg->mutable_statistics());
  msg->clear_characteristics();
  for (const CharacteristicResult& c : outcome.characteristics.characteristics)
    CharacteristicToProto(c, msg->add_characteristics());
  msg->clear_defects();
  for (const Defect& d : outcome.defects.defects) DefectToProto(d, msg->add_defects());
  msg->clear_alignment();
  if (const auto a = ReportAlignmentOf(outcome)) AlignmentToProto(*a, msg->mutable_alignment());
}

}  // namespace

CharacteristicsResult CharacteristicsFromProto(
    const google::protobuf::RepeatedPtrField<v1::CharacteristicResult>& list) {
  CharacteristicsResult out;
  for (const v1::CharacteristicResult& m : list) {
    CharacteristicResult c;
    c.name = m.name();
    c.type = m.type() == v1::CHARACTERISTIC_REGION       ? CharacteristicType::kRegion
             : m.type() == v1::CHARACTERISTIC_POINT      ? CharacteristicType::kPoint
             : m.type() == v1::CHARACTERISTIC_SECTION    ? CharacteristicType::kSection
             : m.type() == v1::CHARACTERISTIC_HOLE       ? CharacteristicType::kHole
             : m.type() == v1::CHARACTERISTIC_SLOT       ? CharacteristicType::kSlot
             : m.type() == v1::CHARACTERISTIC_EDGE_POINT ? CharacteristicType::kEdgePoint
                                                         : CharacteristicType::kSurface;
    c.pass = m.verdict() == v1::VERDICT_PASS;
    c.measured = m.verdict() != v1::VERDICT_NOT_MEASURED;
    c.coverage = m.coverage();
    c.min_coverage = m.min_coverage();
    c.reason = m.reason();
    c.tolerance = BandFromProto(m.tolerance_mm());
    c.points = m.points();
    c.min_mm = m.min_mm();
    c.max_mm = m.max_mm();
    c.mean_mm = m.mean_mm();
    c.stddev_mm = m.stddev_mm();
    c.rms_mm = m.rms_mm();
    c.fraction_within = m.fraction_within();
    c.value_mm = m.value_mm();
    c.allowed_fraction_outside = m.allowed_fraction_outside();
    if (c.is_hole()) HoleFromProto(m.hole(), &c);
    out.failed += !c.pass && c.measured;
    out.not_measured += !c.measured;
    out.characteristics.push_back(std::move(c));
  }
  return out;
}

DefectsResult DefectsFromProto(const google::protobuf::RepeatedPtrField<v1::DefectResult>& list) {
  DefectsResult out;
  for (const v1::DefectResult& m : list) {
    Defect d;
    d.id = m.id();
    d.kind = m.kind() == v1::DEFECT_BUMP ? DefectKind::kBump : DefectKind::kDent;
    if (m.centroid_mm_size() == 3)
      d.centroid_mm = {m.centroid_mm(0), m.centroid_mm(1), m.centroid_mm(2)};
    d.area_mm2 = m.area_mm2();
    d.extent_mm = m.extent_mm();
    d.peak_mm = m.peak_mm();
    d.peak_fitted = m.peak_fitted();
    d.measured_extreme_mm = m.measured_extreme_mm();
    d.noise_mm = m.noise_mm();
    d.points = m.points();
    d.region = m.region();
    out.defects.push_back(std::move(d));
  }
  return out;
}

const char* VerdictName(const ErrorMapResult& map) { return map.verdict.pass ? "pass" : "fail"; }

void ErrorMapToProto(const ErrorMapResult& map, const ErrorMapSettings& settings,
                     const PlanOutcome& outcome, bool with_deviations, v1::ErrorMapResponse* msg) {
  msg->set_report_json(ErrorMapReportText(map, settings, outcome));
  msg->set_verdict(outcome.pass() ? "pass" : "fail");
  OutcomeToProto(map, outcome, msg);
  if (with_deviations) msg->set_deviations(PackFloats(map.deviation_mm));
}

void ViewOutcomeToProto(const ViewOutcome& view, v1::ViewSummary* msg) {
  msg->set_name(view.name);
  msg->set_valid_points(view.valid_points);
  msg->set_removed_points(view.removed_points);
}

void InspectionResultToProto(const std::string& part_id, const InspectionResult& result,
                             const ErrorMapSettings& settings, bool with_deviations,
                             v1::InspectResult* msg) {
  msg->set_part_id(part_id);
  msg->set_verdict(result.plan.pass() ? "pass" : "fail");
  OutcomeToProto(result.error_map, result.plan, msg);
  msg->set_report_json(ErrorMapReportText(result.error_map, settings, result.plan));
  msg->clear_views();
  for (const ViewOutcome& v : result.views) ViewOutcomeToProto(v, msg->add_views());
  if (with_deviations) {
    msg->set_deviations(PackFloats(result.error_map.deviation_mm));
    CloudToProto(result.merged.cloud_in_world, msg->mutable_merged());
  }
}

v1::Progress::Stage StageToProto(InspectionStage stage) {
  switch (stage) {
    case InspectionStage::kViewFiltered:
      return v1::Progress::STAGE_VIEW_FILTERED;
    case InspectionStage::kViewRegistered:
      return v1::Progress::STAGE_VIEW_REGISTERED;
    case InspectionStage::kErrorMap:
      return v1::Progress::STAGE_ERROR_MAP;
  }
  return v1::Progress::STAGE_ERROR_MAP;
}

}  // namespace surfinspect::wire
