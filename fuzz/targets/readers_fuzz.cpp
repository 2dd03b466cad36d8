// The file readers on untrusted bytes: clouds (PCD, PLY) and meshes (STL,
// OBJ, PLY, OFF). Each reads through the same entry point as the programs,
// so the extension picks the parser exactly as for a file in the inbox.
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"
#include "fuzz/fuzz_target.h"

namespace {

// A reader may refuse anything; it must only come back.
void ReadCloud(std::string_view bytes, const char* extension) {
  surfinspect::CloudReadLimits limits;
  limits.max_points = 4'000'000;  // the fuzzer's memory limit, not a format limit
  (void)surfinspect::ReadPointCloud(surfinspect::fuzz::WriteScratchFile(bytes, extension), limits);
}

void ReadMesh(std::string_view bytes, const char* extension) {
  surfinspect::MeshReadLimits limits;
  limits.max_triangles = 2'000'000;
  (void)surfinspect::ReadMesh(surfinspect::fuzz::WriteScratchFile(bytes, extension), limits);
}

}  // namespace

#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_pcd)
SURFINSPECT_FUZZ_TARGET(pcd) { ReadCloud(bytes, "pcd"); }
#endif
#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_ply_cloud)
SURFINSPECT_FUZZ_TARGET(ply_cloud) { ReadCloud(bytes, "ply"); }
#endif
#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_stl)
SURFINSPECT_FUZZ_TARGET(stl) { ReadMesh(bytes, "stl"); }
#endif
#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_obj)
SURFINSPECT_FUZZ_TARGET(obj) { ReadMesh(bytes, "obj"); }
#endif
#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_ply_mesh)
SURFINSPECT_FUZZ_TARGET(ply_mesh) { ReadMesh(bytes, "ply"); }
#endif
#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_off)
SURFINSPECT_FUZZ_TARGET(off) { ReadMesh(bytes, "off"); }
#endif
