#include "core/distance/hint_alone.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "core/distance/point_triangle.h"
#include "core/distance/wide_bvh.h"

namespace surfinspect {
namespace {

constexpr double kWiden = 1e-9;  // η, in longest edges: covers the edge normals' rounding (~1e-12)
constexpr double kRound = 1e-9;  // per mm of coordinate: the kernel's and the normal's rounding
constexpr double kGap = 1e-10;   // of the coordinates' square: the proof's least margin in d^2

// Edge k (a_k to a_k+1)'s outward normal in the face's plane, scaled by the
// edge's length: the same doubles when the rise is built and when it is
// tested.
Eigen::Vector3d OutwardEdge(const Eigen::Vector3d a[3], int k, const Eigen::Vector3d& n) {
  return (a[(k + 1) % 3] - a[k]).cross(n);
}

// The edge between corners i and j of a triangle: AB = 0, BC = 1, CA = 2.
int EdgeOf(int i, int j) { return (i + j == 1) ? 0 : (i + j == 3) ? 1 : 2; }

struct Lines {
  Eigen::Vector3d m[3];  // OutwardEdge
  double len[3];
  const Eigen::Vector3d* a;
  double eta;
  // Beyond edge line k widened by η, times the edge length (mm^2): >= 0 in G_k.
  double Beyond(int k, const Eigen::Vector3d& x) const { return m[k].dot(x - a[k]) + eta * len[k]; }
  bool Clear(int k, const Eigen::Vector3d& x) const { return Beyond(k, x) >= eta * len[k]; }
};

// The edge lines (bit k for line k) whose widened half-spaces hold the
// ring triangle with corners u, of which shared[i] >= 0 sit on the face's
// corner shared[i]; 0 when it fits none of the cases in hint_alone.h.
uint32_t PlaceNeighbour(const Lines& lines, const Eigen::Vector3d u[3], const int shared[3]) {
  Eigen::Vector3d w[3];
  int free_corners = 0, first = -1, second = -1;
  for (int i = 0; i < 3; ++i) {
    if (shared[i] < 0) {
      w[free_corners++] = u[i];
    } else if (first < 0 || shared[i] == first) {
      first = shared[i];
    } else if (second < 0 || shared[i] == second) {
      second = shared[i];
    } else {
      return 0;  // on all three corners: a duplicate of the face
    }
  }
  if (free_corners == 0 || first < 0) return 0;
  if (second >= 0) {  // an edge neighbour: beyond the shared edge's line
    const int k = EdgeOf(first, second);
    for (int i = 0; i < free_corners; ++i)
      if (!lines.Clear(k, w[i])) return 0;
    return lines.Beyond(k, lines.a[(k + 1) % 3]) >= 0 ? 1u << k : 0;
  }
  // A neighbour at corner j: beyond line k1 (a_j a_j+1), line k2 (a_j-1 a_j) or their union.
  const int k1 = first, k2 = (first + 2) % 3;
  const Eigen::Vector3d& v = lines.a[first];
  if (!(lines.Beyond(k1, v) > 0 && lines.Beyond(k2, v) > 0)) return 0;
  bool all1 = true, all2 = true;
  for (int i = 0; i < free_corners; ++i) {
    all1 = all1 && lines.Clear(k1, w[i]);
    all2 = all2 && lines.Clear(k2, w[i]);
  }
  if (all1) return 1u << k1;
  if (all2) return 1u << k2;
  if (free_corners != 2) return 0;
  for (int order = 0; order < 2; ++order) {
    const Eigen::Vector3d& w1 = w[order];
    const Eigen::Vector3d& w2 = w[1 - order];
    if (!lines.Clear(k1, w1) || !lines.Clear(k2, w2)) continue;
    const double x = lines.Beyond(k1, w1) * lines.Beyond(k2, w2);
    const double y = lines.Beyond(k1, w2) * lines.Beyond(k2, w1);
    if (x - y >= 1e-9 * (std::abs(x) + std::abs(y))) return (1u << k1) | (1u << k2);
  }
  return 0;
}

}  // namespace

HintRise ComputeHintRise(const TriangleMesh& mesh, const std::vector<uint32_t>& weld, uint32_t t,
                         const Eigen::Vector3d& n, const uint32_t* ring, std::size_t ring_size) {
  HintRise out;
  const Triangle& tri = mesh.triangles[t];
  Eigen::Vector3d a[3];
  for (int k = 0; k < 3; ++k) a[k] = mesh.vertices[tri[k]].cast<double>();
  if (ClassifyTriangle(a[0], a[1], a[2]) != TriangleShape::kRegular) return out;
  Lines lines;
  lines.a = a;
  double longest = 0, coordinate = 0;
  for (int k = 0; k < 3; ++k) {
    lines.m[k] = OutwardEdge(a, k, n);
    lines.len[k] = (a[(k + 1) % 3] - a[k]).norm();
    longest = std::max(longest, lines.len[k]);
    coordinate = std::max(coordinate, a[k].cwiseAbs().maxCoeff());
  }
  lines.eta = kWiden * longest;
  double rise[2][3] = {};
  for (std::size_t r = 0; r < ring_size; ++r) {
    const uint32_t u_id = ring[r];
    if (u_id == t) continue;
    Eigen::Vector3d u[3];
    int shared[3];
    for (int i = 0; i < 3; ++i) {
      const uint32_t vertex = mesh.triangles[u_id][i];
      u[i] = mesh.vertices[vertex].cast<double>();
      shared[i] = -1;
      for (int k = 0; k < 3; ++k)
        if (weld[vertex] == weld[tri[k]]) shared[i] = k;
    }
    const uint32_t placed = PlaceNeighbour(lines, u, shared);
    if (placed == 0) return out;
    for (int side = 0; side < 2; ++side) {
      double h = 0;  // H+, with a margin over the normal's rounding
      for (int i = 0; i < 3; ++i) {
        const Eigen::Vector3d up = u[i] - a[0];
        h = std::max(h, (side == 0 ? 1 : -1) * n.dot(up) + kRound * (up.lpNorm<1>() + longest));
      }
      for (int k = 0; k < 3; ++k)
        if (placed >> k & 1u) rise[side][k] = std::max(rise[side][k], h);
    }
  }
  for (int side = 0; side < 2; ++side)
    for (int k = 0; k < 3; ++k)
      out.rise[side][k] = RoundUpToFloat(rise[side][k] * lines.len[k] * lines.len[k] * (1 + 1e-12));
  out.tol_mm = RoundUpToFloat(lines.eta + kRound * (coordinate + longest));
  out.longest_edge_mm = RoundUpToFloat(longest);
  out.valid = std::isfinite(out.tol_mm) && std::isfinite(out.longest_edge_mm);
  return out;
}

bool RingIsFarther(const HintRise& rise, const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                   double d, const Eigen::Vector3d& n, const TriangleMesh& mesh, uint32_t t) {
  if (!rise.valid) return false;
  // The corners are widened here, not by the caller: a caller's array of
  // doubles, written one coordinate at a time and read here two at a time,
  // stalls every load on a failed store forward.
  const Triangle& tri = mesh.triangles[t];
  const Eigen::Vector3d a[3] = {mesh.vertices[tri[0]].cast<double>(),
                                mesh.vertices[tri[1]].cast<double>(),
                                mesh.vertices[tri[2]].cast<double>()};
  const int side = n.dot(p - a[0]) >= 0 ? 0 : 1;
  const double longest = rise.longest_edge_mm;
  const double scale = p.cwiseAbs().maxCoeff() + longest + d;
  const double eps = rise.tol_mm + kRound * scale;  // η and every rounding, mm
  const double d_hi = d + eps;
  const double gap = kGap * scale * scale * longest * longest;
  for (int k = 0; k < 3; ++k) {
    // δ_k |e_k| less the margins, at most (δ_k - η - rounding) |e_k|.
    const double inside = -OutwardEdge(a, k, n).dot(q - a[k]) - eps * longest;
    if (!(inside > 0 && inside * inside > 2 * d_hi * rise.rise[side][k] + gap)) return false;
  }
  return true;
}

}  // namespace surfinspect
