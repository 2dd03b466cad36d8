// What plant integration costs a part: writing result.qif for a plan of 50
// characteristics (goal < 50 ms), and the cell-agent's MQTT listeners (the
// started and result events, goal <= 5 ms per part on the agent's thread)
// against a real mosquitto started here on a loopback port, with the broker
// up and with it away (events queued). Also the time until the broker has
// acknowledged every result.
//
//   build/bin/plant_integration_bench [PARTS]     (default 200)
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "client/agent/mqtt_publisher.h"
#include "core/pipeline/inspection_report.h"
#include "core/report/qif_results.h"

extern char** environ;

namespace {

using namespace surfinspect;
using namespace surfinspect::client;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

double Ms(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// A report/2 with the surface, 20 regions, 29 points (50 characteristics),
// 12 defects and a 41-bin histogram: the size of a real plan's report.
std::string FiftyCharacteristicReport() {
  nlohmann::json r = {{"schema", "surfinspect.report/2"},
                      {"verdict", "fail"},
                      {"statistics", {{"min_mm", -0.41}, {"max_mm", 0.33}}}};
  auto c = [](const std::string& name, const char* type, int k) {
    nlohmann::json j = {{"name", name},
                        {"type", type},
                        {"verdict", k % 7 == 0 ? "fail" : "pass"},
                        {"reason", "pass: 0.000% of 811712 points outside [-0.15, 0.15] mm"},
                        {"tolerance_mm", {{"lower", -0.05 - 0.001 * k}, {"upper", 0.15}}},
                        {"points", 1000 + k},
                        {"min_mm", -0.01 * k},
                        {"max_mm", 0.02 + 0.001 * k},
                        {"mean_mm", 0.001},
                        {"stddev_mm", 0.01},
                        {"rms_mm", 0.01},
                        {"fraction_within", 0.999}};
    if (std::string(type) == "point") j["value_mm"] = 0.001 * k;
    return j;
  };
  r["characteristics"] = nlohmann::json::array({c("surface", "surface", 0)});
  for (int k = 0; k < 20; ++k)
    r["characteristics"].push_back(c("slice" + std::to_string(k), "region", k));
  for (int k = 0; k < 29; ++k)
    r["characteristics"].push_back(c("P" + std::to_string(k), "point", k));
  r["defects"] = nlohmann::json::array();
  for (int k = 0; k < 12; ++k)
    r["defects"].push_back({{"id", k + 1},
                            {"kind", "dent"},
                            {"centroid_mm", {1.0, 2.0, 3.0}},
                            {"area_mm2", 12.5},
                            {"peak_mm", -0.2},
                            {"points", 300},
                            {"region", ""}});
  r["histogram"] = {{"bins", std::vector<int>(41, 5000)},
                    {"edges_mm", std::vector<double>(42, 0.1)}};
  return r.dump(2);
}

void BenchQif(const std::string& report, const fs::path& dir) {
  QifContext ctx;
  ctx.part_id = "part-0001";
  ctx.cell = "bench";
  ctx.points_count = 2000000;
  ctx.time_created = QifTimeNow();
  double best = 1e30, best_write = 1e30;
  std::size_t bytes = 0;
  for (int k = 0; k < 20; ++k) {
    auto t0 = Clock::now();
    const absl::StatusOr<InspectionReport> typed = ParseReport(report);
    auto xml = QifResultsXml(*typed, ctx);
    best = std::min(best, Ms(t0));
    bytes = xml->size();
    t0 = Clock::now();
    (void)WriteQifResults((dir / "result.qif").string(), *typed, ctx);
    best_write = std::min(best_write, Ms(t0));
  }
  std::printf(
      "QIF, 50 characteristics: build %.3f ms, build + atomic write %.3f ms (%zu bytes)"
      "  [goal < 50 ms]\n",
      best, best_write, bytes);
}

pid_t StartBroker(const fs::path& dir, int port) {
  const fs::path conf = dir / "mosquitto.conf";
  std::ofstream(conf) << "listener " << port << " 127.0.0.1\nallow_anonymous true\n"
                      << "persistence false\nuser root\nlog_dest none\n";
  const std::string c = conf.string();
  char* argv[] = {const_cast<char*>("mosquitto"), const_cast<char*>("-c"),
                  const_cast<char*>(c.c_str()), nullptr};
  pid_t pid = 0;
  if (posix_spawnp(&pid, "mosquitto", nullptr, nullptr, argv, environ) != 0) return 0;
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  return pid;
}

// Per part: OnStarted + OnStored on the caller's thread, as the agent calls them.
void BenchMqtt(const std::string& report, const fs::path& dir, int parts, bool broker_up) {
  const fs::path results = dir / (broker_up ? "results-up" : "results-down");
  for (int k = 0; k < parts; ++k) {
    fs::create_directories(results / ("p" + std::to_string(k)));
    std::ofstream(results / ("p" + std::to_string(k)) / "report.json") << report;
  }
  const int port = 20000 + static_cast<int>(getpid() % 20000);
  const pid_t broker = broker_up ? StartBroker(dir, port) : 0;
  MqttSettings s;
  s.url = "tcp://127.0.0.1:" + std::to_string(port);
  s.client_id = broker_up ? "bench-up" : "bench-down";
  // An empty results folder at start: every part below is published by its listener.
  auto pub =
      MqttPublisher::Start(s, "bench", (dir / "none").string(), MqttLog{}, broker_up ? 2 : 0.2);
  if (!pub.ok()) {
    std::printf("mqtt: %s\n", std::string(pub.status().message()).c_str());
    return;
  }
  std::vector<double> per_part;
  const auto all0 = Clock::now();
  for (int k = 0; k < parts; ++k) {
    const std::string id = "p" + std::to_string(k);
    const auto t0 = Clock::now();
    (*pub)->OnStarted(id);
    (*pub)->OnStored(id, (results / id).string());
    per_part.push_back(Ms(t0));
  }
  const double queued_ms = Ms(all0);
  while (broker_up && (*pub)->Pending() > 0 && Ms(all0) < 30000)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  const double acked_ms = Ms(all0);
  std::sort(per_part.begin(), per_part.end());
  double sum = 0;
  for (double v : per_part) sum += v;
  std::printf(
      "MQTT, broker %s, %d parts: per part mean %.3f ms, p50 %.3f, p99 %.3f, max %.3f ms"
      "  [goal <= 5 ms]",
      broker_up ? "up  " : "away", parts, sum / parts, per_part[per_part.size() / 2],
      per_part[per_part.size() * 99 / 100], per_part.back());
  if (broker_up)
    std::printf("; all %d events acknowledged %.1f ms after the first (listeners %.1f ms)",
                2 * parts, acked_ms, queued_ms);
  std::printf("\n");
  (*pub)->Stop(broker_up ? 3.0 : 0.0);
  pub->reset();
  if (broker > 0) {
    kill(broker, SIGTERM);
    waitpid(broker, nullptr, 0);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const int parts = argc > 1 ? std::max(1, std::atoi(argv[1])) : 200;
  const fs::path dir = fs::temp_directory_path() / ("plant-bench-" + std::to_string(getpid()));
  fs::create_directories(dir);
  const std::string report = FiftyCharacteristicReport();
  std::printf("report.json: %zu bytes\n", report.size());
  BenchQif(report, dir);
  BenchMqtt(report, dir, parts, true);
  BenchMqtt(report, dir, parts, false);
  fs::remove_all(dir);
  return 0;
}
