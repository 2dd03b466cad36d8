// Covers core/filter/link_clustering.cpp (ClusterLinks, ApplyFilter, the settings checks),
// core/filter/link_clustering_grid.cpp (ClusterLinksOrganized: BFS oracle on random grids,
// mask-word borders, snakes, single rows and columns, cancel) and
// core/filter/link_clustering_unorganized.cpp (ClusterLinksUnorganized: pairwise oracle,
// cell borders and diagonals, the 2^21-cell limit, cancel).
#include "core/filter/link_clustering.h"

#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <queue>
#include <random>

#include "core/filter/link_clustering_grid.h"
#include "core/filter/link_clustering_unorganized.h"
#include "tests/support/link_grids.h"

namespace surfinspect {
namespace {

constexpr int32_t kInvalid = LinkClusteringResult::kInvalid;
using testing::GridOracle;
using testing::RandomGrid;

// The random inputs below are scaled for a 0.5 mm link distance.
LinkClusteringSettings HalfMm() {
  LinkClusteringSettings s;
  s.link_distance_mm = 0.5;
  return s;
}

// O(n^2) oracle for unorganized clouds: every pair is tested.
std::vector<int32_t> PairOracle(const PointCloud& c, float r2) {
  const std::size_t n = c.size();
  std::vector<int32_t> label(n, kInvalid);
  int32_t next = 0;
  for (std::size_t start = 0; start < n; ++start) {
    if (!PointCloud::IsValid(c.points[start]) || label[start] != kInvalid) continue;
    std::vector<std::size_t> stack = {start};
    label[start] = next;
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      for (std::size_t j = 0; j < n; ++j)
        if (label[j] == kInvalid && PointCloud::IsValid(c.points[j]) &&
            PointsLinked(c.points[i], c.points[j], r2)) {
          label[j] = next;
          stack.push_back(j);
        }
    }
    ++next;
  }
  return label;
}

// Labels equal up to renaming: a bijection between the two id sets maps one
// labelling onto the other, and no-data agrees exactly.
void ExpectSamePartition(const std::vector<int32_t>& got, const std::vector<int32_t>& want) {
  ASSERT_EQ(got.size(), want.size());
  std::map<int32_t, int32_t> fwd, back;
  for (std::size_t i = 0; i < got.size(); ++i) {
    ASSERT_EQ(got[i] == kInvalid, want[i] == kInvalid) << "point " << i;
    if (got[i] == kInvalid) continue;
    auto f = fwd.emplace(got[i], want[i]).first;
    auto b = back.emplace(want[i], got[i]).first;
    ASSERT_EQ(f->second, want[i]) << "point " << i << " joins two oracle components";
    ASSERT_EQ(b->second, got[i]) << "point " << i << " splits an oracle component";
  }
}

// Sizes, bounding boxes, kept flags, mask and counts against the labels.
void ExpectConsistent(const PointCloud& c, const LinkClusteringResult& r,
                      const LinkClusteringSettings& s) {
  ASSERT_EQ(r.labels.size(), c.size());
  ASSERT_EQ(r.kept_mask.size(), c.size());
  std::vector<ClusterInfo> want(r.clusters.size());
  std::size_t valid = 0;
  const uint32_t w = r.organized_path ? c.width : static_cast<uint32_t>(c.size());
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (r.labels[i] == kInvalid) continue;
    ++valid;
    ASSERT_LT(r.labels[i], static_cast<int32_t>(want.size()));
    ClusterInfo& k = want[r.labels[i]];
    const uint32_t row = r.organized_path ? static_cast<uint32_t>(i / w) : 0;
    const uint32_t col = r.organized_path ? static_cast<uint32_t>(i % w) : static_cast<uint32_t>(i);
    if (k.size++ == 0) {
      k.min_row = k.max_row = row;
      k.min_col = k.max_col = col;
      k.min = k.max = c.points[i];
    }
    k.min_row = std::min(k.min_row, row);
    k.max_row = std::max(k.max_row, row);
    k.min_col = std::min(k.min_col, col);
    k.max_col = std::max(k.max_col, col);
    k.min = k.min.cwiseMin(c.points[i]);
    k.max = k.max.cwiseMax(c.points[i]);
  }
  uint32_t largest = 0;
  for (const auto& k : want) largest = std::max(largest, k.size);
  EXPECT_EQ(r.largest_cluster, largest);
  EXPECT_EQ(r.valid_points, valid);
  EXPECT_EQ(r.input_points, c.size());
  std::size_t kept = 0;
  for (std::size_t id = 0; id < want.size(); ++id) {
    const ClusterInfo& g = r.clusters[id];
    const ClusterInfo& k = want[id];
    ASSERT_GT(k.size, 0u) << "empty cluster " << id;
    EXPECT_EQ(g.size, k.size);
    EXPECT_EQ(g.min_row, k.min_row);
    EXPECT_EQ(g.max_row, k.max_row);
    EXPECT_EQ(g.min_col, k.min_col);
    EXPECT_EQ(g.max_col, k.max_col);
    EXPECT_EQ(g.min, k.min);
    EXPECT_EQ(g.max, k.max);
    const bool keep =
        k.size >= s.min_cluster_points && k.size >= s.min_fraction_of_largest * largest;
    EXPECT_EQ(g.kept, keep) << "cluster " << id << " of " << k.size;
    if (keep) kept += k.size;
  }
  EXPECT_EQ(r.kept, kept);
  EXPECT_EQ(r.removed, valid - kept);
  for (std::size_t i = 0; i < c.size(); ++i) {
    const bool keep = r.labels[i] != kInvalid && r.clusters[r.labels[i]].kept;
    ASSERT_EQ(r.kept_mask[i], keep ? 1 : 0) << "point " << i;
  }
}

TEST(LinkClusteringGrid, MatchesBfsOracleOnRandomGrids) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<uint32_t> size(2, 40);
  for (int trial = 0; trial < 400; ++trial) {
    const uint32_t w = size(rng) - 1, h = size(rng);  // w may be 1
    const PointCloud c = RandomGrid(rng, w, h, trial % 4 == 0 ? 0.0 : 0.2);
    for (int conn : {4, 8}) {
      LinkClusteringSettings s = HalfMm();
      s.connectivity = conn;
      s.min_cluster_points = 1 + trial % 7;
      s.min_fraction_of_largest = trial % 3 == 0 ? 0.1 : 0.0;
      auto r = ClusterLinks(c, s);
      ASSERT_TRUE(r.ok()) << r.status();
      EXPECT_TRUE(r->organized_path);
      SCOPED_TRACE(::testing::Message()
                   << "trial " << trial << " " << w << "x" << h << " conn " << conn);
      ExpectSamePartition(r->labels, GridOracle(c, conn, LinkDistanceSquared(0.5)));
      ExpectConsistent(c, *r, s);
      if (HasFatalFailure()) return;
    }
  }
}

TEST(LinkClusteringGrid, WideGridsCrossMaskWords) {
  // Rows wider than 64 pixels span several 64-bit link masks; runs and
  // links must carry across the word boundaries. Smooth heights make long
  // runs, so many of them cross a boundary.
  std::mt19937 rng(17);
  std::uniform_int_distribution<uint32_t> width(60, 300), height(2, 12);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (int trial = 0; trial < 60; ++trial) {
    const uint32_t w = width(rng), h = height(rng);
    PointCloud c = trial % 2 ? RandomGrid(rng, w, h, 0.05) : PointCloud::Organized(w, h);
    if (trial % 2 == 0)
      for (uint32_t r = 0; r < h; ++r)
        for (uint32_t col = 0; col < w; ++col)
          if (u(rng) > 0.02f)
            c.points[r * w + col] = {0.3f * col, 0.3f * r, u(rng) < 0.03f ? 3.f : 0.1f * u(rng)};
    for (int conn : {4, 8}) {
      LinkClusteringSettings s = HalfMm();
      s.connectivity = conn;
      s.min_cluster_points = 3;
      auto r = ClusterLinks(c, s);
      ASSERT_TRUE(r.ok());
      SCOPED_TRACE(::testing::Message() << "trial " << trial << " " << w << "x" << h);
      ExpectSamePartition(r->labels, GridOracle(c, conn, LinkDistanceSquared(0.5)));
      ExpectConsistent(c, *r, s);
      if (HasFatalFailure()) return;
    }
  }
}

// Ids count up in raster order of each component's first point.
void ExpectRasterNumbering(const std::vector<int32_t>& labels) {
  int32_t next = 0;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (labels[i] == kInvalid || labels[i] < next) continue;
    ASSERT_EQ(labels[i], next) << "point " << i << " starts a component out of raster order";
    ++next;
  }
}

// A comb: every other column is a tooth, joined to the next at the bottom
// or the top; links exist only along it (other heights jump 5 mm). One
// component, met by the row-by-row labelling at many places.
void ExpectTheCombIsOneComponent(uint32_t w, uint32_t h) {
  for (int conn : {4, 8}) {
    PointCloud c = PointCloud::Organized(w, h);
    for (uint32_t r = 0; r < h; ++r)
      for (uint32_t col = 0; col < w; ++col) {
        const bool on = (col % 2 == 0) || (r == (col % 4 == 1 ? h - 1 : 0));
        c.points[r * w + col] = {0.3f * col, 0.3f * r, on ? 0.f : 5.f + 7.f * ((r + col) % 2)};
      }
    LinkClusteringSettings s = HalfMm();
    s.connectivity = conn;
    auto r = ClusterLinks(c, s);
    ASSERT_TRUE(r.ok());
    ExpectSamePartition(r->labels, GridOracle(c, conn, LinkDistanceSquared(0.5)));
    ExpectRasterNumbering(r->labels);
    EXPECT_EQ(r->largest_cluster, (w / 2 + 1) * h + w / 2) << w << "x" << h << " conn " << conn;
  }
}

TEST(LinkClusteringGrid, SnakesAndSpiralsNeedManyMerges) { ExpectTheCombIsOneComponent(37, 41); }

TEST(LinkClusteringGrid, TallGridsJoinTheirBandsAtTheSeams) {
  // Rows are labelled in bands of 64 and the bands joined: components that
  // cross one or several seams, and seams through holes, must come out as
  // one serial pass would number them.
  std::mt19937 rng(23);
  std::uniform_int_distribution<uint32_t> width(1, 90), height(60, 300);
  for (int trial = 0; trial < 40; ++trial) {
    const uint32_t w = width(rng), h = height(rng);
    const PointCloud c = RandomGrid(rng, w, h, trial % 3 == 0 ? 0.0 : 0.15);
    for (int conn : {4, 8}) {
      LinkClusteringSettings s = HalfMm();
      s.connectivity = conn;
      s.min_cluster_points = 1 + trial % 5;
      auto r = ClusterLinks(c, s);
      ASSERT_TRUE(r.ok()) << r.status();
      SCOPED_TRACE(::testing::Message()
                   << "trial " << trial << " " << w << "x" << h << " conn " << conn);
      ExpectSamePartition(r->labels, GridOracle(c, conn, LinkDistanceSquared(0.5)));
      ExpectRasterNumbering(r->labels);
      ExpectConsistent(c, *r, s);
      if (HasFatalFailure()) return;
    }
  }
  // A comb whose teeth run through four bands: almost every merge is a seam's.
  ExpectTheCombIsOneComponent(21, 250);
}

TEST(LinkClusteringGrid, SingleRowAndSingleColumn) {
  std::mt19937 rng(3);
  for (auto [w, h] : {std::pair<uint32_t, uint32_t>{50, 1}, {1, 50}, {1, 2}}) {
    const PointCloud c = RandomGrid(rng, w, h, 0.1);
    LinkClusteringResult r;
    ASSERT_TRUE(ClusterLinksOrganized(c, HalfMm(), r).ok());
    ExpectSamePartition(r.labels, GridOracle(c, 8, LinkDistanceSquared(0.5)));
    ExpectConsistent(c, r, HalfMm());
  }
}

// Random clumps with coordinates on a d/4 lattice, so many pairs sit at
// exactly the link distance and on cell borders, plus NaN points.
PointCloud RandomCloud(std::mt19937& rng, std::size_t n, float d) {
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::uniform_int_distribution<int> lattice(-12, 12);
  std::vector<Eigen::Vector3f> pts;
  for (std::size_t i = 0; i < n; ++i) {
    if (u(rng) < 0.1f) {
      pts.push_back(Eigen::Vector3f::Constant(NAN));
    } else if (u(rng) < 0.5f) {
      pts.push_back(Eigen::Vector3f(lattice(rng), lattice(rng), lattice(rng)) * (d / 4));
    } else {
      pts.push_back(Eigen::Vector3f(u(rng), u(rng), u(rng)) * 6.f * d -
                    Eigen::Vector3f::Constant(100.f));
    }
  }
  return PointCloud::Unorganized(std::move(pts));
}

TEST(LinkClusteringUnorganized, MatchesPairwiseOracle) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<std::size_t> size(1, 400);
  for (int trial = 0; trial < 150; ++trial) {
    LinkClusteringSettings s;
    s.link_distance_mm = trial % 2 ? 0.85 : 0.37;
    s.min_cluster_points = 1 + trial % 5;
    s.min_fraction_of_largest = trial % 3 == 0 ? 0.2 : 0.0;
    const PointCloud c = RandomCloud(rng, size(rng), static_cast<float>(s.link_distance_mm));
    auto r = ClusterLinks(c, s);
    ASSERT_TRUE(r.ok()) << r.status();
    EXPECT_FALSE(r->organized_path);
    SCOPED_TRACE(::testing::Message() << "trial " << trial << " n " << c.size());
    ExpectSamePartition(r->labels, PairOracle(c, LinkDistanceSquared(s.link_distance_mm)));
    ExpectConsistent(c, *r, s);
    if (HasFatalFailure()) return;
  }
}

TEST(LinkClusteringUnorganized, FloatRoundingAtCellBordersStillLinks) {
  // Found by search: PointsLinked (float) links a and b, but in a grid of
  // cells of exactly 0.5 mm from the origin lo their cells would be 2 apart
  // (a float-rounding trap for any voxel scheme).
  const float lo = -255.444946f, a = 0.555053711f, b = 0.0550536998f;
  ASSERT_TRUE(PointsLinked({a, 0, 0}, {b, 0, 0}, LinkDistanceSquared(0.5)));
  ASSERT_EQ(std::floor((double{a} - lo) / 0.5) - std::floor((double{b} - lo) / 0.5), 2.0);
  const PointCloud c = PointCloud::Unorganized({{lo, 0, 0}, {a, 0, 0}, {b, 0, 0}});
  auto r = ClusterLinks(c, HalfMm());
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->labels[1], r->labels[2]);
  EXPECT_EQ(r->clusters.size(), 2u);
}

TEST(LinkClusteringUnorganized, CellDiagonalsJustBeyondTheLinkDistanceDoNotLink) {
  // Points of one voxel cell are linked without a test, so no cell may hold
  // two points farther apart than the link distance: pairs along the cell
  // diagonal at d (1 +- delta) must link exactly when PointsLinked says so.
  for (double d : {0.37, 0.5, 0.85, 1.3})
    for (double delta : {-1e-3, -1e-4, 1e-4, 1e-3})
      for (int signs = 0; signs < 8; ++signs) {
        LinkClusteringSettings s;
        s.link_distance_mm = d;
        s.min_cluster_points = 1;
        const Eigen::Vector3f a(1.5f, -0.75f, 2.25f);  // small: float keeps delta
        const Eigen::Vector3f dir((signs & 1) ? -1.f : 1.f, (signs & 2) ? -1.f : 1.f,
                                  (signs & 4) ? -1.f : 1.f);
        const Eigen::Vector3f b = a + dir * static_cast<float>(d / std::sqrt(3.0) * (1 + delta));
        const bool linked = PointsLinked(a, b, LinkDistanceSquared(d));
        ASSERT_EQ(linked, delta < 0) << d << " " << delta;
        auto r = ClusterLinks(PointCloud::Unorganized({a, b}), s);
        ASSERT_TRUE(r.ok());
        EXPECT_EQ(r->labels[0] == r->labels[1], linked) << d << " " << delta << " " << signs;
      }
}

TEST(LinkClusteringUnorganized, OrganizedCloudThroughGeneralPathLinksAllPairs) {
  // The general path ignores the grid: points 3 columns apart but on top of
  // each other link there, not on the grid path.
  PointCloud c = PointCloud::Organized(4, 2);
  for (uint32_t i = 0; i < 8; ++i) c.points[i] = {(i % 4 == 3) ? 0.f : 10.f * i, 0.f, 0.f};
  LinkClusteringSettings s = HalfMm();
  s.min_cluster_points = 1;
  LinkClusteringResult grid, general;
  ASSERT_TRUE(ClusterLinksOrganized(c, s, grid).ok());
  ASSERT_TRUE(ClusterLinksUnorganized(c, s, general).ok());
  ExpectSamePartition(grid.labels, GridOracle(c, 8, LinkDistanceSquared(0.5)));
  ExpectSamePartition(general.labels, PairOracle(c, LinkDistanceSquared(0.5)));
  EXPECT_EQ(general.labels[0], general.labels[3]);  // (0,0,0) twice
  EXPECT_NE(grid.labels[0], grid.labels[3]);
}

TEST(LinkClusteringUnorganized, AllNoDataAndSinglePoint) {
  auto none = ClusterLinks(PointCloud::Unorganized({Eigen::Vector3f::Constant(NAN)}), {});
  ASSERT_TRUE(none.ok());
  EXPECT_EQ(none->valid_points, 0u);
  EXPECT_EQ(none->clusters.size(), 0u);
  EXPECT_EQ(none->labels[0], kInvalid);
  LinkClusteringSettings s;
  s.min_cluster_points = 1;
  auto one = ClusterLinks(PointCloud::Unorganized({{1.f, 2.f, 3.f}}), s);
  ASSERT_TRUE(one.ok());
  EXPECT_EQ(one->kept, 1u);
  auto grid = ClusterLinks(PointCloud::Organized(3, 3), s);  // all NaN
  ASSERT_TRUE(grid.ok());
  EXPECT_EQ(grid->valid_points, 0u);
  EXPECT_EQ(grid->largest_cluster, 0u);
}

TEST(LinkClustering, ReusedResultEqualsFreshResult) {
  std::mt19937 rng(9);
  LinkClusteringResult reused;
  for (int i = 0; i < 6; ++i) {
    const PointCloud c =
        i % 2 ? RandomGrid(rng, 30 - i, 20 + i, 0.1) : RandomCloud(rng, 200 + 50 * i, 0.5f);
    ASSERT_TRUE(ClusterLinksInto(c, {}, reused).ok());
    auto fresh = ClusterLinks(c, {});
    ASSERT_TRUE(fresh.ok());
    EXPECT_EQ(reused.labels, fresh->labels);
    EXPECT_EQ(reused.kept_mask, fresh->kept_mask);
    EXPECT_EQ(reused.clusters.size(), fresh->clusters.size());
    EXPECT_EQ(reused.kept, fresh->kept);
  }
}

TEST(LinkClustering, ApplyFilterKeepsBitsAndGrid) {
  std::mt19937 rng(21);
  PointCloud c = RandomGrid(rng, 64, 48, 0.1);
  // A NaN payload in a no-data pixel must survive too.
  uint32_t payload = 0x7fc00123u;
  std::memcpy(c.points[5].data(), &payload, 4);
  LinkClusteringSettings s = HalfMm();
  s.min_cluster_points = 4;
  auto r = ClusterLinks(c, s);
  ASSERT_TRUE(r.ok());
  ASSERT_GT(r->removed, 0u);
  ASSERT_GT(r->kept, 0u);
  auto out = ApplyFilter(c, *r);
  ASSERT_TRUE(out.ok());
  EXPECT_EQ(out->width, c.width);
  EXPECT_EQ(out->height, c.height);
  std::size_t nan_removed = 0;
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (r->kept_mask[i] || r->labels[i] == kInvalid) {
      ASSERT_EQ(0, std::memcmp(c.points[i].data(), out->points[i].data(), 12)) << i;
    } else {
      ASSERT_FALSE(PointCloud::IsValid(out->points[i]));
      ++nan_removed;
    }
  }
  EXPECT_EQ(nan_removed, r->removed);
  EXPECT_EQ(out->CountValid(), r->kept);
  EXPECT_FALSE(ApplyFilter(PointCloud::Organized(2, 2), *r).ok());
}

TEST(LinkClustering, BadInputGivesClearErrors) {
  const PointCloud good = PointCloud::Unorganized({{0, 0, 0}, {1, 0, 0}});
  auto expect_error = [](const PointCloud& c, const LinkClusteringSettings& s,
                         const std::string& words) {
    auto r = ClusterLinks(c, s);
    ASSERT_FALSE(r.ok()) << words;
    EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(std::string(r.status().message()).find(words), std::string::npos) << r.status();
  };
  for (double d : {-0.5, 0.0, double(NAN), double(INFINITY), 1e300}) {
    LinkClusteringSettings s;
    s.link_distance_mm = d;
    expect_error(good, s, "link_distance_mm");
    expect_error(PointCloud::Organized(3, 3), s, "link_distance_mm");
  }
  LinkClusteringSettings conn;
  conn.connectivity = 6;
  expect_error(good, conn, "connectivity");
  for (double f : {-0.1, 1.5, double(NAN)}) {
    LinkClusteringSettings s;
    s.min_fraction_of_largest = f;
    expect_error(good, s, "min_fraction_of_largest");
  }
  expect_error(PointCloud{}, {}, "no points");
  PointCloud zero_wide;
  zero_wide.height = 5;
  expect_error(zero_wide, {}, "no points");
  PointCloud mismatch = PointCloud::Organized(4, 4);
  mismatch.points.pop_back();
  expect_error(mismatch, {}, "does not match");
  PointCloud inf_grid = PointCloud::Organized(4, 4);
  inf_grid.points[6] = {1.f, INFINITY, 0.f};
  expect_error(inf_grid, {}, "infinite");
  // An infinity next to a NaN in the same point is still an infinity.
  for (const Eigen::Vector3f& p :
       {Eigen::Vector3f(INFINITY, 0.f, NAN), Eigen::Vector3f(NAN, NAN, -INFINITY),
        Eigen::Vector3f(NAN, INFINITY, 2.f)}) {
    PointCloud g = PointCloud::Organized(70, 3);  // the bad pixel in word 2
    g.points[2 * 70 + 66] = p;
    expect_error(g, {}, "infinite");
    expect_error(PointCloud::Unorganized({{0, 0, 0}, p}), {}, "infinite");
  }
  expect_error(PointCloud::Unorganized({{0, 0, 0}, {0, 0, -INFINITY}}), {}, "infinite");
  // 1 um links across 10 km: more cells than the key can hold.
  LinkClusteringSettings fine;
  fine.link_distance_mm = 1e-3;
  expect_error(PointCloud::Unorganized({{0, 0, 0}, {1e7f, 0, 0}}), fine, "2^21");
}

TEST(LinkClustering, CancelStopsBothPaths) {
  std::atomic<bool> cancel{true};
  std::mt19937 rng(1);
  auto grid = ClusterLinks(RandomGrid(rng, 20, 20, 0.0), {}, &cancel);
  EXPECT_EQ(grid.status().code(), absl::StatusCode::kCancelled);
  auto cloud = ClusterLinks(RandomCloud(rng, 100, 0.5f), {}, &cancel);
  EXPECT_EQ(cloud.status().code(), absl::StatusCode::kCancelled);
}

TEST(LinkClustering, PredicateIsTheEuclideanDistance) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  const float r2 = LinkDistanceSquared(0.5);
  for (int i = 0; i < 10000; ++i) {
    const Eigen::Vector3f a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
    const double d = (a.cast<double>() - b.cast<double>()).norm();
    if (std::abs(d - 0.5) < 1e-5) continue;  // float rounding may go either way
    EXPECT_EQ(PointsLinked(a, b, r2), d <= 0.5) << d;
  }
  EXPECT_FALSE(PointsLinked({0, 0, 0}, Eigen::Vector3f::Constant(NAN), r2));
}

}  // namespace
}  // namespace surfinspect
