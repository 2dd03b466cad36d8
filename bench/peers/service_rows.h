// The scan simulator's ray-cast throughput (no peer: Open3D 0.16's
// cast_rays returns no hits with Debian's Embree, which has ray masks
// compiled in) and the service overhead: a 1024x768 scan's ErrorMap
// in-process (error map, default plan's verdict, report text: the steps of
// the CLI without --server and of the RPC's handler) and through a
// surfinspectd child process on loopback (mesh cached there before timing),
// and one 9.4 MB organized cloud streamed in 1 MB chunks until the server
// reports it received.
#pragma once

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <cmath>
#include <cstring>

#include "bench/peers/report.h"
#include "bench/wavy_sheet.h"
#include "client/remote/remote_client.h"
#include "core/errormap/error_map.h"
#include "core/io/mesh_hash.h"
#include "core/pipeline/inspection.h"
#include "core/pipeline/inspection_report.h"
#include "core/plan/plan_evaluation.h"
#include "core/simulation/demo_cell.h"
#include "core/simulation/scan_simulator.h"
#include "core/types/transform.h"
#include "proto/convert.h"
#include "proto/packed_cloud.h"
#include "tests/support/server_process.h"

namespace surfinspect::bench {

namespace service_detail {

// Seconds from the view header to STAGE_VIEW_RECEIVED; NaN on failure.
inline double StreamOnce(v1::InspectionService::Stub& stub, const v1::InspectRequest& part,
                         const v1::InspectRequest& view, const std::string& bytes) {
  grpc::ClientContext ctx;
  auto stream = stub.Inspect(&ctx);
  stream->Write(part);
  const auto t0 = std::chrono::steady_clock::now();
  stream->Write(view);
  v1::InspectRequest chunk;
  for (std::size_t off = 0; off < bytes.size(); off += 1 << 20) {
    chunk.mutable_chunk()->set_xyz(bytes.data() + off,
                                   std::min<std::size_t>(1 << 20, bytes.size() - off));
    stream->Write(chunk);
  }
  v1::InspectResponse resp;
  bool received = false;
  while (!received && stream->Read(&resp))
    received = resp.has_progress() && resp.progress().stage() == v1::Progress::STAGE_VIEW_RECEIVED;
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ctx.TryCancel();
  stream->Finish();
  return received ? s : NAN;
}

}  // namespace service_detail

inline void AddSimulatorRow(std::vector<Row>& rows) {
  const TriangleMesh mesh = WavySheet(224, 300);  // 100,352 triangles
  const Eigen::Isometry3d world_from_sensor = LookAt({10, -20, 400}, {0, 0, 0});
  ScanOptions opt;
  opt.noise_sigma_mm = 0.015;
  opt.pulse_fraction = 0.003;
  opt.stripes = true;
  std::size_t hits = 0;
  const double t = MedianSeconds(5, true, [&] {
    auto scan = SimulateScan(mesh, Eigen::Isometry3d::Identity(), world_from_sensor, {}, opt);
    hits = scan.ok() ? scan->hits : 0;
  });
  rows.push_back({"Scan simulator, 1024x768 rays on 100k triangles (BVH build included, 2 threads)",
                  Time(t) + Fmt(" (%.1f M rays/s)", 1024.0 * 768.0 / t / 1e6),
                  "none (Open3D 0.16 cast_rays gets no hits with Debian's Embree)", "—",
                  std::to_string(hits) + " valid points", "< 0.5 s", Verdict(hits > 0 && t < 0.5)});
}

inline void AddServiceRows(std::vector<Row>& rows) {
  const DemoCell cell = MakeDemoCell();
  const DemoViewpoint& vp = cell.viewpoints[2];
  ScanOptions opt;
  opt.noise_sigma_mm = 0.015;
  auto scan =
      SimulateScan(cell.part, cell.world_from_part, vp.world_from_sensor, cell.intrinsics, opt);
  auto index = MeshIndex::Build(cell.part);
  testing::ServerProcess server;
  client::RemoteOptions o;
  o.target = server.target();
  auto client = server.started() ? client::RemoteClient::Connect(o)
                                 : absl::StatusOr<std::unique_ptr<client::RemoteClient>>(
                                       absl::UnavailableError("surfinspectd did not start"));
  if (!scan.ok() || !index.ok() || !client.ok()) {
    rows.push_back({"Service overhead", "failed to set up", "", "", "", "", ""});
    return;
  }
  const PointCloud cloud = TransformCloud(scan->cloud_in_sensor, vp.world_from_sensor);
  v1::ErrorMapRequest req;
  wire::CloudToRequestProto(cloud, req.mutable_cloud());
  wire::TransformToProto(cell.world_from_part, req.mutable_world_from_part());
  req.set_return_deviations(true);

  // In-process is what `surfinspect errormap` does without --server, and
  // what the ErrorMap handler does once the request is decoded: the error
  // map, then the verdict of the default plan and the report.
  const ErrorMapSettings settings;
  const InspectionPlan plan = PlanFromSettings(settings);
  ErrorMapResult local;
  std::string local_report, local_verdict;
  v1::ErrorMapResponse remote;
  bool remote_ok = true;
  // A client builds its request once and moves it into the call, so each
  // call gets its own copy made here, untimed. The two sides alternate, so
  // a change in the machine's load hits both alike.
  constexpr int kReps = 7;
  std::vector<v1::ErrorMapRequest> requests(kReps + 1, req);  // + the warm-up
  std::size_t next = 0;
  const auto [t_local, t_remote] = MedianSecondsInterleaved(
      kReps, true,
      [&] {  // the handler's steps: error map, plan verdict, report text
        auto r = ComputeErrorMap(**index, cloud, cell.world_from_part, {});
        if (!r.ok()) return;
        auto outcome = EvaluatePlan(*r, cloud, cell.part, plan, settings.threads);
        if (!outcome.ok()) return;
        local_report = ErrorMapReportText(*r, settings, *outcome);
        local_verdict = outcome->pass() ? "pass" : "fail";
        local = std::move(*r);
      },
      [&] {  // the warm-up caches the mesh
        if (next == requests.size()) {
          remote_ok = false;
          return;
        }
        auto r = (*client)->ErrorMap(std::move(requests[next++]), cell.part);
        remote_ok = remote_ok && r.ok();
        if (r.ok()) remote = std::move(*r);
      });
  // Agreement: the deviations sent back equal the in-process ones.
  std::size_t differ = 0;
  const std::string& bytes = remote.deviations();
  const bool sized = bytes.size() == 4 * local.deviation_mm.size();
  for (std::size_t i = 0; sized && i < local.deviation_mm.size(); ++i) {
    float d;
    std::memcpy(&d, bytes.data() + 4 * i, 4);
    const float l = local.deviation_mm[i];
    if (!(d == l || (std::isnan(d) && std::isnan(l)))) ++differ;
  }
  const double ratio = t_remote / t_local;
  rows.push_back({"Service: ErrorMap of a 1024x768 scan, gRPC loopback vs in-process",
                  Time(t_local), remote_ok ? Time(t_remote) + " (via surfinspectd)" : "failed",
                  Fmt("%.2fx", ratio),
                  !sized        ? "deviations missing"
                  : differ != 0 ? std::to_string(differ) + " deviations differ"
                  : local_verdict != remote.verdict()
                      ? "verdicts differ"
                      : "identical deviations (" + std::to_string(local.deviation_mm.size()) +
                            " points), same verdict",
                  "≤ 1.3x in-process", Verdict(remote_ok && ratio <= 1.3)});

  // Streaming one view.
  auto stub = v1::InspectionService::NewStub(
      grpc::CreateChannel(server.target(), grpc::InsecureChannelCredentials()));
  const std::string raw(reinterpret_cast<const char*>(cloud.points.data()), cloud.size() * 12);
  v1::InspectRequest part, view;
  part.mutable_part()->set_part_id("bench");
  part.mutable_part()->mutable_part()->set_sha256(MeshSha256(cell.part));
  wire::TransformToProto(cell.world_from_part, part.mutable_part()->mutable_world_from_part());
  view.mutable_view()->set_name("v");
  view.mutable_view()->set_width(cloud.width);
  view.mutable_view()->set_height(cloud.height);
  wire::TransformToProto(Eigen::Isometry3d::Identity(),
                         view.mutable_view()->mutable_world_from_sensor());
  double t_stream = NAN;
  std::vector<double> times;
  service_detail::StreamOnce(*stub, part, view, raw);  // warm-up
  bool all_received = true;
  for (int i = 0; i < 15; ++i) {
    const double t = service_detail::StreamOnce(*stub, part, view, raw);
    all_received = all_received && !std::isnan(t);
    if (!std::isnan(t)) times.push_back(t);
  }
  std::sort(times.begin(), times.end());
  if (all_received) t_stream = times[times.size() / 2];
  const double mb = raw.size() / 1e6;
  rows.push_back(
      {Fmt("Service: stream one %.1f MB view in 1 MB chunks until received", mb),
       std::isnan(t_stream) ? "failed" : Time(t_stream) + Fmt(" (%.0f MB/s)", mb / t_stream),
       "none", "—", "server reported STAGE_VIEW_RECEIVED", "≤ 15 ms",
       Verdict(!std::isnan(t_stream) && t_stream <= 15e-3)});
}

}  // namespace surfinspect::bench
