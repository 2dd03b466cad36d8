#include "core/filter/grid_bands.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/filter/link_row_masks.h"
#include "core/types/cancel.h"

namespace surfinspect::grid {
namespace {

using link_row::kNone;
using link_row::NextBit;
using link_row::RowMasks;
using link_row::RowSoA;

// Pass-1 state: two rows of structure-of-arrays (this row and the one
// above), the link masks of the current row, and the runs with their
// union-find.
struct GridScratch {
  GridScratch(uint32_t width, uint32_t height)
      : isa(link_row::ResolveRowIsa(link_row::RowIsa::kAuto)),
        words((width + 63) / 64),
        rows{RowSoA(64 * words), RowSoA(64 * words)},
        masks(7 * std::size_t{words}) {
    // The demo scan has about 30 runs a row; the reserve avoids regrowing.
    runs.reserve(32 * std::size_t{height});
    forest.Reserve(32 * std::size_t{height});
  }
  const link_row::RowIsa isa;  // the row kernels' set, resolved once per band
  const uint32_t words;
  RowSoA rows[2];
  // Masks: valid, west, north-west, north, north-east, run starts, run ends.
  std::vector<uint64_t> masks;
  RowMasks m() {
    return {masks.data(), masks.data() + words, masks.data() + 2 * words, masks.data() + 3 * words,
            masks.data() + 4 * words};
  }
  uint64_t* starts() { return masks.data() + 5 * words; }
  uint64_t* ends() { return masks.data() + 6 * words; }
  std::vector<Run> runs;
  std::size_t row_first = 0;  // index of the current row's first run
  UnionFind forest;           // over run indices
};

// The runs of the row above, runs[first..] in column order, walked by a
// cursor: the columns a row's runs link to rise along the row, except that
// a run's north-west link may reach one or two columns left of where the
// run before it ended (its north-east link), so the cursor also steps back.
// A row's lookups cost about one pass over the runs above (no per-column
// table to fill). `offset` turns an index into runs into the forest's.
struct RowAbove {
  const std::vector<Run>& runs;
  std::size_t cursor;
  int32_t offset;
  RowAbove(const std::vector<Run>& r, std::size_t first, int32_t off)
      : runs(r), cursor(first), offset(off) {}
  // The run holding column `col`, which must be valid.
  std::size_t RunAt(uint32_t col) {
    while (runs[cursor].last_col < col) ++cursor;
    while (runs[cursor].first_col > col) --cursor;
    return cursor;
  }
};

// Bits of mask word k that lie in columns s..e.
uint64_t InColumns(uint32_t k, uint32_t s, uint32_t e) {
  if (k < s / 64 || k > e / 64) return 0;
  const uint64_t from = k == s / 64 ? ~uint64_t{0} << (s % 64) : ~uint64_t{0};
  const uint64_t to = k == e / 64 ? ~uint64_t{0} >> (63 - e % 64) : ~uint64_t{0};
  return from & to;
}

// Word k of the columns above that pixels s..e link to: north at the same
// column, north-west one to the left, north-east one to the right (the
// diagonals' bits carried across words).
uint64_t LinkedAbove(const uint64_t* const vertical[3], uint32_t k, uint32_t s, uint32_t e,
                     bool eight) {
  const uint64_t in_run = InColumns(k, s, e);
  uint64_t above = vertical[1][k] & in_run;
  if (!eight) return above;
  above |= (vertical[0][k] & in_run) >> 1;
  above |= (vertical[2][k] & in_run) << 1;
  if (const uint64_t next = InColumns(k + 1, s, e)) above |= (vertical[0][k + 1] & next) << 63;
  if (k > 0)
    if (const uint64_t prev = InColumns(k - 1, s, e)) above |= (vertical[2][k - 1] & prev) >> 63;
  return above;
}

// Merges run `id` (columns s..e of its row) with every run above that one
// of its pixels links to along the row's north-west, north and north-east
// masks: the three directions as one mask of the columns above, so each
// linked run above is found, and merged, once.
void MergeWithRunsAbove(const uint64_t* const vertical[3], int32_t id, uint32_t s, uint32_t e,
                        uint32_t width, bool eight, RowAbove& above, UnionFind& forest) {
  // Most runs are a single outlier pixel, linked to nothing above: one test.
  if (s / 64 == e / 64) {
    const uint32_t k = s / 64;
    const uint64_t in_run = InColumns(k, s, e);
    const uint64_t up = vertical[1][k] | (eight ? vertical[0][k] | vertical[2][k] : 0);
    if ((up & in_run) == 0) return;
  }
  // The columns above that can be linked: one beyond each end with the diagonals.
  const uint32_t last = eight && e + 1 < width ? e + 1 : e;
  uint32_t from = eight && s > 0 ? s - 1 : s;  // the first column above still to look at
  while (from <= last) {
    const uint32_t k = from / 64;
    const uint64_t bits = LinkedAbove(vertical, k, s, e, eight) & (~uint64_t{0} << (from % 64));
    if (bits == 0) {
      from = 64 * (k + 1);
      continue;
    }
    const uint32_t c = 64 * k + static_cast<uint32_t>(__builtin_ctzll(bits));
    const std::size_t run_up = above.RunAt(c);
    forest.Union(id, static_cast<int32_t>(run_up) + above.offset);
    // Every column up to the end of that run reaches the same run.
    from = above.runs[run_up].last_col + 1;
  }
}

// Pass 1 for row r: transposes it, computes its link masks, appends its runs
// and, unless r is its band's first row, merges them with the linked runs of
// the row above. A band's first row below another keeps its vertical masks
// for the join instead (`seam`, 3 * words).
absl::Status LabelRow(const PointCloud& cloud, uint32_t r, uint32_t band_first, float r2,
                      bool eight, GridScratch& g, std::vector<uint64_t>& seam) {
  const uint32_t w = cloud.width, h = cloud.height;
  RowSoA& cur = g.rows[r & 1];
  const RowSoA& up = g.rows[(r + 1) & 1];
  const bool above = r > 0;
  const Eigen::Vector3f* next = r + 1 < h ? &cloud.points[std::size_t{r + 1} * w] : nullptr;
  if (link_row::TransposeAndComputeMasks(&cloud.points[std::size_t{r} * w], w, cur,
                                         above ? &up : nullptr, eight, g.words, r2, g.m(), g.isa,
                                         next))
    return absl::InvalidArgumentError(
        absl::StrCat("link clustering: row ", r, " holds an infinite coordinate"));
  const RowMasks m = g.m();
  const uint64_t* const vertical[3] = {m.north_west, m.north, m.north_east};
  const bool merge = above && r > band_first;
  if (above && !merge)
    for (int k = 0; k < 3; ++k) std::copy(vertical[k], vertical[k] + g.words, &seam[k * g.words]);
  link_row::RunBounds(m, g.words, g.starts(), g.ends());
  const uint64_t* starts = g.starts();
  const uint64_t* ends = g.ends();
  RowAbove row_above(g.runs, g.row_first, 0);
  g.row_first = g.runs.size();
  for (uint32_t s = NextBit(starts, g.words, 0); s != kNone; s = NextBit(starts, g.words, s + 1)) {
    const uint32_t e = NextBit(ends, g.words, s);
    const int32_t id = g.forest.Add();
    // Built in place: a Run assembled on the stack and copied costs a
    // failed store forwarding per run (bench/link_clustering_bench.cpp's grid
    // rows show it).
    Run& run = g.runs.emplace_back();
    run.row = r, run.first_col = s, run.last_col = e;
    link_row::Bounds(cur, s, e, run.lo, run.hi, g.isa);
    if (merge) MergeWithRunsAbove(vertical, id, s, e, w, eight, row_above, g.forest);
  }
  return absl::OkStatus();
}

}  // namespace

void LabelBand(const PointCloud& cloud, float r2, bool eight, const std::atomic<bool>* cancel,
               Band& band) {
  GridScratch g(cloud.width, band.end - band.first);
  band.seam.assign(3 * std::size_t{g.words}, 0);
  // The row above the band, for the first row's vertical masks.
  if (band.first > 0)
    link_row::Transpose(&cloud.points[std::size_t{band.first - 1} * cloud.width], cloud.width,
                        g.rows[(band.first - 1) & 1], g.isa);
  for (uint32_t r = band.first; r < band.end; ++r) {
    if (IsCancelled(cancel)) {
      band.status = absl::CancelledError("link clustering: cancelled");
      return;
    }
    band.status = LabelRow(cloud, r, band.first, r2, eight, g, band.seam);
    if (!band.status.ok()) return;
    if (r == band.first) band.first_row_runs = g.runs.size();
  }
  band.runs = std::move(g.runs);
  band.forest = std::move(g.forest);
  band.last_row_first = g.row_first;
}

UnionFind JoinBands(std::vector<Band>& bands, uint32_t width, bool eight) {
  const uint32_t words = (width + 63) / 64;
  UnionFind forest;
  for (std::size_t b = 0; b < bands.size(); ++b) {
    Band& band = bands[b];
    band.offset = forest.size();
    forest.Append(band.forest);
    if (b == 0) continue;
    const uint64_t* const vertical[3] = {&band.seam[0], &band.seam[words],
                                         &band.seam[2 * std::size_t{words}]};
    const Band& above = bands[b - 1];
    RowAbove row_above(above.runs, above.last_row_first, static_cast<int32_t>(above.offset));
    for (std::size_t i = 0; i < band.first_row_runs; ++i)
      MergeWithRunsAbove(vertical, static_cast<int32_t>(band.offset + i), band.runs[i].first_col,
                         band.runs[i].last_col, width, eight, row_above, forest);
  }
  return forest;
}

}  // namespace surfinspect::grid
