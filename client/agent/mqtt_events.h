// The cell-agent's MQTT events, without the network: the broker URL, the
// settings and their one validator, the topics, and the JSON payloads
// (schemas in docs/integration.md). mqtt_publisher.h sends them.
//
// Topics (PREFIX defaults to "surfinspect/v1"):
//   PREFIX/<cell>/<part>/started   a part's scans were read; it is being inspected
//   PREFIX/<cell>/<part>/result    its results are on disk (verdict, failures, files)
//   PREFIX/<cell>/status           retained: online, offline (the Last Will, or a clean
//                                  stop), calibration_expired (a viewpoint cannot be used),
//                                  disk_full (parts wait in the inbox until space returns)
// Delivery is QoS 1: a message may arrive twice, so each carries the part id
// and an idempotency key that is the same for every copy of one event.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "client/cell/cell_config.h"

namespace surfinspect::client {

struct MqttBroker {
  bool tls = false;  // mqtts://
  std::string host;
  int port = 1883;  // default 1883, 8883 with TLS
};

// tcp://HOST[:PORT] or mqtts://HOST[:PORT] (mqtt:// and ssl:// are accepted
// as their synonyms). InvalidArgument naming the URL otherwise.
absl::StatusOr<MqttBroker> ParseMqttUrl(const std::string& url);

struct MqttSettings {
  std::string url;                              // empty: MQTT off
  std::string topic_prefix = "surfinspect/v1";  // no '#', '+', empty levels or edge '/'
  std::string username;
  std::string password_file;      // the password is the file's first line
  std::string tls_ca;             // PEM CA of the broker (mqtts://); empty: the system's CAs
  std::string tls_cert, tls_key;  // client certificate and key (both or neither)
  int keepalive_s = 30;           // 5..3600; the Last Will fires ~1.5 x this after a crash
  std::string client_id;  // empty: "surfinspect-agent-<cell>" (stable: a persistent session)
};

// cell.json's optional "mqtt" block {url, topic_prefix, username,
// password_file, tls_ca, tls_cert, tls_key, keepalive_s, client_id}, file
// paths relative to cell.json. Unset fields keep the defaults; an unknown
// key or a wrong type is InvalidArgument "<cell.json>: mqtt.<key>: ...".
absl::StatusOr<MqttSettings> MqttSettingsFromCell(const CellConfig& cell);

// The one validator: the URL, the prefix, the keep-alive, TLS options only
// with mqtts://, files that exist. Messages name the option.
absl::Status ValidateMqttSettings(const MqttSettings& s);

// PREFIX/<cell>/<part>/<event> and PREFIX/<cell>/status.
std::string PartTopic(const MqttSettings& s, const std::string& cell, const std::string& part_id,
                      const std::string& event);
std::string StatusTopic(const MqttSettings& s, const std::string& cell);
std::string ClientIdOf(const MqttSettings& s, const std::string& cell);

// Payloads. `time` is an ISO 8601 UTC time ("2026-12-01T10:00:00.123Z").
std::string StartedPayload(const std::string& cell, const std::string& part_id,
                           const std::string& time);
// From the part's report.json text and the results folder. The idempotency
// key is derived from the cell, the part and the report's bytes, so a
// re-publication of the same results (after a restart) carries the same key.
absl::StatusOr<std::string> ResultPayload(const std::string& cell, const std::string& part_id,
                                          const std::string& results_dir,
                                          const std::string& report_json, const std::string& time);
// state: "online", "offline", "calibration_expired" or "disk_full"; reason may be empty.
std::string StatusPayload(const std::string& cell, const std::string& state,
                          const std::string& reason, const std::string& time);

std::string EventTimeNow();

}  // namespace surfinspect::client
