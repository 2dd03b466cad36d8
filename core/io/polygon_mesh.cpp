#include "core/io/polygon_mesh.h"

#include <assimp/fast_atof.h>

#include <cmath>
#include <exception>
#include <string>

#include "absl/strings/str_cat.h"
#include "core/io/text_parse.h"
#include "core/types/first_equal_point.h"

namespace surfinspect {
namespace {

// Assimp's aiVector3D arithmetic in float, operation for operation.
struct V3 {
  float x, y, z;
};
V3 Sub(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  return {a.x() - b.x(), a.y() - b.y(), a.z() - b.z()};
}
float Dot(const V3& a, const V3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
void Normalize(V3* v) {
  const float l = std::sqrt(Dot(*v, *v));
  if (l == 0) return;
  const float inv = 1.0f / std::sqrt(Dot(*v, *v));
  v->x *= inv;
  v->y *= inv;
  v->z *= inv;
}

constexpr float kAssimpPi = 3.1415926538f;  // AI_MATH_PI_F

// The corner a quad is fanned from (TriangulateProcess, quad branch).
int QuadStart(const std::vector<Eigen::Vector3f>& v, const uint32_t* q) {
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3f& p = v[q[i]];
    V3 left = Sub(v[q[(i + 3) % 4]], p);
    V3 diag = Sub(v[q[(i + 2) % 4]], p);
    V3 right = Sub(v[q[(i + 1) % 4]], p);
    Normalize(&left);
    Normalize(&diag);
    Normalize(&right);
    const float angle = std::acos(Dot(left, diag)) + std::acos(Dot(right, diag));
    if (angle > kAssimpPi) return i;
  }
  return 0;
}

std::vector<Triangle> Triangulate(const IndexedPolygons& p) {
  bool has_quads = false;
  for (uint8_t s : p.sizes) has_quads |= s == 4;
  std::vector<Triangle> tris;
  tris.reserve(p.sizes.size() + (has_quads ? p.sizes.size() : 0));
  uint32_t last_first = UINT32_MAX;
  std::size_t c = 0;
  for (uint8_t s : p.sizes) {
    const uint32_t* f = p.corners.data() + c;
    c += s;
    if (s == 3) {
      Triangle t{f[0], f[1], f[2]};
      if (has_quads && t[0] == last_first) t = {t[2], t[0], t[1]};
      last_first = t[0];
      tris.push_back(t);
      continue;
    }
    const int k = QuadStart(p.vertices, f);
    Triangle a{f[k], f[(k + 1) % 4], f[(k + 2) % 4]};
    Triangle b{f[k], f[(k + 2) % 4], f[(k + 3) % 4]};
    if (a[0] == last_first) {
      // Both now start at the diagonal's far corner.
      a = {a[2], a[0], a[1]};
      b = {b[1], b[2], b[0]};
    }
    last_first = a[0];
    tris.push_back(a);
    tris.push_back(b);
  }
  return tris;
}

}  // namespace

absl::StatusOr<TriangleMesh> TriangulateAndMerge(const IndexedPolygons& p, std::string_view name) {
  const std::size_t nv = p.vertices.size();
  if (nv >= UINT32_MAX) return BadFile(name, "cannot import: more than 2^32 - 2 vertices");
  std::size_t total = 0;
  for (uint8_t s : p.sizes) {
    if (s != 3 && s != 4) return BadFile(name, "cannot import: a face is not a triangle or quad");
    total += s;
  }
  if (total != p.corners.size()) return BadFile(name, "cannot import: face corner count mismatch");
  for (uint32_t i : p.corners)
    if (i >= nv)
      return BadFile(name, absl::StrCat("cannot import: vertex index ", i, " out of range"));
  std::vector<Triangle> tris = Triangulate(p);
  std::vector<bool> used(nv, false);
  for (const Triangle& t : tris)
    for (uint32_t i : t) used[i] = true;
  TriangleMesh mesh;
  std::vector<uint32_t> remap(nv, UINT32_MAX);
  FirstEqualPoint first(p.vertices, nv);
  for (uint32_t i = 0; i < nv; ++i) {
    if (!used[i]) continue;
    const uint32_t f = first.FindOrAdd(i);
    if (f != i) {
      remap[i] = remap[f];
      continue;
    }
    remap[i] = static_cast<uint32_t>(mesh.vertices.size());
    mesh.vertices.push_back(p.vertices[i]);
  }
  mesh.triangles.reserve(tris.size());
  for (const Triangle& t : tris) mesh.triangles.push_back({remap[t[0]], remap[t[1]], remap[t[2]]});
  return mesh;
}

namespace {
// Thrown by fast_atoreal_move instead of Assimp's DeadlyImportError (whose
// base is not exported by the shared library).
struct AtofOverflow {
  template <typename... T>
  explicit AtofOverflow(T&&...) {}
};

template <typename Real>
bool AssimpReal(std::string_view token, Real* out) {
  double check;
  if (!ParseDouble(token, &check) || token.size() > 64) return false;
  const std::string terminated(token);
  try {
    Assimp::fast_atoreal_move<Real, AtofOverflow>(terminated.c_str(), *out, /*check_comma=*/false);
  } catch (const AtofOverflow&) {
    return false;  // more digits than fit in 64 bits
  }
  return true;
}
}  // namespace

bool ParseMeshCoordinate(std::string_view token, float* out) { return AssimpReal(token, out); }
bool ParseMeshCoordinate(std::string_view token, double* out) { return AssimpReal(token, out); }

}  // namespace surfinspect
