// The unit options of the commands that read clouds and meshes
// (core/io/length_units.h, docs/units.md): --units for every file read,
// --cloud-units / --mesh-units where they differ. A unit not given is
// assumed millimetres and checked for plausibility (core/io/unit_doubt.h).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "core/io/length_units.h"

namespace surfinspect::cli {

struct UnitArgs {
  std::string units, cloud_units, mesh_units;
  InputUnit Cloud() const;  // --cloud-units, else --units, else assumed mm
  InputUnit Mesh() const;   // --mesh-units, else --units, else assumed mm
};

// `with_mesh`: the command reads a mesh too (adds --mesh-units).
void AddUnitOptions(CLI::App* cmd, UnitArgs& a, bool with_mesh);

// Prints each doubt loudly on stderr ("WARNING: ..."), as read.
void WarnUnitDoubt(const std::string& doubt);

}  // namespace surfinspect::cli
