#include "core/history/trend_png.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/errormap/deviation_color.h"
#include "core/report/error_map_png.h"

namespace surfinspect {
namespace {

constexpr Rgb kWhite{255, 255, 255};
constexpr Rgb kBlack{0, 0, 0};
constexpr int kMargin = 40, kBarWidth = 150;

struct View {
  int axis = 2, u = 0, v = 1;
  double u0 = 0, v0 = 0, scale = 1;  // pixels per mm
  int height = 0;
  Eigen::Vector3d Project(const Eigen::Vector3f& p) const {
    return {kMargin + (p[u] - u0) * scale, kMargin + height - (p[v] - v0) * scale, p[axis]};
  }
};

// Fills one triangle into the image where it is nearer the viewer (larger
// coordinate along the axis) than what is there; edge functions over its
// bounding box.
void FillTriangle(RgbImage& img, std::vector<float>& depth, const Eigen::Vector3d& a,
                  const Eigen::Vector3d& b, const Eigen::Vector3d& c, Rgb colour) {
  const double area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
  if (std::abs(area) < 1e-12) return;
  const int x0 = std::max(0, static_cast<int>(std::floor(std::min({a.x(), b.x(), c.x()}))));
  const int x1 =
      std::min<int>(img.width - 1, static_cast<int>(std::ceil(std::max({a.x(), b.x(), c.x()}))));
  const int y0 = std::max(0, static_cast<int>(std::floor(std::min({a.y(), b.y(), c.y()}))));
  const int y1 =
      std::min<int>(img.height - 1, static_cast<int>(std::ceil(std::max({a.y(), b.y(), c.y()}))));
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const double px = x + 0.5, py = y + 0.5;
      const double w0 = ((b.x() - px) * (c.y() - py) - (b.y() - py) * (c.x() - px)) / area;
      const double w1 = ((c.x() - px) * (a.y() - py) - (c.y() - py) * (a.x() - px)) / area;
      const double w2 = 1 - w0 - w1;
      if (w0 < 0 || w1 < 0 || w2 < 0) continue;
      const float z = static_cast<float>(w0 * a.z() + w1 * b.z() + w2 * c.z());
      float& d = depth[std::size_t{static_cast<uint32_t>(y)} * img.width + x];
      if (z < d) continue;
      d = z;
      img.at(x, y) = colour;
    }
}

void DrawColourBar(RgbImage& img, int x, double range, double band, std::size_t parts) {
  const int top = kMargin, h = static_cast<int>(img.height) - 2 * kMargin;
  for (int y = 0; y < h; ++y) {
    const double d = range * (1 - 2.0 * y / (h - 1));
    img.FillRect(x, top + y, 24, 1, DeviationColor(d, band, range));
  }
  for (int k = 0; k <= 4; ++k) {
    const double d = range * (1 - 0.5 * k);
    img.DrawText(x + 30, top + k * (h - 1) / 4 - 3, absl::StrFormat("%+.4f", d), kBlack);
  }
  img.DrawText(x, top - 24, "MEAN MM", kBlack);
  img.DrawText(x, top + h + 8, absl::StrCat(parts, " PARTS"), kBlack);
}

}  // namespace

absl::StatusOr<RgbImage> RenderTrendMap(const TrendMap& map, const TriangleMesh& mesh,
                                        const TrendPngOptions& o) {
  std::vector<double> mean(mesh.num_triangles(), NAN);
  double largest = 0;
  for (const TriangleTrend& t : map.triangles) {
    if (t.triangle_id >= mesh.num_triangles())
      return absl::InvalidArgumentError(absl::StrCat("trend map: triangle ", t.triangle_id,
                                                     " is not in the mesh of ",
                                                     mesh.num_triangles(), " triangles"));
    mean[t.triangle_id] = t.mean_mm;
    largest = std::max(largest, std::abs(t.mean_mm));
  }
  const double range = o.range_mm > 0 ? o.range_mm : std::max(largest, 1e-3);
  const double band = o.band_mm > 0 ? o.band_mm : range / 4;
  const Bounds3 b = ComputeBounds(mesh);
  View view;
  view.axis = ThinnestAxis(b);
  view.u = view.axis == 0 ? 1 : 0;
  view.v = view.axis == 2 ? 1 : 2;
  const double eu = std::max(1e-6, b.max[view.u] - b.min[view.u]);
  const double ev = std::max(1e-6, b.max[view.v] - b.min[view.v]);
  view.scale = o.map_width / std::max(eu, ev);
  view.u0 = b.min[view.u];
  view.v0 = b.min[view.v];
  view.height = static_cast<int>(std::ceil(ev * view.scale));
  const int width = static_cast<int>(std::ceil(eu * view.scale));
  RgbImage img(width + 2 * kMargin + kBarWidth, std::max(view.height + 2 * kMargin, 300), kWhite);
  std::vector<float> depth(img.pixels.size(), -std::numeric_limits<float>::infinity());
  for (std::size_t t = 0; t < mesh.num_triangles(); ++t) {
    const auto& tri = mesh.triangles[t];
    FillTriangle(img, depth, view.Project(mesh.vertices[tri[0]]),
                 view.Project(mesh.vertices[tri[1]]), view.Project(mesh.vertices[tri[2]]),
                 DeviationColor(mean[t], band, range));
  }
  img.DrawText(kMargin, 12, "PROCESS TREND MAP: MEAN DEVIATION PER TRIANGLE", kBlack);
  DrawColourBar(img, width + 2 * kMargin, range, band, map.parts);
  return img;
}

}  // namespace surfinspect
