// The order in which the HTML report stores its shown points, so that the
// viewer can draw any prefix as an evenly spread preview of the whole cloud
// (core/report/viewer/viewer.js draws a prefix while the camera moves).
//
// The points are sorted along the Morton curve of their quantised positions
// and then taken in bit-reversed order of their rank (the van der Corput
// sequence in base 2): with n points and m = 2^b >= n, step r of 0..m-1 takes
// rank reverse_b(r) when it is below n. After the first m / 2^k steps the
// prefix holds exactly the ranks that are multiples of 2^(b-k), every
// 2^(b-k)-th point along the curve, so a prefix of any length covers the
// part at a uniform density instead of one end of it. Deterministic: equal
// inputs give equal orders; equal codes keep their input order.
#pragma once

#include <cstdint>
#include <vector>

namespace surfinspect {

// `xyz` holds 3 quantised coordinates per point of the cloud; `points` are
// indices into it. Returns the same indices, reordered.
std::vector<uint32_t> ProgressiveOrder(const std::vector<uint16_t>& xyz,
                                       const std::vector<uint32_t>& points);

// reverse_b(r): the low `bits` bits of r in reverse order (bits <= 32).
uint32_t ReverseBits(uint32_t r, int bits);

}  // namespace surfinspect
