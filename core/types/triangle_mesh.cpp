#include "core/types/triangle_mesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace surfinspect {
namespace {

Eigen::Vector3d V(const TriangleMesh& m, uint32_t i) { return m.vertices[i].cast<double>(); }

}  // namespace

std::vector<Eigen::Vector3f> TriangleMesh::FaceNormals() const {
  std::vector<Eigen::Vector3f> normals(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    const Eigen::Vector3d n =
        (V(*this, tri[1]) - V(*this, tri[0])).cross(V(*this, tri[2]) - V(*this, tri[0]));
    const double len = n.norm();
    normals[t] = len > 0 ? Eigen::Vector3f((n / len).cast<float>()) : Eigen::Vector3f::Zero();
  }
  return normals;
}

bool TriangleMesh::IsDegenerate(std::size_t t) const {
  const auto& tri = triangles[t];
  const Eigen::Vector3d a = V(*this, tri[0]), b = V(*this, tri[1]), c = V(*this, tri[2]);
  const double longest2 =
      std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  const double twice_area = (b - a).cross(c - a).norm();
  return longest2 == 0 || twice_area <= 1e-12 * longest2;
}

std::size_t TriangleMesh::CountDegenerate() const {
  std::size_t n = 0;
  for (std::size_t t = 0; t < triangles.size(); ++t) n += IsDegenerate(t) ? 1 : 0;
  return n;
}

absl::Status TriangleMesh::Validate() const {
  if (triangles.empty()) return absl::InvalidArgumentError("mesh: no triangles");
  for (std::size_t i = 0; i < vertices.size(); ++i)
    if (!vertices[i].allFinite())
      return absl::InvalidArgumentError(
          absl::StrCat("mesh: vertex ", i, " is not finite (NaN or inf)"));
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (uint32_t v : triangles[t])
      if (v >= vertices.size())
        return absl::InvalidArgumentError(absl::StrCat("mesh: triangle ", t, " refers to vertex ",
                                                       v, " but there are only ", vertices.size()));
  // One triangle with an area is enough; a count would classify them all.
  bool any_regular = false;
  for (std::size_t t = 0; t < triangles.size() && !any_regular; ++t) any_regular = !IsDegenerate(t);
  if (!any_regular)
    return absl::InvalidArgumentError(
        absl::StrCat("mesh: all ", triangles.size(), " triangles are degenerate"));
  return absl::OkStatus();
}

std::vector<EdgeUse> SortedEdgeUses(const TriangleMesh& mesh) {
  std::vector<EdgeUse> edges;
  edges.reserve(mesh.triangles.size() * 3);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      uint32_t a = mesh.triangles[t][k], b = mesh.triangles[t][(k + 1) % 3];
      if (a > b) std::swap(a, b);
      edges.push_back({(uint64_t{a} << 32) | b, static_cast<uint32_t>(t)});
    }
  std::sort(edges.begin(), edges.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return x.edge != y.edge ? x.edge < y.edge : x.triangle < y.triangle;
  });
  return edges;
}

MeshTopology AnalyzeTopology(const TriangleMesh& mesh) {
  // Count the runs of equal edges.
  const std::vector<EdgeUse> edges = SortedEdgeUses(mesh);
  MeshTopology topo;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].edge == edges[i].edge) ++j;
    const std::size_t uses = j - i;
    if (uses == 1) ++topo.boundary_edges;
    if (uses >= 3) ++topo.nonmanifold_edges;
    i = j;
  }
  return topo;
}

Bounds3 ComputeBounds(const TriangleMesh& mesh) {
  Bounds3 b;
  for (const auto& v : mesh.vertices) b.Extend(v.cast<double>());
  return b;
}

}  // namespace surfinspect
