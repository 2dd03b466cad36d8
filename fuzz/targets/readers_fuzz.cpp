// The file readers on untrusted bytes: clouds (PCD, PLY) and meshes (STL,
// OBJ, PLY, OFF). PCD, PLY and OFF are parsed by our own code from a byte
// buffer, so their targets call those parsers directly (ReadPointCloud and
// ReadMesh read the file and hand its bytes to the same functions). STL and
// OBJ go through ReadMesh on a scratch file, the programs' full path: the
// strict check (mesh_precheck.h), then Assimp. ply_cloud_direct checks the
// direct PLY read (ReadPackedXyzPly, a scratch file) against ParsePlyCloud
// on the same bytes: where it answers, the same cloud or the same error.
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "core/io/io_mesh.h"
#include "core/io/off_format.h"
#include "core/io/pcd_format.h"
#include "core/io/ply_cloud.h"
#include "core/io/ply_mesh.h"
#include "fuzz/fuzz_target.h"

namespace {

// The fuzzer's memory limit (2 GB RSS), not a format limit.
surfinspect::CloudReadLimits CloudLimits() {
  surfinspect::CloudReadLimits limits;
  limits.max_points = 4'000'000;
  return limits;
}

surfinspect::MeshReadLimits MeshLimits() {
  surfinspect::MeshReadLimits limits;
  limits.max_triangles = 2'000'000;
  return limits;
}

// A reader may refuse anything; it must only come back.
void ReadMeshFile(std::string_view bytes, const char* extension) {
  (void)surfinspect::ReadMesh(surfinspect::fuzz::WriteScratchFile(bytes, extension), MeshLimits());
}

}  // namespace

#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_pcd)
SURFINSPECT_FUZZ_TARGET(pcd) { (void)surfinspect::ParsePcd(bytes, CloudLimits(), "fuzz.pcd"); }
#endif
#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_ply_cloud)
SURFINSPECT_FUZZ_TARGET(ply_cloud) {
  (void)surfinspect::ParsePlyCloud(bytes, CloudLimits(), "fuzz.ply");
}
#endif
#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_ply_cloud_direct)
namespace {
// Both readers' answers alike: the same status, or clouds equal bit for bit
// (NaN payloads included) in their points and grid.
bool SameAnswer(const absl::StatusOr<surfinspect::PointCloud>& a,
                const absl::StatusOr<surfinspect::PointCloud>& b) {
  if (a.ok() != b.ok()) return false;
  if (!a.ok()) return a.status() == b.status();
  return a->width == b->width && a->height == b->height && a->size() == b->size() &&
         std::memcmp(a->points.data(), b->points.data(), a->size() * sizeof(a->points[0])) == 0;
}
}  // namespace
SURFINSPECT_FUZZ_TARGET(ply_cloud_direct) {
  const std::string path = surfinspect::fuzz::WriteScratchFile(bytes, "ply");
  const auto direct = surfinspect::ReadPackedXyzPly(path, CloudLimits());
  if (!direct) return;  // not its layout: the general reader answers
  if (!SameAnswer(*direct, surfinspect::ParsePlyCloud(bytes, CloudLimits(), path))) {
    std::fprintf(stderr, "ReadPackedXyzPly and ParsePlyCloud disagree\n");
    std::abort();
  }
}
#endif
#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_stl)
SURFINSPECT_FUZZ_TARGET(stl) { ReadMeshFile(bytes, "stl"); }
#endif
#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_obj)
SURFINSPECT_FUZZ_TARGET(obj) { ReadMeshFile(bytes, "obj"); }
#endif
#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_ply_mesh)
SURFINSPECT_FUZZ_TARGET(ply_mesh) {
  (void)surfinspect::ParsePlyMesh(bytes, MeshLimits(), "fuzz.ply");
}
#endif
#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_off)
SURFINSPECT_FUZZ_TARGET(off) { (void)surfinspect::ParseOff(bytes, MeshLimits(), "fuzz.off"); }
#endif
