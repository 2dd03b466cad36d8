// The STEP/IGES import on untrusted bytes, as the CLI and the agent run it
// (core/cad/cad_import.h): the bytes as a file, surfinspect-cad-worker in
// its limited child, the cache entry written and read back. OpenCASCADE
// may refuse, crash or hang on the bytes; ImportCad must still come back
// with a status within its limits, and a mesh it returns must agree with
// its report. Anything else aborts, which the fuzzer reports.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/cad/cad_import.h"
#include "fuzz/fuzz_target.h"

namespace {

// Under ./run fuzz's 5 s per input, with room for the child's start.
constexpr double kSeconds = 3;

void Fail(const char* what) {
  std::fprintf(stderr, "cad fuzz: %s\n", what);
  std::abort();
}

void Import(std::string_view bytes, const char* extension) {
  namespace fs = std::filesystem;
  const std::string path = surfinspect::fuzz::WriteScratchFile(bytes, extension);
  const fs::path cache = fs::path(path).concat(".cache");
  surfinspect::CadSettings settings;
  settings.limits.seconds = kSeconds;
  settings.limits.memory_mb = 1024;
  const auto t0 = std::chrono::steady_clock::now();
  const absl::StatusOr<surfinspect::CadMesh> mesh =
      surfinspect::ImportCad(path, settings, cache.string());
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::error_code ec;
  fs::remove_all(cache, ec);  // each input meshes anew
  if (took > kSeconds + 2) Fail("the import outlasted its time limit");
  if (mesh.ok() && mesh->mesh.num_triangles() != mesh->report.triangles)
    Fail("the mesh and its report disagree on the triangle count");
}

}  // namespace

#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_cad_step)
SURFINSPECT_FUZZ_TARGET(cad_step) { Import(bytes, "step"); }
#endif
#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_cad_iges)
SURFINSPECT_FUZZ_TARGET(cad_iges) { Import(bytes, "igs"); }
#endif
