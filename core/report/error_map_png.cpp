#include "core/report/error_map_png.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/errormap/deviation_color.h"
#include "core/report/error_map_panel.h"
#include "core/types/status_macros.h"
#include "core/types/transform.h"

namespace surfinspect {
namespace {

constexpr Rgb kWhite{255, 255, 255};
constexpr Rgb kBlack{0, 0, 0};
constexpr uint32_t kMinMapPixels = 400;  // small grids are enlarged to at least this
constexpr int kMinHeight = 520;

Rgb Color(const ErrorMapResult& r, double d) {
  return DeviationColor(d, r.tolerance_mm, r.color_range_mm);
}

// Where each point lands on the map panel: the top-left corner of its
// zoom x zoom block.
struct MapLayout {
  bool organized = false;
  uint32_t width = 0, height = 0;  // in blocks
  uint32_t zoom = 1;
  uint32_t step = 1;           // organized: sensor pixels per block side
  uint32_t cloud_width = 0;    // organized
  int axis = 2, u = 0, v = 1;  // unorganized: view along -axis
  Bounds3 bounds;              // unorganized
  double pixel = 1;            // unorganized: mm per block
  std::pair<uint32_t, uint32_t> BlockOf(std::size_t i, const Eigen::Vector3f& p) const {
    if (organized)
      return {static_cast<uint32_t>(i % cloud_width) / step,
              static_cast<uint32_t>(i / cloud_width) / step};
    return {static_cast<uint32_t>((p[u] - bounds.min[u]) / pixel),
            height - 1 - static_cast<uint32_t>((p[v] - bounds.min[v]) / pixel)};
  }
};

MapLayout GridLayout(const PointCloud& pts, uint32_t max_px) {
  MapLayout l;
  l.organized = true;
  l.cloud_width = pts.width;
  const uint32_t longest = std::max(pts.width, pts.height);
  l.step = std::max<uint32_t>(1, (longest + max_px - 1) / max_px);
  l.width = (pts.width + l.step - 1) / l.step;
  l.height = (pts.height + l.step - 1) / l.step;
  l.zoom = std::max<uint32_t>(1, kMinMapPixels / std::max(l.width, l.height));
  return l;
}

// The pixel size follows the point density so a dense scan has no gaps.
MapLayout OrthoLayout(const PointCloud& pts, int axis, uint32_t max_px) {
  MapLayout l;
  l.axis = axis;
  l.u = (axis + 1) % 3;
  l.v = (axis + 2) % 3;
  l.bounds = ComputeBounds(pts);
  if (l.bounds.empty()) return l;
  const double eu = std::max(l.bounds.max[l.u] - l.bounds.min[l.u], 1e-9);
  const double ev = std::max(l.bounds.max[l.v] - l.bounds.min[l.v], 1e-9);
  const double n = static_cast<double>(std::max<std::size_t>(1, pts.CountValid()));
  l.pixel =
      std::max({std::max(eu, ev) / max_px, std::sqrt(eu * ev / n), std::max(eu, ev) / 4000.0});
  l.width = static_cast<uint32_t>(eu / l.pixel) + 1;
  l.height = static_cast<uint32_t>(ev / l.pixel) + 1;
  l.zoom = std::max<uint32_t>(1, kMinMapPixels / std::max(l.width, l.height));
  return l;
}

// Organized: the sensor grid, block-averaged down (or enlarged by an integer
// factor) to fit. A block with valid but unmatched points is grey.
RgbImage GridMap(const PointCloud& pts, const ErrorMapResult& r, const MapLayout& l) {
  const uint32_t step = l.step, w = l.width, h = l.height, zoom = l.zoom;
  RgbImage img(w * zoom, h * zoom, kWhite);
  for (uint32_t by = 0; by < h; ++by)
    for (uint32_t bx = 0; bx < w; ++bx) {
      double sum = 0;
      int matched = 0, valid = 0;
      for (uint32_t y = by * step; y < std::min(pts.height, (by + 1) * step); ++y)
        for (uint32_t x = bx * step; x < std::min(pts.width, (bx + 1) * step); ++x) {
          const std::size_t i = std::size_t{y} * pts.width + x;
          if (!PointCloud::IsValid(pts.points[i])) continue;
          ++valid;
          if (std::isnan(r.deviation_mm[i])) continue;
          sum += r.deviation_mm[i];
          ++matched;
        }
      if (valid == 0) continue;
      const Rgb c = matched ? Color(r, sum / matched) : kUnmatchedGrey;
      img.FillRect(static_cast<int>(bx * zoom), static_cast<int>(by * zoom), static_cast<int>(zoom),
                   static_cast<int>(zoom), c);
    }
  return img;
}

// Unorganized: orthographic along -axis, image right = u, up = v (a right-
// handed u, v, axis triple), the point nearest the viewer wins each pixel.
RgbImage OrthoMap(const PointCloud& pts, const ErrorMapResult& r, const MapLayout& l) {
  if (l.bounds.empty()) return RgbImage(kMinMapPixels, kMinMapPixels, kWhite);
  const uint32_t w = l.width, h = l.height, zoom = l.zoom;
  RgbImage img(w * zoom, h * zoom, kWhite);
  std::vector<float> depth(std::size_t{w} * h, -INFINITY);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Eigen::Vector3f& p = pts.points[i];
    if (!PointCloud::IsValid(p)) continue;
    const auto [x, y] = l.BlockOf(i, p);
    float& z = depth[std::size_t{y} * w + x];
    if (p[l.axis] <= z) continue;
    z = p[l.axis];
    img.FillRect(static_cast<int>(x * zoom), static_cast<int>(y * zoom), static_cast<int>(zoom),
                 static_cast<int>(zoom), Color(r, r.deviation_mm[i]));
  }
  return img;
}

// Each defect: a black square ring (radius 7 px) around the block of the
// valid point nearest its centroid, and its id beside it. One pass over the
// points finds every defect's nearest point (the first of equals).
void DrawDefects(RgbImage& map, const PointCloud& pts, const MapLayout& l,
                 const std::vector<Defect>& defects) {
  std::vector<Eigen::Vector3f> centroids;
  for (const Defect& d : defects) centroids.push_back(d.centroid_mm.cast<float>());
  std::vector<std::size_t> nearest(defects.size(), pts.size());
  std::vector<float> nearest_d2(defects.size(), INFINITY);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (!PointCloud::IsValid(pts.points[i])) continue;
    for (std::size_t k = 0; k < centroids.size(); ++k) {
      const float d2 = (pts.points[i] - centroids[k]).squaredNorm();
      if (d2 < nearest_d2[k]) nearest_d2[k] = d2, nearest[k] = i;
    }
  }
  for (std::size_t k = 0; k < defects.size(); ++k) {
    const Defect& d = defects[k];
    const std::size_t best = nearest[k];
    if (best == pts.size()) continue;
    const auto [bx, by] = l.BlockOf(best, pts.points[best]);
    const int x = static_cast<int>(bx * l.zoom + l.zoom / 2);
    const int y = static_cast<int>(by * l.zoom + l.zoom / 2);
    constexpr int kR = 7;
    map.FillRect(x - kR, y - kR, 2 * kR + 1, 2, kBlack);
    map.FillRect(x - kR, y + kR - 1, 2 * kR + 1, 2, kBlack);
    map.FillRect(x - kR, y - kR, 2, 2 * kR + 1, kBlack);
    map.FillRect(x + kR - 1, y - kR, 2, 2 * kR + 1, kBlack);
    map.DrawText(x + kR + 3, y - kR, absl::StrCat(d.id), kBlack, 2);
  }
}

}  // namespace

int ThinnestAxis(const Bounds3& b) {
  if (b.empty()) return 2;
  const Eigen::Vector3d e = b.max - b.min;
  int axis = 2;
  for (int a : {1, 0})
    if (e[a] < e[axis]) axis = a;
  return axis;
}

absl::StatusOr<RgbImage> RenderErrorMapView(const PointCloud& points, const ErrorMapResult& result,
                                            const Bounds3& mesh_bounds,
                                            const ErrorMapPngOptions& options) {
  if (result.deviation_mm.size() != points.size())
    return absl::InvalidArgumentError("error map png: result does not belong to these points");
  if (options.view_axis < -1 || options.view_axis > 2)
    return absl::InvalidArgumentError(
        absl::StrCat("error map png: view_axis must be -1, 0, 1 or 2, got ", options.view_axis));
  if (options.max_map_pixels < 16 || options.max_map_pixels > 20000)
    return absl::InvalidArgumentError("error map png: max_map_pixels must be in [16, 20000]");
  if (!(result.color_range_mm > 0))
    return absl::InvalidArgumentError("error map png: the result has no colour range");
  const int axis = options.view_axis >= 0 ? options.view_axis : ThinnestAxis(mesh_bounds);
  const MapLayout layout = points.organized() ? GridLayout(points, options.max_map_pixels)
                                              : OrthoLayout(points, axis, options.max_map_pixels);
  RgbImage map =
      points.organized() ? GridMap(points, result, layout) : OrthoMap(points, result, layout);
  if (options.defects) DrawDefects(map, points, layout, *options.defects);
  return map;
}

absl::StatusOr<RgbImage> RenderErrorMap(const PointCloud& points, const ErrorMapResult& result,
                                        const Bounds3& mesh_bounds,
                                        const ErrorMapPngOptions& options) {
  ASSIGN_OR_RETURN(auto map, RenderErrorMapView(points, result, mesh_bounds, options));
  RgbImage img(map.width + kPanelWidth, std::max<uint32_t>(map.height, kMinHeight), kWhite);
  for (uint32_t y = 0; y < map.height; ++y) std::copy_n(&map.at(0, y), map.width, &img.at(0, y));
  DrawErrorMapPanel(img,
                    MakePanelLayout(static_cast<int>(map.width), img.height, result.color_range_mm),
                    result, options.part_pass.value_or(result.verdict.pass));
  return img;
}

absl::Status WriteErrorMapPng(const std::string& path, const PointCloud& points,
                              const ErrorMapResult& result, const Bounds3& mesh_bounds,
                              const ErrorMapPngOptions& options) {
  ASSIGN_OR_RETURN(auto img, RenderErrorMap(points, result, mesh_bounds, options));
  return WritePng(path, img);
}

absl::StatusOr<std::string> ErrorMapPngBytes(const PointCloud& cloud_in_world,
                                             const Eigen::Isometry3d& world_from_part,
                                             const ErrorMapResult& result,
                                             const TriangleMesh& part_in_part,
                                             const PlanOutcome& outcome) {
  const PointCloud in_part = TransformCloud(cloud_in_world, world_from_part.inverse());
  ErrorMapPngOptions options;
  options.defects = &outcome.defects.defects;
  options.part_pass = outcome.pass();
  ASSIGN_OR_RETURN(auto image,
                   RenderErrorMap(in_part, result, ComputeBounds(part_in_part), options));
  return EncodePng(image);
}

}  // namespace surfinspect
