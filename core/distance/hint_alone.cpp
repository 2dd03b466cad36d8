#include "core/distance/hint_alone.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <new>

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
  Eigen::Vector3d e[3];  // a_k+1 - a_k
  double len[3], len2[3];
  // The face's angles at both ends of edge k are at most 90 degrees, so
  // every point of the face projects inside the edge.
  bool projects_inside[3];
  const Eigen::Vector3d* a;
  double eta;
  double longest = 0, coordinate = 0;  // the longest edge, the largest |coordinate| of a corner
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

// A corner of a placed neighbour: how far inside each widened G_k it lies (T =
// Beyond, t |e_k|, mm^2), how far past an end of edge k along its line (S = s |e_k|,
// mm^2, 0 unless the whole neighbour lies past that end), its rise on each side
// with the rounding margin (mm), and the lines its neighbour was placed beyond.
struct Corner {
  double inside[3], past[3], rise[2];
  uint32_t placed;
};

// S for the corners u of one neighbour along edge k's line (see Corner): e_k .
// (u - a_k) is s |e_k| from a_k, so a neighbour whose corners all have it <= 0 lies
// past a_k, one whose corners all have it >= |e_k|^2 past a_k+1. Only where the
// face's angles at both ends of edge k are at most 90 degrees does q project inside
// the edge, which the bound needs. Less `margin` (mm^2) for s's rounding, floor 0.
void PastEnds(const Lines& lines, const Eigen::Vector3d u[3], int k, double margin,
              double past[3]) {
  double s[3];
  bool before = lines.projects_inside[k], after = lines.projects_inside[k];
  for (int i = 0; i < 3; ++i) {
    s[i] = lines.e[k].dot(u[i] - lines.a[k]);
    before = before && s[i] <= 0;
    after = after && s[i] >= lines.len2[k];
  }
  for (int i = 0; i < 3; ++i)
    past[i] = std::max(0.0, (before ? -s[i] : after ? s[i] - lines.len2[k] : 0) - margin);
}

Corner MakeCorner(const Lines& lines, const Eigen::Vector3d& n, const Eigen::Vector3d& u,
                  uint32_t placed, const std::array<double, 3>& past) {
  Corner c;
  const Eigen::Vector3d up = u - lines.a[0];
  const double margin = kRound * (up.lpNorm<1>() + lines.longest);  // over the normal's rounding
  c.rise[0] = n.dot(up) + margin;
  c.rise[1] = -n.dot(up) + margin;
  for (int k = 0; k < 3; ++k) {
    c.inside[k] = placed >> k & 1u ? lines.Beyond(k, u) : 0;
    c.past[k] = past[k];
  }
  c.placed = placed;
  return c;
}

// The fit rise |e_k|^2 <= A + B T + C S over the corners placed beyond
// line k (`beyond`), for side +n and -n, all three >= 0: B from the
// corners well inside G_k and not past an end, C from those well past an
// end, then the least A. A alone makes the fit hold at every corner, so B
// and C only need to be good, not exact: the largest ratios are picked by
// cross-multiplying and divided once. A is fitted to B and C as stored (rounded
// up to float), so the fit also holds at corners with T < 0 (placed by a union).
void FitRise(const Corner* const* beyond, std::size_t count, int k, double len2, HintRise& out) {
  double slope_num[2] = {0, 0}, slope_den[2] = {1, 1};
  for (std::size_t i = 0; i < count; ++i) {
    const Corner& c = *beyond[i];
    if (c.past[k] != 0 || c.inside[k] < 0.1 * len2) continue;
    for (int side = 0; side < 2; ++side)
      if (c.rise[side] * slope_den[side] > slope_num[side] * c.inside[k]) {
        slope_num[side] = c.rise[side];
        slope_den[side] = c.inside[k];
      }
  }
  double slope[2], end_num[2] = {0, 0}, end_den[2] = {1, 1};
  for (int side = 0; side < 2; ++side)
    slope[side] = RoundUpToFloat(slope_num[side] * len2 / slope_den[side] * (1 + 1e-12));
  for (std::size_t i = 0; i < count; ++i) {
    const Corner& c = *beyond[i];
    if (c.past[k] < 0.1 * len2) continue;
    for (int side = 0; side < 2; ++side) {
      const double num = c.rise[side] * len2 - slope[side] * c.inside[k];
      if (num * end_den[side] > end_num[side] * c.past[k]) {
        end_num[side] = num;
        end_den[side] = c.past[k];
      }
    }
  }
  for (int side = 0; side < 2; ++side) {
    const double end = RoundUpToFloat(end_num[side] / end_den[side] * (1 + 1e-12));
    double base = 0;
    for (std::size_t i = 0; i < count; ++i) {
      const Corner& c = *beyond[i];
      base = std::max(base, c.rise[side] * len2 - slope[side] * c.inside[k] - end * c.past[k]);
    }
    out.base[side][k] = RoundUpToFloat(base * (1 + 1e-12));
    out.slope[side][k] = static_cast<float>(slope[side]);  // already a float
    out.end[side][k] = static_cast<float>(end);
  }
}

// The face's edge lines; `a` must outlive them.
Lines LinesOf(const Eigen::Vector3d a[3], const Eigen::Vector3d& n) {
  Lines lines;
  lines.a = a;
  for (int k = 0; k < 3; ++k) {
    lines.m[k] = OutwardEdge(a, k, n);
    lines.e[k] = a[(k + 1) % 3] - a[k];
    lines.len[k] = lines.e[k].norm();
    lines.len2[k] = lines.e[k].squaredNorm();
    const double apex = lines.e[k].dot(a[(k + 2) % 3] - a[k]);
    lines.projects_inside[k] = apex >= 0 && apex <= lines.len2[k];
    lines.longest = std::max(lines.longest, lines.len[k]);
    lines.coordinate = std::max(lines.coordinate, a[k].cwiseAbs().maxCoeff());
  }
  lines.eta = kWiden * lines.longest;
  return lines;
}

// The corners the fits run over, on the stack (a heap buffer per triangle cost a
// quarter of the certificates' build): at most two free per neighbour, two per line.
// Each is built in place: a copy's loads would wait on failed store forwards.
struct CornerSet {
  std::array<Corner, 2 * kMaxRiseRing + 6> items;
  std::size_t used = 0;
  uint32_t placed_any = 0;  // the lines some neighbour was placed beyond
};

// Places the ring triangle with corners u (shared as in PlaceNeighbour) and
// adds its free corners; false when it fits none of the cases.
bool AddNeighbour(const Lines& lines, const Eigen::Vector3d& n, const Eigen::Vector3d u[3],
                  const int shared[3], CornerSet& set) {
  const uint32_t placed = PlaceNeighbour(lines, u, shared);
  if (placed == 0) return false;
  double past[3][3] = {};  // [edge line][corner], only where placed
  for (int k = 0; k < 3; ++k)
    if (placed >> k & 1u)
      PastEnds(lines, u, k, kRound * (lines.coordinate + lines.longest) * lines.len[k], past[k]);
  // A shared corner is one of the face's corners on each line the
  // neighbour was placed beyond: those are fitted once, by ComputeHintRise.
  for (int i = 0; i < 3; ++i)
    if (shared[i] < 0)
      ::new (&set.items[set.used++])
          Corner(MakeCorner(lines, n, u[i], placed, {past[0][i], past[1][i], past[2][i]}));
  set.placed_any |= placed;
  return true;
}

}  // namespace

HintRise ComputeHintRise(const TriangleMesh& mesh, const std::vector<uint32_t>& weld, uint32_t t,
                         const Eigen::Vector3d& n, const uint32_t* ring, std::size_t ring_size) {
  HintRise out;
  const Triangle& tri = mesh.triangles[t];
  Eigen::Vector3d a[3];
  for (int k = 0; k < 3; ++k) a[k] = mesh.vertices[tri[k]].cast<double>();
  if (ClassifyTriangle(a[0], a[1], a[2]) != TriangleShape::kRegular) return out;
  if (ring_size > kMaxRiseRing) return out;
  const Lines lines = LinesOf(a, n);
  CornerSet set;
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
    if (!AddNeighbour(lines, n, u, shared, set)) return out;
  }
  for (int k = 0; k < 3; ++k)
    if (set.placed_any >> k & 1u)
      for (int j : {k, (k + 1) % 3})
        ::new (&set.items[set.used++]) Corner(MakeCorner(lines, n, a[j], 1u << k, {}));
  for (int k = 0; k < 3; ++k) {
    std::array<const Corner*, 2 * kMaxRiseRing + 6> beyond;
    std::size_t count = 0;
    for (std::size_t i = 0; i < set.used; ++i) {  // without a branch: the bits are irregular
      beyond[count] = &set.items[i];
      count += set.items[i].placed >> k & 1u;
    }
    FitRise(beyond.data(), count, k, lines.len2[k], out);
  }
  out.tol_mm = RoundUpToFloat(lines.eta + kRound * (lines.coordinate + lines.longest));
  out.longest_edge_mm = RoundUpToFloat(lines.longest);
  out.valid = std::isfinite(out.tol_mm) && std::isfinite(out.longest_edge_mm);
  return out;
}

bool RingIsFarther(const HintRise& rise, const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                   double d, const Eigen::Vector3d& n, const TriangleMesh& mesh, uint32_t t) {
  if (!rise.valid) return false;
  // Widened here: a caller's array of doubles, stored one coordinate at a time and
  // loaded here two at a time, stalls every load on a failed store forward.
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
    if (!(inside > 0)) return false;
    // g at its minimiser (t*, s* = d γ), times |e_k|^2; g falls as d
    // grows, so d_hi.
    const double base = rise.base[side][k], slope = rise.slope[side][k];
    const double end = d_hi * rise.end[side][k];
    const double t = std::max(0.0, d_hi * slope - inside);
    const double reach = inside + t;
    if (!(reach * reach - 2 * d_hi * (base + slope * t) - end * end > gap)) return false;
  }
  return true;
}

}  // namespace surfinspect
