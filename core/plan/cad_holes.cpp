#include "core/plan/cad_holes.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>

#include "core/plan/profile_fit.h"

namespace surfinspect {
namespace {

// The runs of one in SortedEdgeUses' list: the edges used by one triangle.
std::vector<EdgeUse> UsedOnce(const std::vector<EdgeUse>& uses) {
  std::vector<EdgeUse> out;
  for (std::size_t i = 0; i < uses.size(); ++i)
    if ((i == 0 || uses[i - 1].edge != uses[i].edge) &&
        (i + 1 == uses.size() || uses[i + 1].edge != uses[i].edge))
      out.push_back(uses[i]);
  return out;
}

// Boundary edges directed as their one triangle walks them, chained into
// closed loops of vertex ids (a loop that does not close is dropped).
// `uses` is SortedEdgeUses(mesh).
std::vector<std::vector<uint32_t>> BoundaryLoops(const TriangleMesh& mesh,
                                                 const std::vector<EdgeUse>& uses) {
  std::multimap<uint32_t, uint32_t> next;  // from -> to
  for (const EdgeUse& use : UsedOnce(uses)) {
    const Triangle& t = mesh.triangles[use.triangle];
    const auto lo = static_cast<uint32_t>(use.edge >> 32);
    const auto hi = static_cast<uint32_t>(use.edge);
    for (int k = 0; k < 3; ++k)
      if ((t[k] == lo && t[(k + 1) % 3] == hi) || (t[k] == hi && t[(k + 1) % 3] == lo))
        next.emplace(t[k], t[(k + 1) % 3]);
  }
  std::vector<std::vector<uint32_t>> loops;
  while (!next.empty()) {
    const uint32_t first = next.begin()->first;
    std::vector<uint32_t> loop{first};
    uint32_t at = first;
    bool closed = false;
    while (true) {
      const auto it = next.find(at);
      if (it == next.end()) break;
      at = it->second;
      next.erase(it);
      if (at == first) {
        closed = true;
        break;
      }
      loop.push_back(at);
    }
    if (closed && loop.size() >= 3) loops.push_back(std::move(loop));
  }
  return loops;
}

// A solid's hole rim: edges where two triangles meet at more than
// kRimAngleDeg (the face meets the hole's cylinder wall at ~90 degrees; the
// wall's own facets meet at 360/N degrees, far less at any sensible
// tessellation), chained into closed loops through vertices on exactly two
// such edges (a vertex where more meet, a box's corner, ends no hole rim).
constexpr double kRimAngleDeg = 60;

std::vector<std::vector<uint32_t>> RimLoops(const TriangleMesh& mesh,
                                            const std::vector<EdgeUse>& uses) {
  const std::vector<Eigen::Vector3f> normals = mesh.FaceNormals();
  const float cos_max = static_cast<float>(std::cos(kRimAngleDeg * M_PI / 180));
  std::map<uint32_t, std::vector<uint32_t>> sharp;  // vertex -> its sharp edges' other ends
  for (std::size_t i = 0; i + 1 < uses.size(); ++i) {
    const bool pair = uses[i].edge == uses[i + 1].edge &&
                      (i == 0 || uses[i - 1].edge != uses[i].edge) &&
                      (i + 2 == uses.size() || uses[i + 2].edge != uses[i].edge);
    if (!pair || !(normals[uses[i].triangle].dot(normals[uses[i + 1].triangle]) < cos_max))
      continue;
    const auto lo = static_cast<uint32_t>(uses[i].edge >> 32);
    const auto hi = static_cast<uint32_t>(uses[i].edge);
    sharp[lo].push_back(hi);
    sharp[hi].push_back(lo);
  }
  std::vector<std::vector<uint32_t>> loops;
  std::set<uint32_t> seen;
  for (const auto& [first, ends] : sharp) {
    if (ends.size() != 2 || !seen.insert(first).second) continue;
    std::vector<uint32_t> loop{first};
    uint32_t prev = first, at = ends[0];
    while (at != first) {
      const auto it = sharp.find(at);
      if (it->second.size() != 2 || !seen.insert(at).second) break;
      loop.push_back(at);
      const uint32_t next = it->second[0] == prev ? it->second[1] : it->second[0];
      prev = at, at = next;
    }
    if (at == first && loop.size() >= 3) loops.push_back(std::move(loop));
  }
  return loops;
}

// Whether the wall below each rim loop faces its hole's axis (a hole)
// rather than away from it (a boss): over the triangles at the loop's
// vertices that stand across the axis, their normals' radial parts. One
// pass over the mesh for every loop (a vertex is on at most one rim loop).
std::vector<bool> WallsFaceAxes(const TriangleMesh& mesh,
                                const std::vector<std::vector<uint32_t>>& loops,
                                const std::vector<CadHole>& holes) {
  std::map<uint32_t, std::size_t> loop_of;  // vertex -> its loop
  for (std::size_t k = 0; k < loops.size(); ++k)
    for (uint32_t v : loops[k]) loop_of.emplace(v, k);
  std::vector<double> inward(loops.size(), 0);
  for (const Triangle& t : mesh.triangles) {
    std::set<std::size_t> touched;  // the loops this triangle has a vertex on
    for (uint32_t v : t)
      if (const auto it = loop_of.find(v); it != loop_of.end()) touched.insert(it->second);
    if (touched.empty()) continue;
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>(),
                          b = mesh.vertices[t[1]].cast<double>(),
                          c = mesh.vertices[t[2]].cast<double>();
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
    for (std::size_t k : touched) {
      const CadHole& hole = holes[k];
      if (!n.allFinite() || std::abs(n.dot(hole.axis)) > 0.5) continue;  // the face, not the wall
      Eigen::Vector3d radial = (a + b + c) / 3 - hole.position_mm;
      radial -= radial.dot(hole.axis) * hole.axis;
      inward[k] -= n.dot(radial.normalized());
    }
  }
  std::vector<bool> out;
  for (double w : inward) out.push_back(w > 0);
  return out;
}

// Per vertex, the sum of its triangles' area-weighted normals: over a
// loop's vertices, the side the hole's face looks to.
std::vector<Eigen::Vector3d> VertexSides(const TriangleMesh& mesh) {
  std::vector<Eigen::Vector3d> side(mesh.vertices.size(), Eigen::Vector3d::Zero());
  for (const Triangle& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>(),
                          b = mesh.vertices[t[1]].cast<double>(),
                          c = mesh.vertices[t[2]].cast<double>();
    const Eigen::Vector3d n = (b - a).cross(c - a);
    for (uint32_t v : t) side[v] += n;
  }
  return side;
}

std::optional<CadHole> HoleOfLoop(const TriangleMesh& mesh,
                                  const std::vector<Eigen::Vector3d>& sides,
                                  const std::vector<uint32_t>& loop, const CadHoleSettings& s) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (uint32_t v : loop) mean += mesh.vertices[v].cast<double>();
  mean /= double(loop.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (uint32_t v : loop) {
    const Eigen::Vector3d d = mesh.vertices[v].cast<double>() - mean;
    cov += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  Eigen::Vector3d axis = eig.eigenvectors().col(0);
  Eigen::Vector3d side = Eigen::Vector3d::Zero();
  for (uint32_t v : loop) side += sides[v];
  if (axis.dot(side) < 0) axis = -axis;
  const PlaneFrame frame = MakePlaneFrame(mean, axis, eig.eigenvectors().col(2));
  std::vector<Eigen::Vector2d> pts;
  double lo = INFINITY, hi = -INFINITY, size = 0;
  for (uint32_t v : loop) {
    const Eigen::Vector3d p = mesh.vertices[v].cast<double>();
    pts.push_back(frame.To2d(p));
    lo = std::min(lo, (p - mean).dot(axis));
    hi = std::max(hi, (p - mean).dot(axis));
    size = std::max(size, 2 * pts.back().norm());
  }
  if (!(size > 0) || size > s.max_size_mm || hi - lo > s.max_flatness_ratio * size)
    return std::nullopt;
  CadHole hole;
  hole.axis = axis;
  hole.flatness_mm = hi - lo;
  hole.vertices = loop.size();
  auto fit = FitCircle2d(pts);
  if (!fit.ok() || fit->inliers < pts.size() || fit->form > s.max_form_ratio * fit->diameter()) {
    ProfileFit start;  // the principal axes: e1 along the longest extent
    double umax = 0, vmax = 0;
    for (const auto& q : pts)
      umax = std::max(umax, std::abs(q.x())), vmax = std::max(vmax, std::abs(q.y()));
    start.radius = vmax;
    start.half_length = std::max(umax - vmax, 0.0);
    fit = FitSlot2d(pts, start);
    if (!fit.ok() || fit->inliers < pts.size() || fit->form > s.max_form_ratio * fit->diameter())
      return std::nullopt;
    hole.slot = true;
    hole.length_mm = fit->length();
    hole.direction = (fit->direction.x() * frame.e1 + fit->direction.y() * frame.e2).normalized();
  }
  hole.position_mm = frame.To3d(fit->centre);
  hole.diameter_mm = fit->diameter();
  hole.form_mm = fit->form;
  return hole;
}

}  // namespace

PlaneFrame MakePlaneFrame(const Eigen::Vector3d& origin, const Eigen::Vector3d& axis,
                          const Eigen::Vector3d& along) {
  PlaneFrame f;
  f.origin = origin;
  f.axis = axis.normalized();
  Eigen::Vector3d e1 = along - along.dot(f.axis) * f.axis;
  if (!(e1.norm() > 1e-6 * std::max(along.norm(), 1e-300))) {
    Eigen::Index least = 0;
    f.axis.cwiseAbs().minCoeff(&least);
    const Eigen::Vector3d w = Eigen::Vector3d::Unit(least);
    e1 = w - w.dot(f.axis) * f.axis;
  }
  f.e1 = e1.normalized();
  f.e2 = f.axis.cross(f.e1);
  return f;
}

std::vector<CadHole> ListHoles(const TriangleMesh& mesh, const CadHoleSettings& settings) {
  std::vector<CadHole> holes;
  const std::vector<EdgeUse> uses = SortedEdgeUses(mesh);  // once, for both kinds of loop
  const auto loops = BoundaryLoops(mesh, uses);
  const auto rims = RimLoops(mesh, uses);
  if (loops.empty() && rims.empty()) return holes;
  const std::vector<Eigen::Vector3d> sides = VertexSides(mesh);
  for (const auto& loop : loops)
    if (auto hole = HoleOfLoop(mesh, sides, loop, settings)) holes.push_back(*hole);
  std::vector<std::vector<uint32_t>> round;  // the rim loops that fit a circle or a slot
  std::vector<CadHole> candidates;
  for (const auto& loop : rims)
    if (auto hole = HoleOfLoop(mesh, sides, loop, settings)) {
      hole->rim = true;
      round.push_back(loop);
      candidates.push_back(*hole);
    }
  const std::vector<bool> hole_not_boss = WallsFaceAxes(mesh, round, candidates);
  for (std::size_t k = 0; k < candidates.size(); ++k)
    if (hole_not_boss[k]) holes.push_back(candidates[k]);
  std::sort(holes.begin(), holes.end(), [](const CadHole& a, const CadHole& b) {
    return std::lexicographical_compare(a.position_mm.data(), a.position_mm.data() + 3,
                                        b.position_mm.data(), b.position_mm.data() + 3);
  });
  return holes;
}

std::vector<EdgeUse> BoundaryEdges(const TriangleMesh& mesh) {
  return UsedOnce(SortedEdgeUses(mesh));
}

std::optional<CadEdge> NearestBoundaryEdge(const TriangleMesh& mesh, const Eigen::Vector3d& p) {
  std::optional<CadEdge> best;
  for (const EdgeUse& use : BoundaryEdges(mesh)) {
    const Triangle& t = mesh.triangles[use.triangle];
    const auto lo = static_cast<uint32_t>(use.edge >> 32);
    const auto hi = static_cast<uint32_t>(use.edge);
    const Eigen::Vector3d a = mesh.vertices[lo].cast<double>(),
                          b = mesh.vertices[hi].cast<double>();
    const double len2 = (b - a).squaredNorm();
    if (!(len2 > 0)) continue;
    const double u = std::clamp((p - a).dot(b - a) / len2, 0.0, 1.0);
    const Eigen::Vector3d on = a + u * (b - a);
    if (best && (p - on).norm() >= best->distance_mm) continue;
    const uint32_t third = t[0] != lo && t[0] != hi ? t[0] : t[1] != lo && t[1] != hi ? t[1] : t[2];
    const Eigen::Vector3d c = mesh.vertices[third].cast<double>();
    CadEdge e;
    e.point_mm = on;
    e.tangent = (b - a).normalized();
    e.normal = (mesh.vertices[t[1]].cast<double>() - mesh.vertices[t[0]].cast<double>())
                   .cross(mesh.vertices[t[2]].cast<double>() - mesh.vertices[t[0]].cast<double>())
                   .normalized();
    e.outward = e.tangent.cross(e.normal);
    if (e.outward.dot(c - a) > 0) e.outward = -e.outward;
    e.distance_mm = (p - on).norm();
    if (e.normal.allFinite()) best = e;
  }
  return best;
}

}  // namespace surfinspect
