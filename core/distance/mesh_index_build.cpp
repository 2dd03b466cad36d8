// MeshIndex::Build (declared in mesh_index.h): face normals, the spatial
// order, Embree's BVH beside the pseudonormals, then the hint certificates.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <new>

#include "absl/strings/str_cat.h"
#include "core/distance/embree_handles.h"
#include "core/distance/hint_certificate.h"
#include "core/distance/mesh_index.h"
#include "core/distance/mesh_order.h"
#include "core/distance/wide_bvh.h"
#include "core/types/status_macros.h"

namespace surfinspect {

absl::StatusOr<std::unique_ptr<MeshIndex>> MeshIndex::Build(TriangleMesh mesh,
                                                            const MeshIndexSettings& settings) {
  if (settings.build_threads < 0)
    return absl::InvalidArgumentError(
        absl::StrCat("mesh index: build_threads must be >= 0, got ", settings.build_threads));
  RETURN_IF_ERROR(mesh.Validate());
  if (mesh.triangles.size() >= UINT32_MAX || mesh.vertices.size() >= UINT32_MAX)
    return absl::InvalidArgumentError("mesh index: more than 2^32-1 triangles or vertices");
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<MeshIndex> index(new MeshIndex());
  index->mesh_ = std::move(mesh);
  ASSIGN_OR_RETURN(auto device, EmbreeDevice::Create());
  // Embree builds with TBB; an arena bounds the build's threads without a
  // process-global limit (Embree's own "threads=" config sets one).
  tbb::task_arena arena(settings.build_threads > 0 ? settings.build_threads
                                                   : tbb::task_arena::automatic);
  absl::StatusOr<WideBvh> bvh;
  arena.execute([&] {
    try {
      index->ComputeFaceNormals();
      bvh = index->BuildInOrder(device->get(), settings);
    } catch (const std::bad_alloc&) {
      bvh = absl::ResourceExhaustedError(
          absl::StrCat("mesh index: out of memory building the index of ",
                       index->mesh_.num_triangles(), " triangles"));
    }
  });
  if (!bvh.ok()) {
    RETURN_IF_ERROR(device->TakeError());
    return bvh.status();
  }
  index->bvh_ = std::make_unique<WideBvh>(*std::move(bvh));
  if (settings.hint_certificates) RETURN_IF_ERROR(index->BuildCertificates(settings));
  index->info_.triangles = index->mesh_.num_triangles();
  index->info_.bvh_nodes = index->bvh_->stats().nodes;
  index->info_.bvh_depth = index->bvh_->stats().depth;
  index->info_.search_isa = SearchIsaName(index->bvh_->isa());
  index->info_.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return index;
}

// The BVH on the spatial order (with certificates; the mesh's own without),
// and the per-triangle data moved to it. The edge and vertex pseudonormals
// are computed on the mesh's order, so that their sums add in the mesh's
// order; they are serial work and run beside Embree's parallel build.
absl::StatusOr<WideBvh> MeshIndex::BuildInOrder(RTCDevice device,
                                                const MeshIndexSettings& settings) {
  // Called inside Build's task arena.
  MeshOrder order = settings.hint_certificates ? OrderMesh(mesh_) : KeepOrder(mesh_);
  std::vector<Eigen::Vector3d> ordered_normal;
  std::vector<TriangleShape> ordered_shape;
  if (!order.identity) {
    ordered_normal.resize(order.mesh_triangle.size());
    ordered_shape.resize(order.mesh_triangle.size());
    for (std::size_t i = 0; i < order.mesh_triangle.size(); ++i) {
      ordered_normal[i] = face_normal_[order.mesh_triangle[i]];
      ordered_shape[i] = shape_[order.mesh_triangle[i]];
    }
  }
  absl::StatusOr<WideBvh> bvh;
  tbb::parallel_invoke(
      [&] {
        bvh = WideBvh::Build(device, order.ordered, order.identity ? face_normal_ : ordered_normal,
                             order.identity ? shape_ : ordered_shape,
                             EmbreeBuildQuality(settings.build_quality), settings.search_isa);
      },
      [&] { ComputeFeatureNormals(); });
  if (!order.identity) {
    face_normal_ = std::move(ordered_normal);
    shape_ = std::move(ordered_shape);
  }
  ApplyOrder(std::move(order));
  return bvh;
}

absl::Status MeshIndex::BuildCertificates(const MeshIndexSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  tbb::task_arena arena(settings.build_threads > 0 ? settings.build_threads
                                                   : tbb::task_arena::automatic);
  bool out_of_memory = false;
  arena.execute([&] {
    try {
      certificates_ = std::make_unique<HintCertificates>(
          HintCertificates::Build(ordered_, weld_, face_normal_, *bvh_));
    } catch (const std::bad_alloc&) {
      out_of_memory = true;
    }
  });
  if (out_of_memory)
    return absl::ResourceExhaustedError(
        absl::StrCat("mesh index: out of memory building the hint certificates of ",
                     mesh_.num_triangles(), " triangles"));
  info_.certifiable_triangles = certificates_->certifiable();
  info_.hint_alone_triangles = certificates_->alone();
  info_.certificate_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return absl::OkStatus();
}

// The face normals and kernel shapes, which the BVH needs; the edge and
// vertex pseudonormals below are built beside it. Each triangle's are its
// own, so they are computed in parallel.
void MeshIndex::ComputeFaceNormals() {
  const auto& verts = mesh_.vertices;
  const auto& tris = mesh_.triangles;
  face_normal_.resize(tris.size());
  shape_.resize(tris.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tris.size(), 4096), [&](const auto& range) {
    for (std::size_t t = range.begin(); t != range.end(); ++t) {
      const Eigen::Vector3d a = verts[tris[t][0]].cast<double>(),
                            b = verts[tris[t][1]].cast<double>(),
                            c = verts[tris[t][2]].cast<double>();
      // The kernel's degeneracy test is TriangleMesh::IsDegenerate's. A
      // degenerate triangle's zero normal adds nothing to its neighbours' sums.
      shape_[t] = ClassifyTriangle(a, b, c);
      face_normal_[t] = shape_[t] == TriangleShape::kDegenerate
                            ? Eigen::Vector3d::Zero()
                            : Eigen::Vector3d((b - a).cross(c - a).normalized());
    }
  });
  info_.degenerate_triangles = static_cast<std::size_t>(
      std::count(shape_.begin(), shape_.end(), TriangleShape::kDegenerate));
}

// Moves the per-triangle and per-vertex data, computed in the mesh's
// order, to the spatial order's positions; the values are unchanged.
void MeshIndex::ApplyOrder(MeshOrder order) {
  ordered_ = std::move(order.ordered);
  mesh_triangle_ = std::move(order.mesh_triangle);
  position_of_triangle_ = std::move(order.position_of_triangle);
  if (order.identity) return;
  std::vector<std::array<uint32_t, 3>> edges(triangle_edges_.size());
  for (std::size_t i = 0; i < edges.size(); ++i) edges[i] = triangle_edges_[mesh_triangle_[i]];
  triangle_edges_ = std::move(edges);
  // A vertex's representative keeps its role, and its corners, under its
  // new position.
  const std::size_t nv = weld_.size();
  std::vector<uint32_t> weld(nv), corner_start(nv + 1, 0);
  for (std::size_t v = 0; v < nv; ++v) {
    const uint32_t at = order.position_of_vertex[v];
    weld[at] = order.position_of_vertex[weld_[v]];
    corner_start[at + 1] = corner_start_[v + 1] - corner_start_[v];
  }
  for (std::size_t v = 0; v < nv; ++v) corner_start[v + 1] += corner_start[v];
  std::vector<uint32_t> corners(corners_.size());
  for (std::size_t v = 0; v < nv; ++v)
    std::copy(corners_.begin() + corner_start_[v], corners_.begin() + corner_start_[v + 1],
              corners.begin() + corner_start[order.position_of_vertex[v]]);
  weld_ = std::move(weld);
  corner_start_ = std::move(corner_start);
  corners_ = std::move(corners);
}

}  // namespace surfinspect
