#include "core/simulation/pillar.h"

#include <algorithm>
#include <cmath>

namespace surfinspect {
namespace {

using Vec2 = Eigen::Vector2d;  // (y, z) in the pillar's cross-section

// Pillar cross-section: a hat channel. Top ridge half-width, height, wall
// angle, flange width and bend radius, all mm; the numbers are those of a
// typical stamped B-pillar reinforcement.
constexpr double kTopHalfWidth = 30, kHeight = 60, kWallDeg = 75, kFlange = 30, kBendRadius = 6;
constexpr int kBendSegments = 8;
constexpr double kStepAlongMm = 5;     // extrusion step
constexpr double kBowSagMm = 3;        // the ridge sags 3 mm towards the ends
constexpr int kHolePoints = 96;        // vertices on a hole's edge
constexpr double kTileMarginMm = 1.5;  // least sheet between a hole and its tile's side

// Rounds the corners of a polyline with circular arcs of radius r.
std::vector<Vec2> FilletPolyline(const std::vector<Vec2>& sharp, double r, int segments) {
  std::vector<Vec2> out{sharp.front()};
  for (std::size_t i = 1; i + 1 < sharp.size(); ++i) {
    const Vec2 c = sharp[i];
    const Vec2 u1 = (c - sharp[i - 1]).normalized(), u2 = (sharp[i + 1] - c).normalized();
    const double cross = u1.x() * u2.y() - u1.y() * u2.x();
    const double theta = std::acos(std::clamp(u1.dot(u2), -1.0, 1.0));  // turning angle
    const double d = r * std::tan(theta / 2);
    const Vec2 start = c - d * u1;
    const Vec2 left(-u1.y(), u1.x());
    const Vec2 centre = start + (cross > 0 ? r : -r) * left;
    const double signed_theta = cross > 0 ? theta : -theta;
    for (int k = 0; k <= segments; ++k) {
      const double a = signed_theta * k / segments;
      const Vec2 v = start - centre;
      out.push_back(centre + Vec2(std::cos(a) * v.x() - std::sin(a) * v.y(),
                                  std::sin(a) * v.x() + std::cos(a) * v.y()));
    }
  }
  out.push_back(sharp.back());
  return out;
}

std::vector<Vec2> PillarProfile() {
  const double run = kHeight / std::tan(kWallDeg * M_PI / 180);
  const double a = kTopHalfWidth;
  const std::vector<Vec2> sharp = {
      {-(a + run + kFlange), 0}, {-(a + run), 0}, {-a, kHeight}, {a, kHeight}, {a + run, 0},
      {a + run + kFlange, 0}};
  return FilletPolyline(sharp, kBendRadius, kBendSegments);
}

// Where a hole sits in the grid: profile segment `seg` (flat), steps
// [j0, j1) along x.
struct Tile {
  uint32_t seg = 0, j0 = 0, j1 = 0;
};

bool PlaceTile(const PillarHole& h, const std::vector<Vec2>& profile, const std::vector<double>& xs,
               Tile* tile) {
  const double half_x = 0.5 * std::max(h.length_mm, h.diameter_mm) + kTileMarginMm;
  const double half_y = 0.5 * h.diameter_mm + kTileMarginMm;
  for (uint32_t i = 0; i + 1 < profile.size(); ++i) {
    const Vec2 &a = profile[i], &b = profile[i + 1];
    if (std::abs(a.y() - b.y()) > 1e-9 || h.y_mm - half_y < a.x() || h.y_mm + half_y > b.x())
      continue;
    tile->seg = i;
    const auto first = std::upper_bound(xs.begin(), xs.end(), h.x_mm - half_x);
    const auto last = std::lower_bound(xs.begin(), xs.end(), h.x_mm + half_x);
    if (first == xs.begin() || last == xs.end()) return false;
    tile->j0 = uint32_t(first - xs.begin()) - 1;
    tile->j1 = uint32_t(last - xs.begin());
    return true;
  }
  return false;
}

// The hole's edge, CCW about +z, on the sagging face of height z0.
// The hole's edge, CCW about +z, on the sagging face of height z0: a 96-gon,
// or for a slot its two halves joined by straight sides (the vertices at
// 90 and 270 degrees appear at both ends).
std::vector<Eigen::Vector3d> HoleEdge(const PillarHole& h, double z0, double length) {
  std::vector<Eigen::Vector3d> edge;
  const double r = 0.5 * h.diameter_mm, half = std::max(0.5 * h.length_mm - r, 0.0);
  auto add = [&](double a, double shift) {
    const double x = h.x_mm + r * std::cos(a) + shift;
    edge.emplace_back(x, h.y_mm + r * std::sin(a), z0 - (kHeight - PillarRidgeZ(x, length)));
  };
  for (int k = 0; k < kHolePoints; ++k) {
    const double a = 2 * M_PI * k / kHolePoints;
    if (half > 0 && k * 4 == kHolePoints) {  // 90 degrees: right end, then left
      add(a, half);
      add(a, -half);
    } else if (half > 0 && k * 4 == 3 * kHolePoints) {  // 270 degrees: left end, then right
      add(a, -half);
      add(a, half);
    } else {
      add(a, k * 4 < kHolePoints || k * 4 > 3 * kHolePoints ? half : -half);
    }
  }
  return edge;
}

// Triangulates the ring between the tile's outline (vertex ids, CCW about
// +z) and the hole's edge (ids, CCW) by ear clipping (Eberly,
// "Triangulation by ear clipping", Geometric Tools 2002): a bridge from the
// outline's first vertex to the nearest edge vertex makes one simple
// polygon, whose convex corners with no other vertex inside are cut off one
// by one. Walking both loops in step (by angle, or by the shorter diagonal)
// folds triangles where a long tile side cannot see the far side of a slot;
// ear clipping cannot (the lister's test checks the areas).
void StitchRing(TriangleMesh& m, const std::vector<uint32_t>& outer,
                const std::vector<uint32_t>& inner) {
  auto xy = [&](uint32_t v) { return Eigen::Vector2d(m.vertices[v].x(), m.vertices[v].y()); };
  auto cross = [&](uint32_t a, uint32_t b, uint32_t c) {
    const Eigen::Vector2d u = xy(b) - xy(a), v = xy(c) - xy(a);
    return u.x() * v.y() - u.y() * v.x();
  };
  std::size_t first = 0;
  for (std::size_t k = 1; k < inner.size(); ++k)
    if ((xy(inner[k]) - xy(outer[0])).squaredNorm() <
        (xy(inner[first]) - xy(outer[0])).squaredNorm())
      first = k;
  std::vector<uint32_t> poly(outer.begin(), outer.end());
  poly.push_back(outer[0]);
  for (std::size_t k = 0; k <= inner.size(); ++k)  // the hole clockwise, back to the bridge
    poly.push_back(inner[(first + inner.size() - k % inner.size()) % inner.size()]);
  while (poly.size() > 3) {
    const std::size_t n = poly.size();
    std::size_t ear = n;
    for (std::size_t i = 0; i < n && ear == n; ++i) {
      const uint32_t a = poly[(i + n - 1) % n], b = poly[i], c = poly[(i + 1) % n];
      if (!(cross(a, b, c) > 1e-12)) continue;
      bool empty = true;
      for (std::size_t j = 0; j < n && empty; ++j) {
        const uint32_t p = poly[j];
        if (p == a || p == b || p == c) continue;
        empty = !(cross(a, b, p) >= 0 && cross(b, c, p) >= 0 && cross(c, a, p) >= 0);
      }
      if (empty) ear = i;
    }
    if (ear == n) return;  // degenerate input: leave the rest open (the test would see it)
    m.triangles.push_back({poly[(ear + n - 1) % n], poly[ear], poly[(ear + 1) % n]});
    poly.erase(poly.begin() + long(ear));
  }
  m.triangles.push_back({poly[0], poly[1], poly[2]});
}

void CutHole(TriangleMesh& m, const PillarHole& h, const Tile& t, uint32_t np, double z0,
             double length, double wall_depth) {
  std::vector<uint32_t> outer;  // CCW about +z: low y side along +x, then back at high y
  for (uint32_t j = t.j0; j <= t.j1; ++j) outer.push_back(j * np + t.seg);
  for (uint32_t j = t.j1 + 1; j-- > t.j0;) outer.push_back(j * np + t.seg + 1);
  std::vector<uint32_t> inner;
  for (const Eigen::Vector3d& p : HoleEdge(h, z0, length)) {
    inner.push_back(uint32_t(m.vertices.size()));
    m.vertices.push_back(p.cast<float>());
  }
  StitchRing(m, outer, inner);
  if (!(wall_depth > 0)) return;
  // The wall runs along the face's normal at the hole, as a punch cuts it.
  const double u = h.x_mm / (0.5 * length), slope = -2 * kBowSagMm * u / (0.5 * length);
  const Eigen::Vector3f down =
      Eigen::Vector3d(-slope, 0, 1).normalized().cast<float>() * wall_depth;
  const auto base = uint32_t(m.vertices.size());
  for (uint32_t v : inner) m.vertices.push_back(m.vertices[v] - down);
  for (uint32_t k = 0; k < inner.size(); ++k) {  // facing the hole's axis: out of the material
    const uint32_t a = inner[k], b = inner[(k + 1) % inner.size()];
    const uint32_t a2 = base + k, b2 = base + (k + 1) % uint32_t(inner.size());
    m.triangles.push_back({a, b, a2});
    m.triangles.push_back({b, b2, a2});
  }
}

}  // namespace

double PillarRidgeZ(double x, double length) {
  const double u = x / (0.5 * length);
  return kHeight - kBowSagMm * u * u;
}

TriangleMesh MakePillarMesh(double length_mm, const PillarFeatures& features) {
  const std::vector<Vec2> profile = PillarProfile();
  const int along = std::max(1, static_cast<int>(std::lround(length_mm / kStepAlongMm)));
  const auto np = static_cast<uint32_t>(profile.size());
  std::vector<double> xs;
  for (int j = 0; j <= along; ++j) xs.push_back(-0.5 * length_mm + length_mm * j / along);
  xs.back() += features.trim_offset_mm;
  TriangleMesh m;
  for (double x : xs) {
    const double sag = kHeight - PillarRidgeZ(x, length_mm);
    for (const Vec2& p : profile) m.vertices.emplace_back(x, p.x(), p.y() - sag);
  }
  std::vector<Tile> tiles(features.holes.size());
  std::vector<uint8_t> placed(features.holes.size()), cut(std::size_t(along) * np, 0);
  for (std::size_t h = 0; h < features.holes.size(); ++h) {
    placed[h] = PlaceTile(features.holes[h], profile, xs, &tiles[h]);
    for (uint32_t j = tiles[h].j0; placed[h] && j < tiles[h].j1; ++j)
      placed[h] &= !cut[j * np + tiles[h].seg];
    for (uint32_t j = tiles[h].j0; placed[h] && j < tiles[h].j1; ++j)
      cut[j * np + tiles[h].seg] = 1;
  }
  // (x step) x (profile tangent) points out of the material: +z on the ridge.
  for (uint32_t j = 0; j < static_cast<uint32_t>(along); ++j)
    for (uint32_t i = 0; i + 1 < np; ++i) {
      if (cut[j * np + i]) continue;
      const uint32_t v00 = j * np + i, v01 = (j + 1) * np + i, v10 = j * np + i + 1,
                     v11 = (j + 1) * np + i + 1;
      m.triangles.push_back({v00, v01, v10});
      m.triangles.push_back({v10, v01, v11});
    }
  for (std::size_t h = 0; h < features.holes.size(); ++h)
    if (placed[h])
      CutHole(m, features.holes[h], tiles[h], np, profile[tiles[h].seg].y(), length_mm,
              features.wall_depth_mm);
  return m;
}

PillarFeatures DemoPillarFeatures() {
  PillarFeatures f;
  f.holes = {{-110, 0, 8, 0}, {-20, -12, 5, 0},   {35, 10, 10, 0},
             {95, -8, 6, 14}, {-45, -63.4, 6, 0}, {75, 63.4, 12, 0}};
  return f;
}

}  // namespace surfinspect
