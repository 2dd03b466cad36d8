// Service overhead (issue 7): a 1024x768 scan's ErrorMap in-process and
// through surfinspectd on loopback (goal: <= 1.3x), and the time to stream
// one 9.4 MB organized cloud to the server in 1 MB chunks until it reports
// the view received (goal: <= 15 ms). The server runs as a child process on
// a free port; the mesh is cached there by hash before timing.
#include <benchmark/benchmark.h>

#include <chrono>

#include "client/remote/remote_client.h"
#include "core/demo_cell.h"
#include "core/error_map.h"
#include "core/mesh_hash.h"
#include "core/transform.h"
#include "proto/convert.h"
#include "tests/support/server_process.h"

namespace {

using namespace surfinspect;

struct Fixture {
  DemoCell cell = MakeDemoCell();
  PointCloud scan_in_world;
  std::unique_ptr<MeshIndex> index;
  std::unique_ptr<testing::ServerProcess> server;
  std::unique_ptr<client::RemoteClient> client;
  Fixture() {
    const DemoViewpoint& vp = cell.viewpoints[2];
    ScanOptions opt;
    opt.noise_sigma_mm = 0.015;
    scan_in_world = TransformCloud(
        SimulateScan(cell.part, cell.world_from_part, vp.world_from_sensor, cell.intrinsics, opt)->cloud_in_sensor,
        vp.world_from_sensor);
    index = *MeshIndex::Build(cell.part);
    server = std::make_unique<testing::ServerProcess>();
    client::RemoteOptions o;
    o.target = server->target();
    client = *client::RemoteClient::Connect(o);
  }
};

Fixture& F() {
  static Fixture* f = new Fixture();
  return *f;
}

v1::ErrorMapRequest Request() {
  v1::ErrorMapRequest req;
  wire::CloudToProto(F().scan_in_world, req.mutable_cloud());
  wire::TransformToProto(F().cell.world_from_part, req.mutable_world_from_part());
  req.set_return_deviations(true);
  return req;
}

void BM_ErrorMapInProcess(benchmark::State& state) {
  for (auto _ : state) {
    auto r = ComputeErrorMap(*F().index, F().scan_in_world, F().cell.world_from_part, {});
    benchmark::DoNotOptimize(r);
  }
  state.counters["points"] = double(F().scan_in_world.size());
}
BENCHMARK(BM_ErrorMapInProcess)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

void BM_ErrorMapViaService(benchmark::State& state) {
  const v1::ErrorMapRequest req = Request();
  if (!F().client->ErrorMap(req, F().cell.part).ok()) state.SkipWithError("server call failed");
  for (auto _ : state) {
    auto r = F().client->ErrorMap(req, F().cell.part);
    if (!r.ok()) state.SkipWithError("server call failed");
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_ErrorMapViaService)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

// Header + 1 MB chunks of one 1024x768 view, timed until the server's
// STAGE_VIEW_RECEIVED event arrives; the stream is then cancelled.
void BM_StreamOneCloud(benchmark::State& state) {
  auto stub = v1::InspectionService::NewStub(
      grpc::CreateChannel(F().server->target(), grpc::InsecureChannelCredentials()));
  const PointCloud& cloud = F().scan_in_world;
  const std::string bytes(reinterpret_cast<const char*>(cloud.points.data()), cloud.size() * 12);
  v1::InspectRequest part, view, chunk;
  part.mutable_part()->set_part_id("bench");
  part.mutable_part()->mutable_part()->set_sha256(MeshSha256(F().cell.part));
  wire::TransformToProto(F().cell.world_from_part, part.mutable_part()->mutable_world_from_part());
  view.mutable_view()->set_name("v");
  view.mutable_view()->set_width(cloud.width);
  view.mutable_view()->set_height(cloud.height);
  wire::TransformToProto(Eigen::Isometry3d::Identity(), view.mutable_view()->mutable_world_from_sensor());
  for (auto _ : state) {
    grpc::ClientContext ctx;
    auto stream = stub->Inspect(&ctx);
    stream->Write(part);
    const auto t0 = std::chrono::steady_clock::now();
    stream->Write(view);
    for (std::size_t off = 0; off < bytes.size(); off += 1 << 20) {
      chunk.mutable_chunk()->set_xyz(bytes.data() + off, std::min<std::size_t>(1 << 20, bytes.size() - off));
      stream->Write(chunk);
    }
    v1::InspectResponse resp;
    bool received = false;
    while (!received && stream->Read(&resp))
      received = resp.has_progress() && resp.progress().stage() == v1::Progress::STAGE_VIEW_RECEIVED;
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    if (!received) state.SkipWithError("no VIEW_RECEIVED");
    ctx.TryCancel();
    stream->Finish();
  }
  state.counters["MB"] = double(bytes.size()) / 1e6;
}
BENCHMARK(BM_StreamOneCloud)->Unit(benchmark::kMillisecond)->UseManualTime()->MinTime(2.0);

}  // namespace

BENCHMARK_MAIN();
