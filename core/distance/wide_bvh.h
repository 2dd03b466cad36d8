// The mesh index's BVH: built by Embree (rtcBuildBVH, binned SAH or Morton,
// 8 children per node, leaves of at most 8 triangles) and copied into our
// own flat layout (core/distance/wide_bvh_layout.h), which a nearest-first
// search walks 8 boxes and 8 triangle bounds at a time
// (core/distance/wide_bvh_search.cpp). The search only culls: every
// triangle it cannot rule out is handed to the caller's exact kernel, so
// the answer is the brute-force answer whatever the instruction set.
//
// Instruction sets: the search is compiled for SSE2 (any x86-64) and for
// AVX2 + FMA; kAuto takes AVX2 when the CPU and the OS support it
// (__builtin_cpu_supports checks both). A 512-bit path would need 16-wide
// nodes; the AVX2 code is what runs on an AVX-512 machine.
#pragma once

#include <embree3/rtcore.h>

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <vector>

#include "absl/status/statusor.h"
#include "core/distance/point_triangle.h"
#include "core/distance/wide_bvh_layout.h"
#include "core/types/default_init_vector.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

// Embree's build quality for ours (kHigh: binned SAH).
RTCBuildQuality EmbreeBuildQuality(BvhQuality quality);
// "sse2" or "avx2"; kAuto resolves first.
const char* SearchIsaName(SearchIsa isa);
// kAuto as it resolves on this machine.
SearchIsa ResolveSearchIsa(SearchIsa isa);
bool SearchIsaSupported(SearchIsa isa);

struct WideBvhStats {
  std::size_t nodes = 0;
  std::size_t leaf_blocks = 0;
  int depth = 0;  // levels of nodes, the root's included
};

class WideBvh {
 public:
  // `face_normals` are the unit normals per triangle (0 for a degenerate
  // one), `shapes` their ClassifyTriangle. `quality` is Embree's: LOW builds by Morton codes,
  // MEDIUM and HIGH by binned SAH. Fails with Embree's error or InvalidArgument for an ISA this
  // machine lacks. Run inside a TBB arena to bound the threads.
  static absl::StatusOr<WideBvh> Build(RTCDevice device, const TriangleMesh& mesh,
                                       const std::vector<Eigen::Vector3d>& face_normals,
                                       const std::vector<TriangleShape>& shapes,
                                       RTCBuildQuality quality, SearchIsa isa);

  void Search(wide::Query& query) const { search_(view(), query); }
  // Offers the lanes set in `lanes` of one block, culled by the leaf bound
  // as the search culls a leaf (core/distance/hint_certificate.h).
  void VisitLanes(uint32_t block, uint32_t lanes, wide::Query& query) const {
    visit_(view(), block, lanes, query);
  }
  const DefaultInitVector<wide::LeafBlock>& blocks() const { return blocks_; }
  wide::View view() const { return {nodes_.data(), blocks_.data()}; }
  SearchIsa isa() const { return isa_; }
  const WideBvhStats& stats() const { return stats_; }
  std::size_t memory_bytes() const;

 private:
  std::vector<wide::Node> nodes_;
  // Left unwritten by resize: the parallel fill writes every block, so its
  // pages are first touched on all cores, not in one serial pass.
  DefaultInitVector<wide::LeafBlock> blocks_;
  SearchIsa isa_ = SearchIsa::kSse2;
  void (*search_)(const wide::View&, wide::Query&) = &wide::sse2::Search;
  void (*visit_)(const wide::View&, uint32_t, uint32_t, wide::Query&) = &wide::sse2::VisitLanes;
  WideBvhStats stats_;
  friend class WideBvhBuilder;
};

// Puts triangle `t` (vertices a, b, c, unit normal n or 0, its kernel
// shape) in a block's
// lane: the floats the leaf bound reads. Unused lanes keep triangle
// UINT32_MAX. Exposed for the bound's tests.
void FillLeafLane(wide::LeafBlock& block, int lane, uint32_t t, const Eigen::Vector3f& a,
                  const Eigen::Vector3f& b, const Eigen::Vector3f& c, const Eigen::Vector3d& n,
                  TriangleShape shape);
// std::nextafter(f, INFINITY) without the library call on the search's
// path: for a finite f > 0 the next float up is the next bit pattern.
inline float NextUp(float f) {
  if (!(f > 0 && f < INFINITY)) return std::nextafter(f, INFINITY);
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  ++bits;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

// The smallest float >= v.
inline float RoundUpToFloat(double v) {
  const float f = static_cast<float>(v);
  return static_cast<double>(f) >= v ? f : NextUp(f);
}
// The search culls boxes in float, with the query point rounded to float
// (relative error 2^-24 per coordinate; the bound is derived in
// core/distance/wide_bvh_search.cpp). Padding the radius well beyond that
// keeps the true minimiser and every exact tie inside the search, so the
// double-precision answer is the brute-force answer. `coordinate_scale` is
// the query point's largest |coordinate|.
inline float SearchRadius(double distance_mm, double coordinate_scale) {
  if (!(distance_mm < static_cast<double>(std::numeric_limits<float>::max()) / 2)) return INFINITY;
  const double padded = distance_mm * (1 + 1e-6) + 1e-6 * coordinate_scale + 1e-9;
  return NextUp(static_cast<float>(padded));
}
// SearchRadius squared, rounded up to a float (the double product is
// exact: 48 bits): what a search culls boxes and lanes against.
inline float SearchRadius2(double distance_mm, double coordinate_scale) {
  const float radius = SearchRadius(distance_mm, coordinate_scale);
  return RoundUpToFloat(static_cast<double>(radius) * radius);
}
// A leaf lane's triangle: the mesh's float vertices, exactly, as doubles.
inline void LaneVertices(const wide::LeafBlock& block, int lane, Eigen::Vector3d v[3]) {
  for (int k = 0; k < 3; ++k)
    v[k] = Eigen::Vector3d(block.vertex[k][0][lane], block.vertex[k][1][lane],
                           block.vertex[k][2][lane]);
}
// A block with every lane unused.
wide::LeafBlock EmptyLeafBlock();
// The query's share of the float leaf bound's error: 8 2^-24 |p|_1, rounded
// up (core/distance/wide_bvh_search.cpp).
inline float LeafMargin(const Eigen::Vector3d& p) {
  return RoundUpToFloat(8 * 0x1p-24 * (std::abs(p.x()) + std::abs(p.y()) + std::abs(p.z())));
}
// The leaf bound of the given ISA (the tests compare them); SSE2 when this
// machine lacks the ISA. At most 3 2^-24 above the exact squared prism
// bound, which is at most the squared distance.
void LeafBounds2(SearchIsa isa, const wide::LeafBlock& block, const Eigen::Vector3d& p,
                 float out[wide::kLeafWidth]);

}  // namespace surfinspect
