// surfinspect holes MESH: the holes and slots a CAD mesh has (its boundary
// loops that are circles or slots, core/plan/cad_holes.h), as a table or,
// with --plan, as the plan entries to start an inspection plan from.
#include <cstdio>
#include <nlohmann/json.hpp>

#include "absl/strings/str_format.h"
#include "client/cli/commands.h"
#include "client/cli/unit_args.h"
#include "core/io/io_mesh.h"
#include "core/plan/inspection_plan.h"

namespace surfinspect::cli {
namespace {

struct HolesArgs {
  std::string mesh;
  UnitArgs units;
  bool plan = false;
  double position_tolerance_mm = PlanHole{}.position_tolerance_mm;
};

void RunHoles(const HolesArgs& a) {
  TriangleMesh mesh = Take(ReadMesh(a.mesh));
  ScaleToMillimetres(a.units.Mesh().unit, &mesh);
  const std::vector<CadHole> holes = ListHoles(mesh);
  if (a.plan) {
    std::printf("%s\n", PlanHolesJson(holes, a.position_tolerance_mm).dump(2).c_str());
    return;
  }
  std::printf("%zu holes and slots in %s (mm, part frame)\n", holes.size(), a.mesh.c_str());
  std::printf("%-5s %-28s %-24s %9s %9s %8s\n", "kind", "position", "axis", "diameter", "length",
              "form");
  for (const CadHole& h : holes)
    std::printf("%-5s %8.3f %8.3f %9.3f  %6.3f %6.3f %6.3f  %9.3f %9s %8.4f\n",
                h.slot ? "slot" : "hole", h.position_mm.x(), h.position_mm.y(), h.position_mm.z(),
                h.axis.x(), h.axis.y(), h.axis.z(), h.diameter_mm,
                h.slot ? absl::StrFormat("%.3f", h.length_mm).c_str() : "-", h.form_mm);
}

}  // namespace

void AddHolesCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("holes",
                                 "List the holes and slots of a CAD mesh (boundary loops or a "
                                 "solid's sharp rims that are circles or slots)");
  auto a = std::make_shared<HolesArgs>();
  cmd->add_option("mesh", a->mesh, "CAD mesh (.stl/.obj/.ply/.off)")->required();
  AddUnitOptions(cmd, a->units, true);
  cmd->add_flag("--plan", a->plan,
                "print plan entries ({\"holes\", \"slots\"}) instead of a table");
  cmd->add_option("--position-tolerance", a->position_tolerance_mm,
                  "with --plan: the true-position zone, mm")
      ->check(CLI::PositiveNumber);
  cmd->callback([a] { RunHoles(*a); });
}

}  // namespace surfinspect::cli
