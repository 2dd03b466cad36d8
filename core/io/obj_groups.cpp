#include "core/io/obj_groups.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/obj_lines.h"
#include "core/io/text_parse.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

struct ObjFace {
  std::vector<uint32_t> corners;  // 0-based vertex indices
  uint32_t statement = 0;         // index into ObjFaces::statements
  std::size_t line = 0;
};

struct ObjFaces {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<ObjFace> faces;
  MeshGroups groups;  // names only
  // The groups each `g` statement named, in order; statement 0 names none.
  std::vector<std::vector<uint32_t>> statements{{}};
};

// A corner "v", "v/vt", "v//vn" or "v/vt/vn" as a 0-based vertex index;
// negative indices count back from the vertices read so far.
bool CornerVertex(std::string_view corner, std::size_t so_far, uint32_t* out) {
  int64_t i = 0;
  if (!ParseInt(corner.substr(0, corner.find('/')), &i) || i == 0) return false;
  const int64_t index = i > 0 ? i - 1 : static_cast<int64_t>(so_far) + i;
  if (index < 0 || index >= static_cast<int64_t>(UINT32_MAX)) return false;
  *out = static_cast<uint32_t>(index);
  return true;
}

uint32_t GroupIndex(MeshGroups* groups, std::string_view name) {
  const auto it = std::find(groups->names.begin(), groups->names.end(), name);
  if (it != groups->names.end()) return static_cast<uint32_t>(it - groups->names.begin());
  groups->names.emplace_back(name);
  return static_cast<uint32_t>(groups->names.size() - 1);
}

// `g a b c`: the faces after it belong to a, b and c.
void OpenGroups(const std::vector<std::string_view>& tok, ObjFaces* r, uint32_t* open) {
  std::vector<uint32_t> named;
  for (std::size_t k = 1; k < tok.size(); ++k) {
    const uint32_t g = GroupIndex(&r->groups, tok[k]);
    if (std::find(named.begin(), named.end(), g) == named.end()) named.push_back(g);
  }
  *open = static_cast<uint32_t>(r->statements.size());
  r->statements.push_back(std::move(named));
}

absl::StatusOr<ObjFaces> ReadFaces(std::string_view bytes, std::string_view name) {
  ObjFaces r;
  uint32_t open = 0;
  absl::Status st = ForEachObjLine(
      bytes, [&](const std::vector<std::string_view>& tok, std::size_t line) -> absl::Status {
        if (tok[0] == "g" || tok[0] == "o") {
          OpenGroups(tok, &r, &open);
        } else if (tok[0] == "v" && tok.size() >= 4) {
          double x, y, z;
          if (!ParseDouble(tok[1], &x) || !ParseDouble(tok[2], &y) || !ParseDouble(tok[3], &z))
            return BadFile(name, absl::StrCat("OBJ line ", line, ": bad vertex"));
          r.vertices.emplace_back(static_cast<float>(x), static_cast<float>(y),
                                  static_cast<float>(z));
        } else if (tok[0] == "f") {
          ObjFace f{{}, open, line};
          for (std::size_t k = 1; k < tok.size(); ++k) {
            uint32_t v;
            if (!CornerVertex(tok[k], r.vertices.size(), &v) || v >= r.vertices.size())
              return BadFile(name, absl::StrCat("OBJ line ", line, ": bad face index"));
            f.corners.push_back(v);
          }
          if (f.corners.size() >= 3) r.faces.push_back(std::move(f));
        }
        return absl::OkStatus();
      });
  if (!st.ok()) return st;
  return r;
}

// Assimp parses numbers with its own routine, so positions may differ from
// ours in the last bits of the float: equal within 1e-6 relative.
bool SamePosition(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  for (int k = 0; k < 3; ++k)
    if (std::abs(a[k] - b[k]) > 1e-6f * std::max(1.0f, std::abs(b[k]))) return false;
  return true;
}

bool CornersOf(const TriangleMesh& mesh, std::size_t t, const ObjFaces& file, const ObjFace& f) {
  for (int c = 0; c < 3; ++c) {
    const Eigen::Vector3f& p = mesh.vertices[mesh.triangles[t][c]];
    bool found = false;
    for (uint32_t v : f.corners) found = found || SamePosition(p, file.vertices[v]);
    if (!found) return false;
  }
  return true;
}

}  // namespace

absl::StatusOr<MeshGroups> ObjGroups(std::string_view bytes, const TriangleMesh& imported,
                                     std::string_view name, LengthUnit file_unit) {
  ASSIGN_OR_RETURN(auto file, ReadFaces(bytes, name));
  MeshGroups groups;
  if (file.groups.names.empty()) return groups;
  // Compared with the imported mesh as it was scaled (SamePosition's
  // tolerance covers the two roundings).
  ScaleToMillimetres(file_unit, &file.vertices);
  groups.names = file.groups.names;
  groups.triangle_group.reserve(imported.num_triangles());
  std::size_t t = 0;
  for (const ObjFace& f : file.faces) {
    for (std::size_t k = 0; k + 2 < f.corners.size(); ++k, ++t) {
      if (t >= imported.num_triangles() || !CornersOf(imported, t, file, f))
        return absl::FailedPreconditionError(absl::StrCat(
            ToAbsl(name), ": OBJ groups cannot be mapped: the imported triangle ", t,
            " is not part of the face on line ", f.line,
            " (the importer reorders faces of different materials; use one material per "
            "group, or select regions by box or triangle ids)"));
      const std::vector<uint32_t>& named = file.statements[f.statement];
      groups.triangle_group.push_back(named.empty() ? MeshGroups::kNoGroup : named[0]);
      for (std::size_t g = 1; g < named.size(); ++g)
        groups.more.push_back({static_cast<uint32_t>(t), named[g]});
    }
  }
  if (t != imported.num_triangles())
    return absl::FailedPreconditionError(
        absl::StrCat(ToAbsl(name), ": OBJ groups cannot be mapped: the file's faces give ", t,
                     " triangles, the import ", imported.num_triangles()));
  return groups;
}

namespace {

std::vector<uint32_t> GroupsOf(const MeshGroups& groups, uint32_t t, std::size_t* more) {
  std::vector<uint32_t> out;
  if (t < groups.triangle_group.size() && groups.triangle_group[t] != MeshGroups::kNoGroup)
    out.push_back(groups.triangle_group[t]);
  for (; *more < groups.more.size() && groups.more[*more].first == t; ++*more)
    out.push_back(groups.more[*more].second);
  return out;
}

}  // namespace

absl::StatusOr<std::string> ObjWithGroups(const TriangleMesh& mesh, const MeshGroups& groups) {
  for (const std::string& n : groups.names)
    if (n.empty() || n.find_first_of(" \t\r\n") != std::string::npos)
      return absl::InvalidArgumentError(
          absl::StrCat("OBJ group name \"", n, "\" is empty or has a blank"));
  std::string out;
  out.reserve(mesh.vertices.size() * 40 + mesh.num_triangles() * 24);
  char line[128];
  for (const Eigen::Vector3f& v : mesh.vertices) {
    std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", v.x(), v.y(), v.z());
    out += line;
  }
  std::vector<uint32_t> open = {MeshGroups::kNoGroup};
  std::size_t more = 0;
  for (uint32_t t = 0; t < mesh.num_triangles(); ++t) {
    std::vector<uint32_t> now = GroupsOf(groups, t, &more);
    if (now != open) {
      out += "g";
      for (uint32_t g : now) absl::StrAppend(&out, " ", groups.names[g]);
      out += "\n";
      open = std::move(now);
    }
    const Triangle& tri = mesh.triangles[t];
    std::snprintf(line, sizeof line, "f %u %u %u\n", tri[0] + 1, tri[1] + 1, tri[2] + 1);
    out += line;
  }
  return out;
}

}  // namespace surfinspect
