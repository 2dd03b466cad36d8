#include "core/report/html_payload.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/report/grid_thinning.h"
#include "core/report/progressive_order.h"

namespace surfinspect {
namespace {

constexpr double kLevels = 65535.0;  // 16-bit steps per axis

uint16_t Quantise(double v, double min, double step) {
  if (!(step > 0)) return 0;
  const double q = std::round((v - min) / step);
  return static_cast<uint16_t>(std::clamp(q, 0.0, kLevels));
}

// Quantisation step of the deviations: max |d| maps to +-32767.
double DeviationStep(const std::vector<float>& deviation_mm, const std::vector<uint32_t>& shown) {
  double largest = 0;
  for (uint32_t i : shown)
    if (std::isfinite(deviation_mm[i]))
      largest = std::max(largest, std::abs(double(deviation_mm[i])));
  return largest > 0 ? largest / 32767.0 : 1e-6;
}

int16_t QuantiseDeviation(float d, double step) {
  if (!std::isfinite(d)) return kDeviationMissing;
  const double q = std::clamp(std::round(d / step), -32767.0, 32767.0);
  return static_cast<int16_t>(q);
}

}  // namespace

Eigen::Vector3d QuantisedPositions::Decode(std::size_t i) const {
  return min + Eigen::Vector3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]).cwiseProduct(step);
}

double HtmlPayload::DecodeDeviation(std::size_t i) const {
  return deviation[i] == kDeviationMissing ? NAN : deviation[i] * deviation_step_mm;
}

QuantisedPositions QuantisePositions(const std::vector<Eigen::Vector3f>& points) {
  QuantisedPositions q;
  Bounds3 box;
  for (const Eigen::Vector3f& p : points) box.Extend(p.cast<double>());
  if (box.empty()) return q;
  q.min = box.min;
  q.step = (box.max - box.min) / kLevels;
  q.xyz.resize(3 * points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    for (int a = 0; a < 3; ++a) q.xyz[3 * i + a] = Quantise(points[i][a], q.min[a], q.step[a]);
  return q;
}

absl::StatusOr<HtmlPayload> BuildHtmlPayload(const PointCloud& points_in_part,
                                             const std::vector<float>& deviation_mm,
                                             const DeviationPalette& palette,
                                             const TriangleMesh* mesh_in_part,
                                             const PayloadSettings& settings) {
  if (deviation_mm.size() != points_in_part.size())
    return absl::InvalidArgumentError(absl::StrCat("HTML report: ", points_in_part.size(),
                                                   " points but ", deviation_mm.size(),
                                                   " deviations"));
  if (settings.max_points < 1)
    return absl::InvalidArgumentError("HTML report: max_points must be >= 1");
  HtmlPayload out;
  out.input_points = points_in_part.size();
  std::vector<uint32_t> finite;
  std::vector<Eigen::Vector3f> xyz;
  points_in_part.ForEachValid([&](std::size_t i, const Eigen::Vector3f& p) {
    finite.push_back(static_cast<uint32_t>(i));
    xyz.push_back(p);
  });
  out.finite_points = finite.size();
  // Thinning works on the quantisation grid of all finite points.
  QuantisedPositions all = QuantisePositions(xyz);
  std::vector<float> priority(finite.size());
  for (std::size_t j = 0; j < finite.size(); ++j) {
    const float d = deviation_mm[finite[j]];
    priority[j] = std::isfinite(d) ? std::abs(d) : -1.0f;  // unmatched last
  }
  const ThinningResult thin = ThinOnGrid(all.xyz, priority, settings.max_points);
  out.thinned = thin.level >= 0;
  if (out.thinned) out.cell_mm = std::ldexp(all.step.maxCoeff(), thin.level);
  out.per_cell = thin.per_cell;
  std::vector<Eigen::Vector3f> shown_xyz;
  shown_xyz.reserve(thin.kept.size());
  // Stored so that every prefix is an even preview (progressive_order.h).
  for (uint32_t j : ProgressiveOrder(all.xyz, thin.kept)) {
    out.source.push_back(finite[j]);
    shown_xyz.push_back(xyz[j]);
  }
  out.positions = QuantisePositions(shown_xyz);  // the shown points' own, tighter box
  out.deviation_step_mm = DeviationStep(deviation_mm, out.source);
  for (uint32_t i : out.source) {
    out.deviation.push_back(QuantiseDeviation(deviation_mm[i], out.deviation_step_mm));
    out.palette_index.push_back(PaletteIndex(palette, deviation_mm[i]));
  }
  out.mesh_omitted = mesh_in_part && mesh_in_part->num_triangles() > settings.max_mesh_triangles;
  if (mesh_in_part && !out.mesh_omitted) {
    out.mesh_vertices = QuantisePositions(mesh_in_part->vertices);
    for (const Triangle& t : mesh_in_part->triangles)
      out.mesh_triangles.insert(out.mesh_triangles.end(), t.begin(), t.end());
  }
  return out;
}

}  // namespace surfinspect
