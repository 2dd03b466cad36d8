// How a STEP or IGES file becomes the mesh an error map is measured against
// (docs/cad.md): the tessellation's tolerances, which body of an assembly,
// and the limits of the child process that runs OpenCASCADE on the file's
// untrusted bytes. Validated in one place, ValidateCadSettings.
#pragma once

#include <cstdint>
#include <string>

#include "absl/status/status.h"

namespace surfinspect {

struct TessellationSettings {
  // The largest distance allowed between the exact surface and its
  // triangles, as measured after meshing (cad_report.h), not OCCT's target.
  double chord_tolerance_mm = 0.01;
  // OCCT's angular deflection between neighbouring triangles' normals.
  double angular_tolerance_deg = 15;
  // One body (product) of an assembly by name; empty: every body.
  std::string body;
};

// The import runs in a child process (limited_child.h) under these limits:
// a file that hangs or explodes OpenCASCADE ends in an error, not in a hung
// or killed agent. A real IGES file kept OCCT's mesher busy for minutes.
struct CadImportLimits {
  double seconds = 120;       // wall clock
  uint64_t memory_mb = 4096;  // address space (RLIMIT_AS)
  uint64_t max_file_bytes = uint64_t{512} << 20;
};

struct CadSettings {
  TessellationSettings tessellation;
  CadImportLimits limits;
};

// InvalidArgument naming the field: tolerances finite and in range
// (chord 1e-4 .. 10 mm, angle 1 .. 60 degrees), limits positive.
absl::Status ValidateCadSettings(const CadSettings& settings);

// True for the extensions OpenCASCADE reads here: .step .stp .iges .igs
// (any case).
bool IsCadPath(const std::string& path);

}  // namespace surfinspect
