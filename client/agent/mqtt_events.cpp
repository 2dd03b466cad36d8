#include "client/agent/mqtt_events.h"

#include <chrono>
#include <ctime>
#include <filesystem>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/cell/part_files.h"
#include "core/pipeline/inspection_report.h"
#include "core/report/qif_results.h"
#include "core/types/status_macros.h"

namespace surfinspect::client {
namespace fs = std::filesystem;
using nlohmann::json;
namespace {

absl::Status Bad(const std::string& what) {
  return absl::InvalidArgumentError(absl::StrCat("mqtt: ", what));
}

absl::Status NeedFile(const char* option, const std::string& path) {
  if (path.empty()) return absl::OkStatus();
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return Bad(absl::StrCat(option, ": no such file ", path));
  return absl::OkStatus();
}

std::string ResolveBeside(const CellConfig& cell, const std::string& p) {
  if (p.empty() || fs::path(p).is_absolute()) return p;
  return (fs::path(cell.path).parent_path() / p).lexically_normal().string();
}

}  // namespace

absl::StatusOr<MqttBroker> ParseMqttUrl(const std::string& url) {
  const std::size_t sep = url.find("://");
  if (sep == std::string::npos)
    return Bad(
        absl::StrCat("\"", url, "\" is not a URL (use tcp://HOST:1883 or mqtts://HOST:8883)"));
  const std::string scheme = url.substr(0, sep);
  MqttBroker b;
  if (scheme == "tcp" || scheme == "mqtt") {
    b.tls = false;
  } else if (scheme == "mqtts" || scheme == "ssl") {
    b.tls = true;
    b.port = 8883;
  } else {
    return Bad(
        absl::StrCat("unknown scheme \"", scheme, "\" in ", url, " (use tcp:// or mqtts://)"));
  }
  std::string rest = url.substr(sep + 3);
  if (!rest.empty() && rest.back() == '/') rest.pop_back();
  const std::size_t colon = rest.rfind(':');
  b.host = rest.substr(0, colon);
  if (colon != std::string::npos) {
    int port = 0;
    if (!absl::SimpleAtoi(rest.substr(colon + 1), &port) || port < 1 || port > 65535)
      return Bad(absl::StrCat("bad port in ", url));
    b.port = port;
  }
  if (b.host.empty() || absl::StrContains(b.host, "/"))
    return Bad(absl::StrCat("no host in ", url));
  return b;
}

absl::StatusOr<MqttSettings> MqttSettingsFromCell(const CellConfig& cell) {
  MqttSettings s;
  if (!cell.raw.is_object() || !cell.raw.contains("mqtt")) return s;
  const json& m = cell.raw["mqtt"];
  const auto bad = [&](const std::string& key, const std::string& why) {
    return absl::InvalidArgumentError(absl::StrCat(cell.path, ": mqtt", key, ": ", why));
  };
  if (!m.is_object()) return bad("", "not an object");
  std::map<std::string, std::string*> strings = {
      {"url", &s.url},           {"topic_prefix", &s.topic_prefix},
      {"username", &s.username}, {"password_file", &s.password_file},
      {"tls_ca", &s.tls_ca},     {"tls_cert", &s.tls_cert},
      {"tls_key", &s.tls_key},   {"client_id", &s.client_id}};
  for (const auto& [key, value] : m.items()) {
    if (key == "keepalive_s") {
      if (!m[key].is_number_integer()) return bad(".keepalive_s", "not an integer");
      s.keepalive_s = m[key].get<int>();
      continue;
    }
    auto it = strings.find(key);
    if (it == strings.end()) return bad("." + key, "unknown key");
    if (!value.is_string()) return bad("." + key, "not a string");
    *it->second = value.get<std::string>();
  }
  for (std::string* path : {&s.password_file, &s.tls_ca, &s.tls_cert, &s.tls_key})
    *path = ResolveBeside(cell, *path);
  return s;
}

absl::Status ValidateMqttSettings(const MqttSettings& s) {
  ASSIGN_OR_RETURN(auto broker, ParseMqttUrl(s.url));
  const std::string& p = s.topic_prefix;
  if (p.find_first_of("#+") != std::string::npos)
    return Bad(absl::StrCat("topic prefix \"", p, "\" contains a wildcard ('#' or '+')"));
  if (p.empty() || p.front() == '/' || p.back() == '/' || absl::StrContains(p, "//"))
    return Bad(absl::StrCat("topic prefix \"", p, "\" has an empty level"));
  if (s.keepalive_s < 5 || s.keepalive_s > 3600)
    return Bad(absl::StrCat("keep-alive ", s.keepalive_s, " s outside [5, 3600]"));
  if (!broker.tls && !(s.tls_ca.empty() && s.tls_cert.empty() && s.tls_key.empty()))
    return Bad(absl::StrCat("TLS files given but ", s.url, " is not mqtts://"));
  if (s.tls_cert.empty() != s.tls_key.empty())
    return Bad("a client certificate needs its key, and a key its certificate");
  if (!s.password_file.empty() && s.username.empty())
    return Bad("a password file needs a username");
  for (const auto& [option, path] : {std::pair{"CA file", s.tls_ca},
                                     {"certificate", s.tls_cert},
                                     {"key", s.tls_key},
                                     {"password file", s.password_file}})
    RETURN_IF_ERROR(NeedFile(option, path));
  return absl::OkStatus();
}

std::string PartTopic(const MqttSettings& s, const std::string& cell, const std::string& part_id,
                      const std::string& event) {
  return absl::StrCat(s.topic_prefix, "/", cell, "/", part_id, "/", event);
}

std::string StatusTopic(const MqttSettings& s, const std::string& cell) {
  return absl::StrCat(s.topic_prefix, "/", cell, "/status");
}

std::string ClientIdOf(const MqttSettings& s, const std::string& cell) {
  return s.client_id.empty() ? absl::StrCat("surfinspect-agent-", cell) : s.client_id;
}

std::string StartedPayload(const std::string& cell, const std::string& part_id,
                           const std::string& time) {
  return json{{"schema", "surfinspect.event.started/1"},
              {"cell", cell},
              {"part_id", part_id},
              {"idempotency_key", QifUuid(absl::StrCat("started/", cell, "/", part_id))},
              {"time", time}}
      .dump();
}

absl::StatusOr<std::string> ResultPayload(const std::string& cell, const std::string& part_id,
                                          const std::string& results_dir,
                                          const std::string& report_json, const std::string& time) {
  const absl::StatusOr<InspectionReport> report = ParseReport(report_json);
  if (!report.ok() || report->verdict.empty())
    return absl::DataLossError(absl::StrCat(results_dir, "/report.json: not a report"));
  json failed = json::array();
  for (const ReportCharacteristic& c : report->characteristics)
    if (!c.passed()) failed.push_back({{"name", c.name}, {"type", c.type}, {"reason", c.reason}});
  json files = json::object();
  std::error_code ec;
  const fs::path dir = fs::absolute(results_dir, ec).lexically_normal();
  // The event's keys for the catalogue's files (client/cell/part_files.h).
  for (const auto& [key, file] : {std::pair{"report", PartFile::kReport},
                                  {"qif", PartFile::kQif},
                                  {"errormap_ply", PartFile::kPly},
                                  {"errormap_png", PartFile::kPng},
                                  {"deviations_csv", PartFile::kCsv}}) {
    const char* name = EntryOf(file).file_name;
    if (fs::exists(dir / name, ec)) files[key] = (dir / name).string();
  }
  return json{
      {"schema", "surfinspect.event.result/1"},
      {"cell", cell},
      {"part_id", part_id},
      {"idempotency_key", QifUuid(absl::StrCat("result/", cell, "/", part_id, "/", report_json))},
      {"time", time},
      {"verdict", report->verdict},
      {"characteristics", report->characteristics.size()},
      {"failed", failed},
      {"defects", report->defects.size()},
      {"min_mm", JsonNumber(report->stats.min_mm)},
      {"max_mm", JsonNumber(report->stats.max_mm)},
      {"files", files}}
      .dump();
}

std::string StatusPayload(const std::string& cell, const std::string& state,
                          const std::string& reason, const std::string& time) {
  return json{{"schema", "surfinspect.event.status/1"},
              {"cell", cell},
              {"state", state},
              {"reason", reason},
              {"time", time}}
      .dump();
}

std::string EventTimeNow() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
  return absl::StrFormat("%s.%03dZ", buf, static_cast<int>(ms));
}

}  // namespace surfinspect::client
