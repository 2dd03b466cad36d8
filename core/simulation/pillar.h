// The demo's part: a procedural stamped sheet-metal "pillar" (a hat-channel
// profile extruded along +x, with flanges and bends, sagging towards its
// ends; outward CCW normals, +z on the top and the flanges), optionally with
// holes and slots cut in its flat faces, a trimmed end, and hole walls. The
// same function makes the nominal CAD and a manufactured part that differs
// from it by known amounts (shifted or resized holes, an offset trim edge):
// the truth of the feature tests.
#pragma once

#include <vector>

#include "core/types/triangle_mesh.h"

namespace surfinspect {

// A hole or slot in a flat face of the profile: the top (|y| < 25.4 mm) or
// a flange (50.7 < |y| < 76.1 mm), part frame, mm. Its axis is +z.
struct PillarHole {
  double x_mm = 0, y_mm = 0;  // centre
  double diameter_mm = 8;     // a slot's width
  double length_mm = 0;       // > diameter_mm: a slot of this overall length along x
};

struct PillarFeatures {
  std::vector<PillarHole> holes;  // each in its own 5 mm steps along x, clear of the bends
  double trim_offset_mm = 0;      // the +x end's edge moved by this along +x
  double wall_depth_mm = 0;       // > 0: each hole gets a wall this deep (the sheet's thickness)
};

// The z of the ridge at x for a pillar of length_mm; the flanges lie 60 mm
// lower.
double PillarRidgeZ(double x_mm, double length_mm);

// The pillar alone, e.g. for tests (hat channel along +x, top ridge at the
// highest z, centred on the origin). Holes whose tile does not fit a flat
// face are left out (the tests check the list they get with ListHoles).
TriangleMesh MakePillarMesh(double length_mm = 300.0, const PillarFeatures& features = {});

// The demo part's holes: round holes of 5-12 mm and a slot in the top and
// the flanges (docs/inspection-plan.md#holes-and-slots lists them).
PillarFeatures DemoPillarFeatures();

}  // namespace surfinspect
