#include "proto/convert.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "absl/strings/str_cat.h"
#include "core/types/transform.h"

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
  PointCloud c;
  c.width = width;
  c.height = height;
  c.points.resize(n);
  std::memcpy(static_cast<void*>(c.points.data()), xyz.data(), xyz.size());
  if (auto st = c.Validate(); !st.ok()) return Invalid(field, st.message());
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

const char* VerdictName(const ErrorMapResult& map) { return map.verdict.pass ? "pass" : "fail"; }

void ErrorMapToProto(const ErrorMapResult& map, const ErrorMapSettings& settings,
                     const PlanOutcome& outcome, bool with_deviations, v1::ErrorMapResponse* msg) {
  msg->set_report_json(ErrorMapReportText(map, settings, outcome));
  msg->set_verdict(outcome.pass() ? "pass" : "fail");
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
