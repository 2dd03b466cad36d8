// MeshIndex: exact closest-point and signed-distance queries against a CAD
// mesh, the core of the error map (paper §IV, steps 1-4).
//
// A wide BVH built by Embree (core/distance/wide_bvh.h) culls the triangles
// by float boxes and per-triangle lower bounds; each triangle it cannot rule
// out is answered by the double-precision kernel in
// core/distance/point_triangle.h, and every better answer shrinks the search
// radius, so the search prunes as it goes. Ties between equally close
// triangles go to the lower triangle id, so an answer never depends on
// traversal order, start radius, instruction set or thread count.
//
// Sign: the angle-weighted pseudonormal of the closest feature (Bærentzen &
// Aanæs, "Signed distance computation using the angle weighted
// pseudonormal", IEEE TVCG 2005): the face normal inside a face, the sum of
// the adjacent face normals on an edge, the incident-angle-weighted sum at a
// vertex. This is the paper's step 4 (points whose closest point lies on a
// shared boundary). A boundary edge of an open mesh has one face and uses its
// normal; no ray parity is involved, so open sheet-metal surfaces sign right.
// + is the side the CCW face normal points to (above the material), - below.
//
// Batch queries over whole clouds are declared here too and live in
// core/distance/mesh_index_batch.cpp.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "absl/functional/function_ref.h"
#include "absl/status/statusor.h"
#include "core/distance/point_triangle.h"
#include "core/distance/wide_bvh_layout.h"
#include "core/types/point_cloud.h"
#include "core/types/triangle_mesh.h"

struct RTCDeviceTy;  // Embree's device (RTCDevice)

namespace surfinspect {

class WideBvh;
class HintCertificates;
struct MeshOrder;

struct ClosestPoint {
  uint32_t triangle_id = UINT32_MAX;  // UINT32_MAX = unmatched
  Eigen::Vector3d point =
      Eigen::Vector3d::Constant(NAN);  // closest point on the mesh, mm, mesh frame
  ClosestFeature feature = ClosestFeature::kFace;
  double distance_mm = NAN;         // unsigned; NaN if unmatched
  double signed_distance_mm = NAN;  // + on the CCW-normal side; NaN if unmatched
  Eigen::Vector3d normal =
      Eigen::Vector3d::Zero();  // unit face normal of triangle_id (0 if degenerate)
  bool matched() const { return triangle_id != UINT32_MAX; }
};

// How a query found its answer: by the tree, by the hint's certificate
// and its ring's lanes, or by the hint's certificate alone
// (core/distance/hint_certificate.h). The answer is the same in each.
enum class QueryPath : uint8_t { kTree, kRing, kHintAlone };

struct MeshIndexSettings {
  // Embree's build: kLow sorts by Morton codes (fast to build), kMedium and
  // kHigh split by the surface area heuristic (slower to build, faster to
  // query); the answers are the same.
  BvhQuality build_quality = BvhQuality::kHigh;
  int build_threads = 0;                    // Embree build threads; 0 = all cores
  SearchIsa search_isa = SearchIsa::kAuto;  // the answers are the same in each
  // Per-triangle certificates that let a query whose hint is close enough
  // skip the tree (core/distance/hint_certificate.h). The answers are the
  // same either way; building them costs about one search per triangle, so
  // they pay when there are several queries per triangle.
  bool hint_certificates = true;
};

// Hint certificates cost about one search per triangle to build and save
// part of a search per coherent query: a one-shot call (build, query once,
// exit) gains from them only with this many points per triangle or more,
// in scan order and in Morton order alike (bench/error_map_bench.cpp's
// build and query rows on its 150k-triangle torus show the two costs).
// An index that is kept (the server's cache, calibration's many ICP
// iterations) builds them always.
constexpr double kCertificatePointsPerTriangle = 16;
inline bool CertificatesPayOnce(std::size_t points, std::size_t triangles) {
  return static_cast<double>(points) >= kCertificatePointsPerTriangle * triangles;
}

// What Build() found in the mesh; reported with the error map.
struct MeshIndexInfo {
  std::size_t triangles = 0;
  std::size_t degenerate_triangles = 0;  // kept in the BVH, but never signed by their own normal
  std::size_t boundary_edges = 0;        // open mesh when > 0
  std::size_t nonmanifold_edges = 0;
  std::size_t welded_vertices = 0;  // duplicate vertex positions merged for the pseudonormals
  std::size_t bvh_nodes = 0;
  int bvh_depth = 0;
  const char* search_isa = "";  // "sse2" or "avx2"
  // Triangles whose hint certificate can certify (0 when they are off).
  std::size_t certifiable_triangles = 0;
  std::size_t hint_alone_triangles = 0;  // of them, those that can also prove themselves alone
  double certificate_seconds = 0;        // their share of build_seconds
  double build_seconds = 0;
};

class MeshIndex {
 public:
  // Fails (InvalidArgument) on a mesh that TriangleMesh::Validate rejects,
  // or with Embree's error turned into a status.
  static absl::StatusOr<std::unique_ptr<MeshIndex>> Build(TriangleMesh mesh,
                                                          const MeshIndexSettings& settings = {});
  ~MeshIndex();
  MeshIndex(const MeshIndex&) = delete;
  MeshIndex& operator=(const MeshIndex&) = delete;

  // The closest point on the mesh to `p_in_mesh` (mm, mesh frame) if it lies
  // within `max_distance_mm` (inclusive), otherwise unmatched. A non-finite
  // point is unmatched. `hint_triangle`, a triangle likely to be close (the
  // previous scan point's), only speeds the search up: the answer is the
  // same with any hint or none. `path`, when given, is set to how the
  // answer was found; `try_certificate` false skips the hint's certificate
  // (the answer is the same). Thread-safe.
  ClosestPoint Closest(const Eigen::Vector3d& p_in_mesh, double max_distance_mm = INFINITY,
                       uint32_t hint_triangle = UINT32_MAX, QueryPath* path = nullptr,
                       bool try_certificate = true) const;

  const TriangleMesh& mesh() const { return mesh_; }
  const MeshIndexInfo& info() const { return info_; }
  // AnalyzeTopology(mesh()). The build counted the same edges on the welded
  // vertices, so its counts are taken when no vertex was welded; a mesh
  // that repeats positions is counted again on its own indices.
  MeshTopology Topology() const;
  // The BVH and the hint certificates (null when off), for their tests.
  // Both number the triangles by their position in the index's order
  // (core/distance/mesh_order.h), not by mesh id.
  const WideBvh& bvh() const { return *bvh_; }
  const HintCertificates* hint_certificates() const { return certificates_.get(); }
  uint32_t position_of(uint32_t triangle) const { return position_of_triangle_[triangle]; }
  uint32_t mesh_triangle(uint32_t position) const { return mesh_triangle_[position]; }
  // Mesh, pseudonormals and the BVH, for an LRU cache of indices.
  std::size_t memory_bytes() const;

 private:
  MeshIndex() = default;
  void ComputeFaceNormals();
  void ComputeFeatureNormals();  // mesh_index_normals.cpp
  void ApplyOrder(MeshOrder order);
  // mesh_index_build.cpp; both run on `settings.build_threads` threads.
  absl::StatusOr<WideBvh> BuildInOrder(RTCDeviceTy* device, const MeshIndexSettings& settings);
  absl::Status BuildCertificates(const MeshIndexSettings& settings);
  const Eigen::Vector3d& Pseudonormal(uint32_t triangle, ClosestFeature feature) const;
  const Eigen::Vector3d& VertexNormal(uint32_t representative) const;  // mesh_index_normals.cpp
  Eigen::Vector3d SumVertexNormal(uint32_t representative) const;
  QueryPath CertifiedByHint(wide::Query& q, uint32_t hint_triangle) const;
  int EdgeBeyond(uint32_t triangle, const Eigen::Vector3d& p) const;
  uint32_t WalkTowards(uint32_t hint_triangle, const Eigen::Vector3d& p) const;

  // The mesh as given, for mesh() and the answers' ids, and the same
  // triangles in the index's order (spatial with certificates, the mesh's
  // own without), which every array below follows (the per-vertex ones by
  // the order's vertex positions).
  TriangleMesh mesh_;
  TriangleMesh ordered_;
  std::vector<uint32_t> mesh_triangle_;         // position -> mesh triangle id
  std::vector<uint32_t> position_of_triangle_;  // mesh triangle id -> position
  MeshIndexInfo info_;
  std::vector<Eigen::Vector3d> face_normal_;             // per triangle, unit or 0
  std::vector<TriangleShape> shape_;                     // per triangle, for the kernel
  std::vector<std::array<uint32_t, 3>> triangle_edges_;  // per triangle: edge ids of AB, BC, CA
  std::vector<Eigen::Vector3d> edge_normal_;             // per edge: sum of adjacent face normals
  std::vector<uint32_t> weld_;                           // vertex -> representative vertex
  // Per representative: the corners t * 3 + k (mesh triangle ids, in that
  // order) whose angle-weighted face normals sum to its pseudonormal, at
  // corners_[corner_start_[v], corner_start_[v + 1]). The sums are made on
  // first use (VertexNormal): few answers lie at a vertex (8 of the
  // bench's 10^6 points), and the atan2 of every corner was a third of the
  // build's serial work. State per representative: 0 not made, 1 being
  // made, 2 made (vertex_normal_ holds it from then on).
  std::vector<uint32_t> corner_start_;
  std::vector<uint32_t> corners_;
  mutable std::vector<Eigen::Vector3d> vertex_normal_;
  mutable std::unique_ptr<std::atomic<uint8_t>[]> vertex_normal_state_;
  std::unique_ptr<WideBvh> bvh_;
  std::unique_ptr<HintCertificates> certificates_;  // null when off
};

constexpr int kMaxQueryThreads = 1024;  // the largest task arena a batch query makes

struct BatchQuerySettings {
  double max_distance_mm = INFINITY;  // points farther from the mesh are unmatched (NaN)
  int threads = 0;  // in [0, kMaxQueryThreads], 0 = all cores; results do not depend on it
  // Exploit coherence: visit points in a spatially coherent order (the
  // sensor grid for organized clouds, Morton order otherwise) and start each
  // query's radius at previous distance + |p - p_prev| (triangle
  // inequality), so traversal prunes from the first node. Results are
  // identical with and without it; only the speed differs.
  bool coherent_start = true;
};

// One result per input point, in input order. Points are transformed by
// `mesh_from_points` first; invalid (NaN) points give unmatched results.
// `cancel` (may be null) is polled every chunk of points -> CancelledError.
// InvalidArgument for a malformed cloud or bad settings.
absl::StatusOr<std::vector<ClosestPoint>> QueryClosest(const MeshIndex& index,
                                                       const PointCloud& points,
                                                       const Eigen::Isometry3d& mesh_from_points,
                                                       const BatchQuerySettings& settings,
                                                       const std::atomic<bool>* cancel = nullptr);

// The same, streaming: `sink(i, result)` is called exactly once for every
// input index i, concurrently from worker threads (for different i), so
// callers can store only the fields they need.
// Where a batch query's time went, s: the visiting order (Morton keys and
// their sort; 0 for organized clouds) and the searches, which include the
// signs (a pseudonormal per answer, inside Closest).
struct BatchQueryTiming {
  double order_seconds = 0;
  double search_seconds = 0;
  // Answered without the tree by the hint's certificate: with its ring's
  // lanes, and (of those) by the hint alone.
  std::size_t certified_points = 0;
  std::size_t hint_alone_points = 0;
};

absl::Status QueryClosestEach(const MeshIndex& index, const PointCloud& points,
                              const Eigen::Isometry3d& mesh_from_points,
                              const BatchQuerySettings& settings, const std::atomic<bool>* cancel,
                              absl::FunctionRef<void(std::size_t, const ClosestPoint&)> sink,
                              BatchQueryTiming* timing = nullptr);

}  // namespace surfinspect
