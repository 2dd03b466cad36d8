// The mesh index's edge and vertex pseudonormals (declared in
// mesh_index.h), which sign a closest point on an edge or a vertex
// (Bærentzen & Aanæs 2005).
#include <algorithm>
#include <cmath>
#include <thread>

#include "core/distance/mesh_index.h"
#include "core/types/first_equal_point.h"

namespace surfinspect {
namespace {

constexpr uint32_t kNoBucket = UINT32_MAX;

// The indices i of `bucket` (each < n, or kNoBucket to leave i out) grouped
// by bucket, in increasing i within each: a stable counting sort. Bucket v
// holds items[start[v], start[v + 1]).
void GroupByBucket(const std::vector<uint32_t>& bucket, std::size_t n, std::vector<uint32_t>& start,
                   std::vector<uint32_t>& items) {
  start.assign(n + 1, 0);
  for (uint32_t b : bucket)
    if (b != kNoBucket) ++start[b + 1];
  for (std::size_t v = 0; v < n; ++v) start[v + 1] += start[v];
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  items.resize(start.back());
  for (std::size_t i = 0; i < bucket.size(); ++i)
    if (bucket[i] != kNoBucket) items[fill[bucket[i]]++] = static_cast<uint32_t>(i);
}

// The corner slots t * 3 + k of `tris`, each naming the edge from its corner
// to the next, sorted by the edge's welded vertex pair (u, w), u < w, with
// equal pairs in slot order (a stable sort by u * n + w). Grouped by u, then
// each group (a vertex's few edges) put in w order by insertion, which keeps
// equal pairs in slot order: about a quarter of a radix sort's time on the
// 64-bit keys. `keys` gets u * n + w.
void SortEdgeSlots(const std::vector<Triangle>& tris, const std::vector<uint32_t>& weld,
                   std::vector<uint64_t>& keys, std::vector<uint32_t>& slots) {
  const std::size_t n = weld.size(), m = tris.size() * 3;
  std::vector<uint32_t> low(m), high(m), start;
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      uint32_t u = weld[tris[t][k]], w = weld[tris[t][(k + 1) % 3]];
      if (u > w) std::swap(u, w);
      low[t * 3 + k] = u;
      high[t * 3 + k] = w;
    }
  GroupByBucket(low, n, start, slots);
  keys.resize(m);
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
  // One normal per distinct key, reserved at its count: grown by doubling,
  // the 180k-triangle bench mesh's 6.5 MB would fault in about 11 MB more.
  std::size_t edges = keys.empty() ? 0 : 1;
  for (std::size_t i = 1; i < keys.size(); ++i) edges += keys[i] != keys[i - 1];
  edge_normal_.clear();
  edge_normal_.reserve(edges);
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

  // Vertices: the corners of the triangles with a normal, by
  // representative, in (t, k) order.
  std::vector<uint32_t> corner_vertex(tris.size() * 3, kNoBucket);
  for (std::size_t t = 0; t < tris.size(); ++t)
    if (!face_normal_[t].isZero())
      for (int k = 0; k < 3; ++k) corner_vertex[t * 3 + k] = weld_[tris[t][k]];
  GroupByBucket(corner_vertex, verts.size(), corner_start_, corners_);
  vertex_normal_.resize(verts.size());
  vertex_normal_state_.reset(new std::atomic<uint8_t>[verts.size()]());
}

// Each incident face normal weighted by its angle at the vertex, summed in
// the corners' (t, k) order. Made once, by the first thread to claim it;
// another that asks meanwhile waits the sum's few hundred nanoseconds.
const Eigen::Vector3d& MeshIndex::VertexNormal(uint32_t representative) const {
  std::atomic<uint8_t>& state = vertex_normal_state_[representative];
  uint8_t seen = state.load(std::memory_order_acquire);
  if (seen == 0 && state.compare_exchange_strong(seen, 1, std::memory_order_acquire)) {
    vertex_normal_[representative] = SumVertexNormal(representative);
    state.store(2, std::memory_order_release);
    return vertex_normal_[representative];
  }
  while (state.load(std::memory_order_acquire) != 2) std::this_thread::yield();
  return vertex_normal_[representative];
}

Eigen::Vector3d MeshIndex::SumVertexNormal(uint32_t representative) const {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (uint32_t j = corner_start_[representative]; j < corner_start_[representative + 1]; ++j) {
    const uint32_t t = corners_[j] / 3;
    const int k = static_cast<int>(corners_[j] % 3);
    const Triangle& tri = mesh_.triangles[t];
    const Eigen::Vector3d v = mesh_.vertices[tri[k]].cast<double>();
    const Eigen::Vector3d u = mesh_.vertices[tri[(k + 1) % 3]].cast<double>();
    const Eigen::Vector3d w = mesh_.vertices[tri[(k + 2) % 3]].cast<double>();
    n += Angle(v, u, w) * face_normal_[position_of_triangle_[t]];
  }
  if (n.norm() > 0) n.normalize();
  return n;
}

MeshTopology MeshIndex::Topology() const {
  if (info_.welded_vertices > 0) return AnalyzeTopology(mesh_);
  MeshTopology topo;
  topo.boundary_edges = info_.boundary_edges;
  topo.nonmanifold_edges = info_.nonmanifold_edges;
  return topo;
}

}  // namespace surfinspect
