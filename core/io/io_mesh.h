// Mesh files through Assimp: STL (ascii and binary), OBJ, PLY and OFF are
// read; STL, OBJ and PLY are written. On read, per-vertex attributes are
// dropped and identical vertex positions merged, so an STL (which stores
// three vertices per facet) comes back with shared vertices and its
// topology (closed or open) can be analysed.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

struct MeshReadLimits {
  uint64_t max_file_bytes = uint64_t{2} << 30;
  uint64_t max_triangles = 50'000'000;
};

// Fails with a message naming the file for: unreadable or truncated files,
// no triangles, non-finite vertices, only degenerate triangles, limits.
absl::StatusOr<TriangleMesh> ReadMesh(const std::string& path, const MeshReadLimits& limits = {});

enum class MeshFormat { kStlBinary, kStlAscii, kObj, kPlyBinary, kPlyAscii };

// Format from the extension when omitted (.stl binary, .obj, .ply binary).
// Written atomically.
absl::Status WriteMesh(const std::string& path, const TriangleMesh& mesh);
absl::Status WriteMesh(const std::string& path, const TriangleMesh& mesh, MeshFormat format);

}  // namespace surfinspect
