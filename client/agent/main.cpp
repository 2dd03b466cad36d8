// cell-agent: runs at the robot cell. `calibrate` fits every viewpoint's
// gauge scan on the service and stores the results in cell.json; `run`
// watches the inbox, streams each complete part to Inspect, writes the
// results, and archives the scans. Nothing is lost (a part leaves the inbox
// only after its results are on disk; retryable failures are retried with
// backoff; a restart resumes the inbox) and nothing is doubled (a part with
// results is never sent again).
#include <signal.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <random>
#include <thread>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "client/agent/inbox.h"
#include "client/agent/simulated_robot.h"
#include "client/cell/cell_config.h"
#include "client/cell/part_outputs.h"
#include "client/remote/remote_client.h"
#include "core/io/atomic_file.h"
#include "core/io/io_mesh.h"
#include "core/io/io_point_cloud.h"
#include "core/process/buffer_reuse.h"
#include "core/process/quiet_consoles.h"
#include "proto/convert.h"

namespace surfinspect::client {
namespace {

std::atomic<bool> g_stop{false};
void OnSignal(int) { g_stop.store(true); }

struct AgentArgs {
  std::string cell, inbox = "inbox", results = "results", archive, quarantine, gauge_scans;
  std::string server, tls_ca, tls_cert, tls_key, token_file;
  int simulate = 0;
  uint64_t seed = 1;
  bool once = false;
  double poll_s = 1.0, backoff_initial_s = 0.5, backoff_max_s = 15.0, timeout_s = 300;
  int max_attempts = 0;  // 0 = keep retrying retryable errors
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

// Exponential backoff with full jitter (AWS architecture blog, 2015).
void Backoff(const AgentArgs& a, int attempt, std::mt19937_64& rng) {
  const double cap = std::min(a.backoff_max_s, a.backoff_initial_s * std::pow(2.0, attempt));
  const double wait = std::uniform_real_distribution<double>(0.5 * cap, cap)(rng);
  for (double t = 0; t < wait && !g_stop.load(); t += 0.05)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

int Calibrate(const AgentArgs& a) {
  CellConfig cell = OrDie(ReadCellConfig(a.cell));
  const TriangleMesh gauge = OrDie(ReadMesh(cell.gauge_mesh));
  auto client = ConnectFor(a, cell);
  std::vector<std::pair<std::string, nlohmann::json>> quality;
  std::mt19937_64 rng(a.seed);
  int failures = 0;
  std::printf("%-8s %10s %12s %12s %6s %10s\n", "view", "rms_mm", "sigma_t_um", "sigma_r_deg",
              "iters", "degenerate");
  for (auto& vp : cell.viewpoints) {
    const std::string scan_path =
        a.gauge_scans.empty() ? vp.gauge_scan : a.gauge_scans + "/" + vp.name + ".pcd";
    auto scan = ReadPointCloud(scan_path);
    if (!scan.ok()) {
      spdlog::error("{}: {}", vp.name, std::string(scan.status().message()));
      ++failures;
      continue;
    }
    v1::CalibrateRequest req;
    wire::TransformToProto(vp.world_from_gauge, req.mutable_world_from_gauge());
    wire::TransformToProto(vp.nominal_world_from_sensor, req.mutable_initial_world_from_sensor());
    wire::CloudToProto(*scan, req.mutable_scan());
    wire::IcpSettingsToProto(CalibrationSettings{}.icp, req.mutable_icp());
    absl::StatusOr<v1::CalibrateResponse> resp;
    for (int attempt = 0;; ++attempt) {
      resp = client->Calibrate(req, gauge);
      if (resp.ok() || !IsRetryable(resp.status()) || g_stop.load() ||
          (a.max_attempts > 0 && attempt + 1 >= a.max_attempts))
        break;
      spdlog::warn("{}: {} (retrying)", vp.name, std::string(resp.status().message()));
      Backoff(a, attempt, rng);
    }
    if (!resp.ok()) {
      spdlog::error("{}: {}", vp.name, std::string(resp.status().message()));
      ++failures;
      continue;
    }
    const v1::CalibrationQuality& q = resp->quality();
    std::printf("%-8s %10.4f %12.2f %12.5f %6u %10s\n", vp.name.c_str(), q.rms_mm(),
                q.sigma_translation_um(), q.sigma_rotation_deg(), q.iterations(),
                q.degenerate() ? "YES" : "no");
    for (const auto& w : q.warnings()) spdlog::warn("{}: {}", vp.name, w);
    vp.world_from_sensor =
        OrDie(wire::TransformFromProto(resp->world_from_sensor(), "world_from_sensor"));
    quality.emplace_back(vp.name, nlohmann::json{{"rms_mm", q.rms_mm()},
                                                 {"sigma_translation_um", q.sigma_translation_um()},
                                                 {"sigma_rotation_deg", q.sigma_rotation_deg()},
                                                 {"iterations", q.iterations()},
                                                 {"converged", q.converged()},
                                                 {"degenerate", q.degenerate()}});
  }
  if (auto st = WriteCellCalibrations(cell, quality); !st.ok()) {
    spdlog::error("{}", std::string(st.message()));
    return 2;
  }
  std::printf("calibrated %zu of %zu viewpoints -> %s (previous kept as %s.bak)\n", quality.size(),
              cell.viewpoints.size(), a.cell.c_str(), a.cell.c_str());
  return failures == 0 ? 0 : 1;
}

// One part: read, send with retries, write results, archive. Returns false
// when it should be tried again later (stop requested mid-way).
enum class PartOutcome { kDone, kQuarantined, kRetryLater };

PartOutcome ProcessPart(const AgentArgs& a, const CellConfig& cell, const TriangleMesh& part,
                        RemoteClient& client, const InboxLayout& layout, const std::string& id,
                        std::mt19937_64& rng, bool* passed) {
  *passed = false;
  const auto t0 = std::chrono::steady_clock::now();
  if (!IsValidPartId(id)) {
    Quarantine(layout, id, "invalid part id (use letters, digits, . _ -)").IgnoreError();
    return PartOutcome::kQuarantined;
  }
  if (HasResults(layout, id)) {  // done before a restart: never send twice
    spdlog::info("{}: results already on disk; archiving", id);
    if (auto st = MovePart(layout.inbox, layout.archive, id); !st.ok())
      spdlog::error("{}", std::string(st.message()));
    return PartOutcome::kDone;
  }
  std::vector<ViewScan> views;
  for (const auto& vp : cell.viewpoints) {
    const std::string path = layout.inbox + "/" + id + "/" + vp.name + ".pcd";
    if (!std::filesystem::exists(path)) continue;
    auto cloud = ReadPointCloud(path);
    if (!cloud.ok()) {
      const std::string why = std::string(cloud.status().message());
      spdlog::error("{}: {} -> quarantine", id, why);
      Quarantine(layout, id, why).IgnoreError();
      return PartOutcome::kQuarantined;
    }
    if (!vp.world_from_sensor) {
      spdlog::error("{}: viewpoint {} is not calibrated; run cell-agent calibrate", id, vp.name);
      std::exit(2);
    }
    views.push_back({vp.name, *std::move(cloud), *vp.world_from_sensor});
  }
  if (views.empty()) {
    Quarantine(layout, id, "no <viewpoint>.pcd scan of this cell's viewpoints").IgnoreError();
    return PartOutcome::kQuarantined;
  }
  const v1::PartHeader header =
      MakePartHeader(id, cell.world_from_part, InspectionSettingsOf(cell));
  const bool tty = isatty(STDERR_FILENO);
  absl::StatusOr<v1::InspectResult> result;
  for (int attempt = 0;; ++attempt) {
    result = client.Inspect(header, part, views, [&](const v1::Progress& p) {
      if (tty)
        std::fprintf(stderr, "\r  %s: %-24s %-6s      ", id.c_str(),
                     v1::Progress::Stage_Name(p.stage()).c_str(), p.view().c_str());
    });
    if (tty) std::fprintf(stderr, "\r%*s\r", 60, "");
    if (result.ok() || !IsRetryable(result.status())) break;
    if (g_stop.load()) return PartOutcome::kRetryLater;
    if (a.max_attempts > 0 && attempt + 1 >= a.max_attempts) return PartOutcome::kRetryLater;
    spdlog::warn("{}: {} (attempt {}, retrying)", id, std::string(result.status().message()),
                 attempt + 1);
    Backoff(a, attempt, rng);
  }
  if (!result.ok()) {
    const std::string why = absl::StrCat(absl::StatusCodeToString(result.status().code()), ": ",
                                         result.status().message());
    spdlog::error("{}: {} -> quarantine", id, why);
    Quarantine(layout, id, why).IgnoreError();
    return PartOutcome::kQuarantined;
  }
  auto outputs = OutputsFromRemote(*result);
  absl::Status written =
      outputs.ok() ? WritePartOutputs(layout.results + "/" + id, *outputs) : outputs.status();
  if (!written.ok()) {  // disk trouble: keep the part in the inbox for the next pass
    spdlog::error("{}: cannot write results: {}", id, std::string(written.message()));
    return PartOutcome::kRetryLater;
  }
  if (auto st = MovePart(layout.inbox, layout.archive, id); !st.ok())
    spdlog::error("{}", std::string(st.message()));
  *passed = outputs->verdict == "pass";
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%-16s %-4s  max %+.3f mm  min %+.3f mm  %.1f s\n", id.c_str(),
              outputs->verdict.c_str(), outputs->max_mm, outputs->min_mm, s);
  std::fflush(stdout);
  return PartOutcome::kDone;
}

int Run(const AgentArgs& a) {
  const CellConfig cell = OrDie(ReadCellConfig(a.cell));
  InboxLayout layout{a.inbox, a.results, a.archive.empty() ? "archive" : a.archive,
                     a.quarantine.empty() ? "quarantine" : a.quarantine};
  std::error_code ec;
  for (const auto& d : {layout.inbox, layout.results}) std::filesystem::create_directories(d, ec);
  if (a.simulate > 0) {
    const auto ids = OrDie(SimulateParts(cell, layout.inbox, a.simulate, a.seed));
    spdlog::info("simulated robot: {} parts dropped into {}", ids.size(), layout.inbox);
  }
  const TriangleMesh part = OrDie(ReadMesh(cell.part_mesh));
  auto client = ConnectFor(a, cell);
  std::mt19937_64 rng(a.seed ^ static_cast<uint64_t>(::getpid()));
  int done = 0, quarantined = 0, pass = 0;
  while (!g_stop.load()) {
    const auto parts = CompleteParts(layout.inbox);
    bool progressed = false;
    for (const auto& id : parts) {
      if (g_stop.load()) break;
      bool passed = false;
      const PartOutcome o = ProcessPart(a, cell, part, *client, layout, id, rng, &passed);
      if (o == PartOutcome::kDone) {
        ++done;
        pass += passed ? 1 : 0;
        progressed = true;
      } else if (o == PartOutcome::kQuarantined) {
        ++quarantined;
        progressed = true;
      }
    }
    if (a.once && !progressed) break;
    if (a.once && CompleteParts(layout.inbox).empty()) break;
    if (!progressed)
      for (double t = 0; t < a.poll_s && !g_stop.load(); t += 0.05)
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  std::printf("summary: %d parts done (%d pass, %d fail), %d quarantined, %zu left in %s\n", done,
              pass, done - pass, quarantined, CompleteParts(layout.inbox).size(),
              layout.inbox.c_str());
  return quarantined == 0 ? 0 : 3;
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
  cmd->add_option("--max-attempts", a.max_attempts,
                  "per part/view on retryable errors; 0 = unlimited");
  cmd->add_option("--backoff", a.backoff_initial_s, "first retry delay, s")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--backoff-max", a.backoff_max_s, "longest retry delay, s")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--seed", a.seed, "random seed (simulation, jitter)");
}

}  // namespace
}  // namespace surfinspect::client

int main(int argc, char** argv) {
  using namespace surfinspect::client;
  surfinspect::ReuseFreedLargeBuffers();  // clouds are ~10 MB buffers, over and over
  surfinspect::QuietDependencyConsoles();
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
  run->add_option("--inbox", a.inbox, "where the scanner drops <part-id>/<viewpoint>.pcd + DONE");
  run->add_option("--results", a.results,
                  "results/<part-id>/{report.json,errormap.ply,errormap.png,deviations.csv}");
  run->add_option("--archive", a.archive, "processed scans (default: archive)");
  run->add_option("--quarantine", a.quarantine,
                  "parts that cannot succeed, with error.txt (default: quarantine)");
  run->add_option("--simulate", a.simulate, "first drop N simulated parts into the inbox")
      ->check(CLI::Range(0, 10000));
  run->add_flag("--once", a.once, "process what is there, then exit");
  run->add_option("--poll", a.poll_s, "inbox poll interval, s")->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  signal(SIGTERM, OnSignal);
  signal(SIGINT, OnSignal);
  if (cal->parsed()) return Calibrate(a);
  return Run(a);
}
