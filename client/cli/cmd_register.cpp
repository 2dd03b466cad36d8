// surfinspect register: clouds into the world frame through their
// calibrated world_from_sensor (paper §II), merged into one PLY.
#include <spdlog/spdlog.h>

#include "client/cli/commands.h"
#include "client/cli/remote_args.h"
#include "core/io/io_point_cloud.h"
#include "core/io/io_transform.h"
#include "core/registration/registration.h"
#include "proto/convert.h"
#include "proto/packed_cloud.h"

namespace surfinspect::cli {
namespace {

struct RegisterArgs {
  std::vector<std::string> scans, poses;
  std::string out;
  bool filter = false;
  RemoteArgs remote;
};

void Register(const RegisterArgs& a) {
  if (a.scans.size() != a.poses.size())
    throw CommandFailed("give one --world-from-sensor per --scan, in the same order");
  v1::RegisterRequest req;
  req.set_filter(a.filter);
  for (std::size_t i = 0; i < a.scans.size(); ++i) {
    v1::ViewScan* v = req.add_views();
    v->set_name("view" + std::to_string(i + 1));
    wire::TransformToProto(Take(ReadTransformJson(a.poses[i])), v->mutable_world_from_sensor());
    wire::CloudToRequestProto(Take(ReadPointCloud(a.scans[i])), v->mutable_cloud());
  }
  PointCloud merged;
  if (a.remote.remote()) {
    const v1::RegisterResponse resp = Take(Connect(a.remote)->Register(req, nullptr));
    merged = Take(wire::CloudFromProto(resp.merged(), "merged", wire::Limits{}));
  } else {
    std::vector<ViewScan> views;
    const wire::Limits limits;
    for (const auto& v : req.views())
      views.push_back({v.name(), Take(wire::CloudFromProto(v.cloud(), v.name(), limits)),
                       Take(wire::TransformFromProto(v.world_from_sensor(), v.name()))});
    if (a.filter) Check(FilterViews(views, LinkClusteringSettings{}));
    merged = Take(RegisterToWorld(views)).cloud_in_world;
  }
  Check(WritePointCloud(a.out, merged));
  std::printf("merged %zu points from %zu scans into %s (world frame, mm)\n", merged.size(),
              a.scans.size(), a.out.c_str());
}

}  // namespace

void AddRegisterCommand(CLI::App& app) {
  auto a = std::make_shared<RegisterArgs>();
  auto* cmd = app.add_subcommand("register", "Transform scans into the world frame and merge them");
  cmd->add_option("--scan", a->scans, "scan (sensor frame); repeat per viewpoint")->required();
  cmd->add_option("--world-from-sensor", a->poses, "calibrated pose JSON; one per --scan")
      ->required();
  cmd->add_option("--out", a->out, "merged cloud (.ply or .pcd)")->required();
  cmd->add_flag("--filter", a->filter, "link-clustering filter each scan first");
  AddRemoteOptions(cmd, a->remote);
  cmd->callback([a] { Register(*a); });
}

void AddHealthCommand(CLI::App& app) {
  auto a = std::make_shared<RemoteArgs>();
  auto service = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("health", "Ask a server's grpc.health.v1; exit 1 unless SERVING");
  AddRemoteOptions(cmd, *a);
  cmd->add_option("--service", *service, "service name (default: the whole server)");
  cmd->callback([a, service] {
    if (!a->remote()) throw CommandFailed("health needs --server");
    auto status = Connect(*a)->Health(*service);
    if (!status.ok()) throw CommandFailed(std::string(status.status().message()));
    std::printf("%s\n", status->c_str());
    if (*status != "SERVING") throw CommandFailed("not serving");
  });
}

}  // namespace surfinspect::cli
