#include "core/filter/grid_bands.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/filter/link_clustering.h"
#include "tests/support/link_grids.h"

namespace surfinspect::grid {
namespace {

// The bands' runs and forest against the grid path's brute-force oracle
// (tests/support/link_grids.h), on grids of one to four bands.
TEST(GridBands, JoinedBandsGiveThePixelGraphsComponentsWithTheLowestRunAsRoot) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<uint32_t> width(1, 80), height(1, 3 * kBandRows + 20);
  const float r2 = LinkDistanceSquared(0.5);
  for (int trial = 0; trial < 30; ++trial) {
    const uint32_t w = width(rng), h = height(rng);
    const PointCloud c = testing::RandomGrid(rng, w, h, 0.15);
    const bool eight = trial % 2 == 0;
    std::vector<Band> bands((h + kBandRows - 1) / kBandRows);
    for (std::size_t b = 0; b < bands.size(); ++b) {
      bands[b].first = static_cast<uint32_t>(b * kBandRows);
      bands[b].end = std::min(h, static_cast<uint32_t>((b + 1) * kBandRows));
      LabelBand(c, r2, eight, nullptr, bands[b]);
      ASSERT_TRUE(bands[b].status.ok()) << bands[b].status;
    }
    UnionFind forest = JoinBands(bands, w, eight);
    SCOPED_TRACE(::testing::Message() << "trial " << trial << " " << w << "x" << h);
    // The runs tile the valid pixels, each a maximal west-linked chain.
    std::vector<int32_t> run_of(c.size(), -1);
    for (const Band& band : bands)
      for (std::size_t i = 0; i < band.runs.size(); ++i) {
        const grid::Run& run = band.runs[i];
        ASSERT_LT(band.offset + i, forest.size());
        for (uint32_t col = run.first_col; col <= run.last_col; ++col) {
          const std::size_t p = std::size_t{run.row} * w + col;
          ASSERT_EQ(run_of[p], -1);
          run_of[p] = static_cast<int32_t>(band.offset + i);
          for (int a = 0; a < 3; ++a) {
            EXPECT_LE(run.lo[a], c.points[p][a]);
            EXPECT_GE(run.hi[a], c.points[p][a]);
          }
        }
        const std::size_t row = std::size_t{run.row} * w;
        EXPECT_FALSE(run.first_col > 0 && PointsLinked(c.points[row + run.first_col - 1],
                                                       c.points[row + run.first_col], r2));
        EXPECT_FALSE(run.last_col + 1 < w && PointsLinked(c.points[row + run.last_col],
                                                          c.points[row + run.last_col + 1], r2));
      }
    const std::vector<int32_t> oracle = testing::GridOracle(c, eight ? 8 : 4, r2);
    // Same partition, and every root is its component's lowest run (the
    // raster numbering of pass 2 relies on it).
    std::vector<int32_t> lowest_run(c.size(), INT32_MAX);
    for (std::size_t p = 0; p < c.size(); ++p) {
      ASSERT_EQ(run_of[p] >= 0, PointCloud::IsValid(c.points[p]));
      if (run_of[p] < 0) continue;
      int32_t& low = lowest_run[static_cast<std::size_t>(oracle[p])];
      low = std::min(low, run_of[p]);
    }
    for (std::size_t p = 0; p < c.size(); ++p) {
      if (run_of[p] < 0) continue;
      ASSERT_EQ(forest.Find(run_of[p]), lowest_run[static_cast<std::size_t>(oracle[p])])
          << "pixel " << p;
    }
  }
}

TEST(GridBands, AnInfiniteCoordinateFailsItsBand) {
  PointCloud c = PointCloud::Organized(5, 3);
  for (std::size_t i = 0; i < c.size(); ++i)
    c.points[i] = {0.3f * float(i % 5), 0.3f * float(i / 5), 0};
  c.points[7] = {0, INFINITY, 0};
  Band band;
  band.end = 3;
  LabelBand(c, 0.25f, true, nullptr, band);
  EXPECT_EQ(band.status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(band.status.message().find("row 1"), std::string::npos) << band.status;
}

}  // namespace
}  // namespace surfinspect::grid
