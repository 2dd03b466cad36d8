#include "core/distance/hint_certificate.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace surfinspect {
namespace {

// Triangles around each vertex position: the stars, in compressed rows
// indexed by the representative vertex.
struct Stars {
  std::vector<uint32_t> start;  // representative r's triangles: [start[r], start[r + 1])
  std::vector<uint32_t> triangles;
};

Stars BuildStars(const TriangleMesh& mesh, const std::vector<uint32_t>& weld) {
  Stars s;
  s.start.assign(mesh.vertices.size() + 1, 0);
  for (const Triangle& tri : mesh.triangles)
    for (int k = 0; k < 3; ++k) ++s.start[weld[tri[k]] + 1];
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) s.start[v + 1] += s.start[v];
  s.triangles.resize(s.start.back());
  std::vector<uint32_t> next(s.start.begin(), s.start.end() - 1);
  for (uint32_t t = 0; t < mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) s.triangles[next[weld[mesh.triangles[t][k]]]++] = t;
  return s;
}

// Global lane (block * 8 + lane) of each triangle.
std::vector<uint32_t> LaneOfTriangle(const WideBvh& bvh, std::size_t triangles) {
  std::vector<uint32_t> lane_of(triangles, UINT32_MAX);
  const auto& blocks = bvh.blocks();
  for (std::size_t b = 0; b < blocks.size(); ++b)
    for (int lane = 0; lane < wide::kLeafWidth; ++lane)
      if (blocks[b].triangle[lane] < triangles)
        lane_of[blocks[b].triangle[lane]] = static_cast<uint32_t>(b * wide::kLeafWidth + lane);
  return lane_of;
}

// T's ring: the triangles of its corners' stars (T and repeats included).
void CollectRing(const Stars& stars, const Triangle& tri, const std::vector<uint32_t>& weld,
                 std::vector<uint32_t>& ring) {
  ring.clear();
  for (int k = 0; k < 3; ++k) {
    const uint32_t r = weld[tri[k]];
    ring.insert(ring.end(), stars.triangles.begin() + stars.start[r],
                stars.triangles.begin() + stars.start[r + 1]);
  }
}

// The one other triangle on each of T's edges, if only one.
void SetAcross(const Stars& stars, const TriangleMesh& mesh, const std::vector<uint32_t>& weld,
               uint32_t t, HintCertificate& c) {
  const Triangle& tri = mesh.triangles[t];
  for (int k = 0; k < 3; ++k) {
    const uint32_t from = weld[tri[k]], to = weld[tri[(k + 1) % 3]];
    uint32_t found = UINT32_MAX;
    int count = 0;
    for (uint32_t i = stars.start[from]; i < stars.start[from + 1]; ++i) {
      const uint32_t u = stars.triangles[i];
      if (u == t || u == found) continue;
      const Triangle& other = mesh.triangles[u];
      if (weld[other[0]] == to || weld[other[1]] == to || weld[other[2]] == to) {
        found = u;
        ++count;
      }
    }
    c.across[k] = count == 1 ? found : UINT32_MAX;
  }
}

// Sets `c`'s blocks and lanes to the ring's; false when they span more
// than kMaxBlocks blocks.
bool SetRingLanes(const std::vector<uint32_t>& ring, const std::vector<uint32_t>& lane_of,
                  HintCertificate& c) {
  for (const uint32_t triangle : ring) {
    const uint32_t lane = lane_of[triangle];
    if (lane == UINT32_MAX) return false;
    const uint32_t block = lane / wide::kLeafWidth;
    const auto bit = static_cast<uint8_t>(1u << (lane % wide::kLeafWidth));
    int j = 0;
    while (j < c.blocks && c.block[j] != block) ++j;
    if (j == c.blocks) {
      if (c.blocks == HintCertificate::kMaxBlocks) return false;
      c.block[c.blocks++] = block;
    }
    c.lanes[j] |= bit;
  }
  return true;
}

struct OutsideSearch {
  const wide::LeafBlock* blocks;
  const HintCertificate* ring;
  Eigen::Vector3d m;
  double coordinate_scale;
};

// Offers only the triangles outside the ring; keeps the smallest squared
// distance and shrinks the radius to it.
bool OfferOutside(wide::Query& q, const wide::LeafBlock& block, int lane) {
  const auto& s = *static_cast<const OutsideSearch*>(q.context);
  const auto b = static_cast<uint32_t>(&block - s.blocks);
  for (int j = 0; j < s.ring->blocks; ++j)
    if (s.ring->block[j] == b && (s.ring->lanes[j] >> lane & 1u)) return false;
  Eigen::Vector3d v[3];
  LaneVertices(block, lane, v);
  const double d2 =
      ClosestPointOnTriangle(s.m, v[0], v[1], v[2], static_cast<TriangleShape>(block.shape[lane]))
          .squared_distance;
  if (!(d2 < q.best_d2)) return false;
  q.best_d2 = d2;
  q.box_radius2 = SearchRadius2(std::sqrt(d2), s.coordinate_scale);
  return true;
}

float RoundDownToFloat(double v) {
  const float f = static_cast<float>(v);
  return static_cast<double>(f) <= v ? f : std::nextafter(f, -INFINITY);
}

// Sets c's anchor m, T's centroid, and its reach D(T): min over U outside
// the ring of dist(m, U), capped at (1 + kCapRadii) r, lowered by margins
// over the kernel's rounding and rounded down to float; 0 when not
// positive.
void SetReach(const WideBvh& bvh, const Eigen::Vector3d v[3], HintCertificate& c) {
  const Eigen::Vector3d m = (v[0] + v[1] + v[2]) / 3;
  const Eigen::Vector3f mf = m.cast<float>();
  for (int a = 0; a < 3; ++a) c.anchor[a] = m[a];
  double r = 0, scale = m.cwiseAbs().maxCoeff();
  for (int k = 0; k < 3; ++k) {
    r = std::max(r, (v[k] - m).norm());
    scale = std::max(scale, v[k].cwiseAbs().maxCoeff());
  }
  const double cap = r * (1 + HintCertificates::kCapRadii);
  OutsideSearch s{bvh.blocks().data(), &c, m, scale};
  wide::Query q{{m.x(), m.y(), m.z()},
                {mf.x(), mf.y(), mf.z()},
                cap * cap,
                SearchRadius2(cap, scale),
                LeafMargin(m),
                &s,
                &OfferOutside};
  c.reach_mm = 0;
  if (!mf.allFinite() || !std::isfinite(cap)) return;
  // Every triangle outside the ring that the search did not keep is at
  // least sqrt(best_d2) from m (cap when it kept none).
  bvh.Search(q);
  const double reach = std::sqrt(q.best_d2) * (1 - 1e-9) - 1e-9 * scale;
  c.reach_mm = reach > 0 ? RoundDownToFloat(reach) : 0;
}

}  // namespace

HintCertificates HintCertificates::Build(const TriangleMesh& mesh,
                                         const std::vector<uint32_t>& weld,
                                         const std::vector<Eigen::Vector3d>& face_normals,
                                         const WideBvh& bvh) {
  HintCertificates out;
  const std::size_t n = mesh.triangles.size();
  const Stars stars = BuildStars(mesh, weld);
  const std::vector<uint32_t> lane_of = LaneOfTriangle(bvh, n);
  out.entries_.resize(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      std::vector<uint32_t> ring;
                      for (std::size_t t = range.begin(); t != range.end(); ++t) {
                        HintCertificate& c = out.entries_[t];
                        CollectRing(stars, mesh.triangles[t], weld, ring);
                        if (!SetRingLanes(ring, lane_of, c)) {
                          c = HintCertificate{};
                          continue;
                        }
                        Eigen::Vector3d v[3];
                        for (int k = 0; k < 3; ++k)
                          v[k] = mesh.vertices[mesh.triangles[t][k]].cast<double>();
                        SetReach(bvh, v, c);
                        // Without a reach the rise would never be asked.
                        if (c.reach_mm > 0)
                          c.rise = ComputeHintRise(mesh, weld, static_cast<uint32_t>(t),
                                                   face_normals[t], ring.data(), ring.size());
                        SetAcross(stars, mesh, weld, static_cast<uint32_t>(t), c);
                      }
                    });
  for (const HintCertificate& c : out.entries_) {
    out.certifiable_ += c.reach_mm > 0;
    out.alone_ += c.reach_mm > 0 && c.rise.valid;
  }
  return out;
}

}  // namespace surfinspect
