// The one place that converts between surfinspect.v1 protobuf messages and
// core types, used by the server and by the clients alike (so both sides
// agree on every byte). Every "FromProto" validates what it reads and names
// the offending field in an InvalidArgument status; limits give
// ResourceExhausted. Every "ToProto" builds a message from a core result,
// so a handler reads: parse (FromProto) -> core -> convert (ToProto).
// Implemented by concern: clouds, transforms, meshes and packed arrays in
// convert.cpp; settings, the plan and the results in convert_settings.cpp,
// convert_plan.cpp and convert_results.cpp.
#pragma once

#include <Eigen/Geometry>
#include <string>

#include "absl/functional/function_ref.h"
#include "absl/status/statusor.h"
#include "core/errormap/error_map.h"
#include "core/filter/link_clustering.h"
#include "core/pipeline/inspection.h"
#include "core/registration/calibration.h"
#include "core/registration/registration.h"
#include "core/types/point_cloud.h"
#include "core/types/triangle_mesh.h"
#include "surfinspect/v1/inspection.pb.h"

namespace surfinspect::wire {

namespace v1 = ::surfinspect::v1;

struct Limits {
  uint64_t max_points = 20'000'000;    // per cloud (and per merged part)
  uint64_t max_triangles = 5'000'000;  // per mesh
};

// ---- clouds ----
// Either spelling of a cloud: the whole grid, or packed (valid_bits set;
// proto/packed_cloud.h).
absl::StatusOr<PointCloud> CloudFromProto(const v1::PointCloud& msg, const std::string& field,
                                          const Limits& limits);
// The whole grid, as responses send it; requests use CloudToRequestProto.
void CloudToProto(const PointCloud& cloud, v1::PointCloud* msg);
// Validates width/height against limits; the bytes follow separately.
absl::Status CheckCloudShape(uint64_t width, uint64_t height, const std::string& field,
                             const Limits& limits);
// Raw little-endian xyz bytes (width*height*12) into a cloud.
absl::StatusOr<PointCloud> CloudFromBytes(const std::string& xyz, uint32_t width, uint32_t height,
                                          const std::string& field);
// Points per block of CloudFromBlocks.
constexpr uint64_t kCloudBlock = 1 << 16;
// A width x height cloud whose points fill(b, first, last, points) writes,
// block b being points [first, last) = [b, b + 1) * kCloudBlock (the last
// one shorter). Blocks are written and checked in parallel on the calling
// arena's threads, each checked while it is still in cache (the threads
// also share the faulting-in of the new pages); the lowest failing block
// names the first infinite point, as one serial Validate would, in an
// InvalidArgument naming `field`.
absl::StatusOr<PointCloud> CloudFromBlocks(
    uint32_t width, uint32_t height, const std::string& field,
    absl::FunctionRef<void(uint64_t b, uint64_t first, uint64_t last, Eigen::Vector3f* points)>
        fill);

// A cloud whose xyz bytes arrive in chunks (the Inspect stream). Each chunk
// is copied straight into the points: no staging buffer, no second copy.
class CloudAssembler {
 public:
  // Shape checked with CheckCloudShape first; the points stay unset until filled.
  void Start(uint32_t width, uint32_t height);
  // InvalidArgument (naming `field`) if the chunk overruns width*height*12
  // bytes or completes a point with an infinite coordinate (NaN = no point).
  absl::Status Add(const std::string& chunk, const std::string& field);
  uint64_t received_bytes() const { return received_; }
  uint64_t expected_bytes() const { return uint64_t{cloud_.size()} * 12; }
  bool complete() const { return received_ == expected_bytes(); }
  // The complete, validated cloud (InvalidArgument if incomplete); the
  // assembler is empty afterwards.
  absl::StatusOr<PointCloud> Take(const std::string& field);

 private:
  PointCloud cloud_;
  uint64_t received_ = 0;
  uint64_t checked_ = 0;  // points checked for infinities
};

// ---- transforms ----
absl::StatusOr<Eigen::Isometry3d> TransformFromProto(const v1::Transform& msg,
                                                     const std::string& field);
void TransformToProto(const Eigen::Isometry3d& t, v1::Transform* msg);

// ---- meshes ----
absl::StatusOr<TriangleMesh> MeshFromProto(const v1::InlineMesh& msg, const std::string& field,
                                           const Limits& limits);
void MeshToProto(const TriangleMesh& mesh, v1::InlineMesh* msg);

// ---- settings and results ----
// Unset fields keep `base` (the paper's defaults unless told otherwise).
absl::StatusOr<LinkClusteringSettings> FilterSettingsFromProto(
    const v1::FilterSettings& msg, const std::string& field,
    const LinkClusteringSettings& base = LinkClusteringSettings{});
void FilterSettingsToProto(const LinkClusteringSettings& s, v1::FilterSettings* msg);
void FilterStatsToProto(const LinkClusteringResult& r, v1::FilterStats* msg);

absl::StatusOr<IcpSettings> IcpSettingsFromProto(const v1::IcpSettings& msg,
                                                 const std::string& field);
void IcpSettingsToProto(const IcpSettings& s, v1::IcpSettings* msg);
void CalibrationToProto(const CalibrationResult& r, v1::CalibrateResponse* msg);

absl::StatusOr<ErrorMapSettings> ErrorMapSettingsFromProto(const v1::ErrorMapSettings& msg,
                                                           const std::string& field);
void ErrorMapSettingsToProto(const ErrorMapSettings& s, v1::ErrorMapSettings* msg);

// ---- results ----
// The filtered cloud, the statistics and the kept mask (one byte per input
// point: 1 kept, 0 removed or no data).
void FilterResultToProto(const PointCloud& filtered, const LinkClusteringResult& r,
                         v1::FilterResponse* msg);
// The merged cloud, its per-point view index (uint16) and grid index
// (uint32), and the points per view. best_fit_correction is the caller's.
void MergedCloudToProto(const MergedCloud& merged, v1::RegisterResponse* msg);
// The plan message as a core InspectionPlan: unset tolerance_mm and
// allowed_fraction_outside take `defaults` (+-tolerance_mm), like a JSON plan
// without them. Shapes are checked here (3 numbers per position, one
// selector per region), naming the field ("plan.regions[0].select"); the
// values then go through ValidateInspectionPlan against the part mesh.
absl::StatusOr<InspectionPlan> PlanFromProto(const v1::InspectionPlan& msg,
                                             const ErrorMapSettings& defaults,
                                             const std::string& field);
void PlanToProto(const InspectionPlan& plan, v1::InspectionPlan* msg);
// The typed results back as core structs (the clients' summaries).
CharacteristicsResult CharacteristicsFromProto(
    const google::protobuf::RepeatedPtrField<v1::CharacteristicResult>& list);
DefectsResult DefectsFromProto(const google::protobuf::RepeatedPtrField<v1::DefectResult>& list);
// "pass" or "fail", as in the JSON report.
const char* VerdictName(const ErrorMapResult& map);
// The report JSON text (surfinspect.report/2), the part verdict of
// `outcome` (as "pass"/"fail" and as the enum), the typed statistics,
// characteristics and defects, and, when `with_deviations`, the per-point
// deviations. The PNG is the caller's.
void ErrorMapToProto(const ErrorMapResult& map, const ErrorMapSettings& settings,
                     const PlanOutcome& outcome, bool with_deviations, v1::ErrorMapResponse* msg);
void ViewOutcomeToProto(const ViewOutcome& view, v1::ViewSummary* msg);
// As ErrorMapToProto, plus the part id and the per-view summaries; with
// `with_deviations` also the merged cloud (world frame) they belong to.
void InspectionResultToProto(const std::string& part_id, const InspectionResult& result,
                             const ErrorMapSettings& settings, bool with_deviations,
                             v1::InspectResult* msg);
v1::Progress::Stage StageToProto(InspectionStage stage);

// ---- packed arrays ----
// float32 / uint16 / uint32 arrays as little-endian bytes (the host order on
// every target surfinspect builds for; convert.cpp asserts it). An Unpack
// ignores a trailing partial element.
std::string PackFloats(const std::vector<float>& v);
std::vector<float> UnpackFloats(const std::string& bytes);
std::string PackUint16(const std::vector<uint16_t>& v);
std::vector<uint16_t> UnpackUint16(const std::string& bytes);
std::string PackUint32(const std::vector<uint32_t>& v);
std::vector<uint32_t> UnpackUint32(const std::string& bytes);

}  // namespace surfinspect::wire
