// A cheap lower bound on the distance from a point to a triangle, which the
// wide BVH's leaves (core/distance/wide_bvh_search.cpp) cull candidates with
// before the exact kernel (point_triangle.h).
//
// With n the unit face normal and m_k the in-plane outward normal of edge k
// (for a CCW face, edge u->v's is (v - u) x n): the triangle lies in its
// plane and inside each edge's half-plane, so for any point p
//   d(p, T)^2 >= below^2 + out^2,  below = |n.(p - a)|,
//   out = max(0, max_k m_k.(p - v_k))   (the prism bound).
// Rounding: n, computed in double from float vertices for a triangle with
// longest edge L and twice its area 2A, is off in direction by at most about
// 6u L^2 / 2A (u = 2^-53), and m_k by as much again. Each term is lowered by
// slack * |p - vertex|_1 with slack = 1e-12 + 2e-15 L^2 / 2A, which covers
// both with a margin and lies far above the kernel's own rounding, so a
// triangle whose bound exceeds the best distance so far would have lost to
// it in the kernel as well (exact ties are kept). Slivers get a weaker
// bound, never a wrong one. The leaves store n and m_k as floats and add
// 2e-7 to the slack for that rounding (core/distance/leaf_block.cpp).
#pragma once

#include <Eigen/Core>
#include <array>

namespace surfinspect {

struct PrismBound {
  std::array<Eigen::Vector3d, 3> edge{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                      Eigen::Vector3d::Zero()};  // m_AB, m_BC, m_CA
  double slack = 1e-12;
};

// For triangle abc with unit normal `n`; a zero n (a degenerate triangle)
// gives zero edge normals: no bound beyond 0.
PrismBound MakePrismBound(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                          const Eigen::Vector3d& c, const Eigen::Vector3d& n);

}  // namespace surfinspect
