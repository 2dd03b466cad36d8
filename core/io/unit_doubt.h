// Whether a cloud or mesh read as millimetres is plausibly in millimetres.
// A file in metres read as millimetres gives distances 1000 times too small,
// and nothing downstream notices: the Stanford bunny scan in metres against
// its mesh in metres "passes" with deviations of 0.001 mm where the true ones
// reach 1.2 mm. So when the user did not state a unit, two rules look at the
// sizes (docs/units.md):
//   size:  at least kMinPointsForSize points (or kMinTrianglesForSize
//          triangles) within a bounding-box diagonal under kSmallestPartMm.
//          Real scans in metres (PCL's Kinect and stereo clouds: 2-4 m
//          across) and the bunny (0.15 m) all fall here; a real
//          millimetre scan of a part does not.
//   ratio: the cloud's diagonal and the mesh's differ by more than
//          kLargestSizeRatio: the scan of a part is never hundreds of times
//          larger or smaller than the part, and metres against millimetres
//          is a factor of 1000.
// A doubt is a sentence naming the likely unit and the option that states
// it; stating any unit (even mm, for a part that really is tiny) silences it.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "core/types/point_cloud.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

inline constexpr double kSmallestPartMm = 5.0;
inline constexpr std::size_t kMinPointsForSize = 1000;
inline constexpr std::size_t kMinTrianglesForSize = 100;
inline constexpr double kLargestSizeRatio = 200.0;

// The size of what a file holds, as read (in its own unit).
struct Extent {
  double diagonal = 0;    // of the bounding box of the valid points / vertices
  std::size_t items = 0;  // valid points or triangles
  bool points = true;     // a cloud (false: a mesh)
};
Extent ExtentOf(const PointCloud& cloud);
Extent ExtentOf(const TriangleMesh& mesh);

// Where a file came from, for the sentence: "cloud scan.pcd" and what states
// its unit, followed by the unit's name ("--cloud-units", or
// "cell.json's sensor.units =").
struct UnitSubject {
  std::string what, option;
  Extent extent;
  bool stated = false;
};

// The size rule on one file whose unit was not stated: "" or the doubt.
std::string SizeDoubt(const UnitSubject& s);
// The ratio rule between a cloud and a mesh (both in millimetres as read or
// scaled), when at least one unit was not stated: "" or the doubt.
std::string RatioDoubt(const UnitSubject& cloud, const UnitSubject& mesh);
// Both rules: the size rule on each, the ratio rule when neither size rule
// fired. `mesh` may be null (a cloud alone, as for the filter).
std::vector<std::string> UnitDoubts(const UnitSubject& cloud, const UnitSubject* mesh);

}  // namespace surfinspect
