#include "tests/support/test_meshes.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>

namespace surfinspect::testing {

TriangleMesh Icosphere(double radius, int subdivisions) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                    {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                    {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<Triangle> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                             {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                             {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                             {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& p : v) p.normalize();
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      return mid[key] = static_cast<uint32_t>(v.size() - 1);
    };
    std::vector<Triangle> next;
    for (const auto& tri : f) {
      const uint32_t ab = midpoint(tri[0], tri[1]), bc = midpoint(tri[1], tri[2]),
                     ca = midpoint(tri[2], tri[0]);
      next.insert(next.end(), {{tri[0], ab, ca}, {tri[1], bc, ab}, {tri[2], ca, bc}, {ab, bc, ca}});
    }
    f = std::move(next);
  }
  TriangleMesh m;
  for (const auto& p : v) m.vertices.push_back((p * radius).cast<float>());
  m.triangles = f;
  return m;
}

TriangleMesh Torus(double major_radius, double minor_radius, int major_segments,
                   int minor_segments) {
  TriangleMesh m;
  for (int i = 0; i < major_segments; ++i)
    for (int j = 0; j < minor_segments; ++j) {
      const double u = 2 * M_PI * i / major_segments, w = 2 * M_PI * j / minor_segments;
      const double r = major_radius + minor_radius * std::cos(w);
      m.vertices.emplace_back(r * std::cos(u), r * std::sin(u), minor_radius * std::sin(w));
    }
  auto id = [&](int i, int j) {
    return static_cast<uint32_t>((i % major_segments) * minor_segments + (j % minor_segments));
  };
  for (int i = 0; i < major_segments; ++i)
    for (int j = 0; j < minor_segments; ++j) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

TriangleMesh Box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(),
                            i & 4 ? hi.z() : lo.z());
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

TriangleMesh HeightField(double x0, double x1, double y0, double y1, int nx, int ny,
                         const std::function<double(double, double)>& f) {
  TriangleMesh m;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double x = x0 + (x1 - x0) * i / (nx - 1), y = y0 + (y1 - y0) * j / (ny - 1);
      m.vertices.emplace_back(x, y, f(x, y));
    }
  auto id = [&](int i, int j) { return static_cast<uint32_t>(j * nx + i); };
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

double WindingNumber(const TriangleMesh& mesh, const Eigen::Vector3d& p) {
  double sum = 0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>() - p,
                          b = mesh.vertices[t[1]].cast<double>() - p,
                          c = mesh.vertices[t[2]].cast<double>() - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    sum += 2 * std::atan2(a.dot(b.cross(c)),
                          la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la);
  }
  return sum / (4 * M_PI);
}

double DistanceByProjection(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  auto segment = [&](const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
    const double len2 = (v - u).squaredNorm();
    const double t = len2 > 0 ? std::clamp((p - u).dot(v - u) / len2, 0.0, 1.0) : 0.0;
    return (p - (u + t * (v - u))).norm();
  };
  double best = std::min({segment(a, b), segment(b, c), segment(c, a)});
  const Eigen::Vector3d n = (b - a).cross(c - a);
  if (n.squaredNorm() == 0) return best;
  const Eigen::Vector3d q = p - n * ((p - a).dot(n) / n.squaredNorm());
  if ((b - q).cross(c - q).dot(n) >= 0 && (c - q).cross(a - q).dot(n) >= 0 &&
      (a - q).cross(b - q).dot(n) >= 0)
    best = std::min(best, (p - q).norm());
  return best;
}

double MeshHeightAt(const TriangleMesh& mesh, double x, double y) {
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>(),
                          b = mesh.vertices[t[1]].cast<double>(),
                          c = mesh.vertices[t[2]].cast<double>();
    const double det = (b.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (b.y() - a.y());
    if (det == 0) continue;
    const double s = ((x - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (y - a.y())) / det;
    const double r = ((b.x() - a.x()) * (y - a.y()) - (x - a.x()) * (b.y() - a.y())) / det;
    if (s >= -1e-12 && r >= -1e-12 && s + r <= 1 + 1e-12)
      return a.z() + s * (b.z() - a.z()) + r * (c.z() - a.z());
  }
  return NAN;
}

TriangleMesh FlatSquare() {
  return HeightField(0, 100, 0, 100, 11, 11, [](double, double) { return 0.0; });
}

std::unique_ptr<MeshIndex> IndexOf(const TriangleMesh& mesh) {
  auto index = MeshIndex::Build(mesh);
  EXPECT_TRUE(index.ok()) << index.status();
  return index.ok() ? *std::move(index) : nullptr;
}

}  // namespace surfinspect::testing
