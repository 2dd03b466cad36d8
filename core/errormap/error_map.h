// The error map (paper §IV): for every scanned point, its signed distance
// to the closest CAD triangle, plus the statistics, histogram and tolerance
// verdict an inspector reads from it.
//
// Sign (paper Fig. 11): + where the part surface is above the designed
// surface (on the side the CAD's CCW normals point to, shown red), - below
// (blue). Distances are exact (double precision closest point) and signed by
// the closest feature's angle-weighted pseudonormal, see core/distance/mesh_index.h.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/distance/mesh_index.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

// 100000 bins are 0.8 MB of counts, far below a reply's size limit.
constexpr int kMaxHistogramBins = 100000;
// The smallest tolerance and histogram half-width, mm (1 pm: far below any
// sensor's noise). Smaller ones would only make the bin width overflow.
constexpr double kMinLengthMm = 1e-9;

struct ErrorMapSettings {
  double tolerance_mm = 0.1;     // the +-tol band; > 0
  double max_distance_mm = 5.0;  // farther points are unmatched (NaN), like CloudCompare's
                                 // C2M max distance; > 0, inf allowed
  // Fraction of the matched points allowed outside +-tol for a pass. The
  // default 0 is the strict metrology reading (every matched point within
  // tolerance); raise it to tolerate residual noise that filtering kept.
  double allowed_fraction_outside = 0.0;
  int histogram_bins = 41;        // odd, so one bin is centred on 0; <= kMaxHistogramBins
  double histogram_range_mm = 0;  // half-width of the histogram and colour scale; 0 = auto
  bool split_components = false;  // also fill the X/Y/Z and normal components
  int threads = 0;                // 0 = all cores; <= kMaxQueryThreads
};

// Checks the settings: InvalidArgument naming the bad field. ComputeErrorMap,
// the wire conversion, the CLI and the cell file all use it.
absl::Status ValidateErrorMapSettings(const ErrorMapSettings& settings);

struct ErrorMapStats {
  std::size_t count = 0;    // input points, NaN pixels included
  std::size_t valid = 0;    // points with finite coordinates
  std::size_t matched = 0;  // valid points within max_distance_mm of the mesh
  // Over the matched signed deviations, mm; NaN when nothing matched.
  double min_mm = NAN, max_mm = NAN, mean_mm = NAN, stddev_mm = NAN, rms_mm = NAN;
  // Percentiles 1/5/50/95/99 (linear interpolation between order statistics,
  // core/types/percentile.h).
  double p1_mm = NAN, p5_mm = NAN, p50_mm = NAN, p95_mm = NAN, p99_mm = NAN;
};

struct Histogram {
  double min_mm = 0, max_mm = 0;    // [min, max) cut into counts.size() equal bins
  std::vector<std::size_t> counts;  // matched deviations per bin
  std::size_t below_range = 0, above_range = 0;
  double bin_width_mm() const { return counts.empty() ? 0 : (max_mm - min_mm) / counts.size(); }
};

struct Verdict {
  bool pass = false;
  std::size_t within = 0;         // matched points with |deviation| <= tolerance
  std::size_t above = 0;          // deviation > +tolerance
  std::size_t below = 0;          // deviation < -tolerance
  double fraction_within = NAN;   // of matched points
  double fraction_outside = NAN;  // of matched points
  std::string reason;             // one line, for people
};

// Mean / RMS / extremes of one deviation component, mm.
struct ComponentStats {
  double mean_mm = NAN, rms_mm = NAN, min_mm = NAN, max_mm = NAN;
};

struct ErrorMapResult {
  // Per input point, in input order; NaN / UINT32_MAX where unmatched.
  std::vector<float> deviation_mm;             // signed, + above the CAD surface
  std::vector<uint32_t> triangle_id;           // the closest CAD triangle
  std::vector<Eigen::Vector3f> closest_point;  // on the CAD surface, part frame, mm
  // Only with split_components (else empty). point - closest point in the
  // part frame, and its component along the closest face's normal (the
  // paper's point-to-plane distance, eq. 6; equals the deviation inside a face).
  std::vector<Eigen::Vector3f> deviation_xyz_mm;
  std::vector<float> normal_deviation_mm;
  std::array<ComponentStats, 4> component_stats;  // x, y, z, normal (split only)

  ErrorMapStats stats;
  Histogram histogram;
  Verdict verdict;
  double tolerance_mm = 0;
  double color_range_mm = 0;  // the histogram's half-width, shared by the colour scale
  // Wall time, s: the closest-point queries (order + search) and, of them,
  // the visiting order; then the statistics, histogram and verdict.
  double query_seconds = 0;
  double order_seconds = 0;
  double statistics_seconds = 0;
  // Queries the hint certificates answered without the tree, and of them
  // by the hint alone (core/distance/hint_certificate.h).
  std::size_t certified_points = 0;
  std::size_t hint_alone_points = 0;
};

// `cloud_in_world` is mapped into the part frame with world_from_part^-1.
// InvalidArgument for bad settings or a malformed cloud; CancelledError when
// `cancel` is set during the queries. An empty cloud gives a failing verdict.
absl::StatusOr<ErrorMapResult> ComputeErrorMap(const MeshIndex& index,
                                               const PointCloud& cloud_in_world,
                                               const Eigen::Isometry3d& world_from_part,
                                               const ErrorMapSettings& settings,
                                               const std::atomic<bool>* cancel = nullptr);

// The automatic half-width: max(2 tol, |p1|, |p99|) rounded up to 1, 2, 2.5
// or 5 x 10^k mm, so one outlier does not flatten the scale.
double AutoColorRange(double tolerance_mm, double p1_mm, double p99_mm);

}  // namespace surfinspect
