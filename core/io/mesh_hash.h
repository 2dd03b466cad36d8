// Content hash of a mesh: lowercase hex SHA-256 of its canonical bytes,
// "surfinspect.mesh.v1\0", vertex and triangle counts as little-endian
// uint64, then the float32 xyz vertices and uint32 triangle indices (little
// endian). Clients send the hash instead of the mesh once a server has it;
// any replica that computes the same hash serves the same mesh.
#pragma once

#include <string>
#include <string_view>

#include "core/types/triangle_mesh.h"

namespace surfinspect {

std::string MeshSha256(const TriangleMesh& mesh);
// Lowercase hex SHA-256 of any bytes (a CAD file's, for its cache key).
std::string Sha256Hex(std::string_view bytes);
// The same from the wire layout (12-byte vertices, 12-byte triangles).
std::string MeshSha256(const std::string& vertex_bytes, const std::string& triangle_bytes);

}  // namespace surfinspect
