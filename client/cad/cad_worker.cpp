// surfinspect-cad-worker: one STEP or IGES file to a grouped OBJ mesh and its
// CadReport (core/cad/occt/occt_tessellate.h). Run only as the short-lived,
// limited child of `surfinspect cad`, `inspect` and the cell-agent
// (core/cad/cad_import.h), so that OpenCASCADE's parser and mesher never run
// inside a long-lived process. Exit codes: 0 done, 2 bad input, 3 out of
// memory, 1 anything else; the reason on stderr.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <new>

#include "core/cad/cad_report.h"
#include "core/cad/occt/occt_tessellate.h"
#include "core/io/atomic_file.h"
#include "core/io/obj_groups.h"

namespace {

int ExitCodeOf(const absl::Status& st) {
  if (st.code() == absl::StatusCode::kInvalidArgument) return 2;
  if (st.code() == absl::StatusCode::kResourceExhausted) return 3;
  return 1;
}

int Fail(const absl::Status& st) {
  std::fprintf(stderr, "%s\n", std::string(st.message()).c_str());
  return ExitCodeOf(st);
}

}  // namespace

int main(int argc, char** argv) try {
  CLI::App app{"surfinspect-cad-worker: tessellate one STEP/IGES file (run by surfinspect)"};
  std::string in, out, report_path;
  surfinspect::TessellationSettings s;
  app.add_option("--in", in, "STEP or IGES file")->required();
  app.add_option("--out", out, "OBJ mesh to write (mm, grouped)")->required();
  app.add_option("--report", report_path, "CadReport JSON to write")->required();
  app.add_option("--chord-tolerance", s.chord_tolerance_mm, "mm");
  app.add_option("--angular-tolerance", s.angular_tolerance_deg, "degrees");
  app.add_option("--body", s.body, "one body by name");
  CLI11_PARSE(app, argc, argv);
  auto t = surfinspect::occt::TessellateCad(in, s);
  if (!t.ok()) return Fail(t.status());
  auto obj = surfinspect::ObjWithGroups(t->mesh, t->groups);
  if (!obj.ok()) return Fail(obj.status());
  if (auto st = surfinspect::WriteStringAtomically(out, *obj); !st.ok()) return Fail(st);
  const std::string json = surfinspect::EncodeCadReport(t->report).dump(2) + "\n";
  if (auto st = surfinspect::WriteStringAtomically(report_path, json); !st.ok()) return Fail(st);
  return 0;
} catch (const std::bad_alloc&) {
  std::fprintf(stderr, "out of memory\n");
  return 3;
}
