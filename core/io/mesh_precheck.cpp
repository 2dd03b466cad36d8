#include "core/io/mesh_precheck.h"

#include <algorithm>
#include <cstring>
#include <iterator>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/io/obj_lines.h"
#include "core/io/text_parse.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

constexpr uint64_t kMaxObjCorners = 1000;

absl::Status Refuse(std::string_view name, absl::string_view why) {
  return BadFile(name, absl::StrCat("cannot import: ", why));
}

absl::Status TooMany(std::string_view name, uint64_t n, const MeshReadLimits& limits) {
  return absl::ResourceExhaustedError(
      absl::StrCat(ToAbsl(name), ": ", n, " faces exceed the limit of ", limits.max_triangles));
}

// Whitespace-separated words of an ASCII STL, with the line each is on.
// Keywords match in any case; with `lower` (a writable copy of the same
// bytes), each keyword matched is written back there in lower case.
class Words {
 public:
  Words(std::string_view s, char* lower) : s_(s), lower_(lower) {}
  bool Next(std::string_view* w) {
    while (pos_ < s_.size() && std::strchr(" \t\r\n\v\f", s_[pos_]) && s_[pos_] != '\0') {
      if (s_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (pos_ >= s_.size()) return false;
    const std::size_t start = pos_;
    while (pos_ < s_.size() && !std::strchr(" \t\r\n\v\f", s_[pos_])) ++pos_;
    *w = s_.substr(start, pos_ - start);
    return true;
  }
  // Whether `word`, returned by Next, is `keyword` (lower case) in any case.
  bool Is(std::string_view word, std::string_view keyword) {
    if (!absl::EqualsIgnoreCase(ToAbsl(word), ToAbsl(keyword))) return false;
    if (lower_) std::memcpy(lower_ + (word.data() - s_.data()), keyword.data(), keyword.size());
    return true;
  }
  void SkipLine() {
    while (pos_ < s_.size() && s_[pos_] != '\n') ++pos_;
  }
  std::size_t line() const { return line_; }

 private:
  std::string_view s_;
  char* lower_;
  std::size_t pos_ = 0, line_ = 1;
};

bool Expect(Words* w, std::string_view keyword) {
  std::string_view got;
  return w->Next(&got) && w->Is(got, keyword);
}

bool Numbers(Words* w, int n) {
  std::string_view got;
  double d;
  for (int i = 0; i < n; ++i)
    if (!w->Next(&got) || !ParseDouble(got, &d)) return false;
  return true;
}

// One facet after its "facet" word. Errors here and in CheckAsciiStl are
// the reason alone; CheckStl names the file and the other interpretation.
absl::Status Facet(Words* w, uint64_t index) {
  const auto bad = [&](absl::string_view why) {
    return absl::InvalidArgumentError(
        absl::StrCat("facet ", index, " (line ", w->line(), "): ", why));
  };
  if (!Expect(w, "normal") || !Numbers(w, 3)) return bad("expected 'normal' and 3 numbers");
  if (!Expect(w, "outer") || !Expect(w, "loop")) return bad("expected 'outer loop'");
  uint64_t vertices = 0;
  std::string_view word;
  bool more = false;
  while ((more = w->Next(&word)) && w->Is(word, "vertex")) {
    if (!Numbers(w, 3)) return bad("a vertex needs 3 numbers");
    ++vertices;
  }
  if (!more || !w->Is(word, "endloop")) return bad("expected 'vertex' or 'endloop'");
  if (vertices != 3)
    return bad(absl::StrCat("has ", vertices, " vertices (a facet needs exactly 3)"));
  if (!Expect(w, "endfacet")) return bad("expected 'endfacet'");
  return absl::OkStatus();
}

absl::Status CheckAsciiStl(std::string_view bytes, const MeshReadLimits& limits,
                           std::string_view name, char* lower) {
  Words w(bytes, lower);
  std::string_view word;
  uint64_t facets = 0, solids = 0;
  while (w.Next(&word)) {
    if (!w.Is(word, "solid"))
      return absl::InvalidArgumentError(absl::StrCat("line ", w.line(), ": expected 'solid'"));
    w.SkipLine();  // the solid's name
    ++solids;
    while (true) {
      if (!w.Next(&word)) return absl::InvalidArgumentError("ends without 'endsolid'");
      if (w.Is(word, "endsolid")) {
        w.SkipLine();
        break;
      }
      if (!w.Is(word, "facet"))
        return absl::InvalidArgumentError(absl::StrCat(
            "line ", w.line(), ": expected 'facet' or 'endsolid', found '", Excerpt(word), "'"));
      RETURN_IF_ERROR(Facet(&w, facets));
      if (++facets > limits.max_triangles) return TooMany(name, facets, limits);
    }
  }
  if (solids == 0) return absl::InvalidArgumentError("holds no solid");
  return absl::OkStatus();
}

absl::Status CheckStlBytes(std::string_view bytes, const MeshReadLimits& limits,
                           std::string_view name, char* lower) {
  uint32_t n = 0;
  if (bytes.size() >= 84) std::memcpy(&n, bytes.data() + 80, 4);
  const uint64_t binary_size = 84 + 50 * uint64_t{n};
  if (bytes.size() >= 84 && binary_size == bytes.size()) {
    if (n > limits.max_triangles) return TooMany(name, n, limits);
    return absl::OkStatus();
  }
  const std::string as_binary =
      bytes.size() < 84 ? absl::StrCat("size ", bytes.size(), " is under the 84-byte header")
                        : absl::StrCat("size ", bytes.size(), " does not match 84 + 50 * ", n,
                                       " = ", binary_size);
  std::size_t start = 0;
  while (start < bytes.size() && std::strchr(" \t\r\n", bytes[start]) && bytes[start] != '\0')
    ++start;
  if (!absl::EqualsIgnoreCase(ToAbsl(bytes.substr(start, 5)), "solid"))
    return Refuse(name, absl::StrCat("neither ASCII STL (no 'solid' at the start) nor binary STL: ",
                                     as_binary));
  // A binary STL's 80-byte header may start with "solid" too: when the
  // ASCII reading fails, both readings are named.
  const absl::Status ascii = CheckAsciiStl(bytes, limits, name, lower);
  if (ascii.code() != absl::StatusCode::kInvalidArgument) return ascii;
  return Refuse(name,
                absl::StrCat("as ASCII STL: ", ascii.message(), "; as binary STL: ", as_binary));
}

}  // namespace

absl::Status CheckStl(std::string_view bytes, const MeshReadLimits& limits, std::string_view name) {
  return CheckStlBytes(bytes, limits, name, nullptr);
}

absl::Status CheckStlForAssimp(std::string* bytes, const MeshReadLimits& limits,
                               std::string_view name) {
  return CheckStlBytes(*bytes, limits, name, bytes->data());
}

namespace {

struct ObjCounts {
  uint64_t v = 0, vt = 0, vn = 0;
};

// One index of a corner: non-zero, positive up to `total`, negative back
// to at most `so_far` earlier entries.
bool IndexOk(std::string_view s, uint64_t total, uint64_t so_far) {
  int64_t i = 0;
  if (!ParseInt(s, &i) || i == 0) return false;
  return i > 0 ? static_cast<uint64_t>(i) <= total : static_cast<uint64_t>(-i) <= so_far;
}

// "v", "v/vt", "v//vn" or "v/vt/vn".
bool CornerOk(std::string_view c, const ObjCounts& total, const ObjCounts& so_far) {
  const std::size_t s1 = c.find('/');
  if (s1 == std::string_view::npos) return IndexOk(c, total.v, so_far.v);
  if (!IndexOk(c.substr(0, s1), total.v, so_far.v)) return false;
  const std::string_view rest = c.substr(s1 + 1);
  const std::size_t s2 = rest.find('/');
  const std::string_view vt = rest.substr(0, s2);
  if (!vt.empty() && !IndexOk(vt, total.vt, so_far.vt)) return false;
  if (s2 == std::string_view::npos) return !vt.empty();
  return IndexOk(rest.substr(s2 + 1), total.vn, so_far.vn);
}

ObjCounts CountObjEntries(std::string_view bytes) {
  ObjCounts c;
  (void)ForEachObjLine(bytes, [&c](const std::vector<std::string_view>& tok, std::size_t) {
    c.v += tok[0] == "v";
    c.vt += tok[0] == "vt";
    c.vn += tok[0] == "vn";
    return absl::OkStatus();
  });
  return c;
}

absl::Status CheckObjLine(const std::vector<std::string_view>& tok, const ObjCounts& total,
                          ObjCounts* so_far, std::size_t line, std::string_view name) {
  const std::string_view key = tok[0];
  const auto bad = [&](absl::string_view why) {
    return Refuse(name, absl::StrCat("OBJ line ", line, ": ", why));
  };
  // Polygonal OBJ only. Assimp dispatches on a line's first characters, so a
  // statement that merely starts like a known one ("v0...") reaches parsers
  // that were not written for it: every statement must be one of these.
  static constexpr std::string_view kKnown[] = {"v", "vt", "vn", "vp", "f",      "l",
                                                "p", "g",  "o",  "s",  "mtllib", "usemtl"};
  if (std::find(std::begin(kKnown), std::end(kKnown), key) == std::end(kKnown))
    return bad(absl::StrCat("unsupported statement '", Excerpt(key),
                            "' (polygonal OBJ: v vt vn vp f l p g o s mtllib usemtl)"));
  double d;
  if (key == "v" || key == "vt" || key == "vn" || key == "vp") {
    const std::size_t lo = key == "vt" || key == "vp" ? 1 : 3, hi = key == "v" ? 7 : 3;
    if (tok.size() - 1 < lo || tok.size() - 1 > hi)
      return bad(absl::StrCat("'", ToAbsl(key), "' needs ", lo, " to ", hi, " numbers"));
    for (std::size_t k = 1; k < tok.size(); ++k)
      if (!ParseDouble(tok[k], &d)) return bad(absl::StrCat("bad number '", Excerpt(tok[k]), "'"));
    if (key != "vp") ++(key == "v" ? so_far->v : key == "vt" ? so_far->vt : so_far->vn);
    return absl::OkStatus();
  }
  if (key != "f" && key != "l" && key != "p") return absl::OkStatus();
  const uint64_t corners = tok.size() - 1;
  if (corners == 0) return bad(absl::StrCat("'", ToAbsl(key), "' without indices"));
  if (key == "f" && corners < 3)
    return bad(absl::StrCat("a face has ", corners, " indices (a face needs at least 3)"));
  if (corners > kMaxObjCorners)
    return bad(absl::StrCat("a face has ", corners, " corners, over ", kMaxObjCorners));
  for (std::size_t k = 1; k < tok.size(); ++k)
    if (!CornerOk(tok[k], total, *so_far))
      return bad(absl::StrCat("vertex index '", Excerpt(tok[k]), "' out of range (", total.v,
                              " vertices, ", total.vt, " texture coordinates, ", total.vn,
                              " normals)"));
  return absl::OkStatus();
}

}  // namespace

absl::Status CheckObj(std::string_view bytes, const MeshReadLimits& limits, std::string_view name) {
  const ObjCounts total = CountObjEntries(bytes);
  ObjCounts so_far;
  uint64_t faces = 0;
  absl::Status st = ForEachObjLine(
      bytes, [&](const std::vector<std::string_view>& tok, std::size_t line) -> absl::Status {
        RETURN_IF_ERROR(CheckObjLine(tok, total, &so_far, line, name));
        if (tok[0] == "f" && ++faces > limits.max_triangles) return TooMany(name, faces, limits);
        return absl::OkStatus();
      });
  if (!st.ok()) return st;
  if (total.v == 0) return Refuse(name, "OBJ holds no vertices");
  return absl::OkStatus();
}

}  // namespace surfinspect
