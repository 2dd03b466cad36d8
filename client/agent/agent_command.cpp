#include "client/agent/agent_command.h"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "client/agent/housekeeping.h"
#include "client/agent/retention.h"
#include "client/agent/simulated_robot.h"
#include "client/agent/store_recorder.h"
#include "client/cell/cell_config.h"
#include "client/cell/cell_part.h"
#include "client/remote/remote_client.h"
#include "core/io/atomic_file.h"
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"
#include "core/types/status_macros.h"
#include "proto/convert.h"

namespace surfinspect::client {
namespace {

void Tell(const std::function<void(const std::string&)>& to, const std::string& line) {
  if (to) to(line);
}

absl::StatusOr<std::unique_ptr<RemoteClient>> ConnectFor(const AgentArgs& a,
                                                         const CellConfig& cell) {
  RemoteOptions o;
  o.target = !a.server.empty() ? a.server : cell.server.target;
  o.tls_ca_file = !a.tls_ca.empty() ? a.tls_ca : cell.server.tls_ca;
  o.tls_cert_file = !a.tls_cert.empty() ? a.tls_cert : cell.server.tls_cert;
  o.tls_key_file = !a.tls_key.empty() ? a.tls_key : cell.server.tls_key;
  o.timeout_s = a.timeout_s;
  const std::string token_file = !a.token_file.empty() ? a.token_file : cell.server.token_file;
  if (!token_file.empty()) {
    ASSIGN_OR_RETURN(const std::string token, ReadFileToString(token_file, 4096));
    o.auth_token = std::string(absl::StripAsciiWhitespace(token));
  }
  if (o.target.empty())
    return absl::InvalidArgumentError(
        absl::StrCat("no server: give --server or set server.target in ", cell.path));
  return RemoteClient::Connect(o);
}

// Whether the server answered last time asked, told once per change.
struct ServerWatch {
  bool unreachable = false;

  // The server's answer to a health check that does not wait (OK or
  // Unavailable "cannot reach surfinspectd at ...": retried with backoff).
  absl::Status Ask(RemoteClient& client, const AgentOutput& out) {
    absl::Status st = client.WaitUntilReachable(0);
    if (!st.ok() && !unreachable)
      Tell(out.warn,
           absl::StrCat("waiting for the server (", st.message(), "); parts wait in the inbox"));
    if (st.ok() && unreachable)
      Tell(out.info, absl::StrCat("surfinspectd at ", client.target(), " answers; going on"));
    unreachable = !st.ok();
    return st;
  }
};

// Streams a part with the cell's inspection plan, telling its progress.
InspectFn InspectOver(RemoteClient& client, const TriangleMesh& part,
                      const std::optional<InspectionPlan>& plan, const AgentOutput& out,
                      ServerWatch& watch) {
  return [&client, &part, &plan, &out, &watch](
             const v1::PartHeader& part_header,
             const std::vector<ViewScan>& views) -> absl::StatusOr<v1::InspectResult> {
    RETURN_IF_ERROR(watch.Ask(client, out));
    v1::PartHeader header = part_header;
    if (plan) wire::PlanToProto(*plan, header.mutable_plan());
    return client.Inspect(header, part, views, [&](const v1::Progress& p) {
      if (out.progress) out.progress(header.part_id(), p);
    });
  };
}

// Gauge scans for a drift check: from --gauge-scans, else the simulated robot.
GaugeScanFn GaugeScans(const AgentArgs& a, const CellConfig& cell, const TriangleMesh& gauge,
                       const RobotDrift& drift) {
  auto round = std::make_shared<uint64_t>(0);
  return [&a, &cell, &gauge, drift, round](const CellViewpoint& vp) -> absl::StatusOr<PointCloud> {
    if (!a.gauge_scans.empty()) return ReadPointCloud(a.gauge_scans + "/" + vp.name + ".pcd");
    if (vp.name == cell.viewpoints.front().name) ++*round;
    return SimulateGaugeScan(cell, gauge, vp, drift, a.seed * 7919 + *round);
  };
}

// One drift check: told, and its state written to the status folder.
absl::StatusOr<CellVerification> VerifyAndReport(const AgentArgs& a, const CellConfig& cell,
                                                 const MeshIndex& gauge, const GaugeScanFn& scans,
                                                 const DriftLimits& limits,
                                                 const AgentOutput& out) {
  ASSIGN_OR_RETURN(auto v, VerifyCell(cell, gauge, scans, limits));
  if (out.verified) out.verified(v);
  RETURN_IF_ERROR(WriteVerificationStatus(StatusDir(a), cell, v));
  return v;
}

absl::StatusOr<RobotDrift> RobotDriftOf(const AgentArgs& a) {
  if (a.robot_drift.empty()) return RobotDrift{};
  return ParseRobotDrift(a.robot_drift);
}

// MQTT events when --mqtt or cell.json's "mqtt" names a broker (null
// otherwise); a bad setting stops the agent before it starts.
absl::StatusOr<std::unique_ptr<MqttPublisher>> StartMqtt(const AgentArgs& a, const CellConfig& cell,
                                                         const InboxLayout& layout,
                                                         const AgentOutput& out) {
  ASSIGN_OR_RETURN(MqttSettings s, MqttSettingsFromCell(cell));
  const MqttSettings& f = a.mqtt;
  const MqttSettings defaults;
  for (auto [flag, field] : {std::pair{&f.url, &s.url},
                             {&f.username, &s.username},
                             {&f.password_file, &s.password_file},
                             {&f.tls_ca, &s.tls_ca},
                             {&f.tls_cert, &s.tls_cert},
                             {&f.tls_key, &s.tls_key},
                             {&f.client_id, &s.client_id}})
    if (!flag->empty()) *field = *flag;
  if (f.topic_prefix != defaults.topic_prefix) s.topic_prefix = f.topic_prefix;
  if (f.keepalive_s != defaults.keepalive_s) s.keepalive_s = f.keepalive_s;
  if (s.url.empty()) return nullptr;
  return MqttPublisher::Start(s, cell.name, layout.results, MqttLog{out.info, out.warn, out.error});
}

// The results store's listener, caught up with RESULTS/ (null with --db none).
absl::StatusOr<std::unique_ptr<StoreRecorder>> MakeRecorder(const AgentArgs& a,
                                                            const CellConfig& cell,
                                                            const InboxLayout& layout,
                                                            const TriangleMesh& part,
                                                            const AgentOutput& out) {
  if (a.db == "none") return nullptr;
  const std::string db = a.db.empty() ? layout.results + "/results.db" : a.db;
  const char* env = std::getenv("SURFINSPECT_DB");
  if (RedactDatabaseUrl(db) != db && !(env != nullptr && db == env))
    return absl::InvalidArgumentError(
        absl::StrCat(RedactDatabaseUrl(db),
                     ": a password on the command line is refused; use PGPASSWORD, PGPASSFILE or "
                     "SURFINSPECT_DB"));
  ASSIGN_OR_RETURN(std::shared_ptr<const MeshIndex> index, MeshIndex::Build(part));
  auto recorder =
      std::make_unique<StoreRecorder>(db, RecordContextOf(cell, std::move(index)), layout.results,
                                      [&out](const std::string& m) { Tell(out.error, m); });
  if (absl::Status st = recorder->CatchUp(); !st.ok())
    Tell(out.error, absl::StrCat("results store: ", st.message(),
                                 " (parts are recorded once it can be reached)"));
  else
    Tell(out.info, absl::StrCat("results store ", RedactDatabaseUrl(db), ": ", recorder->recorded(),
                                " earlier parts recorded from their files"));
  return recorder;
}

// The drift monitor when cell.json or --verify-every asks for checks.
struct DriftChecks {
  TriangleMesh gauge;
  std::unique_ptr<MeshIndex> index;
  VerifyConfig config;
  std::unique_ptr<DriftMonitor> monitor;
};

absl::Status StartDriftChecks(const AgentArgs& a, const CellConfig& cell, const RobotDrift& drift,
                              const AgentOutput& out, DriftChecks& d) {
  ASSIGN_OR_RETURN(d.config, VerifyConfigOf(cell));
  if (a.verify_every >= 0) d.config.every_parts = a.verify_every;
  if (d.config.every_parts <= 0 && d.config.every_s <= 0) return absl::OkStatus();
  ASSIGN_OR_RETURN(d.gauge, ReadMesh(cell.gauge_mesh));
  ASSIGN_OR_RETURN(d.index, MeshIndex::Build(d.gauge));
  d.monitor = std::make_unique<DriftMonitor>(
      d.config, [&a, &cell, &d, &out, scans = GaugeScans(a, cell, d.gauge, drift)] {
        Tell(out.info, absl::StrCat("drift check of ", cell.viewpoints.size(), " viewpoints"));
        return VerifyAndReport(a, cell, *d.index, scans, d.config.limits, out);
      });
  return absl::OkStatus();
}

// The disk guard and the retention rule of a running agent.
}  // namespace

std::string StatusDir(const AgentArgs& a) {
  if (!a.status_dir.empty()) return a.status_dir;
  const std::string dir = std::filesystem::path(a.cell).parent_path().string();
  return dir.empty() ? "." : dir;
}

absl::StatusOr<CalibrateOutcome> RunCalibrateCommand(const AgentArgs& a, const AgentOutput& out,
                                                     std::atomic<bool>& stop) {
  ASSIGN_OR_RETURN(CellConfig cell, ReadCellConfig(a.cell));
  ASSIGN_OR_RETURN(const TriangleMesh gauge, ReadMesh(cell.gauge_mesh));
  ASSIGN_OR_RETURN(const std::unique_ptr<RemoteClient> client, ConnectFor(a, cell));
  ASSIGN_OR_RETURN(const std::string kept, KeepPreviousCalibration(cell));
  if (!kept.empty()) Tell(out.info, absl::StrCat("previous calibration kept as ", kept));
  CalibrateCellOptions options;
  options.gauge_scans = a.gauge_scans;
  options.backoff = a.backoff;
  options.seed = a.seed;
  options.on_retry = [&out](const std::string& view, const absl::Status& st, int, double) {
    Tell(out.warn, absl::StrCat(view, ": ", st.message(), " (retrying)"));
  };
  options.on_view = out.calibrated;
  const auto views = CalibrateCell(
      cell, [&](const v1::CalibrateRequest& req) { return client->Calibrate(req, gauge); }, options,
      stop);
  RETURN_IF_ERROR(StoreCalibrations(cell, views));
  CalibrateOutcome outcome;
  outcome.viewpoints = views.size();
  outcome.calibrated = static_cast<std::size_t>(
      std::count_if(views.begin(), views.end(), [](const auto& v) { return v.status.ok(); }));
  return outcome;
}

absl::StatusOr<CellVerification> RunVerifyCommand(const AgentArgs& a, const AgentOutput& out) {
  ASSIGN_OR_RETURN(const CellConfig cell, ReadCellConfig(a.cell));
  ASSIGN_OR_RETURN(const VerifyConfig config, VerifyConfigOf(cell));
  ASSIGN_OR_RETURN(const TriangleMesh gauge, ReadMesh(cell.gauge_mesh));
  ASSIGN_OR_RETURN(const auto index, MeshIndex::Build(gauge));
  ASSIGN_OR_RETURN(const RobotDrift drift, RobotDriftOf(a));
  return VerifyAndReport(a, cell, *index, GaugeScans(a, cell, gauge, drift), config.limits, out);
}

namespace {

// --simulate: drops simulated parts into the inbox first.
absl::Status SimulateIfAsked(const AgentArgs& a, const CellConfig& cell, const InboxLayout& layout,
                             const RobotDrift& drift, const AgentOutput& out) {
  if (a.simulate <= 0) return absl::OkStatus();
  SurfaceDrift surface;
  if (!a.drift.empty()) {
    ASSIGN_OR_RETURN(surface, ParseSurfaceDrift(a.drift));
  }
  ASSIGN_OR_RETURN(const auto ids, SimulateParts(cell, layout.inbox, a.simulate, a.seed, surface,
                                                 drift, a.hole_shift_mm, a.fixture_error_mm));
  Tell(out.info,
       absl::StrCat("simulated robot: ", ids.size(), " parts dropped into ", layout.inbox));
  return absl::OkStatus();
}

// The listeners of plant events and of the results store.
void Listen(MqttPublisher* mqtt, StoreRecorder* recorder, AgentHooks& hooks) {
  if (mqtt) {
    hooks.on_started.push_back([mqtt](const std::string& id) { mqtt->OnStarted(id); });
    hooks.on_stored.push_back(
        [mqtt](const std::string& id, const std::string& dir) { mqtt->OnStored(id, dir); });
    hooks.on_disk.push_back([mqtt](const std::string& reason) { mqtt->DiskFull(reason); });
  }
  if (recorder)
    hooks.on_stored.push_back(
        [recorder](const std::string& id, const std::string& dir) { recorder->OnStored(id, dir); });
}

// A results folder may be pruned once the store and the broker have it.
SettledFn SettledBy(const InboxLayout& layout, const StoreRecorder* recorder, bool mqtt) {
  return [&layout, recorder, mqtt](const std::string& id) {
    if (recorder && recorder->behind()) return false;
    return !mqtt || MqttDelivered((std::filesystem::path(layout.results) / id).string());
  };
}

}  // namespace

absl::StatusOr<RunOutcome> RunCellCommand(const AgentArgs& a, const AgentOutput& out,
                                          std::atomic<bool>& stop) {
  ASSIGN_OR_RETURN(CellConfig cell, ReadCellConfig(a.cell));
  // A part CAD that cannot be imported (a STEP file that crashes, hangs or
  // exhausts the worker) stops no agent: each part is quarantined with why.
  std::string cad_log;
  const absl::Status part_ok = LoadCellPart(&cell, &cad_log);
  Tell(part_ok.ok() ? out.info : out.error,
       part_ok.ok() ? cad_log : std::string(part_ok.message()));
  RunOutcome outcome;
  const InboxLayout& layout = outcome.layout = ResolveLayout(a.paths);
  RETURN_IF_ERROR(PrepareDirectories(layout));
  Tell(out.info, absl::StrCat("inbox ", layout.inbox, ", results ", layout.results, ", archive ",
                              layout.archive, ", quarantine ", layout.quarantine));
  Housekeeping housekeeping;
  RETURN_IF_ERROR(StartHousekeeping(a, cell, layout, StatusDir(a), out, housekeeping));
  ASSIGN_OR_RETURN(const RobotDrift drift, RobotDriftOf(a));
  RETURN_IF_ERROR(SimulateIfAsked(a, cell, layout, drift, out));
  ASSIGN_OR_RETURN(const TriangleMesh part, part_ok.ok()
                                                ? ReadCellPartMesh(cell)
                                                : absl::StatusOr<TriangleMesh>(TriangleMesh{}));
  ASSIGN_OR_RETURN(const std::optional<InspectionPlan> plan,
                   part_ok.ok() ? PlanOf(cell, part, cell.error_map)
                                : absl::StatusOr<std::optional<InspectionPlan>>(std::nullopt));
  ASSIGN_OR_RETURN(const std::unique_ptr<RemoteClient> client, ConnectFor(a, cell));
  ServerWatch watch;
  (void)watch.Ask(*client, out);  // says at start when the server is not there yet
  ASSIGN_OR_RETURN(const std::unique_ptr<MqttPublisher> mqtt, StartMqtt(a, cell, layout, out));
  AgentHooks hooks;
  hooks.inspect = InspectOver(*client, part, plan, out, watch);
  if (!part_ok.ok())
    hooks.inspect = [&part_ok](const v1::PartHeader&, const std::vector<ViewScan>&) {
      return absl::StatusOr<v1::InspectResult>(absl::FailedPreconditionError(
          absl::StrCat("the cell's part could not be imported: ", part_ok.message())));
    };
  hooks.on_retry = [&out, &watch](const std::string& id, const absl::Status& st, int calls,
                                  double) {
    if (!watch.unreachable)  // said once by the watch
      Tell(out.warn, absl::StrCat(id, ": ", st.message(), " (attempt ", calls, ", retrying)"));
  };
  WatchDisk(housekeeping, out, hooks);
  DriftChecks checks;
  RETURN_IF_ERROR(StartDriftChecks(a, cell, drift, out, checks));
  if (checks.monitor)
    hooks.before_part = [&checks](int done) { return checks.monitor->BeforePart(done); };
  ASSIGN_OR_RETURN(const std::unique_ptr<StoreRecorder> recorder,
                   part_ok.ok() ? MakeRecorder(a, cell, layout, part, out)
                                : absl::StatusOr<std::unique_ptr<StoreRecorder>>(nullptr));
  Listen(mqtt.get(), recorder.get(), hooks);
  const SettledFn settled = SettledBy(layout, recorder.get(), mqtt != nullptr);
  AgentSettings settings;
  settings.backoff = a.backoff;
  settings.poll_s = a.poll_s;
  settings.once = a.once;
  CellAgent agent(cell, layout, settings, std::move(hooks),
                  a.seed ^ static_cast<uint64_t>(::getpid()));
  outcome.summary = agent.Run(stop, [&](const PartReport& r) {
    if (out.part) out.part(r);
    if (mqtt && r.outcome == PartOutcome::kConfigError) mqtt->CalibrationExpired(r.message);
    if (r.outcome == PartOutcome::kDone) PruneAfterPart(housekeeping, layout, settled, out);
  });
  // A failed drift check makes the calibration unusable, as a missing one does.
  if (mqtt && !outcome.summary.halted.empty()) mqtt->CalibrationExpired(outcome.summary.halted);
  if (mqtt) mqtt->Stop();
  return outcome;
}

absl::StatusOr<PruneResult> RunPruneCommand(const AgentArgs& a, const AgentOutput& out) {
  ASSIGN_OR_RETURN(CellConfig cell, ReadCellConfig(a.cell));
  ASSIGN_OR_RETURN(const RetentionConfig rule, RetentionConfigOf(cell));
  if (!rule.any())
    return absl::FailedPreconditionError(
        absl::StrCat(cell.path, ": no \"retention\" rule, nothing to prune (docs/cell-agent.md)"));
  const InboxLayout layout = ResolveLayout(a.paths);
  RETURN_IF_ERROR(LoadCellPart(&cell, nullptr));
  ASSIGN_OR_RETURN(const TriangleMesh part, ReadCellPartMesh(cell));
  ASSIGN_OR_RETURN(const std::unique_ptr<StoreRecorder> recorder,
                   MakeRecorder(a, cell, layout, part, out));
  ASSIGN_OR_RETURN(const MqttSettings mqtt, MqttSettingsFromCell(cell));
  const bool mqtt_on = !a.mqtt.url.empty() || !mqtt.url.empty();
  return Prune(layout, rule, SettledBy(layout, recorder.get(), mqtt_on),
               std::chrono::system_clock::now());
}

}  // namespace surfinspect::client
