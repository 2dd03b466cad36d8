#include "core/distance/mesh_order.h"

#include <numeric>

#include "core/distance/morton_order.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

MeshOrder OrderMesh(const TriangleMesh& mesh) {
  const std::size_t n = mesh.triangles.size();
  std::vector<Eigen::Vector3f> centroids(n);
  for (std::size_t t = 0; t < n; ++t) {
    const Triangle& tri = mesh.triangles[t];
    centroids[t] = (mesh.vertices[tri[0]] + mesh.vertices[tri[1]] + mesh.vertices[tri[2]]) / 3;
  }
  // Without a cancel flag the order is never empty. A centroid beyond float
  // range only sorts last.
  const DefaultInitVector<uint64_t> keys =
      MortonOrder(PointCloud::Unorganized(std::move(centroids)), nullptr);

  MeshOrder out;
  out.mesh_triangle.resize(n);
  out.position_of_triangle.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto t = static_cast<uint32_t>(keys[i]);
    out.mesh_triangle[i] = t;
    out.position_of_triangle[t] = static_cast<uint32_t>(i);
  }
  const std::size_t vertices = mesh.vertices.size();
  out.position_of_vertex.assign(vertices, UINT32_MAX);
  out.ordered.vertices.reserve(vertices);
  out.ordered.triangles.resize(n);
  auto place = [&](uint32_t v) {
    if (out.position_of_vertex[v] == UINT32_MAX) {
      out.position_of_vertex[v] = static_cast<uint32_t>(out.ordered.vertices.size());
      out.ordered.vertices.push_back(mesh.vertices[v]);
    }
    return out.position_of_vertex[v];
  };
  for (std::size_t i = 0; i < n; ++i) {
    const Triangle& tri = mesh.triangles[out.mesh_triangle[i]];
    out.ordered.triangles[i] = {place(tri[0]), place(tri[1]), place(tri[2])};
  }
  for (uint32_t v = 0; v < vertices; ++v) place(v);
  return out;
}

MeshOrder KeepOrder(const TriangleMesh& mesh) {
  MeshOrder out;
  out.mesh_triangle.resize(mesh.triangles.size());
  std::iota(out.mesh_triangle.begin(), out.mesh_triangle.end(), 0u);
  out.position_of_triangle = out.mesh_triangle;
  out.position_of_vertex.resize(mesh.vertices.size());
  std::iota(out.position_of_vertex.begin(), out.position_of_vertex.end(), 0u);
  out.ordered = mesh;
  out.identity = true;
  return out;
}

}  // namespace surfinspect
