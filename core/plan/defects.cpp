#include "core/plan/defects.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "absl/strings/str_cat.h"
#include "core/plan/gaussian_fit.h"
#include "core/plan/surface_neighbourhood.h"
#include "core/types/status_macros.h"
#include "core/types/union_find.h"

namespace surfinspect {
namespace {

constexpr std::size_t kBlock = 4096;  // points per parallel task of the median pass

float Distance(const ErrorMapResult& em, std::size_t i, std::size_t j) {
  return (em.closest_point[i] - em.closest_point[j]).norm();
}

// The median of the deviations around each matched point that may pass
// the threshold (NaN elsewhere, and where there are too few neighbours).
std::vector<float> RobustDeviation(const ErrorMapResult& em, const SurfaceNeighbourhood& nb,
                                   const std::vector<uint32_t>& order, float threshold,
                                   int min_neighbours, int threads) {
  std::vector<int8_t> hot(em.deviation_mm.size(), 0);
  for (std::size_t i = 0; i < hot.size(); ++i) {
    const float d = em.deviation_mm[i];  // NaN (unmatched) is neither
    hot[i] = static_cast<int8_t>(d > threshold ? 1 : d < -threshold ? -1 : 0);
  }
  const std::vector<uint8_t> may =
      nb.MayExceed(hot, static_cast<uint32_t>((min_neighbours + 1) / 2));
  std::vector<float> m(em.deviation_mm.size(), NAN);
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, order.size(), kBlock), [&](auto range) {
      std::vector<uint32_t> near;
      std::vector<double> values;
      for (std::size_t k = range.begin(); k != range.end(); ++k) {
        const uint32_t i = order[k];
        if (!may[i]) continue;
        nb.Local(i, near);
        if (near.size() < static_cast<std::size_t>(min_neighbours)) continue;
        values.clear();
        for (uint32_t j : near) values.push_back(em.deviation_mm[j]);
        m[i] = static_cast<float>(MedianInPlace(values));
      }
    });
  });
  return m;
}

// Same-sign candidates linked into patches; each patch's points ascending.
// Only candidates have a sign, so a linked point of the same sign is one.
std::vector<std::vector<uint32_t>> Patches(const std::vector<int8_t>& sign,
                                           const std::vector<uint32_t>& candidates,
                                           const SurfaceNeighbourhood& nb) {
  std::unordered_map<uint32_t, int32_t> dense;  // point -> its index in `candidates`
  dense.reserve(candidates.size());
  for (uint32_t i : candidates) dense.emplace(i, static_cast<int32_t>(dense.size()));
  UnionFind uf(candidates.size());
  std::vector<uint32_t> near;
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    const uint32_t i = candidates[k];
    nb.Links(i, near);
    for (uint32_t j : near)
      if (j < i && sign[j] == sign[i]) uf.Union(static_cast<int32_t>(k), dense.at(j));
  }
  // Candidates ascend, and a set's root is its smallest member, so patches
  // are numbered by their first point.
  std::unordered_map<int32_t, std::size_t> slot;
  std::vector<std::vector<uint32_t>> patches;
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    auto [it, fresh] = slot.emplace(uf.Find(static_cast<int32_t>(k)), patches.size());
    if (fresh) patches.emplace_back();
    patches[it->second].push_back(candidates[k]);
  }
  return patches;
}

// Points within `reach` of the seed, grown from the patch through links.
// Points of an opposite-sign patch (a bump beside a dent) are left out: they
// belong to another defect's profile, and a single Gaussian fitted across
// both is pulled towards the neighbour.
std::vector<uint32_t> FitSupport(const ErrorMapResult& em, const SurfaceNeighbourhood& nb,
                                 const std::vector<uint32_t>& patch, uint32_t seed, double reach,
                                 const std::vector<int8_t>& sign) {
  constexpr std::size_t kMaxPoints = 200000;  // bounds the work on a huge patch
  std::unordered_map<uint32_t, char> seen;
  std::vector<uint32_t> out(patch.begin(), patch.end()), near;
  for (uint32_t i : patch) seen[i] = 1;
  for (std::size_t k = 0; k < out.size() && out.size() < kMaxPoints; ++k) {
    nb.Links(out[k], near);
    for (uint32_t j : near)
      if (seen.emplace(j, 1).second && sign[j] != -sign[seed] && Distance(em, seed, j) <= reach)
        out.push_back(j);
  }
  std::sort(out.begin(), out.end());
  return out;
}

// What the patch measured: its raw deviations' extremes and the noise about
// its local medians (1.4826 MAD, a robust sigma).
struct PatchEvidence {
  double min_mm = INFINITY, max_mm = -INFINITY, noise_mm = 0;
};
PatchEvidence MeasuredExtremes(const ErrorMapResult& em, const std::vector<float>& median,
                               const std::vector<uint32_t>& patch) {
  PatchEvidence e;
  std::vector<double> residual;
  for (uint32_t i : patch) {
    e.min_mm = std::min<double>(e.min_mm, em.deviation_mm[i]);
    e.max_mm = std::max<double>(e.max_mm, em.deviation_mm[i]);
    residual.push_back(std::abs(em.deviation_mm[i] - median[i]));
  }
  e.noise_mm = MadSigma(residual);
  return e;
}

}  // namespace

const char* DefectKindName(DefectKind kind) { return kind == DefectKind::kDent ? "dent" : "bump"; }

namespace {

// The defect placed at `centre` (the fitted Gaussian's, on the seed's
// tangent plane), moved onto the plane of the CAD triangle under the support
// point nearest to it.
void PlaceAtFittedCentre(const ErrorMapResult& em, const std::vector<Eigen::Vector3f>& normals,
                         const std::vector<uint32_t>& support, const Eigen::Vector3d& centre,
                         Defect& d) {
  uint32_t nearest = support[0];
  double best = INFINITY;
  for (uint32_t j : support) {
    const double d2 = (em.closest_point[j].cast<double>() - centre).squaredNorm();
    if (d2 < best) best = d2, nearest = j;
  }
  d.triangle_id = em.triangle_id[nearest];
  const Eigen::Vector3d n = normals[d.triangle_id].cast<double>().normalized();
  d.centroid_mm = centre - (centre - em.closest_point[nearest].cast<double>()).dot(n) * n;
}

// The Gaussian fitted to `uvd`, then refitted once without the samples
// beyond 5 robust sigma of its residuals (stray pixels).
GaussianFit RobustGaussianFit(const std::vector<Eigen::Vector3d>& uvd, const GaussianFit& start) {
  std::vector<char> keep(uvd.size(), 1);
  GaussianFit fit = FitIsotropicGaussian(uvd, keep, start);
  if (!fit.ok) return fit;
  const double s2 = fit.sigma * fit.sigma;
  std::vector<double> abs_res(uvd.size());
  for (std::size_t k = 0; k < uvd.size(); ++k) {
    const double r2 = (uvd[k].head<2>() - fit.centre).squaredNorm();
    abs_res[k] = std::abs(fit.baseline + fit.amplitude * std::exp(-r2 / (2 * s2)) - uvd[k].z());
  }
  std::vector<double> copy = abs_res;
  // 5 robust sigmas (MadSigma), multiplied in this order so that the cut
  // stays bit for bit what it was.
  const double cut = 5 * 1.4826 * MedianInPlace(copy);
  for (std::size_t k = 0; k < uvd.size(); ++k) keep[k] = abs_res[k] <= cut;
  return FitIsotropicGaussian(uvd, keep, fit);
}

// One patch's peak into `d`: the robust Gaussian fit over the patch and a
// ring around it, kept only when it is plausible: a centre within reach, a
// width between a quarter spacing and the reach, the patch's sign, and a
// peak within the patch's measured extremes widened by 3 sigma of the noise
// (a fit can diverge to a huge narrow spike between samples, e.g. beside
// fixture points at a boundary). Otherwise the peak is the deepest local
// median, a measured value. A kept fit also places the defect: its centre
// is not biased where an edge or a view's border cuts the patch, as the
// patch's centroid is.
void FitPeak(const ErrorMapResult& em, const SurfaceNeighbourhood& nb,
             const std::vector<float>& median, const std::vector<int8_t>& sign,
             const std::vector<uint32_t>& patch, const std::vector<Eigen::Vector3f>& normals,
             uint32_t seed, double threshold_mm, double spacing_mm, Defect& d) {
  double radius = 0;
  for (uint32_t i : patch) radius = std::max<double>(radius, Distance(em, seed, i));
  const double reach = std::min(2 * radius + 3 * spacing_mm, 30.0);
  const std::vector<uint32_t> support = FitSupport(em, nb, patch, seed, reach, sign);
  const Eigen::Vector3d n = normals[em.triangle_id[seed]].cast<double>().normalized();
  const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
  const Eigen::Vector3d o = em.closest_point[seed].cast<double>();
  std::vector<Eigen::Vector3d> uvd;
  for (uint32_t j : support) {
    const Eigen::Vector3d q = em.closest_point[j].cast<double>() - o;
    uvd.emplace_back(q.dot(u), q.dot(v), em.deviation_mm[j]);
  }
  GaussianFit start;
  start.amplitude = median[seed];
  const double r_eq = std::sqrt(d.area_mm2 / M_PI);
  start.sigma = std::max(
      spacing_mm,
      r_eq / std::sqrt(2 * std::log(std::max(std::abs(start.amplitude) / threshold_mm, 1.5))));
  const GaussianFit fit = RobustGaussianFit(uvd, start);
  const PatchEvidence e = MeasuredExtremes(em, median, patch);
  d.measured_extreme_mm = median[seed] < 0 ? e.min_mm : e.max_mm;
  d.noise_mm = e.noise_mm;
  const double peak = fit.baseline + fit.amplitude;
  d.peak_fitted = fit.ok && fit.centre.norm() <= reach && fit.sigma > 0.25 * spacing_mm &&
                  fit.sigma < reach && (peak < 0) == (median[seed] < 0) &&
                  peak >= e.min_mm - 3 * e.noise_mm && peak <= e.max_mm + 3 * e.noise_mm;
  d.peak_mm = d.peak_fitted ? peak : median[seed];
  d.fit_sigma_mm = d.peak_fitted ? fit.sigma : NAN;
  d.fit_rms_mm = d.peak_fitted ? fit.rms : NAN;
  if (d.peak_fitted)
    PlaceAtFittedCentre(em, normals, support, o + fit.centre.x() * u + fit.centre.y() * v, d);
}

// Area, centroid on the surface and extent of one patch into `d`.
void Measure(const ErrorMapResult& em, const SurfaceNeighbourhood& nb,
             const std::vector<Eigen::Vector3f>& normals, const std::vector<uint32_t>& patch,
             Defect& d) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::vector<double> area(patch.size());
  for (std::size_t k = 0; k < patch.size(); ++k) {
    area[k] = nb.Area(patch[k]);
    d.area_mm2 += area[k];
    sum += area[k] * em.closest_point[patch[k]].cast<double>();
  }
  const Eigen::Vector3d mean = sum / d.area_mm2;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  uint32_t nearest = patch[0];
  double best = INFINITY;
  for (std::size_t k = 0; k < patch.size(); ++k) {
    const Eigen::Vector3d q = em.closest_point[patch[k]].cast<double>() - mean;
    cov += area[k] * q * q.transpose();
    if (q.squaredNorm() < best) best = q.squaredNorm(), nearest = patch[k];
  }
  // Onto the plane of the CAD triangle under the nearest patch point.
  d.triangle_id = em.triangle_id[nearest];
  const Eigen::Vector3d n = normals[d.triangle_id].cast<double>();
  const Eigen::Vector3d on = em.closest_point[nearest].cast<double>();
  d.centroid_mm = mean - (mean - on).dot(n) * n;
  const Eigen::Vector3d axis =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(2);
  double lo = INFINITY, hi = -INFINITY;
  for (uint32_t i : patch) {
    const double s = (em.closest_point[i].cast<double>() - mean).dot(axis);
    lo = std::min(lo, s), hi = std::max(hi, s);
  }
  d.extent_mm = hi - lo;
  d.points = patch.size();
}

absl::Status CheckInput(const ErrorMapResult& em, const PointCloud& cloud, const TriangleMesh& part,
                        const DefectRules& rules, const DefectSettings& s) {
  const std::size_t n = em.deviation_mm.size();
  if (em.triangle_id.size() != n || em.closest_point.size() != n || cloud.size() != n)
    return absl::InvalidArgumentError("defects: error map and cloud sizes differ");
  if (cloud.organized() && std::size_t{cloud.width} * cloud.height != n)
    return absl::InvalidArgumentError("defects: width x height does not match the points");
  for (uint32_t t : em.triangle_id)
    if (t != UINT32_MAX && t >= part.num_triangles())
      return absl::InvalidArgumentError("defects: triangle id beyond the part mesh");
  if (!(rules.threshold_mm > 0) || !std::isfinite(rules.threshold_mm) ||
      !(rules.min_area_mm2 >= 0) || !std::isfinite(rules.min_area_mm2))
    return absl::InvalidArgumentError("defects: threshold_mm must be > 0, min_area_mm2 >= 0");
  if (!(s.spacing_mm >= 0) || !(s.neighbourhood_spacings > 0) || !(s.link_spacings > 0) ||
      !(s.grid_link_spacings > 0) || s.min_neighbours < 1)
    return absl::InvalidArgumentError("defects: bad settings");
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<DefectsResult> FindDefects(const ErrorMapResult& em, const PointCloud& cloud,
                                          const TriangleMesh& part, const DefectRules& rules,
                                          const ResolvedInspectionPlan* plan,
                                          const DefectSettings& settings) {
  RETURN_IF_ERROR(CheckInput(em, cloud, part, rules, settings));
  DefectsResult out;
  out.organized_path = cloud.organized();
  out.spacing_mm =
      settings.spacing_mm > 0 ? settings.spacing_mm : EstimateSurfaceSpacing(em, cloud);
  const auto radius = static_cast<float>(settings.neighbourhood_spacings * out.spacing_mm);
  std::unique_ptr<SurfaceNeighbourhood> nb;
  if (out.organized_path) {
    out.link_mm = settings.grid_link_spacings * out.spacing_mm;
    nb = MakeGridNeighbourhood(em, cloud, radius, static_cast<float>(out.link_mm), out.spacing_mm);
  } else {
    out.link_mm = settings.link_spacings * out.spacing_mm;
    nb = MakeCellNeighbourhood(em, cloud, radius, static_cast<float>(out.link_mm));
  }
  const std::vector<uint32_t> order = nb->MatchedOrder();
  const std::vector<float> median =
      RobustDeviation(em, *nb, order, static_cast<float>(rules.threshold_mm),
                      settings.min_neighbours, settings.threads);
  std::vector<int8_t> sign(median.size(), 0);
  std::vector<uint32_t> candidates;
  const float thr = static_cast<float>(rules.threshold_mm);
  for (std::size_t i = 0; i < median.size(); ++i)
    if (std::abs(median[i]) > thr) {
      sign[i] = median[i] > 0 ? 1 : -1;
      candidates.push_back(static_cast<uint32_t>(i));
    }
  out.candidate_points = candidates.size();
  const std::vector<Eigen::Vector3f> normals = part.FaceNormals();
  for (const std::vector<uint32_t>& patch : Patches(sign, candidates, *nb)) {
    Defect d;
    Measure(em, *nb, normals, patch, d);
    if (d.area_mm2 < rules.min_area_mm2) {
      ++out.rejected_patches;
      continue;
    }
    uint32_t seed = patch[0];
    for (uint32_t i : patch)
      if (std::abs(median[i]) > std::abs(median[seed])) seed = i;
    d.kind = median[seed] < 0 ? DefectKind::kDent : DefectKind::kBump;
    FitPeak(em, *nb, median, sign, patch, normals, seed, rules.threshold_mm, out.spacing_mm, d);
    if (plan) {
      const int region = plan->FirstRegionOf(d.triangle_id);
      if (region >= 0) d.region = plan->plan.regions[static_cast<std::size_t>(region)].name;
    }
    out.defects.push_back(std::move(d));
  }
  std::stable_sort(out.defects.begin(), out.defects.end(), [](const Defect& a, const Defect& b) {
    return std::abs(a.peak_mm) > std::abs(b.peak_mm);
  });
  for (std::size_t k = 0; k < out.defects.size(); ++k) out.defects[k].id = static_cast<int>(k + 1);
  return out;
}

}  // namespace surfinspect
