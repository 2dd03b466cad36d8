// The whole command, process start to exit, on the same files: 10^6 points
// near a 180k-triangle torus (binary PLY cloud, binary PLY mesh), as
//  - ours: `surfinspect errormap` writing its PLY and JSON report;
//  - Open3D: a python3 script that reads both files, builds its
//    RaycastingScene and calls compute_distance;
//  - CloudCompare: `CloudCompare -SILENT -C2M_DIST` on both files.
// Each is a child process timed by wall clock, medians of five runs after
// one warm-up run (the files in page cache for all; CloudCompare once). Agreement: our |deviation|
// from a separate, untimed run with --csv against Open3D's unsigned distances.
#pragma once

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bench/peers/distance_rows.h"
#include "bench/peers/report.h"
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"

namespace surfinspect::bench {

namespace command_detail {

// A fresh folder under /tmp, removed with its files at the end of the scope.
struct ScratchDir {
  std::string path;
  ScratchDir() {
    char name[] = "/tmp/surfinspect-command-XXXXXX";
    path = mkdtemp(name) ? name : "";
  }
  ~ScratchDir() {
    std::error_code ec;
    if (!path.empty()) std::filesystem::remove_all(path, ec);
  }
  std::string File(const std::string& name) const { return path + "/" + name; }
};

inline std::string BinDir() {
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return ".";
  std::string path(buf, static_cast<std::size_t>(n));
  return path.substr(0, path.rfind('/'));
}

// Timed runs of each command, after its warm-up run. Each command's runs
// follow each other, as a cell runs one tool again and again: on this VM a
// process that faults in fresh memory right after another has freed a lot
// (the Open3D script frees several hundred MB) spends up to 0.2 s more in
// the kernel, as the freed pages went back to the host (measured with
// /usr/bin/time: ours 0.03-0.05 s of system time in a row, 0.07-0.22 s
// after each Open3D run).
constexpr int kCommandReps = 5;

// Median wall seconds of `command` (a shell line), NaN if it ever fails.
inline double CommandSeconds(const std::string& command, int reps) {
  bool failed = false;
  const double t = MedianSeconds(reps, true, [&] { failed |= std::system(command.c_str()) != 0; });
  return failed ? NAN : t;
}

constexpr const char* kOpen3dScript = R"(import sys
import numpy as np
import open3d as o3d
cloud = o3d.io.read_point_cloud(sys.argv[1])
mesh = o3d.io.read_triangle_mesh(sys.argv[2])
scene = o3d.t.geometry.RaycastingScene()
scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(mesh))
d = scene.compute_distance(o3d.core.Tensor(np.asarray(cloud.points, dtype=np.float32))).numpy()
if len(sys.argv) > 3:
    d.astype(np.float32).tofile(sys.argv[3])
)";

// max abs(abs(ours) - open3d) over points both matched, from our CSV's last
// column and Open3D's raw float32 file; NaN when either cannot be read.
inline double MaxDifference(const std::string& csv, const std::string& raw, std::size_t n) {
  std::ifstream in_raw(raw, std::ios::binary);
  std::vector<float> o3d(n);
  if (!in_raw.read(reinterpret_cast<char*>(o3d.data()), std::streamsize(n * sizeof(float))))
    return NAN;
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);  // header
  double worst = 0;
  std::size_t i = 0;
  for (; i < n && std::getline(in, line); ++i) {
    const double ours = std::strtod(line.c_str() + line.rfind(',') + 1, nullptr);
    if (std::isfinite(ours)) worst = std::max(worst, std::abs(std::abs(ours) - o3d[i]));
  }
  return i == n ? worst : NAN;
}

// A peer that is not installed is skipped, never faked; one that is and
// fails fails the run (peers_bench checks for "failed").
inline std::string PeerCell(bool installed, double seconds, const std::string& label) {
  if (!installed) return "skipped (not installed)";
  return std::isfinite(seconds) ? Time(seconds) + label : "failed";
}

inline std::string RatioCell(double peer, double ours) {
  return std::isfinite(peer) && std::isfinite(ours) ? Fmt("%.1fx", peer / ours) : "—";
}

}  // namespace command_detail

inline void AddCommandRows(std::vector<Row>& rows) {
  using namespace command_detail;
  const ScratchDir dir;
  const std::string cloud = dir.File("cloud.ply"), mesh = dir.File("torus.ply");
  const PointCloud points = distance_detail::RandomPoints(1'000'000, 7);
  const std::string what =
      "Whole command, 10^6 points (binary PLY) near a 180k-triangle torus (binary PLY), read to "
      "written (2 threads)";
  if (!WritePointCloud(cloud, points).ok() ||
      !WriteMesh(mesh, distance_detail::Torus(600, 150), MeshFormat::kPlyBinary).ok()) {
    rows.push_back({what, "failed to write the inputs", "", "", "", "", ""});
    return;
  }
  constexpr const char* kQuiet = " >/dev/null 2>&1";
  const std::string ours_run = BinDir() + "/surfinspect errormap --cloud " + cloud + " --mesh " +
                               mesh + " --out " + dir.File("out.ply") + " --report " +
                               dir.File("report.json");
  const double ours = CommandSeconds(ours_run + kQuiet, kCommandReps);
  const std::string script = dir.File("o3d.py");
  std::ofstream(script) << kOpen3dScript;
  const bool have_o3d = std::system("/usr/bin/python3 -c 'import open3d' >/dev/null 2>&1") == 0;
  const std::string o3d_run = "/usr/bin/python3 " + script + " " + cloud + " " + mesh;
  const double o3d = have_o3d ? CommandSeconds(o3d_run + kQuiet, kCommandReps) : NAN;
  std::string agreement = "—";
  if (have_o3d) {  // untimed runs: our CSV and Open3D's raw distances
    const bool ran =
        std::system((ours_run + " --csv " + dir.File("out.csv") + kQuiet).c_str()) == 0 &&
        std::system((o3d_run + " " + dir.File("o3d.raw") + kQuiet).c_str()) == 0;
    const double diff =
        ran ? MaxDifference(dir.File("out.csv"), dir.File("o3d.raw"), points.size()) : NAN;
    agreement = std::isfinite(diff) ? Fmt("max abs(abs(ours) − Open3D) = %.1e mm", diff)
                                    : "comparison failed";
  }
  const std::string ours_cell = std::isfinite(ours) ? Time(ours) : "failed";
  rows.push_back({what, ours_cell,
                  PeerCell(have_o3d, o3d, " (Open3D script: read, build, compute_distance)"),
                  RatioCell(o3d, ours), agreement, "≥ 4x the Open3D script",
                  std::isfinite(o3d) ? Verdict(o3d / ours >= 4) : "—"});

  const bool have_cc = std::system("command -v CloudCompare >/dev/null 2>&1") == 0;
  const double cc = have_cc ? CommandSeconds(
                                  "QT_QPA_PLATFORM=offscreen CloudCompare -SILENT "
                                  "-AUTO_SAVE OFF -O " +
                                      cloud + " -O " + mesh + " -C2M_DIST" + kQuiet,
                                  1)
                            : NAN;
  rows.push_back({what, ours_cell, PeerCell(have_cc, cc, " (CloudCompare -C2M_DIST)"),
                  RatioCell(cc, ours), "(same files)", "≥ 6x CloudCompare",
                  std::isfinite(cc) ? Verdict(cc / ours >= 6) : "—"});
}

}  // namespace surfinspect::bench
