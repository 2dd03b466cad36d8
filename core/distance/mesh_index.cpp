#include "core/distance/mesh_index.h"

#include <cmath>
#include <cstdint>
#include <cstring>

#include "core/distance/hint_certificate.h"
#include "core/distance/wide_bvh.h"

namespace surfinspect {
namespace {

struct QueryState {
  Eigen::Vector3d p;
  const Eigen::Vector3f* vertices;
  const Triangle* triangles;
  const TriangleShape* shapes;
  const uint32_t* mesh_triangle;  // ties go to the lower mesh id, not position
  double coordinate_scale;
  uint32_t best_triangle = UINT32_MAX;
  PointTriangleResult best;
};

// The float search radius for the best squared distance so far.
float BoxRadius2(const wide::Query& q, const QueryState& s) {
  return SearchRadius2(std::sqrt(q.best_d2), s.coordinate_scale);
}

// The float radius and leaf margin a search culls with: from the best so
// far, or from the distance limit before any triangle is within it.
void PrepareSearch(wide::Query& q, const QueryState& s, double max_distance_mm) {
  q.box_radius2 = s.best_triangle != UINT32_MAX
                      ? BoxRadius2(q, s)
                      : SearchRadius2(max_distance_mm, s.coordinate_scale);
  q.leaf_margin = LeafMargin(s.p);
}

// Keeps the lexicographic minimum of (squared distance, triangle id), so the
// answer does not depend on the order triangles are offered in. Inside a
// search the radius shrinks after each improvement; outside one
// (`in_search` false) it is set once, before the search starts.
bool Consider(wide::Query& q, QueryState& s, uint32_t t, const PointTriangleResult& r,
              bool in_search) {
  const bool better = s.best_triangle == UINT32_MAX
                          ? r.squared_distance <= q.best_d2
                          : r.squared_distance < q.best_d2 ||
                                (r.squared_distance == q.best_d2 &&
                                 s.mesh_triangle[t] < s.mesh_triangle[s.best_triangle]);
  if (!better) return false;
  s.best = r;
  s.best_triangle = t;
  q.best_d2 = r.squared_distance;
  if (in_search) q.box_radius2 = BoxRadius2(q, s);
  return true;
}

// The exact kernel on a triangle the bounds could not rule out, from the
// block's copy of its vertices (the mesh's floats, exactly).
bool OfferLane(wide::Query& q, const wide::LeafBlock& block, int lane) {
  auto& s = *static_cast<QueryState*>(q.context);
  // The best so far (usually the hint) again: the kernel would give the
  // same distance, which is no improvement.
  if (block.triangle[lane] == s.best_triangle) return false;
  Eigen::Vector3d v[3];
  LaneVertices(block, lane, v);
  return Consider(
      q, s, block.triangle[lane],
      ClosestPointOnTriangle(s.p, v[0], v[1], v[2], static_cast<TriangleShape>(block.shape[lane])),
      true);
}

// The hint, or a triangle next to the best so far, from the mesh; true
// when it is the new best.
bool OfferTriangle(wide::Query& q, uint32_t t) {
  auto& s = *static_cast<QueryState*>(q.context);
  const Triangle& tri = s.triangles[t];
  return Consider(q, s, t,
                  ClosestPointOnTriangle(s.p, s.vertices[tri[0]].cast<double>(),
                                         s.vertices[tri[1]].cast<double>(),
                                         s.vertices[tri[2]].cast<double>(), s.shapes[t]),
                  false);
}

// Steps across the edge or corner the best closest point lies on, at most this many
// times: the scan points' hints are mostly one triangle off.
constexpr int kMaxSteps = 2;
// Steps of the walk by edge lines that come before them.
constexpr int kMaxWalk = 3;

}  // namespace

MeshIndex::~MeshIndex() = default;

const Eigen::Vector3d& MeshIndex::Pseudonormal(uint32_t triangle, ClosestFeature feature) const {
  const int k = FeatureIndex(feature);
  if (IsEdge(feature)) return edge_normal_[triangle_edges_[triangle][k]];
  if (IsVertex(feature)) return VertexNormal(weld_[ordered_.triangles[triangle][k]]);
  return face_normal_[triangle];
}

ClosestPoint MeshIndex::Closest(const Eigen::Vector3d& p_in_mesh, double max_distance_mm,
                                uint32_t hint_triangle, QueryPath* path,
                                bool try_certificate) const {
  ClosestPoint out;
  if (path) *path = QueryPath::kTree;
  if (!p_in_mesh.allFinite() || !(max_distance_mm >= 0)) return out;
  QueryState s{p_in_mesh,
               ordered_.vertices.data(),
               ordered_.triangles.data(),
               shape_.data(),
               mesh_triangle_.data(),
               p_in_mesh.cwiseAbs().maxCoeff(),
               UINT32_MAX,
               {}};
  wide::Query q{{p_in_mesh.x(), p_in_mesh.y(), p_in_mesh.z()},
                {static_cast<float>(p_in_mesh.x()), static_cast<float>(p_in_mesh.y()),
                 static_cast<float>(p_in_mesh.z())},
                max_distance_mm * max_distance_mm,
                0,  // the radius and the margin are set before a search needs them
                0,
                &s,
                &OfferLane};
  // Beyond float range the boxes cannot place the point; such a point is unmatched.
  if (!std::isfinite(q.pf[0]) || !std::isfinite(q.pf[1]) || !std::isfinite(q.pf[2])) return out;
  // A good first candidate (the previous point's triangle, or where a walk
  // from it ends) starts the search with a nearly exact radius; the result
  // is the same without it.
  const bool hinted = hint_triangle < mesh_.num_triangles();
  const uint32_t hint = hinted ? position_of_triangle_[hint_triangle] : UINT32_MAX;
  const QueryPath taken =
      hinted && try_certificate && certificates_ ? CertifiedByHint(q, hint) : QueryPath::kTree;
  if (hinted && s.best_triangle == UINT32_MAX) OfferTriangle(q, hint);
  if (taken == QueryPath::kTree) {
    PrepareSearch(q, s, max_distance_mm);
    bvh_->Search(q);
  }
  if (path) *path = taken;
  if (s.best_triangle == UINT32_MAX) return out;

  const uint32_t t = s.best_triangle;
  out.triangle_id = mesh_triangle_[t];
  out.point = s.best.point;
  out.feature = s.best.feature;
  out.distance_mm = std::sqrt(s.best.squared_distance);
  out.normal = face_normal_[t];
  // Bærentzen & Aanæs: sign((p - c) . n) with n the closest feature's
  // pseudonormal. A zero (a fold flat onto itself) falls back to the face.
  const Eigen::Vector3d diff = p_in_mesh - out.point;
  double side = diff.dot(Pseudonormal(t, out.feature));
  if (side == 0) side = diff.dot(face_normal_[t]);
  // The negation as a flip of the sign bit, with no branch: points fall on
  // either side at random (a mispredicted branch per query on the bench).
  uint64_t bits;
  std::memcpy(&bits, &out.distance_mm, sizeof bits);
  bits ^= static_cast<uint64_t>(side < 0) << 63;
  std::memcpy(&out.signed_distance_mm, &bits, sizeof bits);
  return out;
}

// When the hint's certificate proves that the answer is the hint
// (kHintAlone) or lies in the hint's ring (kRing, after offering the ring's
// lanes), `q` holds the answer the whole tree would give
// (core/distance/hint_certificate.h); kTree otherwise.
QueryPath MeshIndex::CertifiedByHint(wide::Query& q, uint32_t hint_triangle) const {
  const auto& s = *static_cast<const QueryState*>(q.context);
  // A point more than twice the hint's reach from its anchor is not a
  // coherent query's: it goes to the tree without a walk.
  if (!certificates_->of(hint_triangle).Near(s.p, 2)) return QueryPath::kTree;
  // Most hints are a triangle off: walking by the edge lines costs less
  // than the kernel on each triangle passed.
  if (!OfferTriangle(q, WalkTowards(hint_triangle, s.p))) return QueryPath::kTree;
  for (int step = 0; step < kMaxSteps && s.best.feature != ClosestFeature::kFace; ++step) {
    // Across the closest edge, or across both edges at the closest corner.
    const HintCertificate& at = certificates_->of(s.best_triangle);
    const int k = FeatureIndex(s.best.feature);
    if (k < 0) break;
    const uint32_t first = at.across[k];
    const uint32_t second = IsVertex(s.best.feature) ? at.across[(k + 2) % 3] : UINT32_MAX;
    bool moved = false;
    if (first != UINT32_MAX) moved |= OfferTriangle(q, first);
    if (second != UINT32_MAX) moved |= OfferTriangle(q, second);
    if (!moved) break;
  }
  const uint32_t t = s.best_triangle;
  const HintCertificate& c = certificates_->of(t);
  const double d = std::sqrt(q.best_d2);
  if (!c.Certifies(s.p, d, s.coordinate_scale)) return QueryPath::kTree;
  if (s.best.feature == ClosestFeature::kFace &&
      RingIsFarther(c.rise, s.p, s.best.point, d, face_normal_[t], ordered_, t))
    return QueryPath::kHintAlone;
  PrepareSearch(q, s, INFINITY);
  for (int j = 0; j < c.blocks; ++j) bvh_->VisitLanes(c.block[j], c.lanes[j], q);
  return QueryPath::kRing;
}

// The edge line of triangle t that p lies beyond, in t's plane: k for edge
// a_k a_k+1, whose outward normal m_k = (a_k+1 - a_k) x n has
// m_k . (p - a_k) > 0 there; where two are, the one p is farther beyond (in
// the edge's length), so each step crosses one edge. -1 when p lies over
// the face, and for a degenerate face (n = 0).
int MeshIndex::EdgeBeyond(uint32_t t, const Eigen::Vector3d& p) const {
  const Triangle& tri = ordered_.triangles[t];
  const Eigen::Vector3d& n = face_normal_[t];
  const Eigen::Vector3d a[3] = {ordered_.vertices[tri[0]].cast<double>(),
                                ordered_.vertices[tri[1]].cast<double>(),
                                ordered_.vertices[tri[2]].cast<double>()};
  int best = -1;
  double best_excess2 = 0, best_len2 = 1;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d e = a[(k + 1) % 3] - a[k];
    const double beyond = e.cross(n).dot(p - a[k]);
    if (!(beyond > 0)) continue;
    // beyond / |e| is the distance past the line: compare those squared.
    const double len2 = e.squaredNorm();
    if (best < 0 || beyond * beyond * best_len2 > best_excess2 * len2) {
      best = k;
      best_excess2 = beyond * beyond;
      best_len2 = len2;
    }
  }
  return best;
}

// From the hint across the edges the point lies beyond, at most
// kMaxWalk triangles: a guess of the closest triangle that only decides
// where the certificate is tried, never the answer.
uint32_t MeshIndex::WalkTowards(uint32_t hint_triangle, const Eigen::Vector3d& p) const {
  uint32_t t = hint_triangle;
  for (int step = 0; step < kMaxWalk; ++step) {
    const int k = EdgeBeyond(t, p);
    if (k < 0) break;
    const uint32_t next = certificates_->of(t).across[k];
    if (next == UINT32_MAX) break;
    t = next;
  }
  return t;
}

std::size_t MeshIndex::memory_bytes() const {
  return sizeof(*this) +
         (mesh_.vertices.capacity() + ordered_.vertices.capacity()) * sizeof(Eigen::Vector3f) +
         (mesh_.triangles.capacity() + ordered_.triangles.capacity()) * sizeof(Triangle) +
         (mesh_triangle_.capacity() + position_of_triangle_.capacity()) * sizeof(uint32_t) +
         face_normal_.capacity() * sizeof(Eigen::Vector3d) + shape_.capacity() +
         triangle_edges_.capacity() * sizeof(triangle_edges_[0]) +
         edge_normal_.capacity() * sizeof(Eigen::Vector3d) + weld_.capacity() * sizeof(uint32_t) +
         (corner_start_.capacity() + corners_.capacity()) * sizeof(uint32_t) +
         vertex_normal_.capacity() * (sizeof(Eigen::Vector3d) + 1) +
         (bvh_ ? bvh_->memory_bytes() : 0) + (certificates_ ? certificates_->memory_bytes() : 0);
}

}  // namespace surfinspect
