#include "core/io/ply_mesh.h"

#include <algorithm>
#include <cstring>

#include "absl/strings/str_cat.h"
#include "core/io/ply_format.h"
#include "core/io/ply_rows.h"
#include "core/io/polygon_mesh.h"
#include "core/io/text_parse.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

// Assimp's conversions: ascii floats by fast_atoreal_move (float for float
// properties, double then float for double ones), integers exactly.
bool Coordinate(PlyFormat f, PlyType t, const PlyValue& v, float* out) {
  if (f != PlyFormat::kAscii) {
    *out = t == PlyType::kFloat32 ? PlyBinaryFloat32(f, v.raw)
                                  : static_cast<float>(PlyBinaryDouble(f, t, v.raw));
    return true;
  }
  if (t == PlyType::kFloat32) return ParseMeshCoordinate(v.text, out);
  if (t == PlyType::kFloat64) {
    double d;
    if (!ParseMeshCoordinate(v.text, &d)) return false;
    *out = static_cast<float>(d);
    return true;
  }
  int64_t i;
  if (!PlyIntValue(f, t, v, &i)) return false;
  *out = static_cast<float>(i);
  return true;
}

// Little-endian faces whose only property is a uchar-counted list of int32
// or uint32 indices: read in one pass, up to the first face that is not a
// valid triangle or quad, which is left to the row reader and its message.
void TakeIndexFaces(PlyRowReader* reader, const PlyHeader& h, const PlyElement& e,
                    uint64_t vertices, IndexedPolygons* out, uint64_t* faces_read) {
  const PlyProperty& p = e.properties[0];
  if (h.format != PlyFormat::kBinaryLittleEndian || e.properties.size() != 1 || !p.is_list ||
      p.count_type != PlyType::kUint8 || (p.type != PlyType::kInt32 && p.type != PlyType::kUint32))
    return;
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__);
  const bool is_signed = p.type == PlyType::kInt32;
  while (*faces_read < e.count) {
    const uint8_t* face = nullptr;
    if (reader->RemainingBytes() < 1 || !reader->TakeBytes(0, &face).ok()) return;
    const unsigned n = face[0];
    if (n < 3 || n > 4 || reader->RemainingBytes() < 1 + 4 * n) return;
    uint32_t idx[4];
    std::memcpy(idx, face + 1, 4 * n);
    for (unsigned k = 0; k < n; ++k)
      if ((is_signed && static_cast<int32_t>(idx[k]) < 0) || idx[k] >= vertices) return;
    reader->TakeBytes(1 + 4 * n, &face).IgnoreError();  // fits: checked above
    out->corners.insert(out->corners.end(), idx, idx + n);
    out->sizes.push_back(static_cast<uint8_t>(n));
    ++*faces_read;
  }
}

absl::Status ReadVertices(PlyRowReader* reader, const PlyHeader& h, const PlyElement& e,
                          std::string_view name, std::vector<Eigen::Vector3f>* out) {
  int prop[3];
  for (int a = 0; a < 3; ++a) {
    const char* axis[] = {"x", "y", "z"};
    prop[a] = e.FindProperty(axis[a]);
    if (prop[a] < 0 || e.properties[prop[a]].is_list)
      return BadFile(
          name, absl::StrCat("cannot import: PLY vertex element has no '", axis[a], "' property"));
  }
  if (TakeFloat32XyzRows(reader, h, e, prop, out)) return absl::OkStatus();
  out->reserve(std::min<uint64_t>(e.count, reader->RemainingBytes() / 2 + 1));
  PlyRow row;
  for (uint64_t i = 0; i < e.count; ++i) {
    RETURN_IF_ERROR(reader->Next(e, i, &row));
    Eigen::Vector3f p;
    for (int a = 0; a < 3; ++a)
      if (!Coordinate(h.format, e.properties[prop[a]].type, row.values[row.first[prop[a]]], &p[a]))
        return BadFile(name, absl::StrCat("cannot import: vertex ", i, ": bad number '",
                                          Excerpt(row.values[row.first[prop[a]]].text), "'"));
    out->push_back(p);
  }
  return absl::OkStatus();
}

absl::Status ReadFaces(PlyRowReader* reader, const PlyHeader& h, const PlyElement& e,
                       uint64_t vertices, std::string_view name, IndexedPolygons* out) {
  int prop = e.FindProperty("vertex_indices");
  if (prop < 0) prop = e.FindProperty("vertex_index");
  if (prop < 0 || !e.properties[prop].is_list || !PlyTypeIsInteger(e.properties[prop].type))
    return BadFile(name, "cannot import: PLY face element has no integer vertex_indices list");
  const PlyType type = e.properties[prop].type;
  out->sizes.reserve(std::min<uint64_t>(e.count, reader->RemainingBytes() + 1));
  out->corners.reserve(std::min<uint64_t>(e.count * 3, reader->RemainingBytes() + 1));
  uint64_t fast = 0;
  TakeIndexFaces(reader, h, e, vertices, out, &fast);
  PlyRow row;
  for (uint64_t f = fast; f < e.count; ++f) {
    RETURN_IF_ERROR(reader->Next(e, f, &row));
    const uint32_t n = row.first[prop + 1] - row.first[prop];
    if (n < 3)
      return BadFile(name, absl::StrCat("cannot import: face ", f, " has ", n,
                                        " indices (a face needs at least 3)"));
    if (n > 4)
      return BadFile(name, absl::StrCat("cannot import: face ", f, " has ", n,
                                        " corners; only triangles and quads are read"));
    for (uint32_t k = 0; k < n; ++k) {
      int64_t idx = -1;
      if (!PlyIntValue(h.format, type, row.values[row.first[prop] + k], &idx) || idx < 0 ||
          static_cast<uint64_t>(idx) >= vertices)
        return BadFile(name, absl::StrCat("cannot import: face ", f, ": vertex index ", idx,
                                          " out of range (", vertices, " vertices)"));
      out->corners.push_back(static_cast<uint32_t>(idx));
    }
    out->sizes.push_back(static_cast<uint8_t>(n));
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<TriangleMesh> ParsePlyMesh(std::string_view bytes, const MeshReadLimits& limits,
                                          std::string_view name) {
  uint64_t max_rows = 0;
  if (!CheckedMul(limits.max_triangles, 3, &max_rows)) max_rows = UINT64_MAX;
  ASSIGN_OR_RETURN(auto h, ParsePlyHeader(bytes, max_rows, name));
  const int vi = h.FindElement("vertex");
  const int fi = h.FindElement("face");
  if (vi < 0 || h.elements[vi].count == 0)
    return BadFile(name, "cannot import: PLY has no vertices");
  if (fi < 0 || h.elements[fi].count == 0) return BadFile(name, "cannot import: PLY has no faces");
  if (h.FindElement("tristrips") >= 0)
    return BadFile(name, "cannot import: PLY triangle strips (tristrips) are not read");
  if (h.elements[fi].count > limits.max_triangles)
    return absl::ResourceExhaustedError(absl::StrCat(ToAbsl(name), ": ", h.elements[fi].count,
                                                     " faces exceed the limit of ",
                                                     limits.max_triangles));
  if (fi < vi) return BadFile(name, "cannot import: PLY faces come before the vertices");
  PlyRowReader reader(bytes, h, name);
  IndexedPolygons polygons;
  for (std::size_t i = 0; i < h.elements.size(); ++i) {
    const PlyElement& e = h.elements[i];
    absl::Status st = static_cast<int>(i) == vi
                          ? ReadVertices(&reader, h, e, name, &polygons.vertices)
                      : static_cast<int>(i) == fi
                          ? ReadFaces(&reader, h, e, h.elements[vi].count, name, &polygons)
                          : reader.Skip(e);
    if (!st.ok()) return st;
  }
  return TriangulateAndMerge(polygons, name);
}

}  // namespace surfinspect
