#include "core/errormap/error_map.h"

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <chrono>
#include <new>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/types/cancel.h"
#include "core/types/percentile.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

// In double, in the vector's order, whatever its element type.
template <typename T>
ComponentStats Summarize(const std::vector<T>& values) {
  ComponentStats c;
  if (values.empty()) return c;
  double sum = 0, sum2 = 0;
  c.min_mm = INFINITY;
  c.max_mm = -INFINITY;
  for (const double v : values) {
    sum += v;
    sum2 += v * v;
    c.min_mm = std::min(c.min_mm, v);
    c.max_mm = std::max(c.max_mm, v);
  }
  c.mean_mm = sum / values.size();
  c.rms_mm = std::sqrt(sum2 / values.size());
  return c;
}

// The verdict's counts of the matched deviations (none NaN) against +-tol.
// Added up, not branched on: a scanned part's deviations fall either side
// of the band at random, and a branch per point is mispredicted.
void CountVerdict(const std::vector<float>& matched, double tol, Verdict& v) {
  std::size_t above = 0, below = 0;
  for (float d : matched) {
    above += d > tol;
    below += d < -tol;
  }
  v.above += above;
  v.below += below;
  v.within += matched.size() - above - below;
}

// Min, max, mean, rms and standard deviation of the matched deviations: two
// passes in double, in input order, so deterministic to the last bit.
void SummarizeMatched(const std::vector<float>& matched, ErrorMapStats& stats) {
  if (matched.empty()) return;
  const ComponentStats s = Summarize(matched);
  double var = 0;
  for (const double d : matched) var += (d - s.mean_mm) * (d - s.mean_mm);
  stats.min_mm = s.min_mm;
  stats.max_mm = s.max_mm;
  stats.mean_mm = s.mean_mm;
  stats.rms_mm = s.rms_mm;
  stats.stddev_mm = std::sqrt(var / matched.size());
}

void SetPercentiles(const std::vector<float>& matched, ErrorMapStats& stats) {
  if (matched.empty()) return;
  const std::vector<double> p = FloatPercentiles(matched, {0.01, 0.05, 0.50, 0.95, 0.99});
  stats.p1_mm = p[0];
  stats.p5_mm = p[1];
  stats.p50_mm = p[2];
  stats.p95_mm = p[3];
  stats.p99_mm = p[4];
}

void SetReason(const ErrorMapSettings& settings, const ErrorMapStats& stats, Verdict& v) {
  if (stats.matched == 0) {
    v.reason =
        absl::StrCat("fail: no point within ", settings.max_distance_mm, " mm of the CAD surface");
    return;
  }
  v.reason = absl::StrFormat(
      "%s: %.3f%% of %u matched points outside +-%.4g mm (%u above, %u below; allowed %.3f%%)",
      v.pass ? "pass" : "fail", 100 * v.fraction_outside, stats.matched, settings.tolerance_mm,
      v.above, v.below, 100 * settings.allowed_fraction_outside);
}

// The histogram of the matched deviations over +-range (the colour scale's).
void FillHistogram(const std::vector<float>& matched, int bins, double range, Histogram& h) {
  h.min_mm = -range;
  h.max_mm = range;
  h.counts.assign(static_cast<std::size_t>(bins), 0);
  const double per_mm = bins / (2 * range);
  const double last_bin = double(h.counts.size() - 1);
  for (float d : matched) {
    if (d < -range)
      ++h.below_range;
    else if (d >= range)
      ++h.above_range;
    else  // clamped in double first: a float-to-integer conversion out of range is undefined
      ++h.counts[static_cast<std::size_t>(std::min(last_bin, (d + range) * per_mm))];
  }
}

// The counts, summary, verdict, percentiles and histogram of the matched
// deviations. The sums' order fixes their bits, so they stay one serial
// pass; the counts of valid points, the verdict's counts and the
// percentiles (which the histogram's range needs) run beside them. `cancel`
// is polled between the steps; false when it was set.
bool ComputeStats(const PointCloud& cloud, const ErrorMapSettings& settings, ErrorMapResult& r,
                  const std::atomic<bool>* cancel) {
  std::vector<float> matched;
  matched.reserve(r.deviation_mm.size());
  for (float d : r.deviation_mm)
    if (!std::isnan(d)) matched.push_back(d);
  r.stats.count = cloud.size();
  r.stats.matched = matched.size();
  if (IsCancelled(cancel)) return false;
  Verdict& v = r.verdict;
  tbb::parallel_invoke(
      [&] {
        r.stats.valid = cloud.CountValid();
        SummarizeMatched(matched, r.stats);
      },
      [&] {
        CountVerdict(matched, settings.tolerance_mm, v);
        SetPercentiles(matched, r.stats);
      });
  if (!matched.empty()) {
    v.fraction_within = static_cast<double>(v.within) / r.stats.matched;
    v.fraction_outside = 1.0 - v.fraction_within;
  }
  v.pass = r.stats.matched > 0 && v.fraction_outside <= settings.allowed_fraction_outside;
  SetReason(settings, r.stats, v);
  if (IsCancelled(cancel)) return false;
  r.color_range_mm = settings.histogram_range_mm > 0
                         ? settings.histogram_range_mm
                         : AutoColorRange(settings.tolerance_mm, r.stats.p1_mm, r.stats.p99_mm);
  FillHistogram(matched, settings.histogram_bins, r.color_range_mm, r.histogram);
  return true;
}

}  // namespace

absl::Status ValidateErrorMapSettings(const ErrorMapSettings& s) {
  auto bad = [](absl::string_view what, double v) {
    return absl::InvalidArgumentError(absl::StrCat("error map: ", what, ", got ", v));
  };
  if (!(s.tolerance_mm >= kMinLengthMm) || !std::isfinite(s.tolerance_mm))
    return bad(absl::StrCat("tolerance_mm must be a number >= ", kMinLengthMm), s.tolerance_mm);
  if (!(s.max_distance_mm > 0))
    return bad("max_distance_mm must be > 0 (inf allowed)", s.max_distance_mm);
  if (!(s.allowed_fraction_outside >= 0 && s.allowed_fraction_outside <= 1))
    return bad("allowed_fraction_outside must be in [0, 1]", s.allowed_fraction_outside);
  if (s.histogram_bins < 1 || s.histogram_bins > kMaxHistogramBins)
    return bad(absl::StrCat("histogram_bins must be in [1, ", kMaxHistogramBins, "]"),
               s.histogram_bins);
  if (!(s.histogram_range_mm == 0 || s.histogram_range_mm >= kMinLengthMm) ||
      !std::isfinite(s.histogram_range_mm))
    return bad(absl::StrCat("histogram_range_mm must be 0 (auto) or >= ", kMinLengthMm),
               s.histogram_range_mm);
  if (s.threads < 0 || s.threads > kMaxQueryThreads)
    return bad(absl::StrCat("threads must be in [0, ", kMaxQueryThreads, "]"), s.threads);
  return absl::OkStatus();
}

double AutoColorRange(double tolerance_mm, double p1_mm, double p99_mm) {
  double want = 2 * tolerance_mm;
  if (std::isfinite(p1_mm)) want = std::max(want, std::abs(p1_mm));
  if (std::isfinite(p99_mm)) want = std::max(want, std::abs(p99_mm));
  const double decade = std::pow(10.0, std::floor(std::log10(want)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * decade >= want * (1 - 1e-12)) return m * decade;
  return 10 * decade;
}

absl::StatusOr<ErrorMapResult> ComputeErrorMap(const MeshIndex& index,
                                               const PointCloud& cloud_in_world,
                                               const Eigen::Isometry3d& world_from_part,
                                               const ErrorMapSettings& settings,
                                               const std::atomic<bool>* cancel) {
  RETURN_IF_ERROR(ValidateErrorMapSettings(settings));
  const absl::Status cancelled = absl::CancelledError("error map cancelled");
  if (IsCancelled(cancel)) return cancelled;
  // The cloud itself is checked by the query below (PointCloud::Validate),
  // which a second pass over every point here would repeat.
  if (!world_from_part.matrix().allFinite())
    return absl::InvalidArgumentError("error map: world_from_part is not finite");
  const std::size_t n = cloud_in_world.size();
  ErrorMapResult r;
  r.tolerance_mm = settings.tolerance_mm;
  const bool split = settings.split_components;
  const Eigen::Vector3f nan3 = Eigen::Vector3f::Constant(NAN);
  try {
    // 20 MB of fresh pages for 10^6 points: the first touches are the cost,
    // so the closest points are filled beside the other two.
    bool filled_points = false, filled_rest = false;
    tbb::parallel_invoke(
        [&] { filled_points = FillUnlessCancelled(r.closest_point, n, nan3, cancel); },
        [&] {
          filled_rest = FillUnlessCancelled(r.deviation_mm, n, float{NAN}, cancel) &&
                        FillUnlessCancelled(r.triangle_id, n, uint32_t{UINT32_MAX}, cancel);
        });
    if (!filled_points || !filled_rest) return cancelled;
    if (split && (!FillUnlessCancelled(r.deviation_xyz_mm, n, nan3, cancel) ||
                  !FillUnlessCancelled(r.normal_deviation_mm, n, float{NAN}, cancel)))
      return cancelled;
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError(
        absl::StrCat("error map: cannot allocate for ", n, " points"));
  }
  const Eigen::Isometry3d part_from_world = world_from_part.inverse();
  BatchQuerySettings query;
  query.max_distance_mm = settings.max_distance_mm;
  query.threads = settings.threads;
  const auto start = std::chrono::steady_clock::now();
  BatchQueryTiming timing;
  auto st = QueryClosestEach(
      index, cloud_in_world, part_from_world, query, cancel,
      [&](std::size_t i, const ClosestPoint& c) {
        if (!c.matched()) return;
        r.deviation_mm[i] = static_cast<float>(c.signed_distance_mm);
        r.triangle_id[i] = c.triangle_id;
        r.closest_point[i] = c.point.cast<float>();
        if (split) {
          const Eigen::Vector3d diff =
              part_from_world * cloud_in_world.points[i].cast<double>() - c.point;
          r.deviation_xyz_mm[i] = diff.cast<float>();
          // The paper's eq. (6): the offset projected on the face normal.
          r.normal_deviation_mm[i] = static_cast<float>(diff.dot(c.normal));
        }
      },
      &timing);
  if (!st.ok()) return st;
  const auto queried = std::chrono::steady_clock::now();
  r.query_seconds = std::chrono::duration<double>(queried - start).count();
  r.order_seconds = timing.order_seconds;
  r.certified_points = timing.certified_points;
  r.hint_alone_points = timing.hint_alone_points;

  if (IsCancelled(cancel)) return cancelled;
  if (!ComputeStats(cloud_in_world, settings, r, cancel)) return cancelled;
  if (split) {
    std::array<std::vector<double>, 4> comp;
    for (std::size_t i = 0; i < n; ++i) {
      if (std::isnan(r.deviation_mm[i])) continue;
      for (int a = 0; a < 3; ++a) comp[a].push_back(r.deviation_xyz_mm[i][a]);
      comp[3].push_back(r.normal_deviation_mm[i]);
    }
    for (int a = 0; a < 4; ++a) {
      if (IsCancelled(cancel)) return cancelled;
      r.component_stats[a] = Summarize(comp[a]);
    }
  }
  r.statistics_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - queried).count();
  return r;
}

}  // namespace surfinspect
