// The file readers on untrusted bytes: clouds (PCD, PLY) and meshes (STL,
// OBJ, PLY, OFF). PCD, PLY and OFF are parsed by our own code from a byte
// buffer, so their targets call those parsers directly (ReadPointCloud and
// ReadMesh read the file and hand its bytes to the same functions). STL and
// OBJ go through ReadMesh on a scratch file, the programs' full path: the
// strict check (mesh_precheck.h), then Assimp.
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
