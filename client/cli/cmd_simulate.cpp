// surfinspect simulate / demo-cell: the virtual area sensor from the CLI.
#include <spdlog/spdlog.h>

#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>

#include "absl/strings/numbers.h"
#include "absl/strings/str_split.h"
#include "client/cell/demo_cell_files.h"
#include "client/cli/commands.h"
#include "core/io/atomic_file.h"
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"
#include "core/io/io_transform.h"
#include "core/simulation/demo_cell.h"

namespace surfinspect::cli {
namespace {

struct SimulateArgs {
  std::string mesh, world_from_part, world_from_sensor, out, truth;
  double noise = 0, pulses = 0;
  bool stripes = false;
  std::vector<std::string> dents;
  uint64_t seed = 1;
};

SurfaceDefect ParseDent(const std::string& text) {
  std::vector<std::string> parts = absl::StrSplit(text, ',');
  double v[5];
  if (parts.size() != 5) throw CommandFailed("--dent wants x,y,z,radius,depth (mm, part frame)");
  for (int i = 0; i < 5; ++i)
    if (!absl::SimpleAtod(parts[i], &v[i]) || !std::isfinite(v[i]))
      throw CommandFailed("--dent: '" + parts[i] + "' is not a finite number");
  SurfaceDefect d;
  d.center_in_part = {v[0], v[1], v[2]};
  d.radius_mm = v[3];
  d.depth_mm = v[4];
  return d;
}

void Simulate(const SimulateArgs& a) {
  const TriangleMesh mesh = Take(ReadMesh(a.mesh));
  const Eigen::Isometry3d world_from_part = a.world_from_part.empty()
                                                ? Eigen::Isometry3d::Identity()
                                                : Take(ReadTransformJson(a.world_from_part));
  const Eigen::Isometry3d world_from_sensor = Take(ReadTransformJson(a.world_from_sensor));
  ScanOptions opt;
  opt.noise_sigma_mm = a.noise;
  opt.pulse_fraction = a.pulses;
  opt.stripes = a.stripes;
  opt.seed = a.seed;
  for (const auto& d : a.dents) opt.defects.push_back(ParseDent(d));
  const SimulatedScan scan =
      Take(SimulateScan(mesh, world_from_part, world_from_sensor, SensorIntrinsics{}, opt));
  Check(WritePointCloud(a.out, scan.cloud_in_sensor));
  spdlog::info("wrote {}: {} valid points ({} pulses, {} stripe pixels, {} defect pixels)", a.out,
               scan.hits, scan.pulses, scan.stripe_pixels, scan.defect_pixels);
  if (!a.truth.empty()) {
    nlohmann::json labels = nlohmann::json::array();
    std::string label_string(scan.labels.size(), '0');
    for (std::size_t i = 0; i < scan.labels.size(); ++i)
      label_string[i] = static_cast<char>('0' + static_cast<int>(scan.labels[i]));
    const nlohmann::json truth = {
        {"width", scan.cloud_in_sensor.width},
        {"height", scan.cloud_in_sensor.height},
        {"label_codes",
         {{"0", "no_data"}, {"1", "good"}, {"2", "pulse"}, {"3", "stripe"}, {"4", "defect"}}},
        {"labels", label_string},
        {"valid_points", scan.hits},
        {"pulses", scan.pulses},
        {"stripe_pixels", scan.stripe_pixels},
        {"defect_pixels", scan.defect_pixels}};
    Check(WriteStringAtomically(a.truth, truth.dump() + "\n"));
  }
}

void WriteCell(const std::string& out, int parts, uint64_t seed) {
  const auto t0 = std::chrono::steady_clock::now();
  client::DemoWriteOptions opt;
  opt.parts = parts;
  opt.scan.noise_sigma_mm = 0.015;
  opt.scan.pulse_fraction = 0.003;
  opt.scan.stripes = true;
  opt.scan.seed = seed;
  Check(client::WriteDemoCell(out, MakeDemoCell(), opt));
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("demo cell written to %s in %.1f s:\n", out.c_str(), s);
  std::printf("  part.stl, gauge.stl        CAD meshes (mm)\n");
  std::printf("  cell.json                  viewpoints, poses, sensor\n");
  std::printf("  gauge_scans/v1..v5.pcd     calibration scans of the gauge\n");
  std::printf("  scans/part-NNN/v1..v5.pcd  production scans with planted dents/bumps\n");
  std::printf("  truth/                     outlier pixels and planted defects (JSON)\n");
  std::printf(
      "  acceptance/                artefact scans + artefacts.json (surfinspect acceptance)\n");
}

}  // namespace

void AddSimulateCommands(CLI::App& app) {
  auto a = std::make_shared<SimulateArgs>();
  auto* sim = app.add_subcommand("simulate",
                                 "Scan a mesh with the virtual area sensor "
                                 "(1024x768, 35 deg; cloud in the sensor frame)");
  sim->add_option("--mesh", a->mesh, "part mesh (part frame, mm)")->required();
  sim->add_option("--world-from-part", a->world_from_part, "transform JSON (default identity)");
  sim->add_option("--world-from-sensor", a->world_from_sensor, "transform JSON")->required();
  sim->add_option("--out", a->out, "organized cloud to write (.pcd)")->required();
  sim->add_option("--noise", a->noise, "Gaussian noise along the ray, sigma in mm")
      ->check(CLI::NonNegativeNumber);
  sim->add_option("--pulses", a->pulses, "fraction of valid pixels made pulse outliers")
      ->check(CLI::Range(0.0, 1.0));
  sim->add_flag("--stripes", a->stripes, "mixed-pixel stripes at depth discontinuities");
  sim->add_option("--dent", a->dents, "x,y,z,radius,depth (mm, part frame; depth<0 = bump)");
  sim->add_option("--seed", a->seed, "random seed");
  sim->add_option("--truth", a->truth, "per-pixel ground truth JSON to write");
  sim->callback([a] { Simulate(*a); });

  auto out = std::make_shared<std::string>();
  auto parts = std::make_shared<int>(3);
  auto seed = std::make_shared<uint64_t>(1);
  auto* demo = app.add_subcommand("demo-cell",
                                  "Write the built-in demo cell: pillar part, gauge, "
                                  "viewpoints and simulated scans");
  demo->add_option("--out", *out, "directory")->required();
  demo->add_option("--parts", *parts, "production parts to scan")->check(CLI::Range(0, 1000));
  demo->add_option("--seed", *seed, "random seed");
  demo->callback([out, parts, seed] { WriteCell(*out, *parts, *seed); });
}

}  // namespace surfinspect::cli
