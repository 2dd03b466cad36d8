#include "proto/convert.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "absl/strings/str_cat.h"
#include "core/types/transform.h"
#include "proto/packed_cloud.h"

namespace surfinspect::wire {
namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "the wire's packed arrays and xyz bytes are the host's little-endian memory");

absl::Status Invalid(const std::string& field, absl::string_view why) {
  return absl::InvalidArgumentError(absl::StrCat(field, ": ", why));
}

template <typename T>
std::string Pack(const std::vector<T>& v) {
  return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

template <typename T>
std::vector<T> Unpack(const std::string& bytes) {
  std::vector<T> v(bytes.size() / sizeof(T));
  if (!v.empty()) std::memcpy(v.data(), bytes.data(), v.size() * sizeof(T));
  return v;
}

}  // namespace

absl::Status CheckCloudShape(uint64_t width, uint64_t height, const std::string& field,
                             const Limits& limits) {
  if (width == 0 || height == 0)
    return Invalid(field, "width and height must be > 0 (empty cloud)");
  if (width * height > limits.max_points)
    return absl::ResourceExhaustedError(absl::StrCat(
        field, ": ", width * height, " points exceed the server limit of ", limits.max_points));
  return absl::OkStatus();
}

absl::StatusOr<PointCloud> CloudFromBytes(const std::string& xyz, uint32_t width, uint32_t height,
                                          const std::string& field) {
  const uint64_t n = uint64_t{width} * height;
  if (xyz.size() != n * 12)
    return Invalid(field,
                   absl::StrCat("xyz holds ", xyz.size(), " bytes but width*height*12 = ", n * 12));
  return CloudFromBlocks(width, height, field,
                         [&](uint64_t, uint64_t first, uint64_t last, Eigen::Vector3f* points) {
                           std::memcpy(static_cast<void*>(points + first), xyz.data() + 12 * first,
                                       12 * (last - first));
                         });
}

absl::StatusOr<PointCloud> CloudFromBlocks(
    uint32_t width, uint32_t height, const std::string& field,
    absl::FunctionRef<void(uint64_t b, uint64_t first, uint64_t last, Eigen::Vector3f* points)>
        fill) {
  const uint64_t n = uint64_t{width} * height;
  PointCloud c;
  c.width = width;
  c.height = height;
  c.points.resize(n);
  const uint64_t blocks = (n + kCloudBlock - 1) / kCloudBlock;
  std::vector<absl::Status> failed(blocks);
  tbb::parallel_for(uint64_t{0}, blocks, [&](uint64_t b) {
    const uint64_t first = b * kCloudBlock, last = std::min(n, first + kCloudBlock);
    fill(b, first, last, c.points.data());
    failed[b] = c.ValidatePoints(first, last);
  });
  for (const absl::Status& st : failed)
    if (!st.ok()) return Invalid(field, st.message());
  return c;
}

void CloudAssembler::Start(uint32_t width, uint32_t height) {
  cloud_.width = width;
  cloud_.height = height;
  cloud_.points.resize(uint64_t{width} * height);  // Eigen's default constructor leaves them unset
  received_ = checked_ = 0;
}

absl::Status CloudAssembler::Add(const std::string& chunk, const std::string& field) {
  if (chunk.size() > expected_bytes() - received_)
    return Invalid(field, absl::StrCat("gets more than its ", expected_bytes(), " bytes"));
  std::memcpy(static_cast<void*>(reinterpret_cast<char*>(cloud_.points.data()) + received_),
              chunk.data(), chunk.size());
  received_ += chunk.size();
  // Check the points this chunk completed while they are in cache and the
  // next chunk is still on the wire, so Take() has nothing left to scan.
  const uint64_t done = received_ / 12;
  if (auto st = cloud_.ValidatePoints(checked_, done); !st.ok())
    return Invalid(field, st.message());
  checked_ = done;
  return absl::OkStatus();
}

absl::StatusOr<PointCloud> CloudAssembler::Take(const std::string& field) {
  if (!complete())
    return Invalid(field,
                   absl::StrCat("incomplete: ", received_, " of ", expected_bytes(), " bytes"));
  PointCloud c = std::move(cloud_);
  cloud_ = PointCloud();
  received_ = checked_ = 0;
  return c;
}

absl::StatusOr<PointCloud> CloudFromProto(const v1::PointCloud& msg, const std::string& field,
                                          const Limits& limits) {
  if (auto st = CheckCloudShape(msg.width(), msg.height(), field, limits); !st.ok()) return st;
  if (!msg.valid_bits().empty())
    return CloudFromPackedBytes(msg.xyz(), msg.valid_bits(), msg.width(), msg.height(), field);
  return CloudFromBytes(msg.xyz(), msg.width(), msg.height(), field);
}

void CloudToProto(const PointCloud& cloud, v1::PointCloud* msg) {
  msg->set_width(cloud.width);
  msg->set_height(cloud.height);
  msg->mutable_xyz()->assign(reinterpret_cast<const char*>(cloud.points.data()), cloud.size() * 12);
}

absl::StatusOr<Eigen::Isometry3d> TransformFromProto(const v1::Transform& msg,
                                                     const std::string& field) {
  if (msg.row_major_size() != 16)
    return Invalid(field, absl::StrCat("needs 16 row-major values, got ", msg.row_major_size()));
  RowMajor16 v{};
  for (int i = 0; i < 16; ++i) v[i] = msg.row_major(i);
  return FromRowMajor(v, field);
}

void TransformToProto(const Eigen::Isometry3d& t, v1::Transform* msg) {
  msg->clear_row_major();
  for (double x : ToRowMajor(t)) msg->add_row_major(x);
}

absl::StatusOr<TriangleMesh> MeshFromProto(const v1::InlineMesh& msg, const std::string& field,
                                           const Limits& limits) {
  if (msg.vertices().size() % 12 != 0 || msg.triangles().size() % 12 != 0)
    return Invalid(field, "vertices and triangles must be whole 12-byte records");
  const uint64_t nt = msg.triangles().size() / 12;
  if (nt > limits.max_triangles)
    return absl::ResourceExhaustedError(absl::StrCat(
        field, ": ", nt, " triangles exceed the server limit of ", limits.max_triangles));
  // Checked before the copies: memcpy from an empty string's buffer into an
  // empty vector's null data() is undefined even for 0 bytes.
  if (msg.vertices().empty() || msg.triangles().empty())
    return Invalid(field, "a mesh needs vertices and triangles");
  TriangleMesh m;
  m.vertices.resize(msg.vertices().size() / 12);
  m.triangles.resize(nt);
  std::memcpy(static_cast<void*>(m.vertices.data()), msg.vertices().data(), msg.vertices().size());
  std::memcpy(m.triangles.data(), msg.triangles().data(), msg.triangles().size());
  if (auto st = m.Validate(); !st.ok()) return Invalid(field, st.message());
  return m;
}

void MeshToProto(const TriangleMesh& mesh, v1::InlineMesh* msg) {
  msg->mutable_vertices()->assign(reinterpret_cast<const char*>(mesh.vertices.data()),
                                  mesh.vertices.size() * 12);
  msg->mutable_triangles()->assign(reinterpret_cast<const char*>(mesh.triangles.data()),
                                   mesh.triangles.size() * 12);
}

absl::StatusOr<LinkClusteringSettings> FilterSettingsFromProto(const v1::FilterSettings& msg,
                                                               const std::string& field,
                                                               const LinkClusteringSettings& base) {
  LinkClusteringSettings s = base;
  if (msg.has_link_distance_mm()) s.link_distance_mm = msg.link_distance_mm();
  if (msg.has_min_cluster_points()) s.min_cluster_points = msg.min_cluster_points();
  if (msg.has_connectivity()) s.connectivity = static_cast<int>(msg.connectivity());
  if (msg.has_min_fraction_of_largest()) s.min_fraction_of_largest = msg.min_fraction_of_largest();
  if (auto st = ValidateLinkClusteringSettings(s); !st.ok()) return Invalid(field, st.message());
  return s;
}

void FilterSettingsToProto(const LinkClusteringSettings& s, v1::FilterSettings* msg) {
  msg->set_link_distance_mm(s.link_distance_mm);
  msg->set_min_cluster_points(s.min_cluster_points);
  msg->set_connectivity(static_cast<uint32_t>(s.connectivity));
  msg->set_min_fraction_of_largest(s.min_fraction_of_largest);
}

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

absl::StatusOr<IcpSettings> IcpSettingsFromProto(const v1::IcpSettings& msg,
                                                 const std::string& field) {
  IcpSettings s;
  switch (msg.step()) {
    case v1::IcpSettings::STEP_UNSPECIFIED:
    case v1::IcpSettings::STEP_POINT_TO_POINT:
      s.step = IcpStep::kPointToPoint;
      break;
    case v1::IcpSettings::STEP_POINT_TO_PLANE:
      s.step = IcpStep::kPointToPlane;
      break;
    default:
      return Invalid(field + ".step", "unknown step");
  }
  // Clamped so a huge uint32 cannot wrap into the valid range; the validator refuses it.
  if (msg.has_max_iterations())
    s.max_iterations = static_cast<int>(std::min<uint32_t>(msg.max_iterations(), INT32_MAX));
  if (msg.has_max_correspondence_mm()) s.max_correspondence_mm = msg.max_correspondence_mm();
  if (msg.has_min_correspondence_mm()) s.min_correspondence_mm = msg.min_correspondence_mm();
  if (msg.has_trim_fraction()) s.trim_fraction = msg.trim_fraction();
  if (msg.has_relative_cost_tolerance()) s.relative_cost_tolerance = msg.relative_cost_tolerance();
  if (msg.has_max_points()) s.max_points = msg.max_points();
  if (auto st = ValidateIcpSettings(s); !st.ok()) return Invalid(field, st.message());
  return s;
}

void IcpSettingsToProto(const IcpSettings& s, v1::IcpSettings* msg) {
  msg->set_step(s.step == IcpStep::kPointToPlane ? v1::IcpSettings::STEP_POINT_TO_PLANE
                                                 : v1::IcpSettings::STEP_POINT_TO_POINT);
  msg->set_max_iterations(static_cast<uint32_t>(s.max_iterations));
  msg->set_max_correspondence_mm(s.max_correspondence_mm);
  msg->set_min_correspondence_mm(s.min_correspondence_mm);
  msg->set_trim_fraction(s.trim_fraction);
  msg->set_relative_cost_tolerance(s.relative_cost_tolerance);
  msg->set_max_points(static_cast<uint32_t>(s.max_points));
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

absl::StatusOr<ErrorMapSettings> ErrorMapSettingsFromProto(const v1::ErrorMapSettings& msg,
                                                           const std::string& field) {
  ErrorMapSettings s;
  if (msg.has_tolerance_mm()) s.tolerance_mm = msg.tolerance_mm();
  if (msg.has_max_distance_mm()) s.max_distance_mm = msg.max_distance_mm();
  if (msg.has_allowed_fraction_outside())
    s.allowed_fraction_outside = msg.allowed_fraction_outside();
  if (msg.has_histogram_bins())
    s.histogram_bins = static_cast<int>(std::min<uint32_t>(msg.histogram_bins(), INT32_MAX));
  if (msg.has_histogram_range_mm()) s.histogram_range_mm = msg.histogram_range_mm();
  s.split_components = msg.split_components();
  if (auto st = ValidateErrorMapSettings(s); !st.ok()) return Invalid(field, st.message());
  return s;
}

void ErrorMapSettingsToProto(const ErrorMapSettings& s, v1::ErrorMapSettings* msg) {
  msg->set_tolerance_mm(s.tolerance_mm);
  msg->set_max_distance_mm(s.max_distance_mm);
  msg->set_allowed_fraction_outside(s.allowed_fraction_outside);
  msg->set_histogram_bins(static_cast<uint32_t>(s.histogram_bins));
  msg->set_histogram_range_mm(s.histogram_range_mm);
  msg->set_split_components(s.split_components);
}

void FilterResultToProto(const PointCloud& filtered, const LinkClusteringResult& r,
                         v1::FilterResponse* msg) {
  CloudToProto(filtered, msg->mutable_cloud());
  FilterStatsToProto(r, msg->mutable_stats());
  msg->set_kept_mask(Pack(r.kept_mask));
}

void MergedCloudToProto(const MergedCloud& merged, v1::RegisterResponse* msg) {
  CloudToProto(merged.cloud_in_world, msg->mutable_merged());
  msg->set_view_index(PackUint16(merged.view_id));
  msg->set_grid_index(PackUint32(merged.grid_index));
  msg->clear_points_per_view();
  for (std::size_t n : merged.points_per_view) msg->add_points_per_view(n);
}

// ---- inspection plan and results ----

namespace {

absl::StatusOr<Eigen::Vector3d> Vector3FromProto(const google::protobuf::RepeatedField<double>& v,
                                                 const std::string& field) {
  if (v.size() != 3) return Invalid(field, "must be 3 numbers");
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

void Vector3ToProto(const Eigen::Vector3d& v, google::protobuf::RepeatedField<double>* out) {
  out->Clear();
  for (int a = 0; a < 3; ++a) out->Add(v[a]);
}

ToleranceBand BandFromProto(const v1::ToleranceBand& b) { return {b.lower_mm(), b.upper_mm()}; }

void BandToProto(const ToleranceBand& b, v1::ToleranceBand* msg) {
  msg->set_lower_mm(b.lower_mm);
  msg->set_upper_mm(b.upper_mm);
}

absl::StatusOr<PlanRegion> RegionFromProto(const v1::PlanRegion& msg, const std::string& field) {
  PlanRegion r;
  r.name = msg.name();
  if (msg.has_tolerance_mm()) r.tolerance = BandFromProto(msg.tolerance_mm());
  if (msg.has_allowed_fraction_outside())
    r.allowed_fraction_outside = msg.allowed_fraction_outside();
  const v1::RegionSelect& s = msg.select();
  switch (s.selector_case()) {
    case v1::RegionSelect::kBoxMm: {
      r.select.kind = RegionSelector::Kind::kBox;
      auto lo = Vector3FromProto(s.box_mm().min_mm(), field + ".select.box_mm.min_mm");
      if (!lo.ok()) return lo.status();
      auto hi = Vector3FromProto(s.box_mm().max_mm(), field + ".select.box_mm.max_mm");
      if (!hi.ok()) return hi.status();
      r.select.box_min_mm = *lo;
      r.select.box_max_mm = *hi;
      break;
    }
    case v1::RegionSelect::kTriangles:
      r.select.kind = RegionSelector::Kind::kTriangles;
      r.select.triangles.assign(s.triangles().ids().begin(), s.triangles().ids().end());
      break;
    case v1::RegionSelect::kGroup:
      r.select.kind = RegionSelector::Kind::kGroup;
      r.select.group = s.group();
      break;
    default:
      return Invalid(field + ".select", "needs exactly one selector (box_mm, triangles, group)");
  }
  return r;
}

absl::StatusOr<ComparisonPoint> PointFromProto(const v1::ComparisonPoint& msg,
                                               const std::string& field) {
  ComparisonPoint p;
  p.name = msg.name();
  auto pos = Vector3FromProto(msg.position_mm(), field + ".position_mm");
  if (!pos.ok()) return pos.status();
  p.position_mm = *pos;
  if (msg.normal_size() != 0) {
    auto n = Vector3FromProto(msg.normal(), field + ".normal");
    if (!n.ok()) return n.status();
    if (!(n->norm() > 0) || !n->allFinite())
      return Invalid(field + ".normal", "must be a finite non-zero vector");
    p.normal = n->normalized();
  }
  if (msg.has_radius_mm()) p.radius_mm = msg.radius_mm();
  if (msg.has_tolerance_mm()) p.tolerance = BandFromProto(msg.tolerance_mm());
  return p;
}

}  // namespace

absl::StatusOr<InspectionPlan> PlanFromProto(const v1::InspectionPlan& msg,
                                             const ErrorMapSettings& defaults,
                                             const std::string& field) {
  InspectionPlan plan = PlanFromSettings(defaults);
  if (msg.has_tolerance_mm()) plan.tolerance = BandFromProto(msg.tolerance_mm());
  if (msg.has_allowed_fraction_outside())
    plan.allowed_fraction_outside = msg.allowed_fraction_outside();
  for (int i = 0; i < msg.regions_size(); ++i) {
    auto r = RegionFromProto(msg.regions(i), absl::StrCat(field, ".regions[", i, "]"));
    if (!r.ok()) return r.status();
    plan.regions.push_back(*std::move(r));
  }
  for (int i = 0; i < msg.points_size(); ++i) {
    auto p = PointFromProto(msg.points(i), absl::StrCat(field, ".points[", i, "]"));
    if (!p.ok()) return p.status();
    plan.points.push_back(*std::move(p));
  }
  if (msg.has_defects()) {
    DefectRules d;
    const v1::DefectRules& m = msg.defects();
    if (m.has_threshold_mm()) d.threshold_mm = m.threshold_mm();
    if (m.has_min_area_mm2()) d.min_area_mm2 = m.min_area_mm2();
    if (m.has_max_count()) d.max_count = m.max_count();
    plan.defects = d;
  }
  return plan;
}

void PlanToProto(const InspectionPlan& plan, v1::InspectionPlan* msg) {
  msg->Clear();
  BandToProto(plan.tolerance, msg->mutable_tolerance_mm());
  msg->set_allowed_fraction_outside(plan.allowed_fraction_outside);
  for (const PlanRegion& r : plan.regions) {
    v1::PlanRegion* m = msg->add_regions();
    m->set_name(r.name);
    if (r.tolerance) BandToProto(*r.tolerance, m->mutable_tolerance_mm());
    m->set_allowed_fraction_outside(r.allowed_fraction_outside);
    v1::RegionSelect* s = m->mutable_select();
    switch (r.select.kind) {
      case RegionSelector::Kind::kBox:
        Vector3ToProto(r.select.box_min_mm, s->mutable_box_mm()->mutable_min_mm());
        Vector3ToProto(r.select.box_max_mm, s->mutable_box_mm()->mutable_max_mm());
        break;
      case RegionSelector::Kind::kTriangles:
        for (uint32_t t : r.select.triangles) s->mutable_triangles()->add_ids(t);
        s->mutable_triangles();  // an empty list is still this selector
        break;
      case RegionSelector::Kind::kGroup:
        s->set_group(r.select.group);
        break;
    }
  }
  for (const ComparisonPoint& p : plan.points) {
    v1::ComparisonPoint* m = msg->add_points();
    m->set_name(p.name);
    Vector3ToProto(p.position_mm, m->mutable_position_mm());
    if (p.normal != Eigen::Vector3d::Zero()) Vector3ToProto(p.normal, m->mutable_normal());
    m->set_radius_mm(p.radius_mm);
    if (p.tolerance) BandToProto(*p.tolerance, m->mutable_tolerance_mm());
  }
  if (plan.defects) {
    v1::DefectRules* d = msg->mutable_defects();
    d->set_threshold_mm(plan.defects->threshold_mm);
    d->set_min_area_mm2(plan.defects->min_area_mm2);
    if (plan.defects->max_count) d->set_max_count(*plan.defects->max_count);
  }
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
  }
  return v1::CHARACTERISTIC_TYPE_UNSPECIFIED;
}

void CharacteristicToProto(const CharacteristicResult& c, v1::CharacteristicResult* msg) {
  msg->set_name(c.name);
  msg->set_type(TypeToProto(c.type));
  msg->set_verdict(VerdictOf(c.pass));
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
}

void DefectToProto(const Defect& d, v1::DefectResult* msg) {
  msg->set_id(d.id);
  msg->set_kind(d.kind == DefectKind::kDent ? v1::DEFECT_DENT : v1::DEFECT_BUMP);
  Vector3ToProto(d.centroid_mm, msg->mutable_centroid_mm());
  msg->set_area_mm2(d.area_mm2);
  msg->set_extent_mm(d.extent_mm);
  msg->set_peak_mm(d.peak_mm);
  msg->set_points(d.points);
  msg->set_region(d.region);
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
}

}  // namespace

CharacteristicsResult CharacteristicsFromProto(
    const google::protobuf::RepeatedPtrField<v1::CharacteristicResult>& list) {
  CharacteristicsResult out;
  for (const v1::CharacteristicResult& m : list) {
    CharacteristicResult c;
    c.name = m.name();
    c.type = m.type() == v1::CHARACTERISTIC_REGION  ? CharacteristicType::kRegion
             : m.type() == v1::CHARACTERISTIC_POINT ? CharacteristicType::kPoint
                                                    : CharacteristicType::kSurface;
    c.pass = m.verdict() == v1::VERDICT_PASS;
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
    out.failed += c.pass ? 0 : 1;
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

std::string PackFloats(const std::vector<float>& v) { return Pack(v); }
std::vector<float> UnpackFloats(const std::string& bytes) { return Unpack<float>(bytes); }
std::string PackUint16(const std::vector<uint16_t>& v) { return Pack(v); }
std::vector<uint16_t> UnpackUint16(const std::string& bytes) { return Unpack<uint16_t>(bytes); }
std::string PackUint32(const std::vector<uint32_t>& v) { return Pack(v); }
std::vector<uint32_t> UnpackUint32(const std::string& bytes) { return Unpack<uint32_t>(bytes); }

}  // namespace surfinspect::wire
