// Defect detection on an error map: connected patches of the surface whose
// robust local deviation exceeds a threshold, with an area, a centroid on
// the CAD surface and a fitted peak depth. Defects are evidence next to the
// deviations and statistics; they change none of them.
//
// The steps, each from a standard source:
//  1. Neighbourhoods on the surface: the scanned points within a radius r
//     (2.5 sampling spacings) in 3D, searched in a pixel window on an
//     organized grid and in a cell grid otherwise (merged views); see
//     core/plan/surface_neighbourhood.h. A window never straddles a
//     depth jump, and a mixed pixel hanging between two surfaces (kept by
//     the filter through a chain of links) has too few neighbours for an
//     estimate, so a band of them is never a defect.
//  2. A robust local estimate: the median of the signed deviations in each
//     point's neighbourhood (Tukey's running median, "Exploratory Data
//     Analysis", 1977). Sensor noise of sigma shrinks to ~1.25 sigma/sqrt(n)
//     (n ~ 20: 0.004 mm at sigma 0.015 mm), and a stray point or a blob
//     smaller than half a neighbourhood cannot move it. It is computed only
//     where a window (or 27-cell) count of same-sign points beyond the
//     threshold allows the median to pass it, which changes no result.
//  3. Threshold |median| > threshold_mm, split by sign (dent below, bump
//     above), and link same-sign candidates closer than the link distance
//     into components with union-find (Tarjan, JACM 1975).
//  4. The area rule: the area of a component is the sum of its points'
//     footprints (organized: |du x dv| of the central differences of the
//     closest CAD points; unorganized: pi r^2 / points within r), and only
//     components of at least min_area_mm2 are defects.
//  5. The peak: an isotropic Gaussian c + A exp(-|x - x0|^2 / (2 s^2)) on
//     the tangent plane at the deepest median, fitted by Levenberg-Marquardt
//     (core/plan/gaussian_fit.h) to the raw deviations of the
//     component and a ring around it (points beyond 5 robust sigma dropped
//     and the fit repeated once); peak = c + A, the deviation at the fitted
//     centre. The fit is kept only when plausible (its peak within the
//     patch's measured extremes +- 3 sigma of the noise, among others);
//     otherwise the peak is the deepest median. A kept fit's centre is the
//     defect's position: a patch cut by an edge has a biased centroid.
//
// Units mm, part frame. Deterministic: the same result for any thread count.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/errormap/error_map.h"
#include "core/plan/inspection_plan.h"
#include "core/types/point_cloud.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

enum class DefectKind { kDent, kBump };       // below / above the CAD surface
const char* DefectKindName(DefectKind kind);  // "dent" | "bump"

struct Defect {
  int id = 0;  // 1.. in order of decreasing |peak_mm|
  DefectKind kind = DefectKind::kDent;
  // On the CAD surface: the fitted Gaussian's centre when the peak is
  // fitted, else the patch's area-weighted centroid.
  Eigen::Vector3d centroid_mm = Eigen::Vector3d::Zero();
  uint32_t triangle_id = UINT32_MAX;  // the CAD triangle under the centroid
  double area_mm2 = 0;
  double extent_mm = 0;      // length along the patch's principal axis
  double peak_mm = 0;        // signed: < 0 for a dent
  bool peak_fitted = false;  // false: the peak is the deepest median
  // Evidence for the peak: the patch's most extreme raw deviation on the
  // defect's side, and the noise about the local medians (robust sigma).
  // A fitted peak lies within the patch's extremes +- 3 noise_mm.
  double measured_extreme_mm = NAN;
  double noise_mm = NAN;
  double fit_sigma_mm = NAN;  // the fitted Gaussian's s (lateral size)
  double fit_rms_mm = NAN;    // RMS residual of the fit
  std::size_t points = 0;     // scanned points in the patch
  std::string region;         // first plan region containing triangle_id, or empty
};

struct DefectSettings {
  // Sampling spacing of the cloud on the surface, mm; 0 = estimated (the
  // median distance between neighbouring closest CAD points).
  double spacing_mm = 0;
  // The median's neighbourhood radius in spacings (2.5: ~20 points), and the
  // unorganized path's link distance.
  double neighbourhood_spacings = 2.5;
  double link_spacings = 2.0;
  // Organized path: the link distance between 8-neighbours, in spacings:
  // generous (1 mm at the demo's 0.25 mm pitch), so steep walls stay
  // linked, and still below the depth jumps between surfaces.
  double grid_link_spacings = 4.0;
  // Fewer scanned points within r: no robust estimate, never a defect. 8 of
  // the ~20 a surface sampled at the spacing has; a surface seen at grazing
  // incidence (spacing > ~1.5x the estimate) gets no estimate either.
  int min_neighbours = 8;
  int threads = 0;  // 0 = all cores; the result is the same for any value
};

struct DefectsResult {
  std::vector<Defect> defects;
  bool organized_path = false;
  double spacing_mm = 0;             // used (estimated or given)
  double link_mm = 0;                // used
  std::size_t candidate_points = 0;  // points above the threshold
  std::size_t rejected_patches = 0;  // patches below min_area_mm2
};

// `cloud` is the cloud the error map was computed on (any frame: only
// distances between its points are used, and its grid layout). `part` is
// the mesh of the error map; `plan`, when given, names each defect's region.
// InvalidArgument for bad rules or mismatched sizes.
absl::StatusOr<DefectsResult> FindDefects(const ErrorMapResult& error_map, const PointCloud& cloud,
                                          const TriangleMesh& part, const DefectRules& rules,
                                          const ResolvedInspectionPlan* plan = nullptr,
                                          const DefectSettings& settings = {});

}  // namespace surfinspect
