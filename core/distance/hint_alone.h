// The proof that a query's hint triangle alone is its closest triangle, so
// that no other triangle needs to be offered: the geometry behind
// HintCertificate's rise (core/distance/hint_certificate.h).
//
// Let the kernel put p's closest point on the hint h at q inside h's face,
// at distance d, with p on side σ of h's plane (unit normal n). Take a
// triangle U of h's ring (it shares a vertex position with h) that lies in
// G_k, the half-space beyond h's edge line k widened by η. With m and e the
// line's unit outward normal and direction in the plane, δ_k the distance
// from q to G_k, t(u) >= 0 how far u lies inside G_k and s(u) >= 0 how far
// past an end of edge k along the line (0 unless all of U lies past that
// end, and only where h's angles at both ends are at most 90 degrees, so
// that q projects inside the edge), Bessel's inequality gives
//   |q - u|^2 >= (m.(u - q))^2 + (e.(u - q))^2 >= (δ_k + t)^2 + s^2.
// The rise of u above the plane on p's side, σn.(u - q), is at most
// α + β t + γ s on all of U when it is at U's corners (both sides are
// affine in u on U), with α, β, γ >= 0 fitted at build time. Then
//   |p - u|^2 - d^2 = |q - u|^2 - 2 d σn.(u - q)
//                   >= (δ_k + t)^2 - 2 d (α + β t) + s^2 - 2 d γ s,
// smallest at t* = max(0, d β - δ_k) and s* = d γ, where it is
//   g = (δ_k + t*)^2 - 2 d (α + β t*) - (d γ)^2.
// So U is farther from p than h whenever g > 0: a flat or convex ring
// (α = β = γ = 0) only needs q off the edge line; on a curved one, whose
// rise grows with the distance from the line (β) and from the edge's ends
// (γ), about the curvature times the ring's width, q must lie a little
// inside, about d β / 2 + d γ. An edge neighbour lies beyond its
// shared edge's line; a neighbour at one corner lies beyond one of the two
// lines through it, or beyond their union, which holds when its two other
// corners w1 (beyond line 1) and w2 (beyond line 2) satisfy F1(w1) F2(w2)
// >= F1(w2) F2(w1), F_i the signed distance beyond line i (the cone they
// span then misses the wedge between the lines). The part of such a
// neighbour beyond each line is covered by that line's test, with the fit
// taken on all three of its corners.
//
// The fit per edge line and side: β the largest slope rise / t over the
// corners of the neighbours placed beyond that line that lie at least a
// tenth of the edge's length inside G_k and not past an end, γ the largest
// (rise - β t) / s over those at least a tenth past an end, then α the
// least that covers every such corner. On the bench's torus this proves
// the hint alone for 98% of the certified scan points, against 71% with the
// rise bounded by its largest value. Every comparison carries margins (η, the
// kernel's and the normal's rounding, a gap of 1e-10 of the coordinates'
// square) that put the proof's inequalities far above the double
// kernel's rounding, so the kernel's computed distances order the
// triangles as the proof does: the answer equals the tree's bit for bit.
// Slivers and degenerate triangles, and a triangle whose ring has a
// neighbour that fits none of the cases (a fold over its face, a
// duplicate), get no such proof.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "core/types/triangle_mesh.h"

namespace surfinspect {

// What the proof keeps per triangle, [side +n, -n][edge AB, BC, CA],
// rounded up: the fit α |e_k|^2 (mm^3), β |e_k| and γ |e_k| (mm), in which
// units the test reads T = t |e_k| and S = s |e_k| (mm^2) and compares
// squared lengths times |e_k|^2.
struct HintRise {
  float base[2][3] = {};   // α |e_k|^2
  float slope[2][3] = {};  // β |e_k|
  float end[2][3] = {};    // γ |e_k|
  float tol_mm = 0;        // η plus the build's rounding margin, rounded up
  float longest_edge_mm = 0;
  bool valid = false;  // false: the hint never proves itself alone
};

// The most ring entries a rise is computed over, repeats included; a
// larger ring gets no proof. A certificate's ring holds at most 48
// triangles (HintCertificate::kMaxBlocks blocks of 8 lanes), and it lists
// each once per corner star it is in.
constexpr std::size_t kMaxRiseRing = 3 * 48;

// The rise of triangle `t` (unit normal `n`) over the triangles `ring`
// (those sharing a vertex position with t; t itself and repeats are
// skipped). `weld` maps vertices to their position's representative.
HintRise ComputeHintRise(const TriangleMesh& mesh, const std::vector<uint32_t>& weld, uint32_t t,
                         const Eigen::Vector3d& n, const uint32_t* ring, std::size_t ring_size);

// True when no triangle of t's ring is as close to p as t, given the
// kernel's answer on t: closest point q inside the face (feature kFace) at
// distance d; `n` is t's unit normal, as above.
bool RingIsFarther(const HintRise& rise, const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                   double d, const Eigen::Vector3d& n, const TriangleMesh& mesh, uint32_t t);

}  // namespace surfinspect
