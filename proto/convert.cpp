#include "proto/convert.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "absl/strings/str_cat.h"
#include "core/types/status_macros.h"
#include "core/types/transform.h"
#include "proto/convert_helpers.h"
#include "proto/packed_cloud.h"

namespace surfinspect::wire {
namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "the wire's packed arrays and xyz bytes are the host's little-endian memory");

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
  RETURN_IF_ERROR(CheckCloudShape(msg.width(), msg.height(), field, limits));
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

std::string PackFloats(const std::vector<float>& v) { return Pack(v); }
std::vector<float> UnpackFloats(const std::string& bytes) { return Unpack<float>(bytes); }
std::string PackUint16(const std::vector<uint16_t>& v) { return Pack(v); }
std::vector<uint16_t> UnpackUint16(const std::string& bytes) { return Unpack<uint16_t>(bytes); }
std::string PackUint32(const std::vector<uint32_t>& v) { return Pack(v); }
std::vector<uint32_t> UnpackUint32(const std::string& bytes) { return Unpack<uint32_t>(bytes); }

}  // namespace surfinspect::wire
