#include "core/plan/characteristics.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"

namespace surfinspect {
namespace {

// Points per chunk: the unit of parallel work and of the fixed reduction
// order. 64k points keeps 2 M points in 31 chunks, enough for any core count
// here, and the per-chunk accumulators (~64 B per characteristic) small.
constexpr std::size_t kChunk = std::size_t{1} << 16;

struct Accumulator {
  std::size_t count = 0, within = 0, above = 0, below = 0;
  double sum = 0, sum2 = 0, min = INFINITY, max = -INFINITY;

  void Add(float d, const ToleranceBand& band) {
    // Counted without branches: most points of a failing part fall on
    // either side of the band at random, which a branch mispredicts.
    ++count;
    const bool in = band.Contains(d), high = d > static_cast<float>(band.upper_mm);
    within += in;
    above += !in & high;
    below += !in & !high;
    const double v = d;
    sum += v;
    sum2 += v * v;
    min = std::min(min, v);
    max = std::max(max, v);
  }
  void Merge(const Accumulator& o) {
    count += o.count;
    within += o.within;
    above += o.above;
    below += o.below;
    sum += o.sum;
    sum2 += o.sum2;
    min = std::min(min, o.min);
    max = std::max(max, o.max);
  }
};

// The characteristics' bands: surface, then regions, then points.
std::vector<ToleranceBand> Bands(const InspectionPlan& plan) {
  std::vector<ToleranceBand> bands{plan.tolerance};
  for (const PlanRegion& r : plan.regions) bands.push_back(r.tolerance.value_or(plan.tolerance));
  for (const ComparisonPoint& p : plan.points)
    bands.push_back(p.tolerance.value_or(plan.tolerance));
  return bands;
}

// Accumulates points [first, last) into acc (one slot per characteristic).
void AccumulateChunk(const ErrorMapResult& em, const ResolvedInspectionPlan& rp,
                     const std::vector<ToleranceBand>& bands, std::size_t first, std::size_t last,
                     std::vector<Accumulator>& acc) {
  const std::size_t region_base = 1, point_base = 1 + rp.plan.regions.size();
  std::vector<double> radius_sq;
  for (const ComparisonPoint& p : rp.plan.points) radius_sq.push_back(p.radius_mm * p.radius_mm);
  // Without regions or points only the surface counts: no lookups by triangle.
  const bool per_triangle = !rp.region_ids.empty() || !rp.point_ids.empty();
  // The surface's sums in locals: through acc[0] every store to them could
  // change bands[0] (both double), so each point would reload and store all.
  Accumulator surface = acc[0];
  const ToleranceBand surface_band = bands[0];
  for (std::size_t i = first; i < last; ++i) {
    const uint32_t t = em.triangle_id[i];
    if (t == UINT32_MAX) continue;
    const float d = em.deviation_mm[i];
    surface.Add(d, surface_band);
    if (!per_triangle) continue;
    for (uint32_t k = rp.region_offsets[t]; k < rp.region_offsets[t + 1]; ++k) {
      const std::size_t c = region_base + rp.region_ids[k];
      acc[c].Add(d, bands[c]);
    }
    for (uint32_t k = rp.point_offsets[t]; k < rp.point_offsets[t + 1]; ++k) {
      const uint32_t p = rp.point_ids[k];
      const Eigen::Vector3d q = em.closest_point[i].cast<double>();
      if ((q - rp.plan.points[p].position_mm).squaredNorm() > radius_sq[p]) continue;
      const float v = rp.point_scale.empty() ? d : d * rp.point_scale[k];  // along its direction
      const std::size_t c = point_base + p;
      if (!std::isnan(v)) acc[c].Add(v, bands[c]);
    }
  }
  acc[0] = surface;
}

void FillStats(const Accumulator& a, CharacteristicResult& c) {
  c.points = a.count;
  c.within = a.within;
  c.above = a.above;
  c.below = a.below;
  if (a.count == 0) return;
  const double n = static_cast<double>(a.count);
  c.min_mm = a.min;
  c.max_mm = a.max;
  c.mean_mm = a.sum / n;
  c.rms_mm = std::sqrt(a.sum2 / n);
  c.stddev_mm = std::sqrt(std::max(0.0, a.sum2 / n - c.mean_mm * c.mean_mm));
  c.fraction_within = a.within / n;
}

void JudgeArea(CharacteristicResult& c) {
  if (c.points == 0) {
    c.pass = false;
    c.reason = "fail: no matched point";
    return;
  }
  const double outside = 1.0 - c.fraction_within;
  c.pass = outside <= c.allowed_fraction_outside;
  c.reason = absl::StrFormat(
      "%s: %.3f%% of %u points outside [%.4g, %.4g] mm (%u above, %u below; allowed %.3f%%)",
      c.pass ? "pass" : "fail", 100 * outside, c.points, c.tolerance.lower_mm, c.tolerance.upper_mm,
      c.above, c.below, 100 * c.allowed_fraction_outside);
}

void JudgePoint(const ComparisonPoint& p, CharacteristicResult& c) {
  const bool directional = p.direction != Eigen::Vector3d::Zero();
  if (c.points == 0) {
    c.pass = false;
    c.reason = absl::StrFormat("fail: unmeasured (no measured point within %.4g mm%s)", p.radius_mm,
                               directional ? " on a face the direction can meet" : "");
    return;
  }
  c.value_mm = c.mean_mm;
  // The value is a mean in double; judge it against the band as a float32
  // deviation like every other one.
  c.pass = c.tolerance.Contains(static_cast<float>(c.value_mm));
  c.reason =
      absl::StrFormat("%s: value %.4f mm (mean of %u points) %s [%.4g, %.4g] mm",
                      c.pass ? "pass" : "fail", c.value_mm, c.points, c.pass ? "inside" : "outside",
                      c.tolerance.lower_mm, c.tolerance.upper_mm);
  if (directional)
    absl::StrAppend(&c.reason, absl::StrFormat(" along (%.4g, %.4g, %.4g)", p.direction.x(),
                                               p.direction.y(), p.direction.z()));
}

// Not measured when its area (a section: its curve) was seen over less
// than it needs.
void JudgeCoverage(double coverage, double min_coverage, CharacteristicResult& c,
                   const char* what = "CAD area") {
  c.coverage = coverage;
  c.min_coverage = min_coverage;
  if (!(coverage < min_coverage)) return;
  c.measured = false;
  c.pass = false;
  c.reason =
      absl::StrFormat("not measured: %.1f%% of its %s seen, at least %.1f%% needed (%u points)",
                      100 * coverage, what, 100 * min_coverage, c.points);
}

// The k-th characteristic (surface, regions, points) judged.
CharacteristicResult Judge(const ErrorMapResult& em, const ResolvedInspectionPlan& rp,
                           const ToleranceBand& band, const Accumulator& total, std::size_t k,
                           const CoverageResult* coverage) {
  CharacteristicResult c;
  c.tolerance = band;
  FillStats(total, c);
  const InspectionPlan& plan = rp.plan;
  if (k == 0) {
    c.name = kSurfaceCharacteristicName;
    c.type = CharacteristicType::kSurface;
    c.allowed_fraction_outside = plan.allowed_fraction_outside;
    // The error map's own two-pass statistics, so report blocks agree.
    c.min_mm = em.stats.min_mm;
    c.max_mm = em.stats.max_mm;
    c.mean_mm = em.stats.mean_mm;
    c.stddev_mm = em.stats.stddev_mm;
    c.rms_mm = em.stats.rms_mm;
    JudgeArea(c);
    if (coverage) JudgeCoverage(coverage->surface, plan.min_coverage, c);
  } else if (k <= plan.regions.size()) {
    const PlanRegion& r = plan.regions[k - 1];
    c.name = r.name;
    c.type = CharacteristicType::kRegion;
    c.allowed_fraction_outside = r.allowed_fraction_outside;
    JudgeArea(c);
    if (coverage)
      JudgeCoverage(coverage->regions[k - 1], r.min_coverage.value_or(plan.min_coverage), c);
  } else {
    const std::size_t i = k - 1 - plan.regions.size();
    const ComparisonPoint& p = plan.points[i];
    c.name = p.name;
    c.type = CharacteristicType::kPoint;
    JudgePoint(p, c);
    if (coverage) JudgeCoverage(coverage->points[i], p.min_coverage.value_or(plan.min_coverage), c);
  }
  return c;
}

}  // namespace

namespace {

// A section judged like a region on the points its cut selected.
CharacteristicResult JudgeSection(const ErrorMapResult& em, const InspectionPlan& plan,
                                  const PlanSection& s, const SectionCut& cut) {
  CharacteristicResult c;
  c.name = s.name;
  c.type = CharacteristicType::kSection;
  c.tolerance = s.tolerance.value_or(plan.tolerance);
  c.allowed_fraction_outside = s.allowed_fraction_outside;
  Accumulator a;
  for (uint32_t i : cut.points) a.Add(em.deviation_mm[i], c.tolerance);
  FillStats(a, c);
  JudgeArea(c);
  if (std::isfinite(cut.coverage)) JudgeCoverage(cut.coverage, plan.min_coverage, c, "curve");
  return c;
}

// A hole judged by its true position and size deviations.
CharacteristicResult JudgeHole(const PlanHole& h, const HoleMeasurement& m) {
  CharacteristicResult c;
  c.name = h.name;
  c.type = h.slot ? CharacteristicType::kSlot : CharacteristicType::kHole;
  c.tolerance = h.diameter_tolerance;
  c.position_tolerance_mm = h.position_tolerance_mm;
  if (h.slot) c.length_tolerance = h.length_tolerance;
  c.hole = m;
  c.points = m.edge_points;
  if (!m.measured) {
    c.measured = false;
    c.reason = "not measured: " + m.reason;
    return c;
  }
  const char* size = h.slot ? "width" : "diameter";
  std::vector<std::string> failed;
  if (!(m.true_position_mm <= h.position_tolerance_mm))
    failed.push_back(absl::StrFormat("true position %.3f mm > %.3g mm", m.true_position_mm,
                                     h.position_tolerance_mm));
  if (!h.diameter_tolerance.Contains(float(m.diameter_deviation_mm)))
    failed.push_back(absl::StrFormat("%s %+.3f mm outside [%+.3g, %+.3g]", size,
                                     m.diameter_deviation_mm, h.diameter_tolerance.lower_mm,
                                     h.diameter_tolerance.upper_mm));
  if (h.slot && !h.length_tolerance.Contains(float(m.length_deviation_mm)))
    failed.push_back(absl::StrFormat("length %+.3f mm outside [%+.3g, %+.3g]",
                                     m.length_deviation_mm, h.length_tolerance.lower_mm,
                                     h.length_tolerance.upper_mm));
  c.pass = failed.empty();
  c.reason = c.pass ? absl::StrFormat(
                          "pass: true position %.3f of %.3g mm, %s %+.3f mm (%u edge "
                          "points over %.0f deg)",
                          m.true_position_mm, h.position_tolerance_mm, size,
                          m.diameter_deviation_mm, m.edge_points, m.arc_coverage_deg)
                    : "fail: " + absl::StrJoin(failed, "; ");
  return c;
}

CharacteristicResult JudgeEdgePoint(const PlanEdgePoint& e, const EdgePointMeasurement& m) {
  CharacteristicResult c;
  c.name = e.name;
  c.type = CharacteristicType::kEdgePoint;
  c.tolerance = e.tolerance;
  c.points = m.points;
  c.value_mm = m.value_mm;
  if (!m.measured) {
    c.measured = false;
    c.reason = "not measured: " + m.reason;
    return c;
  }
  c.pass = e.tolerance.Contains(float(m.value_mm));
  c.reason = absl::StrFormat("%s: edge %+.3f mm %s [%+.3g, %+.3g] (%u edge points)",
                             c.pass ? "pass" : "fail", m.value_mm, c.pass ? "within" : "outside",
                             e.tolerance.lower_mm, e.tolerance.upper_mm, m.points);
  return c;
}

}  // namespace

const char* VerdictName(const CharacteristicResult& c) {
  return c.pass ? "pass" : c.measured ? "fail" : "not_measured";
}

const char* CharacteristicTypeName(CharacteristicType type) {
  switch (type) {
    case CharacteristicType::kSurface:
      return "surface";
    case CharacteristicType::kRegion:
      return "region";
    case CharacteristicType::kPoint:
      return "point";
    case CharacteristicType::kSection:
      return "section";
    case CharacteristicType::kHole:
      return "hole";
    case CharacteristicType::kSlot:
      return "slot";
    case CharacteristicType::kEdgePoint:
      return "edge_point";
  }
  return "surface";
}

absl::StatusOr<CharacteristicsResult> ComputeCharacteristics(
    const ErrorMapResult& em, const ResolvedInspectionPlan& rp, std::size_t defect_count,
    const CharacteristicsSettings& settings, const CoverageResult* coverage,
    const std::vector<SectionCut>& sections, const std::vector<HoleMeasurement>& holes,
    const std::vector<EdgePointMeasurement>& edge_points) {
  const std::size_t n = em.deviation_mm.size();
  if (sections.size() != rp.plan.sections.size())
    return absl::InvalidArgumentError("characteristics: one cut per section of the plan");
  if (holes.size() != rp.plan.holes.size() || edge_points.size() != rp.plan.edge_points.size())
    return absl::InvalidArgumentError(
        "characteristics: one measurement per hole and edge point of the plan");
  if (coverage && (coverage->regions.size() != rp.plan.regions.size() ||
                   coverage->points.size() != rp.plan.points.size()))
    return absl::InvalidArgumentError("characteristics: the coverage is of another plan");
  if (em.triangle_id.size() != n || em.closest_point.size() != n)
    return absl::InvalidArgumentError("characteristics: error map arrays differ in size");
  if (rp.region_offsets.size() != rp.num_triangles + 1 ||
      rp.point_offsets.size() != rp.num_triangles + 1)
    return absl::InvalidArgumentError("characteristics: the plan is not resolved");
  for (uint32_t t : em.triangle_id)
    if (t != UINT32_MAX && t >= rp.num_triangles)
      return absl::InvalidArgumentError(absl::StrCat("characteristics: triangle id ", t,
                                                     " not in the plan's mesh (", rp.num_triangles,
                                                     " triangles)"));

  const std::vector<ToleranceBand> bands = Bands(rp.plan);
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<std::vector<Accumulator>> partial(chunks, std::vector<Accumulator>(bands.size()));
  tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1), [&](const auto& range) {
      for (std::size_t c = range.begin(); c != range.end(); ++c)
        AccumulateChunk(em, rp, bands, c * kChunk, std::min(n, (c + 1) * kChunk), partial[c]);
    });
  });
  std::vector<Accumulator> total(bands.size());
  for (const auto& chunk : partial)
    for (std::size_t k = 0; k < bands.size(); ++k) total[k].Merge(chunk[k]);

  CharacteristicsResult out;
  for (std::size_t k = 0; k < bands.size(); ++k) {
    CharacteristicResult c = Judge(em, rp, bands[k], total[k], k, coverage);
    out.failed += !c.pass && c.measured;
    out.not_measured += !c.measured;
    out.characteristics.push_back(std::move(c));
  }
  for (std::size_t s = 0; s < sections.size(); ++s) {
    CharacteristicResult c = JudgeSection(em, rp.plan, rp.plan.sections[s], sections[s]);
    out.failed += !c.pass;
    out.characteristics.push_back(std::move(c));
  }
  for (std::size_t h = 0; h < holes.size(); ++h) {
    CharacteristicResult c = JudgeHole(rp.plan.holes[h], holes[h]);
    out.failed += !c.pass && c.measured;
    out.not_measured += !c.measured;
    out.characteristics.push_back(std::move(c));
  }
  for (std::size_t e = 0; e < edge_points.size(); ++e) {
    CharacteristicResult c = JudgeEdgePoint(rp.plan.edge_points[e], edge_points[e]);
    out.failed += !c.pass && c.measured;
    out.not_measured += !c.measured;
    out.characteristics.push_back(std::move(c));
  }
  const bool too_many_defects =
      rp.plan.defects && rp.plan.defects->max_count &&
      defect_count > static_cast<std::size_t>(*rp.plan.defects->max_count);
  out.pass =
      out.failed == 0 && (out.not_measured == 0 || rp.plan.allow_not_measured) && !too_many_defects;
  out.reason = absl::StrCat(out.pass ? "pass" : "fail", ": ", out.failed, " of ",
                            out.characteristics.size(), " characteristics fail");
  if (out.not_measured > 0)
    absl::StrAppend(&out.reason, ", ", out.not_measured, " not measured",
                    rp.plan.allow_not_measured ? " (allowed by the plan)" : "");
  if (rp.plan.defects && rp.plan.defects->max_count)
    absl::StrAppend(&out.reason, "; ", defect_count, " defects (at most ",
                    *rp.plan.defects->max_count, " allowed)");
  return out;
}

}  // namespace surfinspect
