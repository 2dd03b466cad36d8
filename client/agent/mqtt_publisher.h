// Sends the cell-agent's events (mqtt_events.h) to an MQTT broker with
// libmosquitto, on the library's own network thread, so a slow or absent
// broker never holds up an inspection.
//
// Delivery: QoS 1 on a persistent session (clean_session false, a stable
// client id). Messages wait in this object's queue while the broker is away
// and are sent, in order, when it is back. A result message is also durable
// across a crash of the agent: when the broker acknowledges it, the file
// RESULTS/<part>/.mqtt-delivered is written, and Start re-publishes every
// RESULTS/<part>/ that has a report.json and no such file. So a result is
// never lost and is sent only for a part whose report.json exists (the
// part's completion mark); it may arrive more than once.
//
// The retained status topic says "online" on every connection, "offline"
// through the Last Will when the agent dies (within ~1.5 keep-alives) or on
// Stop, "calibration_expired" when the agent stops on an unusable
// viewpoint calibration, and "disk_full" while it pauses for lack of space.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "client/agent/mqtt_events.h"

struct mosquitto;

namespace surfinspect::client {

struct MqttLog {
  std::function<void(const std::string&)> info, warn, error;
};

class MqttPublisher {
 public:
  // Validates the settings (an error is returned, nothing is started), then
  // connects in the background. Waits up to `first_connect_s` for the first
  // answer so that an unreachable broker or refused credentials are logged
  // as errors at start-up; either way the publisher runs and retries.
  // `results_dir` is scanned for results not yet delivered.
  static absl::StatusOr<std::unique_ptr<MqttPublisher>> Start(const MqttSettings& settings,
                                                              const std::string& cell,
                                                              const std::string& results_dir,
                                                              MqttLog log,
                                                              double first_connect_s = 2.0);
  ~MqttPublisher();  // Stop(), then frees the client
  MqttPublisher(const MqttPublisher&) = delete;
  MqttPublisher& operator=(const MqttPublisher&) = delete;

  // AgentHooks listeners. Never block on the network, never fail the part.
  void OnStarted(const std::string& part_id);
  void OnStored(const std::string& part_id, const std::string& part_results_dir);
  // Retained status "calibration_expired" with the reason; kept at Stop.
  void CalibrationExpired(const std::string& reason);
  // Retained status "disk_full" with the reason while the agent pauses for
  // lack of space (`reason` non-empty), "online" again when it resumes ("").
  // calibration_expired wins over it.
  void DiskFull(const std::string& reason);

  // Publishes the retained "offline" status (unless calibration_expired was
  // set), waits up to `flush_s` for queued messages to be acknowledged,
  // disconnects. Idempotent.
  void Stop(double flush_s = 3.0);

  // Messages not yet acknowledged by the broker.
  std::size_t Pending() const;

  struct State;  // shared with the libmosquitto callbacks

 private:
  MqttPublisher() = default;
  void Enqueue(std::string topic, std::string payload, bool retain, std::string delivered_mark);

  std::unique_ptr<State> state_;
};

// Whether RESULTS/<part>/'s result event was acknowledged by the broker.
bool MqttDelivered(const std::string& part_results_dir);

}  // namespace surfinspect::client
