// surfinspect trend: SPC, drift lines and the process trend map over the
// parts in a results database (core/history/trend.h), as trend.html, and
// optionally trend.json and trend.png.
#include <spdlog/spdlog.h>

#include <cstdio>
#include <regex>

#include "client/cli/commands.h"
#include "client/cli/db_args.h"
#include "core/history/trend.h"
#include "core/history/trend_html.h"
#include "core/history/trend_png.h"
#include "core/io/atomic_file.h"
#include "core/io/io_mesh.h"

namespace surfinspect::cli {
namespace {

struct TrendArgs {
  std::string db, cell, characteristic, since, out, json, png, mesh;
  int last = 0;
};

std::string SelectionText(const TrendArgs& a) {
  std::string s = "cell " + (a.cell.empty() ? std::string("any") : a.cell);
  if (a.last > 0) s += ", last " + std::to_string(a.last);
  if (!a.since.empty()) s += ", since " + a.since;
  return s;
}

void RunTrend(const TrendArgs& a) {
  if (!a.since.empty() &&
      !std::regex_match(a.since,
                        std::regex(R"(\d{4}-\d\d-\d\d(T\d\d(:\d\d(:\d\d(\.\d+)?)?)?Z?)?)")))
    throw CommandFailed("--since " + a.since + ": not a UTC time like 2026-12-01T08:00:00Z");
  if (!a.png.empty() && a.mesh.empty())
    throw CommandFailed("--png needs --mesh (the CAD part the trend map is drawn on)");
  std::unique_ptr<ResultsStore> store = OpenStore(a.db, /*must_exist=*/true);
  PartSelection sel;
  sel.cell = a.cell;
  sel.since_utc = a.since;
  sel.last = a.last;
  sel.with_triangles = true;
  const std::vector<PartRecord> parts = Take(store->Load(sel));
  if (parts.empty())
    throw CommandFailed(store->Name() + ": no parts match the selection (" + SelectionText(a) +
                        ")");
  const Trend trend = Take(ComputeTrend(parts, a.characteristic));
  const std::string title = "Process trend: " + SelectionText(a);
  std::string html, png;
  if (a.mesh.empty()) {
    html = TrendHtml(trend, title, "");
  } else {  // the map in 3D on the page; as a picture only when asked for
    const TriangleMesh mesh = Take(ReadMesh(a.mesh));
    html = Take(TrendViewerHtml(trend, title, mesh));
    if (!a.png.empty()) png = Take(EncodePng(Take(RenderTrendMap(trend.map, mesh))));
  }
  const nlohmann::json selection = {
      {"cell", a.cell}, {"characteristic", a.characteristic}, {"last", a.last}, {"since", a.since}};
  Check(WriteStringAtomically(a.out, html));
  if (!a.json.empty())
    Check(WriteStringAtomically(a.json, TrendJson(trend, selection).dump(2) + "\n"));
  if (!a.png.empty()) Check(WriteStringAtomically(a.png, png));
  std::printf("%zu parts (%s) from %s\n", parts.size(), SelectionText(a).c_str(),
              store->Name().c_str());
  std::printf("%-20s %5s %10s %10s %7s %7s %11s %s\n", "characteristic", "n", "mean_mm",
              "sigma_w_mm", "cpk", "ppk", "slope/part", "alarms");
  for (const CharacteristicTrend& c : trend.characteristics)
    std::printf("%-20s %5zu %10.4f %10.4f %7.2f %7.2f %+11.5f %zu\n", TrendLabel(c).c_str(),
                c.values_mm.size(), c.spc ? c.spc->mean_mm : NAN,
                c.spc ? c.spc->sigma_within_mm : NAN, c.spc ? c.spc->cpk : NAN,
                c.spc ? c.spc->ppk : NAN, c.drift ? c.drift->slope_mm_per_part : NAN,
                c.violations.size());
  std::printf("wrote %s%s%s%s%s\n", a.out.c_str(), a.json.empty() ? "" : ", ", a.json.c_str(),
              a.png.empty() ? "" : ", ", a.png.c_str());
}

}  // namespace

void AddTrendCommand(CLI::App& app) {
  auto a = std::make_shared<TrendArgs>();
  auto* cmd = app.add_subcommand(
      "trend",
      "SPC (Cp, Cpk, Pp, Ppk, X/MR charts, Western Electric rules), drift lines and "
      "the process trend map over recorded parts");
  AddDbOption(cmd, a->db, "results database to read");
  cmd->add_option("--cell", a->cell, "only this cell's parts (cell.json name)");
  cmd->add_option("--characteristic", a->characteristic, "only this characteristic");
  auto* last =
      cmd->add_option("--last", a->last, "only the newest N parts")->check(CLI::PositiveNumber);
  cmd->add_option("--since", a->since, "only parts inspected at or after this UTC time")
      ->excludes(last);
  cmd->add_option("--out", a->out, "trend.html")->required();
  cmd->add_option("--json", a->json, "trend.json (README: Part history and the process trend)");
  cmd->add_option("--png", a->png, "trend.png: the trend map on the part (needs --mesh)");
  cmd->add_option("--mesh", a->mesh,
                  "the part's CAD mesh: trend.html then shows the trend map on it in 3D");
  cmd->callback([a] {
    if (a->db.empty()) throw CommandFailed("--db: no results database given");
    RunTrend(*a);
  });
}

}  // namespace surfinspect::cli
