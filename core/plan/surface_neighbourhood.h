// Neighbourhoods of the points of a scanned surface, for defect
// detection (core/plan/defects.h): the matched points within a radius of
// a point in 3D (scanned coordinates, any frame), its links, and its
// footprint area on the CAD surface.
//
//  * Organized grid: searched in a square pixel window around the point
//    (half-width ceil(radius / spacing), at most 4); links are the
//    8-neighbours within the link distance; the footprint is |du x dv| of
//    the central differences of the closest CAD points.
//  * Unorganized: a uniform cell grid, cells one radius wide, searched
//    3 x 3 x 3 (the fixed-radius near-neighbour grid, Bentley & Friedman,
//    "Data structures for range searching", Computing Surveys 1979); the
//    footprint is pi r^2 / (points within r).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/errormap/error_map.h"
#include "core/types/percentile.h"  // MedianInPlace, MadSigma, for the plan's robust fits
#include "core/types/point_cloud.h"

namespace surfinspect {

// Matched neighbours of a point on the surface, the point itself included,
// in an order fixed by the data alone (window or cell order, then index).
class SurfaceNeighbourhood {
 public:
  virtual ~SurfaceNeighbourhood() = default;
  // Matched points in the order the median pass walks them (index order;
  // cell order for the cell grid, so consecutive queries share cells).
  virtual std::vector<uint32_t> MatchedOrder() const = 0;
  // The robust-estimate neighbourhood.
  virtual void Local(std::size_t i, std::vector<uint32_t>& out) const = 0;
  // The points i links to (closer than the link distance).
  virtual void Links(std::size_t i, std::vector<uint32_t>& out) const = 0;
  // The footprint area of point i, mm^2.
  virtual double Area(std::size_t i) const = 0;
  // Per point: 1 unless a superset of its neighbourhood (its window, its
  // 27 cells) holds fewer than `need` points of each sign in `hot`, in which
  // case its median cannot pass the threshold (that needs half of its >=
  // min_neighbours points beyond it, on one side).
  virtual std::vector<uint8_t> MayExceed(const std::vector<int8_t>& hot, uint32_t need) const = 0;
};

// `cloud` is the cloud the error map was computed on. Radius, link and
// spacing in mm; the neighbourhood keeps references to both inputs.
std::unique_ptr<SurfaceNeighbourhood> MakeGridNeighbourhood(const ErrorMapResult& error_map,
                                                            const PointCloud& cloud,
                                                            float radius_mm, float link_mm,
                                                            double spacing_mm);
std::unique_ptr<SurfaceNeighbourhood> MakeCellNeighbourhood(const ErrorMapResult& error_map,
                                                            const PointCloud& cloud,
                                                            float radius_mm, float link_mm);

// The sampling spacing on the surface, mm. Organized: the median distance
// from a sample of scanned points to their right or lower neighbour pixel.
// Unorganized: sqrt of the surface area per point, pi R^2 / (points within
// R = 2 mm), median over a sample, so that overlapping views (interleaved,
// nearest neighbours far closer than the sampling) count as the denser
// sampling they are. 1 mm when no spacing can be estimated.
double EstimateSurfaceSpacing(const ErrorMapResult& error_map, const PointCloud& cloud);

}  // namespace surfinspect
