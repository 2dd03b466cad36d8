// surfinspect info FILE: what a cloud or mesh file holds.
#include <cstdio>

#include "absl/strings/ascii.h"
#include "client/cli/commands.h"
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"
#include "core/io/pcd_format.h"

namespace surfinspect::cli {
namespace {

void PrintBounds(const Bounds3& b) {
  if (b.empty()) {
    std::printf("bounds: (no valid points)\n");
    return;
  }
  std::printf("bounds min: %.4f %.4f %.4f mm\n", b.min.x(), b.min.y(), b.min.z());
  std::printf("bounds max: %.4f %.4f %.4f mm\n", b.max.x(), b.max.y(), b.max.z());
}

void PrintCloud(const std::string& path, const PointCloud& cloud) {
  std::printf("file: %s\ntype: point cloud\npoints: %zu\nvalid: %zu\n", path.c_str(), cloud.size(),
              cloud.CountValid());
  if (cloud.organized())
    std::printf("organized: yes (%u x %u)\n", cloud.width, cloud.height);
  else
    std::printf("organized: no\n");
  PrintBounds(ComputeBounds(cloud));
}

void Info(const std::string& path) {
  const auto dot = path.rfind('.');
  const std::string ext =
      dot == std::string::npos ? "" : absl::AsciiStrToLower(path.substr(dot + 1));
  if (ext == "pcd") {
    PrintCloud(path, Take(ReadPointCloud(path)));
    if (const PcdHeader header = Take(ReadPcdHeader(path)); header.viewpoint) {
      const PcdViewpoint& v = *header.viewpoint;
      std::printf(
          "viewpoint: translation %.9g %.9g %.9g, rotation (w x y z) %.9g %.9g %.9g %.9g "
          "(not applied to the points)\n",
          v.tx, v.ty, v.tz, v.qw, v.qx, v.qy, v.qz);
    }
    return;
  }
  // PLY may be a mesh or a cloud: a file with faces is a mesh.
  if (ext == "ply" && !PlyDeclaresFaces(path)) {
    PrintCloud(path, Take(ReadPointCloud(path)));
    return;
  }
  const TriangleMesh mesh = Take(ReadMesh(path));
  const MeshTopology topo = AnalyzeTopology(mesh);
  std::printf("file: %s\ntype: mesh\nvertices: %zu\ntriangles: %zu\ndegenerate: %zu\n",
              path.c_str(), mesh.vertices.size(), mesh.num_triangles(), mesh.CountDegenerate());
  std::printf("closed: %s (boundary edges %zu, non-manifold edges %zu)\n",
              topo.closed() ? "yes" : "no", topo.boundary_edges, topo.nonmanifold_edges);
  PrintBounds(ComputeBounds(mesh));
}

}  // namespace

void AddInfoCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("info",
                                 "Print what a cloud (.pcd/.ply) or mesh "
                                 "(.stl/.obj/.ply/.off) file holds");
  auto path = std::make_shared<std::string>();
  cmd->add_option("file", *path, "cloud or mesh file")->required();
  cmd->callback([path] { Info(*path); });
}

}  // namespace surfinspect::cli
