// The compact point payload of the HTML report: which scanned points the
// page shows and how they are packed.
//
// Thinning: when a cloud has more than max_points finite points, the page
// shows one point per cell of a grid over the cloud's bounding box (the
// point of largest |deviation| in the cell, so a defect's peak is never
// thinned away). The grid is the finest of the quantisation grid's
// power-of-two coarsenings (cells of 2^s x 2^s x 2^s quantisation steps)
// with at most max_points occupied cells; the cells of the next finer grid
// then fill the budget, k per coarse cell with the largest k that fits,
// taken in order of decreasing |deviation|. Cells are found by sorting the
// Morton codes of the quantised positions (Morton, IBM 1966), whose every
// prefix of 3s bits names a cell of the 2^s grid. Statistics never come from
// the payload: the report's are over all points.
//
// Order: the shown points are stored in core/report/progressive_order.h's
// order, so that every prefix is an evenly spread preview of all of them.
//
// Packing: positions are quantised to 16 bits per axis inside the shown
// points' bounding box (error at most half a step, extent / 131070 mm per
// axis); deviations to int16 in steps of max |deviation| / 32767 (error at
// most half a step), kDeviationMissing where unmatched; plus the palette
// index of the float deviation (core/report/deviation_palette.h). The mesh
// overlay is quantised the same way in its own bounding box. Units mm, part
// frame.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "core/report/deviation_palette.h"
#include "core/types/point_cloud.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

inline constexpr int16_t kDeviationMissing = INT16_MIN;

struct PayloadSettings {
  std::size_t max_points = 1'000'000;  // shown points; >= 1
  // A larger mesh is left out of the page (16 bytes per triangle and vertex).
  std::size_t max_mesh_triangles = 2'000'000;
};

// 16-bit positions in a box: p = min + q * step per axis.
struct QuantisedPositions {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d step = Eigen::Vector3d::Zero();  // (max - min) / 65535 per axis, mm
  std::vector<uint16_t> xyz;                       // 3 per point
  std::size_t size() const { return xyz.size() / 3; }
  Eigen::Vector3d Decode(std::size_t i) const;
};

struct HtmlPayload {
  std::size_t input_points = 0;  // all of them, NaN coordinates included
  std::size_t finite_points = 0;
  bool thinned = false;
  int per_cell = 0;              // points kept per cell, largest |deviation| first
  double cell_mm = 0;            // largest edge of the thinning cell (0 unthinned)
  std::vector<uint32_t> source;  // input index of each shown point, progressive order
  QuantisedPositions positions;
  double deviation_step_mm = 0;                 // d = q * step
  std::vector<int16_t> deviation;               // per shown point
  std::vector<uint8_t> palette_index;           // per shown point
  bool mesh_omitted = false;                    // a mesh was given but exceeds the cap
  QuantisedPositions mesh_vertices;             // empty without a mesh
  std::vector<uint32_t> mesh_triangles;         // 3 per triangle
  double DecodeDeviation(std::size_t i) const;  // NaN where missing
};

// Box quantisation of `points` (used for the cloud and the mesh vertices).
QuantisedPositions QuantisePositions(const std::vector<Eigen::Vector3f>& points);

// `points_in_part` and `deviation_mm` have the same size (InvalidArgument
// otherwise); `mesh_in_part` may be null.
absl::StatusOr<HtmlPayload> BuildHtmlPayload(const PointCloud& points_in_part,
                                             const std::vector<float>& deviation_mm,
                                             const DeviationPalette& palette,
                                             const TriangleMesh* mesh_in_part,
                                             const PayloadSettings& settings = {});

}  // namespace surfinspect
