// The peer comparison table: each row runs our code and the tool a
// user would otherwise pick (PCL, Open3D) on the same generated data, back to
// back in this one process, checks that they agree, and prints the ratio
// next to the row's goal, marked met or not met from the
// numbers measured here. A peer that is not installed is reported as
// skipped. Writes the markdown to RESULTS_DIR/latest.md (atomically) with
// the CPU model and core count.
//   build/bin/peers_bench [RESULTS_DIR]      (./run bench calls it)
#include <cstdio>
#include <ctime>
#include <string>

#include "bench/peers/calibration_rows.h"
#include "bench/peers/clustering_rows.h"
#include "bench/peers/command_rows.h"
#include "bench/peers/distance_rows.h"
#include "bench/peers/quiet_pcl.h"
#include "bench/peers/report.h"
#include "bench/peers/service_rows.h"
#include "core/io/atomic_file.h"
#include "core/process/buffer_reuse.h"

int main(int argc, char** argv) {
  surfinspect::ReuseFreedLargeBuffers();  // clouds are ~10 MB buffers, over and over
  surfinspect::bench::QuietPcl();
  using namespace surfinspect::bench;
  // peers_bench [RESULTS_DIR] [--only SECTION]: --only runs one section
  // (e.g. "service") and prints its rows without touching latest.md.
  std::string results_dir = "bench/results", only;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--only" && i + 1 < argc)
      only = argv[++i];
    else
      results_dir = argv[i];
  }
  const auto start = std::chrono::steady_clock::now();
  std::vector<Row> rows;
  std::vector<ScalingRow> scaling;
  auto section = [&](const char* name, auto&& fn) {
    if (!only.empty() && only != name) return;
    std::fprintf(stderr, "[peers_bench] %s ...\n", name);
    const std::size_t before = rows.size();
    fn();
    for (std::size_t i = before; i < rows.size(); ++i)
      std::fprintf(stderr, "  %s: ours %s, peer %s, %s\n", rows[i].what.c_str(),
                   rows[i].ours.c_str(), rows[i].peer.c_str(), rows[i].ratio.c_str());
  };
  section("link clustering", [&] { AddClusteringRows(rows); });
  section("closest-point distances", [&] { AddDistanceRows(rows, scaling); });
  section("ICP calibration", [&] { AddCalibrationRows(rows); });
  section("scan simulator", [&] { AddSimulatorRow(rows); });
  section("service", [&] { AddServiceRows(rows); });
  section("whole command", [&] { AddCommandRows(rows); });
  const double total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  char date[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  std::string md = "# surfinspect vs PCL / Open3D\n\n";
  md += "Measured " + std::string(date) + " on " + CpuModel() + ", " + std::to_string(CoreCount()) +
        " cores, by `./run bench` (build/bin/peers_bench); the whole comparison took " +
        Fmt("%.0f s", total) +
        ". Times are medians of repeated runs (single runs for the slowest peers). " +
#ifdef SURFINSPECT_HAVE_OPEN3D
        "Open3D: found. "
#else
        "Open3D: not installed, its rows are skipped. "
#endif
        "Peer / ours > 1 means we are faster.\n\n";
  md += RenderRows(rows) + "\n" + RenderScaling(scaling);
  std::fputs(md.c_str(), stdout);
  if (!only.empty()) return 0;
  const std::string path = results_dir + "/latest.md";
  if (auto st = surfinspect::WriteStringAtomically(path, md); !st.ok()) {
    std::fprintf(stderr, "peers_bench: cannot write %s: %s\n", path.c_str(),
                 std::string(st.message()).c_str());
    return 1;
  }
  std::fprintf(stderr, "[peers_bench] wrote %s\n", path.c_str());
  // A row that could not be measured fails the run (./run bench stops).
  int failed = 0;
  for (const Row& r : rows)
    for (const std::string* cell : {&r.ours, &r.peer, &r.agreement})
      if (cell->find("failed") != std::string::npos || cell->find("missing") != std::string::npos) {
        std::fprintf(stderr, "peers_bench: row not measured: %s\n", r.what.c_str());
        ++failed;
        break;
      }
  return failed == 0 ? 0 : 2;
}
