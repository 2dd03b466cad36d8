// The leaf blocks' lanes (declared in core/distance/wide_bvh.h): the float
// copy of each triangle that the search's leaf bound reads, with the slack
// that keeps the float bound below the exact one.
#include <algorithm>
#include <cstring>

#include "core/distance/prism_bound.h"
#include "core/distance/wide_bvh.h"

namespace surfinspect {
namespace {

// The extra slack for the leaf's float copies of n and m_k: each component
// is off by at most 2^-24 of itself, so a dot product with p - v by at most
// 2^-24 |p - v|_1. 2e-7 is more than three times that.
constexpr double kFloatStorageSlack = 2e-7;
// And for computing the bound in float: 4 2^-24 |p - v|_1 per term, plus
// the roundings of the slack's product and the subtractions, 1e-6 is more
// than twice all of them (wide_bvh_search.cpp).
constexpr double kFloatArithmeticSlack = 1e-6;
// Beyond 1 a slack zeroes a term in any case; the cap keeps its product's
// error inside the query's leaf margin.
constexpr float kMaxSlack = 2;

}  // namespace

wide::LeafBlock EmptyLeafBlock() {
  wide::LeafBlock block;
  std::memset(&block, 0, sizeof block);
  std::fill(block.triangle, block.triangle + wide::kLeafWidth, UINT32_MAX);
  return block;
}

void FillLeafLane(wide::LeafBlock& block, int lane, uint32_t t, const Eigen::Vector3f& a,
                  const Eigen::Vector3f& b, const Eigen::Vector3f& c, const Eigen::Vector3d& n,
                  TriangleShape shape) {
  const PrismBound bound = MakePrismBound(a.cast<double>(), b.cast<double>(), c.cast<double>(), n);
  const Eigen::Vector3f* v[3] = {&a, &b, &c};
  for (int axis = 0; axis < 3; ++axis) {
    for (int k = 0; k < 3; ++k) {
      block.vertex[k][axis][lane] = (*v[k])[axis];
      block.edge[k][axis][lane] = static_cast<float>(bound.edge[k][axis]);
    }
    block.normal[axis][lane] = static_cast<float>(n[axis]);
  }
  block.slack[lane] =
      std::min(RoundUpToFloat(bound.slack + kFloatStorageSlack + kFloatArithmeticSlack), kMaxSlack);
  block.triangle[lane] = t;
  block.shape[lane] = static_cast<uint8_t>(shape);
}

void LeafBounds2(SearchIsa isa, const wide::LeafBlock& block, const Eigen::Vector3d& p,
                 float out[wide::kLeafWidth]) {
  const float q[3] = {static_cast<float>(p.x()), static_cast<float>(p.y()),
                      static_cast<float>(p.z())};
  if (ResolveSearchIsa(isa) == SearchIsa::kAvx2 && SearchIsaSupported(SearchIsa::kAvx2))
    wide::avx2::BlockBounds2(block, q, LeafMargin(p), out);
  else
    wide::sse2::BlockBounds2(block, q, LeafMargin(p), out);
}

}  // namespace surfinspect
