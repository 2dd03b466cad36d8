// The proof that a query's hint triangle alone is its closest triangle, so
// that no other triangle needs to be offered: the geometry behind
// HintCertificate's rise (core/distance/hint_certificate.h).
//
// Let the kernel put p's closest point on the hint h at q inside h's face,
// at distance d, with p on side σ of h's plane (unit normal n). Take a
// triangle U of h's ring (it shares a vertex position with h) that lies in
// G_k, the half-space beyond h's edge line k widened by η, and rises at
// most H above h's plane on p's side. Every u in U then obeys
//   |p - u|^2 = d^2 + |q - u|^2 - 2 d σn.(u - q) >= d^2 + δ_k^2 - 2 d H+,
// δ_k the distance from q to G_k (|q - u| >= δ_k as u lies in G_k). So U
// is farther from p than h whenever δ_k^2 > 2 d H+: a flat or convex ring
// (H <= 0) only needs q off the edge line, a concave one needs q farther
// in the more p lies above the face. An edge neighbour lies beyond its
// shared edge's line; a neighbour at one corner lies beyond one of the two
// lines through it, or beyond their union, which holds when its two other
// corners w1 (beyond line 1) and w2 (beyond line 2) satisfy
// F1(w1) F2(w2) >= F1(w2) F2(w1), F_i the signed distance beyond line i
// (the cone they span then misses the wedge between the lines).
//
// The rise per edge line and side is the largest H+ of the neighbours
// placed beyond that line. Every comparison carries margins (η, the
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

// What the proof keeps per triangle.
struct HintRise {
  float rise[2][3] = {};  // [side +n, -n][edge AB, BC, CA]: H+ |e_k|^2, mm^3, rounded up
  float tol_mm = 0;       // η plus the build's rounding margin, rounded up
  float longest_edge_mm = 0;
  bool valid = false;  // false: the hint never proves itself alone
};

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
