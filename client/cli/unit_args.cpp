#include "client/cli/unit_args.h"

#include <unistd.h>

#include <cstdio>

#include "client/cli/commands.h"

namespace surfinspect::cli {
namespace {

InputUnit UnitOf(const std::string& specific, const std::string& general) {
  return Take(InputUnitOf(specific.empty() ? general : specific));
}

}  // namespace

InputUnit UnitArgs::Cloud() const { return UnitOf(cloud_units, units); }
InputUnit UnitArgs::Mesh() const { return UnitOf(mesh_units, units); }

void AddUnitOptions(CLI::App* cmd, UnitArgs& a, bool with_mesh) {
  const auto units = CLI::IsMember({"mm", "cm", "m", "in"});
  cmd->add_option("--units", a.units,
                  with_mesh ? "unit of the files read: mm, cm, m or in (default: mm, checked for "
                              "plausibility; docs/units.md)"
                            : "unit of the cloud read: mm, cm, m or in (default: mm, checked for "
                              "plausibility; docs/units.md)")
      ->check(units);
  cmd->add_option("--cloud-units", a.cloud_units, "unit of the cloud, if not --units")
      ->check(units);
  if (with_mesh)
    cmd->add_option("--mesh-units", a.mesh_units, "unit of the mesh, if not --units")->check(units);
}

void WarnUnitDoubt(const std::string& doubt) {
  const bool tty = ::isatty(STDERR_FILENO) != 0;
  std::fprintf(stderr, "%sWARNING:%s %s\n", tty ? "\033[1;31m" : "", tty ? "\033[0m" : "",
               doubt.c_str());
}

}  // namespace surfinspect::cli
