#include "core/filter/link_clustering_unorganized.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "core/types/cancel.h"
#include "core/types/default_init_vector.h"
#include "core/types/radix_sort.h"
#include "core/types/status_macros.h"
#include "core/types/union_find.h"

namespace surfinspect {
namespace {

constexpr int32_t kInvalid = LinkClusteringResult::kInvalid;
constexpr int kMaxAxisBits = 21;  // 3 x 21 bits fit one uint64 key

// Bits needed to hold values 0..v.
int BitsFor(uint64_t v) {
  int b = 1;
  while (b < 64 && (v >> b) != 0) ++b;
  return b;
}

// The valid points sorted by cell, as structure-of-arrays, and the cells.
// The per-position arrays start unwritten (the gather writes every slot):
// zeroing them first would be a serial pass that cannot poll.
struct SortedCells {
  DefaultInitVector<float> x, y, z;     // per sorted position
  std::vector<uint64_t> key;            // per cell, ascending
  std::vector<uint32_t> begin;          // per cell: first sorted position; + end sentinel
  DefaultInitVector<uint32_t> cell_of;  // per sorted position
};

// Whether some point of cell a links to some point of cell b (the first
// link found ends the search: one link merges the two cells).
bool AnyLinked(const SortedCells& s, uint32_t a, uint32_t b, float r2) {
  for (uint32_t i = s.begin[a]; i < s.begin[a + 1]; ++i) {
    const Eigen::Vector3f p(s.x[i], s.y[i], s.z[i]);
    for (uint32_t j = s.begin[b]; j < s.begin[b + 1]; ++j)
      if (PointsLinked(p, Eigen::Vector3f(s.x[j], s.y[j], s.z[j]), r2)) return true;
  }
  return false;
}

// The valid points' bounds and count; InvalidArgument on an infinite
// coordinate, Cancelled when cancelled.
struct ValidBounds {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  std::size_t count = 0;
};
absl::StatusOr<ValidBounds> BoundValidPoints(const PointCloud& cloud,
                                             const std::atomic<bool>* cancel) {
  ValidBounds b;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (CancelledAt(i, cancel)) return absl::CancelledError("link clustering: cancelled");
    const Eigen::Vector3f& p = cloud.points[i];
    if (PointCloud::IsValid(p)) {
      b.lo = b.lo.cwiseMin(p.cast<double>());
      b.hi = b.hi.cwiseMax(p.cast<double>());
      ++b.count;
    } else if (p.array().isInf().any()) {
      return absl::InvalidArgumentError(
          absl::StrCat("link clustering: point ", i, " has an infinite coordinate"));
    }
  }
  return b;
}

// The cell grid: cells of edge d / sqrt(3) and the bits per axis of the
// packed key (z, y, x major to minor).
struct CellGrid {
  Eigen::Vector3d lo;
  double cell = 0;
  int bits[3] = {0, 0, 0};
  int key_bits() const { return bits[0] + bits[1] + bits[2]; }
  uint64_t Key(const Eigen::Vector3f& p) const {
    uint64_t c[3];
    for (int a = 0; a < 3; ++a) c[a] = static_cast<uint64_t>(std::floor((p[a] - lo[a]) / cell)) + 2;
    return c[0] | (c[1] << bits[0]) | (c[2] << (bits[0] + bits[1]));
  }
};
absl::StatusOr<CellGrid> MakeCellGrid(const ValidBounds& b, double link_distance_mm) {
  CellGrid g;
  g.lo = b.lo;
  // Cells of edge d / sqrt(3), shrunk by 1e-4 so that float rounding in
  // PointsLinked can never fail to link two points of the same cell (their
  // true distance is < 0.9999 d; the float error is ~1e-7 relative).
  g.cell = link_distance_mm / std::sqrt(3.0) * (1.0 - 1e-4);
  for (int a = 0; b.count > 0 && a < 3; ++a) {
    // Cell coordinates start at 2 so that x-2 and y-2 never borrow across
    // key fields, and stop 2 below the field's top so that x+2 fits.
    const double cells = std::floor((b.hi[a] - b.lo[a]) / g.cell) + 5.0;
    if (!(cells < static_cast<double>(uint64_t{1} << kMaxAxisBits)))
      return absl::InvalidArgumentError(
          absl::StrCat("link clustering: the cloud spans ", b.hi[a] - b.lo[a], " mm on axis ", a,
                       ", more than 2^21 cells for a link distance of ", link_distance_mm, " mm"));
    g.bits[a] = BitsFor(static_cast<uint64_t>(cells) - 1);
  }
  return g;
}

// The valid points sorted by cell key; `order` maps sorted position to point
// index. False when cancelled.
bool SortByCell(const PointCloud& cloud, const CellGrid& grid, std::size_t valid, SortedCells& s,
                std::vector<uint32_t>& order, const std::atomic<bool>* cancel) {
  std::vector<uint64_t> keys;
  keys.reserve(valid);
  order.clear();
  order.reserve(valid);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (CancelledAt(i, cancel)) return false;
    const Eigen::Vector3f& p = cloud.points[i];
    if (!PointCloud::IsValid(p)) continue;
    keys.push_back(grid.Key(p));
    order.push_back(static_cast<uint32_t>(i));
  }
  if (!RadixSortPairs(keys, order, grid.key_bits(), cancel)) return false;
  for (auto* v : {&s.x, &s.y, &s.z}) v->resize(valid);
  s.cell_of.resize(valid);
  for (std::size_t k = 0; k < valid; ++k) {
    if (CancelledAt(k, cancel)) return false;
    // A gather in cell order: random reads of an unorganized cloud, so the
    // point needed 16 steps later is requested now.
    if (k + 16 < valid) __builtin_prefetch(&cloud.points[order[k + 16]]);
    const Eigen::Vector3f& p = cloud.points[order[k]];
    s.x[k] = p.x();
    s.y[k] = p.y();
    s.z[k] = p.z();
    if (k == 0 || keys[k] != keys[k - 1]) {
      s.key.push_back(keys[k]);
      s.begin.push_back(static_cast<uint32_t>(k));
    }
    s.cell_of[k] = static_cast<uint32_t>(s.key.size() - 1);
  }
  s.begin.push_back(static_cast<uint32_t>(valid));
  return true;
}

// Merges every pair of linked cells (see the header: forward neighbours
// only, found by cursors over the sorted keys). False when cancelled.
bool LinkCells(const SortedCells& s, const CellGrid& grid, float r2, UnionFind& forest,
               const std::atomic<bool>* cancel) {
  const auto num_cells = static_cast<uint32_t>(s.key.size());
  forest.Reset(num_cells);
  const uint64_t step_y = uint64_t{1} << grid.bits[0];
  const uint64_t step_z = uint64_t{1} << (grid.bits[0] + grid.bits[1]);
  // Forward neighbour rows (dy, dz) whose cells x-2..x+2 are one key range:
  // dz = 0 with dy = 1, 2, and dz = 1, 2 with dy = -2..2. The cells x+1 and
  // x+2 of the cell's own row follow it directly in the sorted order.
  uint64_t row_offset[12];
  int rows = 0;
  for (int dz = 0; dz <= 2; ++dz)
    for (int dy = dz == 0 ? 1 : -2; dy <= 2; ++dy)
      row_offset[rows++] = dz * step_z + dy * step_y;  // wraps only for dy < 0, dz > 0
  uint32_t row_first[12] = {};
  auto advance = [&](uint32_t& cursor, uint64_t first_key_not_before) {
    while (cursor < num_cells && s.key[cursor] < first_key_not_before) ++cursor;
  };
  for (uint32_t a = 0; a < num_cells; ++a) {
    if ((a & 4095) == 0 && IsCancelled(cancel)) return false;
    const uint64_t key = s.key[a];
    int32_t root_a = forest.Find(static_cast<int32_t>(a));
    auto try_link = [&](uint32_t b) {
      const int32_t root_b = forest.Find(static_cast<int32_t>(b));
      if (root_b == root_a || !AnyLinked(s, a, b, r2)) return;
      root_a = forest.LinkRoots(root_a, root_b);
    };
    for (uint32_t b = a + 1; b < num_cells && s.key[b] <= key + 2; ++b) try_link(b);
    for (int k = 0; k < rows; ++k) {
      const uint64_t first_key = key + row_offset[k] - 2, last_key = first_key + 4;
      advance(row_first[k], first_key);
      for (uint32_t b = row_first[k]; b < num_cells && s.key[b] <= last_key; ++b) try_link(b);
    }
  }
  return true;
}

// Each point's root cell, found in cell order (local) and scattered to the
// point's index; then ids in order of each component's first point index,
// with statistics. False when cancelled.
bool NumberComponents(const PointCloud& cloud, const SortedCells& s,
                      const std::vector<uint32_t>& order, UnionFind& forest,
                      LinkClusteringResult& result, const std::atomic<bool>* cancel) {
  for (std::size_t k = 0; k < order.size(); ++k) {
    if (CancelledAt(k, cancel)) return false;
    result.labels[order[k]] = forest.Find(static_cast<int32_t>(s.cell_of[k]));
  }
  std::vector<int32_t> id_of_root(s.key.size(), kInvalid);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (CancelledAt(i, cancel)) return false;
    if (result.labels[i] == kInvalid) continue;
    int32_t& id = id_of_root[result.labels[i]];
    const Eigen::Vector3f& p = cloud.points[i];
    const auto col = static_cast<uint32_t>(i);
    if (id == kInvalid) {
      id = static_cast<int32_t>(result.clusters.size());
      ClusterInfo k;
      k.min_col = col;
      k.min = k.max = p;
      result.clusters.push_back(k);
    }
    ClusterInfo& k = result.clusters[static_cast<std::size_t>(id)];
    ++k.size;
    k.max_col = col;
    k.min = k.min.cwiseMin(p);
    k.max = k.max.cwiseMax(p);
    result.labels[i] = id;
  }
  return true;
}

}  // namespace

absl::Status ClusterLinksUnorganized(const PointCloud& cloud,
                                     const LinkClusteringSettings& settings,
                                     LinkClusteringResult& result,
                                     const std::atomic<bool>* cancel) {
  RETURN_IF_ERROR(internal::CheckInput(cloud, settings));
  const absl::Status cancelled = absl::CancelledError("link clustering: cancelled");
  result.input_points = cloud.size();
  result.organized_path = false;
  result.clusters.clear();
  if (!FillUnlessCancelled(result.labels, cloud.size(), kInvalid, cancel)) return cancelled;
  ASSIGN_OR_RETURN(auto bounds, BoundValidPoints(cloud, cancel));
  ASSIGN_OR_RETURN(auto grid, MakeCellGrid(bounds, settings.link_distance_mm));
  SortedCells cells;
  std::vector<uint32_t> order;  // sorted position -> point index
  if (!SortByCell(cloud, grid, bounds.count, cells, order, cancel)) return cancelled;
  UnionFind forest;
  if (!LinkCells(cells, grid, LinkDistanceSquared(settings.link_distance_mm), forest, cancel))
    return cancelled;
  if (!NumberComponents(cloud, cells, order, forest, result, cancel)) return cancelled;
  internal::DecideClusters(settings, result);
  if (IsCancelled(cancel)) return cancelled;
  internal::FillKeptMaskFromLabels(result);
  return absl::OkStatus();
}

}  // namespace surfinspect
