// The one place that converts between surfinspect.v1 protobuf messages and
// core types, used by the server and by the clients alike (so both sides
// agree on every byte). Every "FromProto" validates what it reads and names
// the offending field in an InvalidArgument status; limits give
// ResourceExhausted.
#pragma once

#include <Eigen/Geometry>
#include <string>

#include "absl/status/statusor.h"
#include "core/errormap/error_map.h"
#include "core/filter/link_clustering.h"
#include "core/registration/calibration.h"
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
absl::StatusOr<PointCloud> CloudFromProto(const v1::PointCloud& msg, const std::string& field,
                                          const Limits& limits);
void CloudToProto(const PointCloud& cloud, v1::PointCloud* msg);
// Validates width/height against limits; the bytes follow separately.
absl::Status CheckCloudShape(uint64_t width, uint64_t height, const std::string& field,
                             const Limits& limits);
// Raw little-endian xyz bytes (width*height*12) into a cloud.
absl::StatusOr<PointCloud> CloudFromBytes(const std::string& xyz, uint32_t width, uint32_t height,
                                          const std::string& field);

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

// Packs float32 / uint16 / uint32 arrays little-endian.
std::string PackFloats(const std::vector<float>& v);
std::vector<float> UnpackFloats(const std::string& bytes);

}  // namespace surfinspect::wire
