// A STEP or IGES part as the mesh the pipeline measures against, made once:
// the file is tessellated by surfinspect-cad-worker (client/cad/) in a
// limited child process (limited_child.h), and the result, a grouped OBJ and
// its CadReport, is kept in a cache folder under a key of the file's SHA-256
// and the tessellation settings. The next part of a production run reads
// the cached OBJ (ReadMesh, ReadMeshGroups) and never starts OpenCASCADE.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "core/cad/cad_report.h"
#include "core/cad/cad_settings.h"
#include "core/types/mesh_groups.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

struct CadMesh {
  TriangleMesh mesh;  // mm
  MeshGroups groups;  // face:N, name:, color:, body: (occt_tessellate.h)
  CadReport report;
  std::string mesh_path;  // the cached OBJ: plans read their groups from it
  bool from_cache = false;
};

// The worker program: $SURFINSPECT_CAD_WORKER, else surfinspect-cad-worker
// beside the running program, else /usr/local/bin, /usr/bin. NotFound naming
// where it looked.
absl::StatusOr<std::string> CadWorkerPath();

// The cache folder of commands without a cell: $SURFINSPECT_CAD_CACHE, else
// $XDG_CACHE_HOME/surfinspect/cad, else ~/.cache/surfinspect/cad, else
// /tmp/surfinspect-cad-cache.
std::string DefaultCadCache();

// The cache key: the file's SHA-256, then the settings that change the mesh.
std::string CadCacheKey(const std::string& file_sha256, const TessellationSettings& settings);

// Tessellates `path` into `obj_path` (grouped OBJ, mm) and `report_path`
// (CadReport JSON) in the worker under settings.limits, without the cache:
// what `surfinspect cad` does. Errors as ImportCad's.
absl::StatusOr<CadReport> TessellateCadFile(const std::string& path, const CadSettings& settings,
                                            const std::string& obj_path,
                                            const std::string& report_path);

// Reads the cached tessellation or makes it in the worker under
// settings.limits. Errors name the file: InvalidArgument for a file OCCT
// cannot read (or a body it does not have), DeadlineExceeded or
// ResourceExhausted past the limits, Internal for a crash in OCCT.
absl::StatusOr<CadMesh> ImportCad(const std::string& path, const CadSettings& settings,
                                  const std::string& cache_dir);

}  // namespace surfinspect
