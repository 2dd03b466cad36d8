// The memory layout of the wide BVH (core/distance/wide_bvh.h) and the entry
// points of its search, which is compiled once per instruction set
// (core/distance/wide_bvh_search.cpp). Plain types only: the per-ISA
// translation units include nothing else, so no inline function compiled
// with AVX2 can be merged by the linker into code that runs without it.
#pragma once

#include <cstdint>

namespace surfinspect {

// Which compiled search a mesh index uses; kAuto picks the widest this CPU
// runs (core/distance/wide_bvh.h).
enum class SearchIsa { kAuto, kSse2, kAvx2 };
// Embree's build quality for a mesh index (MeshIndexSettings::build_quality).
enum class BvhQuality { kLow, kMedium, kHigh };

}  // namespace surfinspect

namespace surfinspect::wide {

constexpr int kWidth = 8;             // children per node: one 256-bit register of floats
constexpr int kLeafWidth = 8;         // triangles per leaf block: one 256-bit register of floats
constexpr int kMaxLeafTriangles = 8;  // Embree's leaves; they are packed into blocks
constexpr int kMaxDepth = 64;         // passed to the builder, which fails beyond it
constexpr int kStackSize = kMaxDepth * (kWidth - 1) + kWidth;

// Eight child boxes in structure-of-arrays form. The boxes are the exact
// float bounds of the child's triangles (the vertices are floats).
struct alignas(32) Node {
  float lo[3][kWidth];
  float hi[3][kWidth];
  uint32_t child[kWidth];          // an inner child's node index, or a leaf's first lane
  uint8_t leaf_triangles[kWidth];  // 0 for an inner child, else the leaf's triangle count
  uint32_t count;                  // children in use, from the front
};

// Eight consecutive leaf lanes (lane k of block b is lane 8b + k of the
// leaves; a leaf is a run of lanes inside one block), each a
// triangle with what the leaf's lower bound needs, stored as
// floats: the vertices exactly, the unit face normal n and the in-plane
// outward edge normals m_k rounded, which the slack covers
// (core/distance/prism_bound.h).
struct alignas(32) LeafBlock {
  float vertex[3][3][kLeafWidth];  // [vertex a, b, c][axis][lane]
  float normal[3][kLeafWidth];
  float edge[3][3][kLeafWidth];  // [edge AB, BC, CA][axis][lane]
  float slack[kLeafWidth];
  uint32_t triangle[kLeafWidth];  // mesh triangle id; UINT32_MAX in unused lanes
  uint8_t shape[kLeafWidth];      // the kernel's TriangleShape of each lane
};

struct View {
  const Node* nodes = nullptr;  // the root is node 0
  const LeafBlock* blocks = nullptr;
};

// One closest-point search. `offer` runs the exact double kernel on the
// triangle in a block's lane that survived the bounds; when the triangle is
// the new best it lowers best_d2 and box_radius2 and returns true.
struct Query {
  double p[3];
  float pf[3];        // p rounded to float, for the boxes
  double best_d2;     // the best squared distance so far, or the squared limit
  float box_radius2;  // boxes and leaf lanes whose float squared distance exceeds this are culled
  float leaf_margin;  // LeafMargin(p) (core/distance/wide_bvh.h)
  void* context;
  bool (*offer)(Query& query, const LeafBlock& block, int lane);
};

// The search, a visit of chosen lanes of one block (bounds, then the
// offers, as the search visits a leaf) and the leaf bound, one namespace per
// instruction set. Results are the same in each (the tests compare them).
namespace sse2 {
void Search(const View& view, Query& query);
void VisitLanes(const View& view, uint32_t block, uint32_t lanes, Query& query);
void BlockBounds2(const LeafBlock& block, const float p[3], float margin, float out[kLeafWidth]);
}  // namespace sse2
namespace avx2 {
void Search(const View& view, Query& query);
void VisitLanes(const View& view, uint32_t block, uint32_t lanes, Query& query);
void BlockBounds2(const LeafBlock& block, const float p[3], float margin, float out[kLeafWidth]);
}  // namespace avx2

}  // namespace surfinspect::wide
