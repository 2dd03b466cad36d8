#include "core/filter/link_row_masks.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "core/filter/link_clustering.h"

namespace surfinspect::link_row {
namespace {

bool Bit(const std::vector<uint64_t>& bits, uint32_t i) { return (bits[i / 64] >> (i % 64)) & 1; }

// Rows of random width with NaN holes, 3/8 mm pitch and heights on a 1/8 mm
// lattice, so a height step of 4/8 puts a pair at exactly d = 5/8 mm (all
// exact in float): every mask bit must equal the scalar PointsLinked,
// ties included (the SIMD path may not round or compare differently).
// Each instruction set's row pass, checked on its own against the scalar
// predicate: core/filter/link_row_masks.cpp (SSE2) and
// core/filter/link_row_masks_avx2.cpp and
// core/filter/link_row_masks_avx512.cpp (only where the CPU has them).
class LinkRowMasks : public ::testing::TestWithParam<RowIsa> {
 protected:
  void SetUp() override {
    if (!RowIsaSupported(GetParam())) GTEST_SKIP() << "this CPU lacks the instruction set";
  }
};

TEST_P(LinkRowMasks, EveryBitEqualsThePointsLinkedPredicate) {
  std::mt19937 rng(4);
  std::uniform_int_distribution<uint32_t> width(1, 200);
  std::uniform_int_distribution<int> lattice(-5, 5);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  const float d = 0.625f, r2 = LinkDistanceSquared(d);
  ASSERT_TRUE(PointsLinked({0, 0, 0}, {0.375f, 0, 0.5f}, r2));  // the tie links
  int ties = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const uint32_t w = width(rng), words = (w + 63) / 64;
    std::vector<Eigen::Vector3f> up_pts(w), cur_pts(w);
    for (auto* row : {&up_pts, &cur_pts})
      for (uint32_t c = 0; c < w; ++c)
        (*row)[c] = u(rng) < 0.1f ? Eigen::Vector3f(NAN, 0.f, 0.f)
                                  : Eigen::Vector3f(0.375f * c, (row == &up_pts ? 0.f : 0.375f),
                                                    0.125f * lattice(rng));
    RowSoA up(64 * words), cur(64 * words);
    Transpose(up_pts.data(), w, up);
    Transpose(cur_pts.data(), w, cur);
    for (uint32_t c = 0; c < w; ++c)
      for (int a = 0; a < 3; ++a) {
        ASSERT_EQ(std::isnan(cur.c(a)[c]), std::isnan(cur_pts[c][a]));
        if (!std::isnan(cur_pts[c][a])) {
          ASSERT_EQ(cur.c(a)[c], cur_pts[c][a]);
        }
      }
    std::vector<uint64_t> storage(5 * words, ~uint64_t{0});
    const RowMasks m = {&storage[0], &storage[words], &storage[2 * words], &storage[3 * words],
                        &storage[4 * words]};
    const bool diagonals = trial % 2 == 0;
    ASSERT_FALSE(ComputeMasks(cur, &up, diagonals, words, r2, m, GetParam()));
    auto bits = [&](const uint64_t* p) { return std::vector<uint64_t>(p, p + words); };
    const auto valid = bits(m.valid), west = bits(m.west), nw = bits(m.north_west),
               n = bits(m.north), ne = bits(m.north_east);
    for (uint32_t c = 0; c < 64 * words; ++c) {
      if (c >= w) {  // padding: no data, no links
        ASSERT_FALSE(Bit(valid, c) || Bit(west, c) || Bit(n, c) || Bit(nw, c) || Bit(ne, c));
        continue;
      }
      const Eigen::Vector3f& p = cur_pts[c];
      ASSERT_EQ(Bit(valid, c), PointCloud::IsValid(p)) << c;
      ASSERT_EQ(Bit(west, c), c > 0 && PointsLinked(p, cur_pts[c - 1], r2)) << c;
      ties += c > 0 && (p - cur_pts[c - 1]).squaredNorm() == r2;
      ASSERT_EQ(Bit(n, c), PointsLinked(p, up_pts[c], r2)) << c;
      ASSERT_EQ(Bit(nw, c), diagonals && c > 0 && PointsLinked(p, up_pts[c - 1], r2)) << c;
      ASSERT_EQ(Bit(ne, c), diagonals && c + 1 < w && PointsLinked(p, up_pts[c + 1], r2)) << c;
    }
    // Bounds over any all-valid span equal the scalar min / max.
    for (uint32_t first = 0; first < w; first += 7) {
      uint32_t last = first;
      while (last + 1 < w && PointCloud::IsValid(cur_pts[last + 1]) && last - first < 40) ++last;
      if (!PointCloud::IsValid(cur_pts[first])) continue;
      float lo[3], hi[3];
      Bounds(cur, first, last, lo, hi);
      Eigen::Vector3f want_lo = cur_pts[first], want_hi = cur_pts[first];
      for (uint32_t c = first; c <= last; ++c) {
        want_lo = want_lo.cwiseMin(cur_pts[c]);
        want_hi = want_hi.cwiseMax(cur_pts[c]);
      }
      for (int a = 0; a < 3; ++a) {
        ASSERT_EQ(lo[a], want_lo[a]);
        ASSERT_EQ(hi[a], want_hi[a]);
      }
    }
  }
  EXPECT_GT(ties, 100);
}

TEST_P(LinkRowMasks, FirstRowHasNoVerticalLinksAndInfinityIsReported) {
  std::vector<Eigen::Vector3f> pts(70, Eigen::Vector3f(0.f, 0.f, 1.f));
  RowSoA row(128);
  Transpose(pts.data(), 70, row);
  std::vector<uint64_t> storage(10, ~uint64_t{0});
  const RowMasks m = {&storage[0], &storage[2], &storage[4], &storage[6], &storage[8]};
  EXPECT_FALSE(ComputeMasks(row, nullptr, true, 2, 0.25f, m, GetParam()));
  EXPECT_EQ(storage[6] | storage[7] | storage[4] | storage[5] | storage[8] | storage[9], 0u);
  EXPECT_EQ(storage[0], ~uint64_t{0});
  EXPECT_EQ(storage[1], (uint64_t{1} << 6) - 1);
  pts[69] = {0.f, -INFINITY, NAN};
  Transpose(pts.data(), 70, row);
  EXPECT_TRUE(ComputeMasks(row, nullptr, true, 2, 0.25f, m, GetParam()));
  // Also where every pixel around it is invalid: a pass that skips such
  // pixels' link tests must still see the infinity.
  std::fill(pts.begin(), pts.end(), Eigen::Vector3f(NAN, NAN, NAN));
  pts[40] = {INFINITY, NAN, 0.f};
  Transpose(pts.data(), 70, row);
  EXPECT_TRUE(ComputeMasks(row, nullptr, true, 2, 0.25f, m, GetParam()));
  EXPECT_EQ(storage[0] | storage[1], 0u);
}

// Each set's run bounds are the SSE2 reduction's bits, the sign of a zero
// included: runs of every length from 1 to 70 at every offset in a word,
// over values that are often +0, -0 or repeated.
TEST_P(LinkRowMasks, RunBoundsAreTheSameBitsInEachSet) {
  std::mt19937 rng(9);
  std::uniform_int_distribution<int> pick(0, 5);
  const float values[6] = {0.f, -0.f, 1.5f, -2.25f, 0.f, -0.f};
  std::vector<Eigen::Vector3f> pts(160);
  RowSoA row(192);
  int zero_bounds = 0;
  for (int trial = 0; trial < 40; ++trial) {
    for (auto& p : pts) p = {values[pick(rng)], values[pick(rng)], values[pick(rng)]};
    Transpose(pts.data(), 160, row, RowIsa::kSse2);
    for (uint32_t first = 0; first < 64; first += 5)
      for (uint32_t last = first; last < first + 70; ++last) {
        float lo[3], hi[3], want_lo[3], want_hi[3];
        Bounds(row, first, last, lo, hi, GetParam());
        Bounds(row, first, last, want_lo, want_hi, RowIsa::kSse2);
        ASSERT_EQ(std::memcmp(lo, want_lo, sizeof lo), 0) << first << ".." << last;
        ASSERT_EQ(std::memcmp(hi, want_hi, sizeof hi), 0) << first << ".." << last;
        zero_bounds += want_lo[0] == 0;
      }
  }
  EXPECT_GT(zero_bounds, 100);  // the zero case is exercised
}

// Each set's transpose gives the points' coordinates plane by plane, NaN
// and infinity included, for widths on and off its vector width.
TEST_P(LinkRowMasks, TransposeCopiesEveryCoordinate) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(-100.f, 100.f);
  for (uint32_t w : {1u, 7u, 8u, 9u, 15u, 16u, 17u, 33u, 64u, 70u, 1024u}) {
    std::vector<Eigen::Vector3f> pts(w);
    for (auto& p : pts) p = {u(rng), u(rng), u(rng)};
    pts[0].y() = NAN;
    pts[w - 1].z() = -INFINITY;
    RowSoA row(64 * ((w + 63) / 64));
    Transpose(pts.data(), w, row, GetParam());
    for (uint32_t i = 0; i < w; ++i)
      for (int a = 0; a < 3; ++a) {
        const float want = pts[i][a], got = row.c(a)[i];
        ASSERT_EQ(std::memcmp(&want, &got, sizeof want), 0) << "w " << w << " point " << i;
      }
    EXPECT_TRUE(std::isnan(row.c(0)[-1]));  // the padding is left alone
  }
}

// The one-pass transpose and masks (AVX-512: groups of 16 from registers,
// the west neighbour shifted in, the partial group read back) against the
// two steps in SSE2, plane bits and every mask: widths on and off 16 and
// 64, blocks without data, with and without the row above and diagonals.
TEST_P(LinkRowMasks, TransposeAndComputeMasksEqualsItsTwoSteps) {
  std::mt19937 rng(12);
  std::uniform_int_distribution<int> lattice(-4, 4);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  const float r2 = LinkDistanceSquared(0.625f);
  int links = 0;
  for (uint32_t w : {1u, 15u, 16u, 17u, 63u, 64u, 65u, 100u, 130u, 1024u})
    for (int trial = 0; trial < 8; ++trial) {
      const uint32_t words = (w + 63) / 64;
      std::vector<Eigen::Vector3f> up_pts(w), cur_pts(w);
      for (auto* row : {&up_pts, &cur_pts})
        for (uint32_t c = 0; c < w; ++c) {
          const bool hole = u(rng) < 0.1f || (c / 16) % 5 == 3;  // and whole blocks
          (*row)[c] = hole ? Eigen::Vector3f(NAN, NAN, NAN)
                           : Eigen::Vector3f(0.375f * c, row == &up_pts ? 0.f : 0.375f,
                                             0.125f * lattice(rng));
        }
      const bool above = trial % 4 != 0, diagonals = trial % 2 == 1;
      RowSoA up(64 * words), want(64 * words), got(64 * words);
      std::vector<uint64_t> want_bits(5 * words, 7), got_bits(5 * words, 9);
      auto masks = [&](std::vector<uint64_t>& b) {
        return RowMasks{&b[0], &b[words], &b[2 * words], &b[3 * words], &b[4 * words]};
      };
      Transpose(up_pts.data(), w, up, RowIsa::kSse2);
      Transpose(cur_pts.data(), w, want, RowIsa::kSse2);
      ASSERT_FALSE(ComputeMasks(want, above ? &up : nullptr, diagonals, words, r2, masks(want_bits),
                                RowIsa::kSse2));
      ASSERT_FALSE(TransposeAndComputeMasks(cur_pts.data(), w, got, above ? &up : nullptr,
                                            diagonals, words, r2, masks(got_bits), GetParam(),
                                            up_pts.data()));
      for (int a = 0; a < 3; ++a)
        ASSERT_EQ(std::memcmp(want.c(a) - 1, got.c(a) - 1, (64 * words + 2) * sizeof(float)), 0)
            << "w " << w << " axis " << a;
      ASSERT_EQ(want_bits, got_bits) << "w " << w << " trial " << trial;
      for (uint32_t k = words; k < 5 * words; ++k) links += __builtin_popcountll(got_bits[k]);
    }
  EXPECT_GT(links, 1000);  // links of every kind are exercised
  // An infinite coordinate is reported, wherever it falls.
  for (uint32_t at : {0u, 15u, 16u, 40u}) {
    std::vector<Eigen::Vector3f> pts(50, Eigen::Vector3f(1.f, 2.f, 3.f));
    pts[at].y() = INFINITY;
    RowSoA row(64);
    std::vector<uint64_t> bits(5);
    const RowMasks m{&bits[0], &bits[1], &bits[2], &bits[3], &bits[4]};
    EXPECT_TRUE(TransposeAndComputeMasks(pts.data(), 50, row, nullptr, true, 1, r2, m, GetParam()))
        << at;
  }
}

// Starts and ends against their per-pixel definitions, across words, and
// the bit scan against a linear search.
TEST(LinkRowRuns, StartsEndsAndNextBitMatchTheirDefinitions) {
  std::mt19937_64 rng(8);
  for (uint32_t words : {1u, 2u, 5u}) {
    std::vector<uint64_t> valid(words), west(words), starts(words), ends(words);
    for (uint32_t k = 0; k < words; ++k) {
      valid[k] = rng() | rng();  // mostly valid, so runs cross words
      west[k] = valid[k] & (rng() | rng()) & (valid[k] << 1 | (k > 0 ? valid[k - 1] >> 63 : 0));
    }
    const RowMasks m{valid.data(), west.data(), nullptr, nullptr, nullptr};
    RunBounds(m, words, starts.data(), ends.data());
    const uint32_t n = 64 * words;
    for (uint32_t i = 0; i < n; ++i) {
      const bool next_west = i + 1 < n && Bit(west, i + 1);
      ASSERT_EQ(Bit(starts, i), Bit(valid, i) && !Bit(west, i)) << i;
      ASSERT_EQ(Bit(ends, i), Bit(valid, i) && !next_west) << i;
      uint32_t want = kNone;
      for (uint32_t j = i; j < n && want == kNone; ++j)
        if (Bit(starts, j)) want = j;
      ASSERT_EQ(NextBit(starts.data(), words, i), want) << i;
    }
    EXPECT_EQ(NextBit(starts.data(), words, n), kNone);
    // The bounded scan: the first set bit in [from, last] or none.
    for (uint32_t from = 0; from < n; from += 3)
      for (uint32_t last = from; last < n; last += 17) {
        const uint32_t next = NextBit(starts.data(), words, from);
        ASSERT_EQ(NextBitUpTo(starts.data(), from, last), next <= last ? next : kNone);
      }
  }
}

INSTANTIATE_TEST_SUITE_P(EachIsa, LinkRowMasks,
                         ::testing::Values(RowIsa::kSse2, RowIsa::kAvx2, RowIsa::kAvx512),
                         [](const ::testing::TestParamInfo<RowIsa>& i) {
                           return i.param == RowIsa::kAvx512 ? std::string("Avx512")
                                  : i.param == RowIsa::kAvx2 ? std::string("Avx2")
                                                             : std::string("Sse2");
                         });

}  // namespace
}  // namespace surfinspect::link_row
