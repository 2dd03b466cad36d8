// Hint certificates: a proof, per query, that the closest triangle is the
// hint (the previous point's triangle) or one of its ring, so that a
// coherent query offers those few lanes and skips the tree.
//
// For each triangle T the index keeps S(T), the leaf lanes of T's ring (T
// and every triangle that shares a vertex position with it), an anchor m
// (T's centroid) and a reach D(T), a lower bound on the distance
// from m to every triangle outside S(T). For a query p and any triangle U
// outside S(h), by the triangle inequality
//   dist(p, U) >= dist(m, U) - |p - m| >= D(h) - |p - m|,
// so when D(h) > |p - m| + d_h (plus a rounding margin), d_h being p's
// distance to the hint h, every such U is farther than the hint, and the
// lexicographic minimum of (squared distance, triangle id) over the whole
// mesh is the one over S(h): offering S(h)'s lanes gives the tree's answer,
// bit for bit.
//
// Most queries need not even offer the ring: when the hint's closest point
// lies inside its face, its rise (core/distance/hint_alone.h) proves that
// no ring triangle is as close either, and the hint alone is the answer.
// When it lies on an edge or a corner, the triangles across that edge or
// the corner's two edges are tried first (they are likelier the answer),
// and the proof is asked of the best one.
//
// D(T) comes from one search of the BVH per triangle, from m, that skips
// S(T)'s lanes and is capped at (1 + kCapRadii) r, r the largest distance
// from m to T's vertices: the test only passes for |p - m| + d_h below
// D(T), so a larger D would only serve points far from the surface. A ring
// spread over more than kMaxBlocks leaf blocks (a vertex of high valence)
// gets no certificate; its queries search the tree.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/distance/hint_alone.h"
#include "core/distance/wide_bvh.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

// The fields in the order a query reads them: a walk reads the first 40
// bytes of each triangle it passes, a proof by the hint alone the next 84,
// a ring's lanes the rest (160 bytes in all).
struct HintCertificate {
  static constexpr int kMaxBlocks = 6;
  double anchor[3] = {};  // m, mm, mesh frame
  float reach_mm = 0;     // D, rounded down; 0 never certifies
  // The triangle across edge AB, BC, CA when exactly one other shares it,
  // else UINT32_MAX: where a query whose closest point lies beyond that
  // edge looks next.
  uint32_t across[3] = {UINT32_MAX, UINT32_MAX, UINT32_MAX};
  HintRise rise;                    // when the hint alone is provably the answer (hint_alone.h)
  uint32_t block[kMaxBlocks] = {};  // the leaf blocks holding the ring
  uint8_t lanes[kMaxBlocks] = {};   // the ring's lanes in each block
  uint8_t blocks = 0;               // entries in use

  // True when p is within `reaches` times the reach of the anchor: a cheap
  // test of whether a step or two across the mesh could end in a proof.
  bool Near(const Eigen::Vector3d& p, double reaches) const {
    const Eigen::Vector3d to_anchor(p.x() - anchor[0], p.y() - anchor[1], p.z() - anchor[2]);
    return to_anchor.squaredNorm() < reaches * reaches * reach_mm * reach_mm;
  }
  // True when the certificate proves that no triangle outside the ring is
  // as close to `p` as `hint_distance_mm`, with a margin above the
  // kernel's rounding at coordinates up to `coordinate_scale` (mm).
  bool Certifies(const Eigen::Vector3d& p, double hint_distance_mm, double coordinate_scale) const {
    const Eigen::Vector3d to_anchor(p.x() - anchor[0], p.y() - anchor[1], p.z() - anchor[2]);
    const double margin = 1e-6 * (hint_distance_mm + reach_mm) + 1e-8 * coordinate_scale + 1e-9;
    return to_anchor.norm() + hint_distance_mm + margin < reach_mm;
  }
};

class HintCertificates {
 public:
  static constexpr double kCapRadii = 0.6;  // the search's reach beyond r, in r

  // One certificate per triangle. `weld` maps each vertex to the
  // representative of its position and `face_normals` are the unit normals
  // (MeshIndex's). Runs in parallel in the caller's TBB arena; the result
  // does not depend on the thread count.
  static HintCertificates Build(const TriangleMesh& mesh, const std::vector<uint32_t>& weld,
                                const std::vector<Eigen::Vector3d>& face_normals,
                                const WideBvh& bvh);

  bool empty() const { return entries_.empty(); }
  const HintCertificate& of(uint32_t triangle) const { return entries_[triangle]; }
  std::size_t certifiable() const { return certifiable_; }  // triangles with reach > 0
  std::size_t alone() const { return alone_; }              // of them, with a valid rise
  std::size_t memory_bytes() const { return entries_.capacity() * sizeof(HintCertificate); }

 private:
  std::vector<HintCertificate> entries_;
  std::size_t certifiable_ = 0, alone_ = 0;
};

}  // namespace surfinspect
