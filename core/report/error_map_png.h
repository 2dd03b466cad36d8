// The error-map picture (paper Fig. 11): the coloured map, and beside it the
// panel of core/report/error_map_panel.h (verdict, colour bar with the
// tolerance band bracketed, log-count histogram on the same deviation
// axis). An organized cloud is drawn in its sensor grid; a merged
// (unorganized) cloud as an orthographic view along an axis, by default the
// CAD's thinnest extent (a sheet-metal part seen from above), nearest point
// per pixel. Defects, when given, are marked on the map by a ring at the
// drawn point nearest their centroid and their id beside it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/errormap/error_map.h"
#include "core/io/png_image.h"
#include "core/plan/defects.h"
#include "core/plan/plan_evaluation.h"
#include "core/types/point_cloud.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

struct ErrorMapPngOptions {
  // Unorganized clouds: look along -axis (0 = x, 1 = y, 2 = z), i.e. from
  // the + side; -1 = the thinnest extent of `mesh_bounds`.
  int view_axis = -1;
  uint32_t max_map_pixels = 1000;                // longest side of the map panel
  const std::vector<Defect>* defects = nullptr;  // marked with their ids when given
  // The verdict written above the panel: the part's when given (an
  // inspection plan's), else the error map's +-tolerance verdict.
  std::optional<bool> part_pass;
};

// Index of the smallest extent of `b` (0, 1 or 2); 2 for empty bounds.
int ThinnestAxis(const Bounds3& b);

// `points` are the cloud the result was computed for, in the frame of
// `mesh_bounds` (the part frame) so the view axis means what it says.
absl::StatusOr<RgbImage> RenderErrorMap(const PointCloud& points, const ErrorMapResult& result,
                                        const Bounds3& mesh_bounds,
                                        const ErrorMapPngOptions& options = {});

// The map alone, without the panel (for reports that draw their own colour
// bar): the same raster RenderErrorMap puts at its left edge.
absl::StatusOr<RgbImage> RenderErrorMapView(const PointCloud& points, const ErrorMapResult& result,
                                            const Bounds3& mesh_bounds,
                                            const ErrorMapPngOptions& options = {});

// RenderErrorMap, then WritePng (atomic).
absl::Status WriteErrorMapPng(const std::string& path, const PointCloud& points,
                              const ErrorMapResult& result, const Bounds3& mesh_bounds,
                              const ErrorMapPngOptions& options = {});

// The PNG bytes of an inspected part, as the RPCs send them and the CLI
// writes them: RenderErrorMap in the part frame with the plan's defects
// marked and its part verdict, EncodePng'd.
absl::StatusOr<std::string> ErrorMapPngBytes(const PointCloud& cloud_in_world,
                                             const Eigen::Isometry3d& world_from_part,
                                             const ErrorMapResult& result,
                                             const TriangleMesh& part_in_part,
                                             const PlanOutcome& outcome);

}  // namespace surfinspect
