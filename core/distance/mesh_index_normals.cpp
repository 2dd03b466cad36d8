// The mesh index's edge and vertex pseudonormals (declared in
// mesh_index.h), which sign a closest point on an edge or a vertex
// (Bærentzen & Aanæs 2005).
#include <algorithm>
#include <cmath>

#include "core/distance/mesh_index.h"
#include "core/types/first_equal_point.h"

namespace surfinspect {
namespace {

// The corner slots t * 3 + k of `tris`, each naming the edge from its corner
// to the next, sorted by the edge's welded vertex pair (u, w), u < w, with
// equal pairs in slot order (a stable sort by u * n + w). Counted into one
// bucket per u, slot by slot, then each bucket (a vertex's few edges) put
// in w order by insertion, which keeps equal pairs in slot order: about a
// quarter of a radix sort's time on the 64-bit keys. `keys` gets u * n + w.
void SortEdgeSlots(const std::vector<Triangle>& tris, const std::vector<uint32_t>& weld,
                   std::vector<uint64_t>& keys, std::vector<uint32_t>& slots) {
  const std::size_t n = weld.size(), m = tris.size() * 3;
  std::vector<uint32_t> low(m), high(m), start(n + 1, 0);
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      uint32_t u = weld[tris[t][k]], w = weld[tris[t][(k + 1) % 3]];
      if (u > w) std::swap(u, w);
      low[t * 3 + k] = u;
      high[t * 3 + k] = w;
      ++start[u + 1];
    }
  for (std::size_t v = 0; v < n; ++v) start[v + 1] += start[v];
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  slots.resize(m);
  keys.resize(m);
  for (std::size_t i = 0; i < m; ++i) slots[fill[low[i]]++] = static_cast<uint32_t>(i);
  for (std::size_t v = 0; v < n; ++v)
    for (uint32_t j = start[v] + 1; j < start[v + 1]; ++j) {
      const uint32_t slot = slots[j];
      uint32_t i = j;
      for (; i > start[v] && high[slots[i - 1]] > high[slot]; --i) slots[i] = slots[i - 1];
      slots[i] = slot;
    }
  for (std::size_t i = 0; i < m; ++i) keys[i] = uint64_t{low[slots[i]]} * n + high[slots[i]];
}

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

  // Edges: the slots t * 3 + k sorted by welded vertex pair, then the face
  // normals summed per run in slot order.
  std::vector<uint64_t> keys;
  std::vector<uint32_t> slots;
  SortEdgeSlots(tris, weld_, keys, slots);
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
