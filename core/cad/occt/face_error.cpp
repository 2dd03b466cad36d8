#include "core/cad/occt/face_error.h"

#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <Extrema_ExtPS.hxx>
#include <Extrema_GenLocateExtPS.hxx>
#include <Poly_PolygonOnTriangulation.hxx>
#include <Poly_Triangulation.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "core/distance/point_triangle.h"

namespace surfinspect::occt {
namespace {

// Barycentric samples per triangle edge: (k+1)(k+2)/2 samples per triangle.
// The linear-interpolation error is a smooth function over the triangle, its
// largest value near the centroid or an edge's middle; k = 4 lands a sample
// within an eighth of the triangle of any point.
constexpr int kLevel = 4;

Eigen::Vector3d Vec(const gp_Pnt& p) { return {p.X(), p.Y(), p.Z()}; }

double SegmentDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

// The triangles around each node of a face, for bounding a surface point's
// distance to the mesh by the triangles near the one its UV fell in.
struct FaceRing {
  const MeshedFace& m;
  std::vector<std::vector<uint32_t>> of_node;

  explicit FaceRing(const MeshedFace& face) : m(face), of_node(face.nodes.size()) {
    for (uint32_t t = 0; t < m.triangles.size(); ++t)
      for (uint32_t n : m.triangles[t]) of_node[n].push_back(t);
  }
  // d(s, triangles sharing a node with triangle t): an upper bound of d(s, mesh).
  double Distance(const Eigen::Vector3d& s, uint32_t t) const {
    double best = INFINITY;
    for (uint32_t n : m.triangles[t])
      for (uint32_t r : of_node[n]) {
        const auto& c = m.triangles[r];
        best = std::min(
            best, ClosestPointOnTriangle(s, m.nodes[c[0]].cast<double>(),
                                         m.nodes[c[1]].cast<double>(), m.nodes[c[2]].cast<double>())
                      .squared_distance);
      }
    return std::sqrt(best);
  }
};

// One sample: S = S(uv) on the exact surface at the interpolated UV, P the
// flat triangle's point with the same weights. |S - P| bounds both d(S, mesh)
// and d(P, surface). Where the parametrisation is far from linear (a cone's
// apex, a sphere's pole) that bound is loose, so above `loose_mm` each
// direction is bounded on its own: d(S, the triangles around this one), and
// d(P, surface) by a local projection from uv, then, if that stays loose
// (it can stop at the apex), OCCT's global point-surface extrema.
struct Sampler {
  const TopoDS_Face& face;
  const BRepAdaptor_Surface& surface;
  double loose_mm;
  Extrema_GenLocateExtPS local;
  std::optional<Extrema_ExtPS> global;
  std::optional<FaceRing> ring;

  double ToSurface(const gp_Pnt& p, double u, double v, double bound) {
    local.Perform(p, u, v);
    if (local.IsDone()) bound = std::min(bound, std::sqrt(local.SquareDistance()));
    if (bound <= loose_mm) return bound;
    if (!global) {
      double u0, u1, v0, v1;
      BRepTools::UVBounds(face, u0, u1, v0, v1);
      global.emplace();
      global->SetFlag(Extrema_ExtFlag_MIN);
      global->Initialize(surface, u0, u1, v0, v1, 1e-9, 1e-9);
    }
    global->Perform(p);
    if (global->IsDone())
      for (int k = 1; k <= global->NbExt(); ++k)
        bound = std::min(bound, std::sqrt(global->SquareDistance(k)));
    return bound;
  }

  // The sample's error; `worst` is the face's largest so far. A tightened
  // value is never above `direct`, so where `direct` cannot raise the
  // largest, tightening is skipped: the face's error is the same, bit for
  // bit, and most samples of a curved face need no extrema.
  double Error(const MeshedFace& m, uint32_t t, double u, double v, const Eigen::Vector3d& p,
               double worst) {
    const Eigen::Vector3d s = Vec(surface.Value(u, v));
    const double direct = (s - p).norm();
    if (direct <= std::max(loose_mm, worst)) return direct;
    if (!ring) ring.emplace(m);
    return std::max(ring->Distance(s, t), ToSurface(gp_Pnt(p.x(), p.y(), p.z()), u, v, direct));
  }
};

double InteriorError(const TopoDS_Face& face, const BRepAdaptor_Surface& surface,
                     const Poly_Triangulation& tri, const MeshedFace& m, double loose_mm) {
  const int level = surface.GetType() == GeomAbs_Plane ? 1 : kLevel;  // a plane is affine in UV
  Sampler sampler{face,         surface,     loose_mm, Extrema_GenLocateExtPS(surface),
                  std::nullopt, std::nullopt};
  double worst = 0;
  for (int t = 1; t <= tri.NbTriangles(); ++t) {
    int n[3];
    tri.Triangle(t).Get(n[0], n[1], n[2]);
    Eigen::Vector3d corner[3];
    gp_Pnt2d uv[3];
    for (int c = 0; c < 3; ++c)
      corner[c] = m.nodes[n[c] - 1].cast<double>(), uv[c] = tri.UVNode(n[c]);
    for (int i = 0; i <= level; ++i)
      for (int j = 0; i + j <= level; ++j) {
        const double w[3] = {double(i) / level, double(j) / level, double(level - i - j) / level};
        const double u = w[0] * uv[0].X() + w[1] * uv[1].X() + w[2] * uv[2].X();
        const double v = w[0] * uv[0].Y() + w[1] * uv[1].Y() + w[2] * uv[2].Y();
        const Eigen::Vector3d p = w[0] * corner[0] + w[1] * corner[1] + w[2] * corner[2];
        worst = std::max(worst, sampler.Error(m, static_cast<uint32_t>(t - 1), u, v, p, worst));
      }
  }
  return worst;
}

// Each boundary edge's exact curve against the polyline of mesh nodes that
// replaced it: the part of the face between the curve and its chords.
double EdgeError(const TopoDS_Face& face, const Handle(Poly_Triangulation) & tri,
                 const TopLoc_Location& loc, const MeshedFace& m) {
  double worst = 0;
  for (TopExp_Explorer e(face, TopAbs_EDGE); e.More(); e.Next()) {
    const TopoDS_Edge& edge = TopoDS::Edge(e.Current());
    if (BRep_Tool::Degenerated(edge)) continue;
    const Handle(Poly_PolygonOnTriangulation) poly =
        BRep_Tool::PolygonOnTriangulation(edge, tri, loc);
    if (poly.IsNull() || !poly->HasParameters() || !BRep_Tool::IsGeometric(edge)) continue;
    const BRepAdaptor_Curve curve(edge);
    for (int i = 1; i < poly->NbNodes(); ++i) {
      const Eigen::Vector3d a = m.nodes[poly->Node(i) - 1].cast<double>();
      const Eigen::Vector3d b = m.nodes[poly->Node(i + 1) - 1].cast<double>();
      const double t0 = poly->Parameter(i), t1 = poly->Parameter(i + 1);
      for (int s = 0; s <= kLevel; ++s)
        worst =
            std::max(worst, SegmentDistance(Vec(curve.Value(t0 + (t1 - t0) * s / kLevel)), a, b));
    }
  }
  return worst;
}

}  // namespace

MeshedFace MeasureMeshedFace(const TopoDS_Face& face, double loose_mm) {
  MeshedFace m;
  TopLoc_Location loc;
  const Handle(Poly_Triangulation) tri = BRep_Tool::Triangulation(face, loc);
  if (tri.IsNull() || tri->NbTriangles() == 0 || !tri->HasUVNodes()) {
    m.error_mm = std::numeric_limits<double>::infinity();
    return m;
  }
  const gp_Trsf trsf = loc.Transformation();
  m.nodes.reserve(tri->NbNodes());
  for (int i = 1; i <= tri->NbNodes(); ++i) {
    const gp_Pnt p = tri->Node(i).Transformed(trsf);
    m.nodes.emplace_back(static_cast<float>(p.X()), static_cast<float>(p.Y()),
                         static_cast<float>(p.Z()));
  }
  const bool reversed = face.Orientation() == TopAbs_REVERSED;
  for (int t = 1; t <= tri->NbTriangles(); ++t) {
    int a, b, c;
    tri->Triangle(t).Get(a, b, c);
    if (reversed) std::swap(b, c);
    m.triangles.push_back({uint32_t(a - 1), uint32_t(b - 1), uint32_t(c - 1)});
  }
  const BRepAdaptor_Surface surface(face);
  m.error_mm =
      std::max(InteriorError(face, surface, *tri, m, loose_mm), EdgeError(face, tri, loc, m));
  return m;
}

}  // namespace surfinspect::occt
