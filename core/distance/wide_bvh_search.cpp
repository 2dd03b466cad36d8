// The wide BVH's nearest-first search (core/distance/wide_bvh.h), compiled
// once per instruction set: SURFINSPECT_WIDE_ISA names the namespace, and
// the build adds that set's flags (-mavx2 -mfma for avx2, none for sse2)
// and -ffp-contract=off, so no multiply-add is fused differently in one
// set than in another. The code is written in GCC vector extensions, so
// the same operations in the same order run 8 floats wide in one AVX2
// register or in two SSE2 registers: every lane computes the same
// IEEE values in both.
//
// Boxes (float): the gap to a box along an axis is max(lo - p, p - hi, 0)
// with p rounded to float, squared and summed in float. Against the exact
// distance D from the double point to the box, the computed value d2'
// satisfies sqrt(d2') <= (D + sqrt(3) 2^-24 s)(1 + 3 2^-24), s the largest
// |coordinate| of p (rounding p, then four float operations per lane). A
// box is culled only when d2' exceeds the search radius squared, and the
// caller pads that radius to best (1 + 1e-6) + 1e-6 s + 1e-9 mm, more than
// ten times the float error, so a culled box holds no triangle at or
// below the best distance: the true minimiser and every exact tie are
// always reached.
//
// Leaves (float): the prism bound of core/distance/prism_bound.h, eight
// triangles at a time, from p rounded to float. With u = 2^-24, each of its
// terms t = n.(p - v) (n the face normal or an edge normal, |n_i| <= 1) is
// computed within u |p|_1 (rounding p) + 4u |p - v|_1 (the subtraction,
// three products, two sums) of its value at the double point. Each lane's
// slack holds the double bound's, plus 2e-7 for storing n as floats, plus
// 1e-6 for that arithmetic, times |p - v|_1, capped at 2 (a slack of 1
// already zeroes a term); the query's leaf margin, 8u |p|_1 rounded up,
// covers rounding p and its effect on the slack's own product
// (leaf_block.cpp). So each term, and
// with it below and out, lands at or under its exact value, and the float
// below^2 + out^2 at most 3u over the exact squared bound. Lanes are culled
// only against the padded box radius above, at least (1 + 2e-6) times the
// best squared distance: every triangle at or below the best distance is
// offered to the exact kernel.
#include <immintrin.h>  // gnu_inline intrinsics only: nothing out of line is emitted

#include <cstdint>
#include <cstring>

#include "core/distance/wide_bvh_layout.h"

#ifndef SURFINSPECT_WIDE_ISA
#error "compiled once per instruction set, with SURFINSPECT_WIDE_ISA naming it"
#endif

namespace surfinspect::wide::SURFINSPECT_WIDE_ISA {
namespace {

// Inlined into the search, so the vectors stay in registers.
#define SURFINSPECT_INLINE inline __attribute__((always_inline))

typedef float F8 __attribute__((vector_size(32)));
typedef int32_t I8 __attribute__((vector_size(32)));

// Arithmetic is written with the vector operators; what GCC would lower
// lane by lane on SSE2 (comparisons, max) goes through these, which use the
// same instruction semantics in both sets (maxps, cmpleps).
#ifdef __AVX2__
SURFINSPECT_INLINE F8 Max(F8 a, F8 b) {
  return reinterpret_cast<F8>(
      _mm256_max_ps(reinterpret_cast<__m256>(a), reinterpret_cast<__m256>(b)));
}
// Bit i set when lane i of v is <= limit.
SURFINSPECT_INLINE uint32_t LessEqualMask(F8 v, float limit) {
  return static_cast<uint32_t>(_mm256_movemask_ps(
      _mm256_cmp_ps(reinterpret_cast<__m256>(v), _mm256_set1_ps(limit), _CMP_LE_OQ)));
}
#else
template <class V, class H>
SURFINSPECT_INLINE void Split(V v, H half[2]) {
  std::memcpy(half, &v, sizeof v);
}
template <class V, class H>
SURFINSPECT_INLINE V Join(const H half[2]) {
  V v;
  std::memcpy(&v, half, sizeof v);
  return v;
}
// op(a, b) on each 128-bit half.
template <class H, class V, class Op>
SURFINSPECT_INLINE V PerHalf(V a, V b, Op op) {
  H x[2], y[2], m[2];
  Split(a, x);
  Split(b, y);
  for (int i = 0; i < 2; ++i) m[i] = op(x[i], y[i]);
  return Join<V>(m);
}
SURFINSPECT_INLINE F8 Max(F8 a, F8 b) {
  return PerHalf<__m128>(a, b, [](__m128 x, __m128 y) { return _mm_max_ps(x, y); });
}
SURFINSPECT_INLINE uint32_t LessEqualMask(F8 v, float limit) {
  __m128 x[2];
  Split(v, x);
  const __m128 l = _mm_set1_ps(limit);
  return static_cast<uint32_t>(_mm_movemask_ps(_mm_cmple_ps(x[0], l)) |
                               (_mm_movemask_ps(_mm_cmple_ps(x[1], l)) << 4));
}
#endif

SURFINSPECT_INLINE F8 LoadF8(const float* p) {
  F8 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

SURFINSPECT_INLINE F8 Abs(F8 v) {
  return reinterpret_cast<F8>(reinterpret_cast<I8>(v) & (I8{} + INT32_MAX));
}

// The float squared distance from the point to each of the node's boxes.
SURFINSPECT_INLINE F8 BoxDistance2(const Node& node, const F8 p[3]) {
  F8 d2 = {};
  for (int axis = 0; axis < 3; ++axis) {
    const F8 below = LoadF8(node.lo[axis]) - p[axis];
    const F8 above = p[axis] - LoadF8(node.hi[axis]);
    const F8 gap = Max(Max(below, above), F8{});
    d2 += gap * gap;
  }
  return d2;
}

// below^2 + out^2 per lane (prism_bound.h), in float, never above the
// exact squared bound by more than 3u of it (see the top of this file).
SURFINSPECT_INLINE F8 Bounds2(const LeafBlock& block, const F8 p[3], float margin) {
  F8 d[3][3];  // p - vertex k
  F8 l1[3];    // |p - vertex k|_1
  for (int k = 0; k < 3; ++k) {
    for (int axis = 0; axis < 3; ++axis) d[k][axis] = p[axis] - LoadF8(block.vertex[k][axis]);
    l1[k] = Abs(d[k][0]) + Abs(d[k][1]) + Abs(d[k][2]);
  }
  const F8 slack = LoadF8(block.slack);
  const F8 m = F8{} + margin;
  const F8 below = Max(Abs(LoadF8(block.normal[0]) * d[0][0] + LoadF8(block.normal[1]) * d[0][1] +
                           LoadF8(block.normal[2]) * d[0][2]) -
                           slack * l1[0] - m,
                       F8{});
  F8 out = {};
  for (int k = 0; k < 3; ++k)
    out = Max(LoadF8(block.edge[k][0]) * d[k][0] + LoadF8(block.edge[k][1]) * d[k][1] +
                  LoadF8(block.edge[k][2]) * d[k][2] - slack * l1[k] - m,
              out);
  return below * below + out * out;
}

// The lanes of one block set in `lanes`, each offered unless its bound
// exceeds the radius.
SURFINSPECT_INLINE void VisitBlock(const LeafBlock& block, uint32_t lanes, const F8 p[3],
                                   Query& q) {
  const F8 bound2 = Bounds2(block, p, q.leaf_margin);
  uint32_t mask = LessEqualMask(bound2, q.box_radius2) & lanes;
  while (mask != 0) {
    // The smallest bound first: it is the likeliest to be the answer, and
    // the radius it leaves culls the other lanes before their kernel.
    int lane = __builtin_ctz(mask);
    for (uint32_t rest = mask & (mask - 1); rest != 0; rest &= rest - 1) {
      const int other = __builtin_ctz(rest);
      if (bound2[other] < bound2[lane]) lane = other;
    }
    mask &= ~(1u << lane);
    q.offer(q, block, lane);
    mask &= LessEqualMask(bound2, q.box_radius2);
  }
}

// The leaf of lanes [first, first + count), which lie in one block (the
// builder never lets a leaf cross a block boundary).
SURFINSPECT_INLINE void VisitLeaf(const View& view, uint32_t first, uint32_t count, const F8 p[3],
                                  Query& q) {
  VisitBlock(view.blocks[first / kLeafWidth], ((1u << count) - 1) << (first % kLeafWidth), p, q);
}

struct Entry {
  float d2;
  uint32_t child;
  uint32_t leaf_triangles;  // 0 for a node
};

SURFINSPECT_INLINE Entry ChildEntry(const Node& node, const float d2[kWidth], int i) {
  return {d2[i], node.child[i], node.leaf_triangles[i]};
}

// Visits the node: its children within the radius go nearest first into
// `next`, the others onto the stack, farthest deepest (equal distances in
// slot order). Returns false when no child is within the radius. Most
// nodes on a query's path have one or two such children, which skip the
// sort.
SURFINSPECT_INLINE bool Descend(const Node& node, const F8 p[3], float radius2, Entry& next,
                                Entry* stack, int& top) {
  const F8 d2v = BoxDistance2(node, p);
  uint32_t mask = LessEqualMask(d2v, radius2) & ((1u << node.count) - 1);
  if (mask == 0) return false;
  float d2[kWidth];
  std::memcpy(d2, &d2v, sizeof d2);
  const int first = __builtin_ctz(mask);
  const uint32_t rest = mask & (mask - 1);
  if (rest == 0) {
    next = ChildEntry(node, d2, first);
    return true;
  }
  if ((rest & (rest - 1)) == 0) {  // two: the nearer next, the lower slot on a tie
    const int second = __builtin_ctz(rest);
    const bool swap = d2[second] < d2[first];
    next = ChildEntry(node, d2, swap ? second : first);
    stack[top++] = ChildEntry(node, d2, swap ? first : second);
    return true;
  }
  uint8_t order[kWidth];  // slots by distance, a stable insertion sort
  int n = 0;
  for (; mask != 0; mask &= mask - 1) {
    const int i = __builtin_ctz(mask);
    int j = n++;
    for (; j > 0 && d2[order[j - 1]] > d2[i]; --j) order[j] = order[j - 1];
    order[j] = static_cast<uint8_t>(i);
  }
  for (int j = n - 1; j >= 1; --j) stack[top++] = ChildEntry(node, d2, order[j]);
  next = ChildEntry(node, d2, order[0]);
  return true;
}

}  // namespace

void Search(const View& view, Query& q) {
  const F8 p[3] = {F8{} + q.pf[0], F8{} + q.pf[1], F8{} + q.pf[2]};
  Entry stack[kStackSize];
  int top = 0;
  Entry next{0.f, 0, 0};  // the root
  for (;;) {
    if (next.d2 <= q.box_radius2) {
      if (next.leaf_triangles != 0) {
        VisitLeaf(view, next.child, next.leaf_triangles, p, q);
      } else if (Descend(view.nodes[next.child], p, q.box_radius2, next, stack, top)) {
        continue;
      }
    }
    if (top == 0) return;
    next = stack[--top];
  }
}

void VisitLanes(const View& view, uint32_t block, uint32_t lanes, Query& q) {
  const F8 p[3] = {F8{} + q.pf[0], F8{} + q.pf[1], F8{} + q.pf[2]};
  VisitBlock(view.blocks[block], lanes, p, q);
}

void BlockBounds2(const LeafBlock& block, const float p[3], float margin, float out[kLeafWidth]) {
  const F8 pv[3] = {F8{} + p[0], F8{} + p[1], F8{} + p[2]};
  const F8 bound2 = Bounds2(block, pv, margin);
  for (int lane = 0; lane < kLeafWidth; ++lane) out[lane] = bound2[lane];
}

}  // namespace surfinspect::wide::SURFINSPECT_WIDE_ISA
