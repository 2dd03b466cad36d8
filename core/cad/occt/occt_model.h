// A STEP or IGES file as the faces to mesh, each with the names a plan can
// select it by: its body (product), its own name and its colour. Read with
// OpenCASCADE's XCAF readers, which convert every length to millimetres
// (the file's declared unit is kept for the report). Only the occt/
// translation units include this header: OCCT's headers are heavy.
#pragma once

#include <TopoDS_Compound.hxx>
#include <TopoDS_Face.hxx>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace surfinspect::occt {

struct ModelFace {
  TopoDS_Face face;   // located in the part's frame
  uint32_t body = 0;  // index into OcctModel::bodies
  std::string name;   // the face's own name in the file, "" when none
  std::string color;  // "#rrggbb" (sRGB), the face's or its body's; "" when none
};

struct OcctModel {
  std::string format;               // "STEP" or "IGES"
  std::string declared_unit;        // as the file names it, upper case
  std::vector<std::string> bodies;  // every body of the file, unique names
  std::vector<ModelFace> faces;     // of the chosen body (or all), file order
  TopoDS_Compound shape;            // the same faces, for meshing
};

// InvalidArgument for a file OCCT cannot read or that holds no face, and for
// a `body` the file does not have (the message lists the bodies).
absl::StatusOr<OcctModel> ReadOcctModel(const std::string& path, const std::string& body);

}  // namespace surfinspect::occt
