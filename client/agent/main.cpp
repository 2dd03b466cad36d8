// cell-agent: runs at the robot cell. `calibrate` fits every viewpoint's
// gauge scan on the service and stores the results in cell.json; `run`
// watches the inbox, streams each complete part to Inspect, writes the
// results, and archives the scans (decisions in client/agent/agent.h).
// This file holds the flags, the signal wiring and the printing.
#include <signal.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>

#include "absl/strings/ascii.h"
#include "client/agent/agent.h"
#include "client/agent/calibrate_cell.h"
#include "client/agent/mqtt_publisher.h"
#include "client/agent/simulated_robot.h"
#include "client/agent/store_recorder.h"
#include "client/agent/verify_cell.h"
#include "client/cell/cell_config.h"
#include "client/remote/remote_client.h"
#include "core/io/atomic_file.h"
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"
#include "core/process/buffer_reuse.h"
#include "proto/convert.h"

namespace surfinspect::client {
namespace {

std::atomic<bool> g_stop{false};
void OnSignal(int) { g_stop.store(true); }

struct AgentArgs {
  std::string cell, gauge_scans;
  AgentPaths paths;
  std::string server, tls_ca, tls_cert, tls_key, token_file;
  int simulate = 0;
  std::string drift;  // --drift SPEC for the simulated parts
  std::string db;     // results store; default RESULTS/results.db, "none" = off
  uint64_t seed = 1;
  bool once = false;
  double poll_s = 1.0, timeout_s = 300;
  BackoffSettings backoff;              // max_attempts 0 = keep retrying retryable errors
  std::string robot_drift, status_dir;  // simulated robot's drift "VIEW:MM"; verify's state
  int verify_every = -1;                // parts between drift checks; -1 = cell.json's
  MqttSettings mqtt;                    // flags; each set one overrides cell.json's "mqtt" block
};

template <typename T>
T OrDie(absl::StatusOr<T> v) {
  if (!v.ok()) {
    spdlog::error("{}", std::string(v.status().message()));
    std::exit(2);
  }
  return *std::move(v);
}

std::unique_ptr<RemoteClient> ConnectFor(const AgentArgs& a, const CellConfig& cell) {
  RemoteOptions o;
  o.target = !a.server.empty() ? a.server : cell.server.target;
  o.tls_ca_file = !a.tls_ca.empty() ? a.tls_ca : cell.server.tls_ca;
  o.tls_cert_file = !a.tls_cert.empty() ? a.tls_cert : cell.server.tls_cert;
  o.tls_key_file = !a.tls_key.empty() ? a.tls_key : cell.server.tls_key;
  o.timeout_s = a.timeout_s;
  const std::string token_file = !a.token_file.empty() ? a.token_file : cell.server.token_file;
  if (!token_file.empty())
    o.auth_token =
        std::string(absl::StripAsciiWhitespace(OrDie(ReadFileToString(token_file, 4096))));
  if (o.target.empty()) {
    spdlog::error("no server: give --server or set server.target in {}", cell.path);
    std::exit(2);
  }
  return OrDie(RemoteClient::Connect(o));
}

void PrintCalibration(const ViewCalibration& v) {
  if (!v.status.ok()) {
    spdlog::error("{}: {}", v.name, std::string(v.status.message()));
    return;
  }
  const v1::CalibrationQuality& q = v.response.quality();
  std::printf("%-8s %10.4f %12.2f %12.5f %6u %10s\n", v.name.c_str(), q.rms_mm(),
              q.sigma_translation_um(), q.sigma_rotation_deg(), q.iterations(),
              q.degenerate() ? "YES" : "no");
  for (const auto& w : q.warnings()) spdlog::warn("{}: {}", v.name, w);
}

int Calibrate(const AgentArgs& a) {
  CellConfig cell = OrDie(ReadCellConfig(a.cell));
  const TriangleMesh gauge = OrDie(ReadMesh(cell.gauge_mesh));
  auto client = ConnectFor(a, cell);
  if (const std::string kept = OrDie(KeepPreviousCalibration(cell)); !kept.empty())
    spdlog::info("previous calibration kept as {}", kept);
  CalibrateCellOptions options;
  options.gauge_scans = a.gauge_scans;
  options.backoff = a.backoff;
  options.seed = a.seed;
  options.on_retry = [](const std::string& view, const absl::Status& st, int, double) {
    spdlog::warn("{}: {} (retrying)", view, std::string(st.message()));
  };
  options.on_view = PrintCalibration;
  std::printf("%-8s %10s %12s %12s %6s %10s\n", "view", "rms_mm", "sigma_t_um", "sigma_r_deg",
              "iters", "degenerate");
  const auto views = CalibrateCell(
      cell, [&](const v1::CalibrateRequest& req) { return client->Calibrate(req, gauge); }, options,
      g_stop);
  if (auto st = StoreCalibrations(cell, views); !st.ok()) {
    spdlog::error("{}", std::string(st.message()));
    return 2;
  }
  const auto calibrated =
      std::count_if(views.begin(), views.end(), [](const auto& v) { return v.status.ok(); });
  std::printf("calibrated %zu of %zu viewpoints -> %s (previous kept as %s.bak)\n",
              static_cast<std::size_t>(calibrated), cell.viewpoints.size(), a.cell.c_str(),
              a.cell.c_str());
  return static_cast<std::size_t>(calibrated) == views.size() ? 0 : 1;
}

void PrintPart(const PartReport& r) {
  switch (r.outcome) {
    case PartOutcome::kDone:
      std::printf("%-16s %-4s  max %+.3f mm  min %+.3f mm  %.1f s\n", r.part_id.c_str(),
                  r.verdict.c_str(), r.max_mm, r.min_mm, r.seconds);
      std::fflush(stdout);
      if (!r.message.empty()) spdlog::error("{}: results written; {}", r.part_id, r.message);
      break;
    case PartOutcome::kArchivedWithoutCall:
      spdlog::info("{}: {}", r.part_id, r.message);
      break;
    case PartOutcome::kQuarantined:
      spdlog::error("{}: {} -> quarantine", r.part_id, r.message);
      break;
    case PartOutcome::kRetryLater:
      spdlog::error("{}: {} (left in the inbox; retried later)", r.part_id, r.message);
      break;
    case PartOutcome::kStopped:
      spdlog::info("{}: {}", r.part_id, r.message);
      break;
    case PartOutcome::kConfigError:
      spdlog::error("{}: {}", r.part_id, r.message);
      break;
  }
}

// Streams a part with the cell's inspection plan, showing its progress on a
// terminal.
InspectFn InspectOver(RemoteClient& client, const TriangleMesh& part,
                      const std::optional<InspectionPlan>& plan) {
  return [&client, &part, &plan](const v1::PartHeader& part_header,
                                 const std::vector<ViewScan>& views) {
    v1::PartHeader header = part_header;
    if (plan) wire::PlanToProto(*plan, header.mutable_plan());
    const bool tty = isatty(STDERR_FILENO);
    auto result = client.Inspect(header, part, views, [&](const v1::Progress& p) {
      if (tty)
        std::fprintf(stderr, "\r  %s: %-24s %-6s      ", header.part_id().c_str(),
                     v1::Progress::Stage_Name(p.stage()).c_str(), p.view().c_str());
    });
    if (tty) std::fprintf(stderr, "\r%*s\r", 60, "");
    return result;
  };
}

std::string StatusDir(const AgentArgs& a) {
  if (!a.status_dir.empty()) return a.status_dir;
  const std::string dir = std::filesystem::path(a.cell).parent_path().string();
  return dir.empty() ? "." : dir;
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

// One drift check: printed, and its state written to the status folder.
absl::StatusOr<CellVerification> VerifyAndReport(const AgentArgs& a, const CellConfig& cell,
                                                 const MeshIndex& gauge, const GaugeScanFn& scans,
                                                 const DriftLimits& limits) {
  auto v = VerifyCell(cell, gauge, scans, limits);
  if (!v.ok()) return v.status();
  std::printf("%-8s %12s %12s %12s %10s %6s\n", "view", "part_um", "sensor_um", "rotation_deg",
              "sigma", "state");
  for (const auto& w : v->views) {
    if (!w.status.ok()) {
      std::printf("%-8s %s\n", w.name.c_str(), std::string(w.status.message()).c_str());
      continue;
    }
    std::printf("%-8s %12.2f %12.2f %12.5f %10.1f %6s\n", w.name.c_str(), w.drift.at_part_um,
                w.drift.at_sensor_um, w.drift.rotation_deg, w.drift.significance,
                DriftClassName(w.drift.verdict));
  }
  std::fflush(stdout);
  if (auto st = WriteVerificationStatus(StatusDir(a), cell, *v); !st.ok()) return st;
  return v;
}

int Verify(const AgentArgs& a) {
  const CellConfig cell = OrDie(ReadCellConfig(a.cell));
  const VerifyConfig config = OrDie(VerifyConfigOf(cell));
  const TriangleMesh gauge = OrDie(ReadMesh(cell.gauge_mesh));
  const auto index = OrDie(MeshIndex::Build(gauge));
  const RobotDrift drift =
      a.robot_drift.empty() ? RobotDrift{} : OrDie(ParseRobotDrift(a.robot_drift));
  const CellVerification v =
      OrDie(VerifyAndReport(a, cell, *index, GaugeScans(a, cell, gauge, drift), config.limits));
  std::printf("calibration %s: %s (state in %s/calibration_status.json)\n",
              DriftClassName(v.verdict), v.reason.c_str(), StatusDir(a).c_str());
  return v.verdict == DriftClass::kFail ? 3 : 0;
}

// MQTT events when --mqtt or cell.json's "mqtt" names a broker; a bad
// setting stops the agent before it starts.
std::unique_ptr<MqttPublisher> StartMqtt(const AgentArgs& a, const CellConfig& cell,
                                         const InboxLayout& layout) {
  MqttSettings s = OrDie(MqttSettingsFromCell(cell));
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
  MqttLog log{[](const std::string& m) { spdlog::info("{}", m); },
              [](const std::string& m) { spdlog::warn("{}", m); },
              [](const std::string& m) { spdlog::error("{}", m); }};
  return OrDie(MqttPublisher::Start(s, cell.name, layout.results, std::move(log)));
}

// The results store's listener, caught up with RESULTS/ (null with --db none).
std::unique_ptr<StoreRecorder> MakeRecorder(const AgentArgs& a, const CellConfig& cell,
                                            const InboxLayout& layout, const TriangleMesh& part) {
  if (a.db == "none") return nullptr;
  const std::string db = a.db.empty() ? layout.results + "/results.db" : a.db;
  const char* env = std::getenv("SURFINSPECT_DB");
  if (RedactDatabaseUrl(db) != db && !(env != nullptr && db == env)) {
    spdlog::error(
        "{}: a password on the command line is refused; use PGPASSWORD, PGPASSFILE or "
        "SURFINSPECT_DB",
        RedactDatabaseUrl(db));
    std::exit(2);
  }
  std::shared_ptr<const MeshIndex> index = OrDie(MeshIndex::Build(part));
  auto recorder = std::make_unique<StoreRecorder>(
      db, RecordContextOf(cell, std::move(index)), layout.results,
      [](const std::string& message) { spdlog::error("{}", message); });
  if (auto st = recorder->CatchUp(); !st.ok())
    spdlog::error("results store: {} (parts are recorded once it can be reached)",
                  std::string(st.message()));
  else
    spdlog::info("results store {}: {} earlier parts recorded from their files",
                 RedactDatabaseUrl(db), recorder->recorded());
  return recorder;
}

// The run's last lines, and the exit code: 0, or 2 (configuration), 3 (parts
// quarantined), 4 (stopped by a failed drift check).
int PrintSummary(const AgentArgs& a, const InboxLayout& layout, const RunSummary& s) {
  if (s.config_error) return 2;
  if (!s.halted.empty()) {
    spdlog::error(
        "stopped inspecting: {}; {} parts left in {} (state in {}/calibration_status.json)",
        s.halted, CompleteParts(layout.inbox).size(), layout.inbox, StatusDir(a));
    return 4;
  }
  std::printf("summary: %d parts done (%d pass, %d fail), ", s.done, s.pass, s.done - s.pass);
  if (s.archived_without_call > 0)
    std::printf("%d archived with earlier results, ", s.archived_without_call);
  std::printf("%d quarantined, %zu left in %s\n", s.quarantined, CompleteParts(layout.inbox).size(),
              layout.inbox.c_str());
  return s.quarantined == 0 ? 0 : 3;
}

int Run(const AgentArgs& a) {
  const CellConfig cell = OrDie(ReadCellConfig(a.cell));
  const InboxLayout layout = ResolveLayout(a.paths);
  if (auto st = PrepareDirectories(layout); !st.ok()) {
    spdlog::error("{}", std::string(st.message()));
    return 2;
  }
  spdlog::info("inbox {}, results {}, archive {}, quarantine {}", layout.inbox, layout.results,
               layout.archive, layout.quarantine);
  const RobotDrift drift =
      a.robot_drift.empty() ? RobotDrift{} : OrDie(ParseRobotDrift(a.robot_drift));
  if (a.simulate > 0) {
    const SurfaceDrift surface =
        a.drift.empty() ? SurfaceDrift{} : OrDie(ParseSurfaceDrift(a.drift));
    const auto ids = OrDie(SimulateParts(cell, layout.inbox, a.simulate, a.seed, surface, drift));
    spdlog::info("simulated robot: {} parts dropped into {}", ids.size(), layout.inbox);
  }
  const TriangleMesh part = OrDie(ReadMesh(cell.part_mesh));
  const std::optional<InspectionPlan> plan = OrDie(PlanOf(cell, part, cell.error_map));
  auto client = ConnectFor(a, cell);
  std::unique_ptr<MqttPublisher> mqtt = StartMqtt(a, cell, layout);
  AgentHooks hooks;
  hooks.inspect = InspectOver(*client, part, plan);
  if (mqtt) {
    hooks.on_started.push_back([&mqtt](const std::string& id) { mqtt->OnStarted(id); });
    hooks.on_stored.push_back(
        [&mqtt](const std::string& id, const std::string& dir) { mqtt->OnStored(id, dir); });
  }
  hooks.on_retry = [](const std::string& id, const absl::Status& st, int calls, double) {
    spdlog::warn("{}: {} (attempt {}, retrying)", id, std::string(st.message()), calls);
  };
  VerifyConfig verify = OrDie(VerifyConfigOf(cell));
  if (a.verify_every >= 0) verify.every_parts = a.verify_every;
  std::unique_ptr<MeshIndex> gauge_index;
  std::unique_ptr<DriftMonitor> monitor;
  TriangleMesh gauge;
  if (verify.every_parts > 0 || verify.every_s > 0) {
    gauge = OrDie(ReadMesh(cell.gauge_mesh));
    gauge_index = OrDie(MeshIndex::Build(gauge));
    monitor = std::make_unique<DriftMonitor>(
        verify, [&a, &cell, &gauge_index, &verify, scans = GaugeScans(a, cell, gauge, drift)] {
          spdlog::info("drift check of {} viewpoints", cell.viewpoints.size());
          return VerifyAndReport(a, cell, *gauge_index, scans, verify.limits);
        });
    hooks.before_part = [&monitor](int done) { return monitor->BeforePart(done); };
  }
  std::unique_ptr<StoreRecorder> recorder = MakeRecorder(a, cell, layout, part);
  if (recorder)
    hooks.on_stored.push_back([&recorder](const std::string& id, const std::string& dir) {
      recorder->OnStored(id, dir);
    });
  AgentSettings settings;
  settings.backoff = a.backoff;
  settings.poll_s = a.poll_s;
  settings.once = a.once;
  CellAgent agent(cell, layout, settings, std::move(hooks),
                  a.seed ^ static_cast<uint64_t>(::getpid()));
  const RunSummary s = agent.Run(g_stop, [&mqtt](const PartReport& r) {
    PrintPart(r);
    if (mqtt && r.outcome == PartOutcome::kConfigError) mqtt->CalibrationExpired(r.message);
  });
  // A failed drift check makes the calibration unusable, as a missing one does.
  if (mqtt && !s.halted.empty()) mqtt->CalibrationExpired(s.halted);
  if (mqtt) mqtt->Stop();
  return PrintSummary(a, layout, s);
}

void AddConnection(CLI::App* cmd, AgentArgs& a) {
  cmd->add_option("--cell", a.cell, "cell.json")->required();
  cmd->add_option("--server", a.server, "gRPC target; default: server.target in cell.json")
      ->envname("SURFINSPECT_SERVER");
  cmd->add_option("--tls-ca", a.tls_ca, "PEM CA of the server certificate (enables TLS)");
  cmd->add_option("--tls-cert", a.tls_cert, "client certificate (mTLS)");
  cmd->add_option("--tls-key", a.tls_key, "client key (mTLS)");
  cmd->add_option("--token-file", a.token_file, "bearer token file")
      ->envname("SURFINSPECT_TOKEN_FILE");
  cmd->add_option("--timeout", a.timeout_s, "per-call deadline, s")->check(CLI::PositiveNumber);
  cmd->add_option("--max-attempts", a.backoff.max_attempts,
                  "per part/view on retryable errors; 0 = unlimited");
  cmd->add_option("--backoff", a.backoff.initial_s, "first retry delay, s")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--backoff-max", a.backoff.max_s, "longest retry delay, s")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--seed", a.seed, "random seed (simulation, jitter)");
}

void AddRunOptions(CLI::App* run, AgentArgs& a) {
  AgentPaths& p = a.paths;
  run->add_option("--cell-dir", p.cell_dir,
                  "default parent of inbox/, results/, archive/ and quarantine/");
  run->add_option("--inbox", p.inbox,
                  "where the scanner drops <part-id>/<viewpoint>.pcd + DONE (default: inbox)");
  run->add_option("--results", p.results,
                  "results/<part-id>/{report.json,errormap.ply,errormap.png,deviations.csv} "
                  "(default: results)");
  run->add_option("--archive", p.archive, "processed scans (default: beside the inbox)");
  run->add_option("--quarantine", p.quarantine,
                  "parts that cannot succeed, with error.txt (default: beside the inbox)");
  run->add_option("--simulate", a.simulate, "first drop N simulated parts into the inbox")
      ->check(CLI::Range(0, 10000));
  run->add_option("--drift", a.drift,
                  "with --simulate: a process drift, bow:RATE_MM[:X,Y,R] (grows per part) or "
                  "shift:AMOUNT_MM@PART[:X,Y,R]; its truth goes into truth.json");
  run->add_option("--db", a.db,
                  "results store: SQLite file or postgresql://user@host/db (password from "
                  "PGPASSWORD/PGPASSFILE); default RESULTS/results.db; none = off")
      ->envname("SURFINSPECT_DB");
  run->add_flag("--once", a.once, "process what is there, then exit");
  run->add_option("--poll", a.poll_s, "inbox poll interval, s")->check(CLI::PositiveNumber);
  run->add_option("--verify-every", a.verify_every,
                  "drift check before every N-th part (default: verify.every_parts in cell.json)")
      ->check(CLI::NonNegativeNumber);
  MqttSettings& m = a.mqtt;
  run->add_option("--mqtt", m.url,
                  "publish events to this broker: tcp://HOST:1883 or mqtts://HOST:8883 "
                  "(default: mqtt.url in cell.json; docs/integration.md)");
  run->add_option("--mqtt-topic-prefix", m.topic_prefix, "topics PREFIX/<cell>/...")
      ->default_val(m.topic_prefix);
  run->add_option("--mqtt-username", m.username, "MQTT user name");
  run->add_option("--mqtt-password-file", m.password_file, "file whose first line is the password");
  run->add_option("--mqtt-ca", m.tls_ca, "PEM CA of the broker's certificate (mqtts://)");
  run->add_option("--mqtt-cert", m.tls_cert, "client certificate (mqtts://)");
  run->add_option("--mqtt-key", m.tls_key, "client key (mqtts://)");
  run->add_option("--mqtt-keepalive", m.keepalive_s,
                  "keep-alive, s; the broker publishes 'offline' ~1.5 x this after a crash")
      ->default_val(m.keepalive_s);
  run->add_option("--mqtt-client-id", m.client_id,
                  "persistent-session client id (default surfinspect-agent-<cell>)");
}

void AddVerifyOptions(CLI::App* cmd, AgentArgs& a) {
  cmd->add_option("--robot-drift", a.robot_drift,
                  "simulated robot: VIEW:MM, the sensor stands MM mm off its taught pose there");
  cmd->add_option("--status-dir", a.status_dir,
                  "where calibration_status.json/.prom go (default: beside cell.json)");
}

}  // namespace
}  // namespace surfinspect::client

int main(int argc, char** argv) {
  using namespace surfinspect::client;
  surfinspect::ReuseFreedLargeBuffers();  // clouds are ~10 MB buffers, over and over
  spdlog::set_default_logger(spdlog::stderr_color_mt("cell-agent"));
  AgentArgs a;
  CLI::App app{"cell-agent: streams a robot cell's scans to surfinspectd and keeps the results"};
  app.require_subcommand(1);
  auto* cal = app.add_subcommand("calibrate",
                                 "Calibrate every viewpoint from its gauge scan; update cell.json");
  AddConnection(cal, a);
  cal->add_option("--gauge-scans", a.gauge_scans,
                  "folder of <viewpoint>.pcd (default: gauge_scan in cell.json)");
  auto* run = app.add_subcommand("run", "Process complete parts from the inbox");
  AddConnection(run, a);
  AddRunOptions(run, a);
  AddVerifyOptions(run, a);
  run->add_option("--gauge-scans", a.gauge_scans,
                  "drift checks read <viewpoint>.pcd here (default: the simulated robot scans)");
  auto* verify = app.add_subcommand(
      "verify",
      "Re-scan the gauge at every viewpoint; report and classify the drift since calibration");
  verify->add_option("--cell", a.cell, "cell.json (calibrated)")->required();
  verify->add_option("--gauge-scans", a.gauge_scans,
                     "folder of fresh <viewpoint>.pcd (default: the simulated robot scans)");
  verify->add_option("--seed", a.seed, "random seed (simulated robot)");
  AddVerifyOptions(verify, a);
  CLI11_PARSE(app, argc, argv);
  signal(SIGTERM, OnSignal);
  signal(SIGINT, OnSignal);
  if (cal->parsed()) return Calibrate(a);
  if (verify->parsed()) return Verify(a);
  return Run(a);
}
