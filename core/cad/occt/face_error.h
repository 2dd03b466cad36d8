// One meshed face's triangles, and how far they are from the exact face
// (cad_report.h says what is measured). OCCT types: occt/ only.
#pragma once

#include <Eigen/Core>
#include <TopoDS_Face.hxx>
#include <array>
#include <cstdint>
#include <vector>

namespace surfinspect::occt {

struct MeshedFace {
  std::vector<Eigen::Vector3f> nodes;              // part frame, as written
  std::vector<std::array<uint32_t, 3>> triangles;  // CCW seen from outside
  double error_mm = 0;                             // measured; +inf when unmeshed
};

// The face's triangulation after BRepMesh (location applied, a reversed
// face's winding flipped) with its measured error. The error is taken with
// the float vertices the mesh file will hold, so it is the error of the file.
// A face OCCT left without triangles gets none and error +inf.
// Samples whose simple bound exceeds `loose_mm` are bounded more tightly.
MeshedFace MeasureMeshedFace(const TopoDS_Face& face, double loose_mm);

}  // namespace surfinspect::occt
