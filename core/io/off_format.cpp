#include "core/io/off_format.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "core/io/polygon_mesh.h"
#include "core/io/text_parse.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

// The next line with content, its comment cut off, split into tokens.
bool NextTokens(LineScanner* lines, std::vector<std::string_view>* tok) {
  std::string_view line;
  while (lines->Next(&line)) {
    line = line.substr(0, line.find('#'));
    SplitWhitespace(line, tok);
    if (!tok->empty()) return true;
  }
  return false;
}

bool KnownKeyword(std::string_view k) {
  if (k.substr(0, 2) == "ST") k.remove_prefix(2);
  if (!k.empty() && k[0] == 'C') k.remove_prefix(1);
  if (!k.empty() && k[0] == 'N') k.remove_prefix(1);
  return k == "OFF";
}

struct OffCounts {
  uint64_t vertices = 0, faces = 0;
};

absl::StatusOr<OffCounts> ParseCounts(LineScanner* lines, std::string_view name) {
  std::vector<std::string_view> tok;
  if (!NextTokens(lines, &tok) || !KnownKeyword(tok[0]))
    return BadFile(name, "cannot import: not an OFF file (no OFF keyword on the first line)");
  std::vector<std::string_view> counts(tok.begin() + 1, tok.end());
  if (!counts.empty() && counts[0] == "BINARY")
    return BadFile(name, "cannot import: binary OFF is not read");
  if (counts.empty()) {
    if (!NextTokens(lines, &tok)) return BadFile(name, "cannot import: OFF header has no counts");
    counts = tok;
  }
  OffCounts c;
  uint64_t edges = 0;
  if (counts.size() != 3 || !ParseUint(counts[0], &c.vertices) || !ParseUint(counts[1], &c.faces) ||
      !ParseUint(counts[2], &edges))
    return BadFile(name, "cannot import: OFF counts must be three integers (vertices faces edges)");
  return c;
}

absl::Status CheckCounts(const OffCounts& c, uint64_t remaining, const MeshReadLimits& limits,
                         std::string_view name) {
  if (c.vertices == 0) return BadFile(name, "cannot import: OFF declares no vertices");
  if (c.faces == 0) return BadFile(name, "cannot import: OFF declares no faces");
  if (c.faces > limits.max_triangles)
    return absl::ResourceExhaustedError(absl::StrCat(
        ToAbsl(name), ": ", c.faces, " faces exceed the limit of ", limits.max_triangles));
  // A vertex line takes at least "0 0 0\n", a face line at least "0\n".
  uint64_t need = 0, face_bytes = 0;
  if (!CheckedMul(c.vertices, 6, &need) || !CheckedMul(c.faces, 2, &face_bytes) ||
      !CheckedAdd(need, face_bytes, &need) || need - 1 > remaining)
    return BadFile(name, absl::StrCat("cannot import: OFF header declares ", c.vertices,
                                      " vertices and ", c.faces, " faces, more than the file's ",
                                      remaining, " remaining bytes can hold"));
  return absl::OkStatus();
}

absl::Status ReadVertices(LineScanner* lines, uint64_t n, std::string_view name,
                          std::vector<Eigen::Vector3f>* out) {
  std::vector<std::string_view> tok;
  out->reserve(n);
  for (uint64_t i = 0; i < n; ++i) {
    if (!NextTokens(lines, &tok))
      return BadFile(
          name, absl::StrCat("cannot import: truncated: ", n, " vertices declared, ", i, " found"));
    Eigen::Vector3f p;
    bool ok = tok.size() >= 3;
    for (int a = 0; ok && a < 3; ++a) ok = ParseMeshCoordinate(tok[a], &p[a]);
    double extra;
    for (std::size_t k = 3; ok && k < tok.size(); ++k) ok = ParseDouble(tok[k], &extra);
    if (!ok) return BadFile(name, absl::StrCat("cannot import: vertex ", i, ": bad coordinates"));
    out->push_back(p);
  }
  return absl::OkStatus();
}

absl::Status ReadFaces(LineScanner* lines, uint64_t n, uint64_t vertices, std::string_view name,
                       IndexedPolygons* out) {
  std::vector<std::string_view> tok;
  out->sizes.reserve(n);
  for (uint64_t f = 0; f < n; ++f) {
    if (!NextTokens(lines, &tok))
      return BadFile(
          name, absl::StrCat("cannot import: truncated: ", n, " faces declared, ", f, " found"));
    uint64_t corners = 0;
    if (!ParseUint(tok[0], &corners))
      return BadFile(name, absl::StrCat("cannot import: face ", f, ": bad corner count"));
    if (corners < 3)
      return BadFile(name, absl::StrCat("cannot import: face ", f, " has ", corners,
                                        " indices (a face needs at least 3)"));
    if (corners > 4)
      return BadFile(name, absl::StrCat("cannot import: face ", f, " has ", corners,
                                        " corners; only triangles and quads are read"));
    if (tok.size() < corners + 1)
      return BadFile(
          name, absl::StrCat("cannot import: face ", f, " lists fewer indices than ", corners));
    for (uint64_t k = 1; k <= corners; ++k) {
      uint64_t idx = 0;
      if (!ParseUint(tok[k], &idx) || idx >= vertices)
        return BadFile(name,
                       absl::StrCat("cannot import: face ", f, ": vertex index '", Excerpt(tok[k]),
                                    "' out of range (", vertices, " vertices)"));
      out->corners.push_back(static_cast<uint32_t>(idx));
    }
    double extra;
    for (std::size_t k = corners + 1; k < tok.size(); ++k)
      if (!ParseDouble(tok[k], &extra))
        return BadFile(name, absl::StrCat("cannot import: face ", f, ": bad colour value"));
    out->sizes.push_back(static_cast<uint8_t>(corners));
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<TriangleMesh> ParseOff(std::string_view bytes, const MeshReadLimits& limits,
                                      std::string_view name) {
  LineScanner lines(bytes);
  ASSIGN_OR_RETURN(auto counts, ParseCounts(&lines, name));
  RETURN_IF_ERROR(CheckCounts(counts, bytes.size() - lines.pos(), limits, name));
  IndexedPolygons polygons;
  RETURN_IF_ERROR(ReadVertices(&lines, counts.vertices, name, &polygons.vertices));
  RETURN_IF_ERROR(ReadFaces(&lines, counts.faces, counts.vertices, name, &polygons));
  return TriangulateAndMerge(polygons, name);
}

}  // namespace surfinspect
