// Ray-cast throughput of the virtual area sensor: a 1024x768 scan of a
// 100k-triangle wavy sheet from 400 mm (goal: < 0.5 s on 2 cores).
// Includes the BVH build, as every SimulateScan call does.
#include <benchmark/benchmark.h>

#include <cmath>

#include "bench/wavy_sheet.h"
#include "core/simulation/scan_simulator.h"

namespace {

using surfinspect::TriangleMesh;
using surfinspect::bench::WavySheet;

void BM_SimulateScan(benchmark::State& state) {
  const TriangleMesh mesh = WavySheet(224, 300);  // 100,352 triangles
  const Eigen::Isometry3d world_from_sensor = surfinspect::LookAt({10, -20, 400}, {0, 0, 0});
  surfinspect::ScanOptions opt;
  opt.noise_sigma_mm = 0.015;
  opt.pulse_fraction = 0.003;
  opt.stripes = true;
  std::size_t hits = 0;
  for (auto _ : state) {
    auto scan =
        surfinspect::SimulateScan(mesh, Eigen::Isometry3d::Identity(), world_from_sensor, {}, opt);
    if (!scan.ok()) state.SkipWithError(std::string(scan.status().message()).c_str());
    hits = scan->hits;
    benchmark::DoNotOptimize(scan);
  }
  state.counters["triangles"] = double(mesh.num_triangles());
  state.counters["valid_points"] = double(hits);
  state.counters["rays_per_s"] =
      benchmark::Counter(1024.0 * 768.0 * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SimulateScan)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

}  // namespace

BENCHMARK_MAIN();
