// surfinspect cad: a STEP or IGES file to a mesh in millimetres with its
// measured tessellation error (core/cad/cad_import.h, docs/cad.md). The work
// runs in surfinspect-cad-worker under time and memory limits.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <numeric>

#include "absl/strings/ascii.h"
#include "client/cell/cell_part.h"
#include "client/cli/commands.h"
#include "core/cad/cad_import.h"

namespace surfinspect::cli {
namespace {

struct CadArgs {
  std::string in, out, report;
  CadSettings settings;
};

// The faces with the largest measured error, worst first.
void PrintWorstFaces(const CadReport& r, std::size_t count) {
  std::vector<std::size_t> order(r.face_error_mm.size());
  std::iota(order.begin(), order.end(), 0);
  count = std::min(count, order.size());
  std::partial_sort(
      order.begin(), order.begin() + count, order.end(),
      [&](std::size_t a, std::size_t b) { return r.face_error_mm[a] > r.face_error_mm[b]; });
  for (std::size_t k = 0; k < count; ++k)
    std::printf("  face:%zu  %.5f mm\n", order[k] + 1, r.face_error_mm[order[k]]);
}

void RunCad(const CadArgs& a) {
  const std::string report =
      a.report.empty() ? std::filesystem::path(a.out).replace_extension(".cad.json").string()
                       : a.report;
  const CadReport r = Take(TessellateCadFile(a.in, a.settings, a.out, report));
  std::printf("%s\n", client::CadSummary(r, false).c_str());
  std::printf("bodies: ");
  for (std::size_t i = 0; i < r.bodies.size(); ++i)
    std::printf("%s%s", i ? ", " : "", r.bodies[i].c_str());
  std::printf("%s\n", r.body.empty() ? "" : (" (kept: " + r.body + ")").c_str());
  std::printf("bounds mm: (%.4f, %.4f, %.4f) .. (%.4f, %.4f, %.4f)\n", r.bounds_mm.min.x(),
              r.bounds_mm.min.y(), r.bounds_mm.min.z(), r.bounds_mm.max.x(), r.bounds_mm.max.y(),
              r.bounds_mm.max.z());
  std::printf("largest measured error by face:\n");
  PrintWorstFaces(r, 5);
  std::printf("wrote %s, %s\n", a.out.c_str(), report.c_str());
  if (r.tolerance_held) return;
  // A B-rep whose edges lie this far from their faces cannot be meshed
  // closer than that: say so rather than only "not held".
  const std::string floor =
      r.brep_tolerance_mm > r.chord_tolerance_mm
          ? "; the file's own B-rep tolerance is " + std::to_string(r.brep_tolerance_mm) +
                " mm (its edges lie that far from their faces), so no finer mesh can hold"
          : "";
  throw CommandFailed("the measured tessellation error " + std::to_string(r.tessellation_error_mm) +
                      " mm exceeds the chord tolerance " + std::to_string(r.chord_tolerance_mm) +
                      " mm" + floor + "; the mesh was written, use it knowingly");
}

}  // namespace

void AddCadCommand(CLI::App& app) {
  auto a = std::make_shared<CadArgs>();
  auto* cmd = app.add_subcommand(
      "cad", "Tessellate a STEP/IGES file into a mesh (mm) with its measured tessellation error");
  cmd->add_option("--in", a->in, "STEP (.step .stp) or IGES (.iges .igs) file, any length unit")
      ->required()
      ->check(CLI::ExistingFile);
  // The mesh is OBJ whatever the name says; another extension would be
  // read back as that format and refused, or worse.
  const CLI::Validator obj(
      [](std::string& path) {
        const std::string ext = std::filesystem::path(path).extension().string();
        return absl::AsciiStrToLower(ext) == ".obj"
                   ? std::string()
                   : "must end in .obj: the mesh is written as OBJ, with its groups";
      },
      "OBJ");
  cmd->add_option("--out", a->out, "mesh to write: OBJ with groups face:N, name:, color:, body:")
      ->required()
      ->check(obj);
  cmd->add_option("--report", a->report, "report JSON (default: OUT with .cad.json)");
  cmd->add_option("--chord-tolerance", a->settings.tessellation.chord_tolerance_mm,
                  "largest measured distance between surface and triangles, mm")
      ->capture_default_str();
  cmd->add_option("--angular-tolerance", a->settings.tessellation.angular_tolerance_deg,
                  "largest angle between neighbouring triangles' normals, degrees")
      ->capture_default_str();
  cmd->add_option("--body", a->settings.tessellation.body, "mesh only this body (product) by name");
  cmd->add_option("--timeout", a->settings.limits.seconds, "stop OpenCASCADE after this many s")
      ->capture_default_str();
  cmd->add_option("--memory-mb", a->settings.limits.memory_mb, "OpenCASCADE's memory limit, MB")
      ->capture_default_str();
  cmd->callback([a] { RunCad(*a); });
}

}  // namespace surfinspect::cli
