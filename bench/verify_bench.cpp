// The drift check's time per viewpoint (goal: < 2 s): a fresh gauge scan by
// the simulated robot (ray casting, noise, pulses, stripes) and the refit of
// its pose from the stored calibration (link clustering + point-to-plane
// ICP + covariance), on the demo cell's viewpoint v3.
#include <benchmark/benchmark.h>

#include <filesystem>

#include "client/agent/simulated_robot.h"
#include "client/agent/verify_cell.h"
#include "client/cell/demo_cell_files.h"
#include "core/io/io_mesh.h"
#include "core/io/io_transform.h"

namespace {

using namespace surfinspect;
using namespace surfinspect::client;

void BM_VerifyOneViewpoint(benchmark::State& state) {
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("verify_bench_" + std::to_string(::getpid())))
          .string();
  DemoWriteOptions o;
  o.parts = 0;
  o.acceptance = false;
  if (auto st = WriteDemoCell(dir, MakeDemoCell(), o); !st.ok())
    return state.SkipWithError(std::string(st.message()).c_str());
  CellConfig cell = *ReadCellConfig(dir + "/cell.json");
  for (auto& vp : cell.viewpoints)
    for (const auto& jv : cell.raw["viewpoints"])
      if (jv["name"] == vp.name)
        vp.world_from_sensor =
            *TransformFromJsonValue(jv["simulation_truth_world_from_sensor"], "t");
  cell.viewpoints = {cell.viewpoints[2]};
  const TriangleMesh gauge = *ReadMesh(cell.gauge_mesh);
  const auto index = *MeshIndex::Build(gauge);
  uint64_t seed = 1;
  for (auto _ : state) {
    auto v = VerifyCell(
        cell, *index,
        [&](const CellViewpoint& vp) {
          return SimulateGaugeScan(cell, gauge, vp, RobotDrift{}, seed++);
        },
        DriftLimits{});
    if (!v.ok() || !v->views[0].status.ok()) return state.SkipWithError("verify failed");
    benchmark::DoNotOptimize(v);
  }
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_VerifyOneViewpoint)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

}  // namespace

BENCHMARK_MAIN();
