#include "core/link_clustering.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "core/link_clustering_unorganized.h"

namespace surfinspect {
namespace {

constexpr int32_t kInvalid = LinkClusteringResult::kInvalid;

// One grid row as structure-of-arrays, so the link tests below are plain
// float loops that the compiler vectorizes (4 pixels per SSE instruction).
struct RowSoA {
  std::vector<float> x, y, z;
  explicit RowSoA(uint32_t w) : x(w), y(w), z(w) {}
};

// Copies a row into `out`, marks valid pixels (all coordinates finite:
// 0 * NaN and 0 * inf are both NaN) and reports whether any coordinate is
// infinite, which the cloud contract (PointCloud::Validate) forbids.
bool LoadRow(const Eigen::Vector3f* row, uint32_t w, RowSoA& out, uint8_t* valid) {
  float* __restrict x = out.x.data();
  float* __restrict y = out.y.data();
  float* __restrict z = out.z.data();
  for (uint32_t c = 0; c < w; ++c) {
    x[c] = row[c].x();
    y[c] = row[c].y();
    z[c] = row[c].z();
  }
  int inf = 0;
  for (uint32_t c = 0; c < w; ++c) {
    valid[c] = (x[c] * 0.f + y[c] * 0.f + z[c] * 0.f) == 0.f;
    inf |= (std::fabs(x[c]) == INFINITY) | (std::fabs(y[c]) == INFINITY) |
           (std::fabs(z[c]) == INFINITY);
  }
  return inf != 0;
}

// out[i] = PointsLinked(a[i], b[i]) for i < n, in the same arithmetic as
// PointsLinked; NaN compares false, so no-data pixels never link.
void LinkMask(const float* __restrict ax, const float* __restrict ay,
              const float* __restrict az, const float* __restrict bx,
              const float* __restrict by, const float* __restrict bz, uint32_t n,
              float r2, uint8_t* __restrict out) {
  for (uint32_t i = 0; i < n; ++i) {
    const float dx = ax[i] - bx[i], dy = ay[i] - by[i], dz = az[i] - bz[i];
    out[i] = dx * dx + dy * dy + dz * dz <= r2;
  }
}

// Union-find whose parent forest lives in the label array: every entry is a
// pixel index <= its own index, a root points to itself. Path halving.
inline int32_t Find(int32_t* parent, int32_t i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}
// Links the larger root under the smaller, keeping parent <= index, which
// the in-place flattening of pass 2 relies on.
inline void Union(int32_t* parent, int32_t a, int32_t b) {
  a = Find(parent, a);
  b = Find(parent, b);
  if (a < b) parent[b] = a;
  else if (b < a) parent[a] = b;
}

// Pass 1 for one row: each valid pixel gets a parent pointer. A pixel linked
// to its west neighbour continues that run; links to the row above are
// merged, skipping a neighbour whose pointer equals the one merged last
// (the pixels of one run above share a pointer), so unions happen about
// once per pair of touching runs rather than once per pixel.
void LabelRow(int32_t base, uint32_t w, const uint8_t* valid, const uint8_t* lw,
              const uint8_t* lnw, const uint8_t* ln, const uint8_t* lne, int32_t* labels) {
  int32_t* row = labels + base;
  const int32_t* above = row - w;
  int32_t cur = kInvalid, last = kInvalid;
  auto merge = [&](int32_t q) {
    if (q == last) return;
    last = q;
    if (cur == kInvalid) cur = q;
    else if (cur != q) Union(labels, cur, q);
  };
  for (uint32_t c = 0; c < w; ++c) {
    if (!valid[c]) {
      row[c] = kInvalid;
      cur = last = kInvalid;
      continue;
    }
    if (!lw[c]) cur = last = kInvalid;
    if (lnw && lnw[c]) merge(above[c - 1]);
    if (ln && ln[c]) merge(above[c]);
    if (lne && lne[c]) merge(above[c + 1]);
    if (cur == kInvalid) cur = base + static_cast<int32_t>(c);  // a new root
    row[c] = cur;
  }
}

// Pass 2: parent pointers -> consecutive ids in raster order, plus cluster
// statistics. Because parent[i] <= i, the entry a pixel points to has
// already been replaced by its final id when the pixel is reached.
void Flatten(const PointCloud& cloud, LinkClusteringResult& result) {
  int32_t* labels = result.labels.data();
  auto& clusters = result.clusters;
  const uint32_t w = cloud.width;
  const Eigen::Vector3f* pts = cloud.points.data();
  for (uint32_t r = 0; r < cloud.height; ++r) {
    const int32_t base = static_cast<int32_t>(r * w);
    // Statistics are accumulated per run of equal ids, then merged once.
    int32_t run_id = kInvalid;
    uint32_t run_start = 0, run_size = 0;
    Eigen::Vector3f lo, hi;
    auto flush = [&](uint32_t end_col) {
      if (run_id == kInvalid) return;
      ClusterInfo& k = clusters[static_cast<std::size_t>(run_id)];
      if (k.size == 0) {
        k.min_row = k.max_row = r;
        k.min_col = run_start;
        k.max_col = end_col;
        k.min = lo;
        k.max = hi;
      } else {
        k.min_row = std::min(k.min_row, r);
        k.max_row = std::max(k.max_row, r);
        k.min_col = std::min(k.min_col, run_start);
        k.max_col = std::max(k.max_col, end_col);
        k.min = k.min.cwiseMin(lo);
        k.max = k.max.cwiseMax(hi);
      }
      k.size += run_size;
    };
    for (uint32_t c = 0; c < w; ++c) {
      const int32_t i = base + static_cast<int32_t>(c);
      const int32_t p = labels[i];
      int32_t id = kInvalid;
      if (p == i) {
        id = static_cast<int32_t>(clusters.size());
        clusters.emplace_back();
      } else if (p != kInvalid) {
        id = labels[p];
      }
      labels[i] = id;
      if (id != run_id) {
        flush(c - 1);
        run_id = id;
        run_start = c;
        run_size = 0;
        if (id != kInvalid) lo = hi = pts[i];
      }
      if (id != kInvalid) {
        ++run_size;
        lo = lo.cwiseMin(pts[i]);
        hi = hi.cwiseMax(pts[i]);
      }
    }
    flush(w - 1);
  }
}

}  // namespace

absl::Status ValidateLinkClusteringSettings(const LinkClusteringSettings& s) {
  if (!(std::isfinite(s.link_distance_mm) && s.link_distance_mm > 0.0))
    return absl::InvalidArgumentError(absl::StrCat(
        "link clustering: link_distance_mm must be finite and > 0, got ",
        s.link_distance_mm));
  if (s.link_distance_mm > 1e6)
    return absl::InvalidArgumentError(absl::StrCat(
        "link clustering: link_distance_mm = ", s.link_distance_mm, " is absurd (> 1 km)"));
  if (s.connectivity != 4 && s.connectivity != 8)
    return absl::InvalidArgumentError(absl::StrCat(
        "link clustering: connectivity must be 4 or 8, got ", s.connectivity));
  if (!(s.min_fraction_of_largest >= 0.0 && s.min_fraction_of_largest <= 1.0))
    return absl::InvalidArgumentError(absl::StrCat(
        "link clustering: min_fraction_of_largest must be in [0, 1], got ",
        s.min_fraction_of_largest));
  return absl::OkStatus();
}

namespace internal {

absl::Status CheckInput(const PointCloud& cloud, const LinkClusteringSettings& settings) {
  if (auto st = ValidateLinkClusteringSettings(settings); !st.ok()) return st;
  if (cloud.empty() || cloud.width == 0 || cloud.height == 0)
    return absl::InvalidArgumentError(absl::StrCat(
        "link clustering: the cloud has no points (grid ", cloud.width, " x ",
        cloud.height, ")"));
  if (std::size_t{cloud.width} * cloud.height != cloud.size())
    return absl::InvalidArgumentError(
        absl::StrCat("link clustering: width*height = ", cloud.width, "*", cloud.height,
                     " does not match ", cloud.size(), " points"));
  // Labels are int32 pixel indices during pass 1.
  if (cloud.size() > static_cast<std::size_t>(std::numeric_limits<int32_t>::max()))
    return absl::InvalidArgumentError(absl::StrCat(
        "link clustering: ", cloud.size(), " points exceed the 2^31 - 1 limit"));
  return absl::OkStatus();
}

void DecideKept(const LinkClusteringSettings& settings, LinkClusteringResult& result) {
  uint32_t largest = 0;
  for (const ClusterInfo& k : result.clusters) largest = std::max(largest, k.size);
  result.largest_cluster = largest;
  // A fraction of the largest, rounded up: size >= f * largest keeps.
  const double by_fraction = settings.min_fraction_of_largest * largest;
  std::size_t kept = 0, valid = 0;
  bool all_kept = true;
  for (ClusterInfo& k : result.clusters) {
    k.kept = k.size >= settings.min_cluster_points &&
             static_cast<double>(k.size) >= by_fraction;
    valid += k.size;
    if (k.kept) kept += k.size;
    all_kept = all_kept && k.kept;
  }
  result.valid_points = valid;
  result.kept = kept;
  result.removed = valid - kept;
  const std::size_t n = result.labels.size();
  result.kept_mask.resize(n);
  uint8_t* __restrict mask = result.kept_mask.data();
  const int32_t* __restrict labels = result.labels.data();
  if (all_kept) {  // the common case for a clean scan: no gather needed
    for (std::size_t i = 0; i < n; ++i) mask[i] = labels[i] >= 0;
    return;
  }
  const ClusterInfo* clusters = result.clusters.data();
  for (std::size_t i = 0; i < n; ++i)
    mask[i] = labels[i] >= 0 && clusters[labels[i]].kept;
}

}  // namespace internal

absl::Status ClusterLinksOrganized(const PointCloud& cloud,
                                   const LinkClusteringSettings& settings,
                                   LinkClusteringResult& result,
                                   const std::atomic<bool>* cancel) {
  if (auto st = internal::CheckInput(cloud, settings); !st.ok()) return st;
  const uint32_t w = cloud.width, h = cloud.height;
  const float r2 = LinkDistanceSquared(settings.link_distance_mm);
  const bool eight = settings.connectivity == 8;
  result.input_points = cloud.size();
  result.organized_path = true;
  result.labels.resize(cloud.size());
  result.clusters.clear();

  // Scratch for two rows; sized by the width, never per point.
  RowSoA rows[2] = {RowSoA(w), RowSoA(w)};
  std::vector<uint8_t> masks(5 * std::size_t{w}, 0);
  uint8_t* valid = masks.data();
  uint8_t* lw = valid + w;
  uint8_t* lnw = lw + w;
  uint8_t* ln = lnw + w;
  uint8_t* lne = ln + w;
  for (uint32_t r = 0; r < h; ++r) {
    if (cancel && cancel->load(std::memory_order_relaxed))
      return absl::CancelledError("link clustering: cancelled");
    RowSoA& cur = rows[r & 1];
    const RowSoA& up = rows[(r + 1) & 1];
    if (LoadRow(&cloud.points[std::size_t{r} * w], w, cur, valid))
      return absl::InvalidArgumentError(absl::StrCat(
          "link clustering: row ", r, " holds an infinite coordinate"));
    lw[0] = 0;
    LinkMask(&cur.x[1], &cur.y[1], &cur.z[1], &cur.x[0], &cur.y[0], &cur.z[0], w - 1,
             r2, lw + 1);
    const int32_t base = static_cast<int32_t>(std::size_t{r} * w);
    if (r == 0) {
      LabelRow(base, w, valid, lw, nullptr, nullptr, nullptr, result.labels.data());
      continue;
    }
    LinkMask(cur.x.data(), cur.y.data(), cur.z.data(), up.x.data(), up.y.data(),
             up.z.data(), w, r2, ln);
    if (eight) {
      lnw[0] = 0;
      lne[w - 1] = 0;
      LinkMask(&cur.x[1], &cur.y[1], &cur.z[1], &up.x[0], &up.y[0], &up.z[0], w - 1, r2,
               lnw + 1);
      LinkMask(&cur.x[0], &cur.y[0], &cur.z[0], &up.x[1], &up.y[1], &up.z[1], w - 1, r2,
               lne);
    }
    LabelRow(base, w, valid, lw, eight ? lnw : nullptr, ln, eight ? lne : nullptr,
             result.labels.data());
  }
  Flatten(cloud, result);
  internal::DecideKept(settings, result);
  return absl::OkStatus();
}

absl::Status ClusterLinksInto(const PointCloud& cloud, const LinkClusteringSettings& settings,
                              LinkClusteringResult& result,
                              const std::atomic<bool>* cancel) {
  if (cloud.organized()) return ClusterLinksOrganized(cloud, settings, result, cancel);
  return ClusterLinksUnorganized(cloud, settings, result, cancel);
}

absl::StatusOr<LinkClusteringResult> ClusterLinks(const PointCloud& cloud,
                                                  const LinkClusteringSettings& settings,
                                                  const std::atomic<bool>* cancel) {
  LinkClusteringResult result;
  if (auto st = ClusterLinksInto(cloud, settings, result, cancel); !st.ok()) return st;
  return result;
}

absl::StatusOr<PointCloud> ApplyFilter(const PointCloud& cloud,
                                       const LinkClusteringResult& result) {
  if (result.kept_mask.size() != cloud.size() || result.labels.size() != cloud.size())
    return absl::InvalidArgumentError(absl::StrCat(
        "apply filter: the result covers ", result.labels.size(),
        " points but the cloud has ", cloud.size()));
  PointCloud out = cloud;
  const Eigen::Vector3f nan = Eigen::Vector3f::Constant(NAN);
  // Only removed points change; no-data pixels keep their exact bits too.
  for (std::size_t i = 0; i < out.size(); ++i)
    if (!result.kept_mask[i] && result.labels[i] != kInvalid) out.points[i] = nan;
  return out;
}

}  // namespace surfinspect
