// The mesh index's edge and vertex pseudonormals (declared in
// mesh_index.h), which sign a closest point on an edge or a vertex
// (Bærentzen & Aanæs 2005).
#include <algorithm>
#include <cmath>

#include "core/distance/mesh_index.h"
#include "core/types/first_equal_point.h"
#include "core/types/radix_sort.h"

namespace surfinspect {
namespace {

// Interior angle at `v` between the edges to `u` and `w` (radians).
double Angle(const Eigen::Vector3d& v, const Eigen::Vector3d& u, const Eigen::Vector3d& w) {
  const Eigen::Vector3d a = u - v, b = w - v;
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

}  // namespace

void MeshIndex::ComputeFeatureNormals() {
  const auto& verts = mesh_.vertices;
  const auto& tris = mesh_.triangles;
  // Weld identical positions (an STL from elsewhere may repeat them) so the
  // adjacency, and with it the edge and vertex pseudonormals, is right.
  // Each vertex welds to the lowest index with its position.
  weld_.resize(verts.size());
  FirstEqualPoint first(verts, verts.size());
  for (uint32_t i = 0; i < verts.size(); ++i) {
    weld_[i] = first.FindOrAdd(i);
    info_.welded_vertices += weld_[i] != i;
  }

  // Edges: a stable sort of the slots t * 3 + k by welded vertex pair (u <
  // w, keyed u * n + w), then the face normals summed per run in slot order.
  const uint64_t n = verts.size();
  std::vector<uint64_t> keys;
  std::vector<uint32_t> slots;
  keys.reserve(tris.size() * 3);
  slots.reserve(tris.size() * 3);
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      uint32_t u = weld_[tris[t][k]], w = weld_[tris[t][(k + 1) % 3]];
      if (u > w) std::swap(u, w);
      keys.push_back(u * n + w);
      slots.push_back(static_cast<uint32_t>(t * 3 + k));
    }
  int key_bits = 1;
  while (key_bits < 64 && (n * n - 1) >> key_bits) ++key_bits;
  RadixSortPairs(keys, slots, key_bits);
  triangle_edges_.resize(tris.size());
  edge_normal_.clear();
  for (std::size_t i = 0; i < slots.size();) {
    std::size_t j = i;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    const auto id = static_cast<uint32_t>(edge_normal_.size());
    for (; j < slots.size() && keys[j] == keys[i]; ++j) {
      sum += face_normal_[slots[j] / 3];
      triangle_edges_[slots[j] / 3][slots[j] % 3] = id;
    }
    if (j - i == 1) ++info_.boundary_edges;
    if (j - i >= 3) ++info_.nonmanifold_edges;
    edge_normal_.push_back(sum.norm() > 0 ? Eigen::Vector3d(sum.normalized()) : sum);
    i = j;
  }

  // Vertices: each incident face normal weighted by its angle at the vertex.
  vertex_normal_.assign(verts.size(), Eigen::Vector3d::Zero());
  for (std::size_t t = 0; t < tris.size(); ++t) {
    if (face_normal_[t].isZero()) continue;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d v = verts[tris[t][k]].cast<double>();
      const Eigen::Vector3d u = verts[tris[t][(k + 1) % 3]].cast<double>();
      const Eigen::Vector3d w = verts[tris[t][(k + 2) % 3]].cast<double>();
      vertex_normal_[weld_[tris[t][k]]] += Angle(v, u, w) * face_normal_[t];
    }
  }
  for (auto& n : vertex_normal_)
    if (n.norm() > 0) n.normalize();
}

MeshTopology MeshIndex::Topology() const {
  if (info_.welded_vertices > 0) return AnalyzeTopology(mesh_);
  MeshTopology topo;
  topo.boundary_edges = info_.boundary_edges;
  topo.nonmanifold_edges = info_.nonmanifold_edges;
  return topo;
}

}  // namespace surfinspect
