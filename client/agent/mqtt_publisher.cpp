#include "client/agent/mqtt_publisher.h"

#include <mosquitto.h>

#include <chrono>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "core/io/atomic_file.h"
#include "core/types/status_macros.h"

namespace surfinspect::client {
namespace fs = std::filesystem;

constexpr char kDeliveredMark[] = ".mqtt-delivered";

struct MqttPublisher::State {
  MqttSettings settings;
  MqttBroker broker;
  std::string cell, results_dir, url;
  MqttLog log;
  mosquitto* mosq = nullptr;
  std::thread network;

  struct Message {
    std::string topic, payload;
    bool retain = false;
    std::string mark;  // file written when the broker acknowledges it ("" = none)
  };
  mutable std::mutex mu;
  std::condition_variable cv;
  bool connected = false, answered = false, stopping = false, stopped = false;
  int refused_logged = -1;  // the last CONNACK refusal logged (logged once per code)
  std::string expired_reason;
  bool calibration_expired = false;
  std::string disk_full_reason;          // "" = not full
  std::deque<Message> queue;             // not yet handed to libmosquitto
  std::map<int, std::string> inflight;   // message id -> mark
  std::set<std::string> results_queued;  // parts whose result this process queued

  void Say(const std::function<void(const std::string&)>& sink, const std::string& m) const {
    if (sink) sink(m);
  }

  // Hands the queue to libmosquitto while connected (mu held).
  void Flush() {
    while (connected && !queue.empty()) {
      const Message& m = queue.front();
      int mid = 0;
      const int rc =
          mosquitto_publish(mosq, &mid, m.topic.c_str(), static_cast<int>(m.payload.size()),
                            m.payload.data(), 1, m.retain);
      if (rc != MOSQ_ERR_SUCCESS) break;  // kept; sent after the next connect
      inflight[mid] = m.mark;
      queue.pop_front();
    }
  }

  std::string StatusNow(const std::string& state, const std::string& reason) const {
    return StatusPayload(cell, state, reason, EventTimeNow());
  }

  // The retained status while connected (mu held).
  std::string StatusHeld() const {
    if (calibration_expired) return StatusNow("calibration_expired", expired_reason);
    if (!disk_full_reason.empty()) return StatusNow("disk_full", disk_full_reason);
    return StatusNow("online", "");
  }
};

namespace {

void OnConnect(mosquitto*, void* obj, int rc) {
  auto* s = static_cast<MqttPublisher::State*>(obj);
  std::lock_guard<std::mutex> lock(s->mu);
  s->answered = true;
  if (rc != 0) {
    if (rc != s->refused_logged)
      s->Say(s->log.error,
             absl::StrCat("mqtt: broker ", s->url,
                          " refused the connection: ", mosquitto_connack_string(rc),
                          rc == 4 || rc == 5 ? " (check the username and password file)" : "",
                          "; results are still written, events wait and are retried"));
    s->refused_logged = rc;
    s->cv.notify_all();
    return;
  }
  s->refused_logged = -1;
  s->connected = true;
  s->Say(s->log.info,
         absl::StrCat("mqtt: connected to ", s->url, " as ", ClientIdOf(s->settings, s->cell), "; ",
                      s->queue.size(), " events queued"));
  // The retained status first, then what waited.
  s->queue.push_front({StatusTopic(s->settings, s->cell), s->StatusHeld(), true, ""});
  s->Flush();
  s->cv.notify_all();
}

void OnDisconnect(mosquitto*, void* obj, int rc) {
  auto* s = static_cast<MqttPublisher::State*>(obj);
  std::lock_guard<std::mutex> lock(s->mu);
  const bool was = s->connected;
  s->connected = false;
  if (rc != 0 && was && !s->stopping)
    s->Say(s->log.warn, absl::StrCat("mqtt: lost ", s->url, " (", mosquitto_strerror(rc),
                                     "); events wait until it is back"));
  s->cv.notify_all();
}

void OnPublish(mosquitto*, void* obj, int mid) {
  auto* s = static_cast<MqttPublisher::State*>(obj);
  std::string mark;
  {
    std::lock_guard<std::mutex> lock(s->mu);
    auto it = s->inflight.find(mid);
    if (it == s->inflight.end()) return;
    mark = std::move(it->second);
    s->inflight.erase(it);
  }
  // Outside the lock: the agent's listeners never wait for this file. It
  // needs no fsync: a mark lost to a power cut only means one more copy.
  if (!mark.empty() && !std::ofstream(mark).good())
    s->Say(s->log.warn, absl::StrCat("mqtt: cannot write ", mark));
  std::lock_guard<std::mutex> lock(s->mu);
  s->cv.notify_all();
}

// libmosquitto's loop, restarted after the errors its own loop gives up on
// (TLS, name resolution), so the publisher keeps retrying until Stop.
void NetworkLoop(MqttPublisher::State* s) {
  while (true) {
    const int rc = mosquitto_loop_forever(s->mosq, 1000, 1);
    {
      std::unique_lock<std::mutex> lock(s->mu);
      if (s->stopping) return;
      s->answered = s->answered || rc == MOSQ_ERR_TLS;
      if (rc == MOSQ_ERR_TLS || rc == MOSQ_ERR_EAI)
        s->Say(s->log.error,
               absl::StrCat("mqtt: ", s->url, ": ", mosquitto_strerror(rc), "; retrying"));
      s->cv.notify_all();
      s->cv.wait_for(lock, std::chrono::seconds(2), [&] { return s->stopping; });
      if (s->stopping) return;
    }
    mosquitto_reconnect_async(s->mosq);
  }
}

absl::Status Configure(MqttPublisher::State& s) {
  const MqttSettings& o = s.settings;
  mosquitto_int_option(s.mosq, MOSQ_OPT_PROTOCOL_VERSION, MQTT_PROTOCOL_V311);
  if (!o.username.empty()) {
    std::string password;
    if (!o.password_file.empty()) {
      ASSIGN_OR_RETURN(auto text, ReadFileToString(o.password_file, 4096));
      password = std::string(absl::StripAsciiWhitespace(text.substr(0, text.find('\n'))));
    }
    mosquitto_username_pw_set(s.mosq, o.username.c_str(),
                              o.password_file.empty() ? nullptr : password.c_str());
  }
  if (s.broker.tls) {
    if (o.tls_ca.empty()) mosquitto_int_option(s.mosq, MOSQ_OPT_TLS_USE_OS_CERTS, 1);
    const int rc = mosquitto_tls_set(s.mosq, o.tls_ca.empty() ? nullptr : o.tls_ca.c_str(),
                                     o.tls_ca.empty() ? "/etc/ssl/certs" : nullptr,
                                     o.tls_cert.empty() ? nullptr : o.tls_cert.c_str(),
                                     o.tls_key.empty() ? nullptr : o.tls_key.c_str(), nullptr);
    if (rc != MOSQ_ERR_SUCCESS)
      return absl::InvalidArgumentError(absl::StrCat("mqtt: TLS files: ", mosquitto_strerror(rc)));
  }
  const std::string offline =
      StatusPayload(s.cell, "offline", "no keep-alive from the agent", EventTimeNow());
  mosquitto_will_set(s.mosq, StatusTopic(o, s.cell).c_str(), static_cast<int>(offline.size()),
                     offline.data(), 1, true);
  mosquitto_reconnect_delay_set(s.mosq, 1, 5, true);  // s; also bounds Stop's wait
  mosquitto_threaded_set(s.mosq, true);
  mosquitto_connect_callback_set(s.mosq, OnConnect);
  mosquitto_disconnect_callback_set(s.mosq, OnDisconnect);
  mosquitto_publish_callback_set(s.mosq, OnPublish);
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<std::unique_ptr<MqttPublisher>> MqttPublisher::Start(const MqttSettings& settings,
                                                                    const std::string& cell,
                                                                    const std::string& results_dir,
                                                                    MqttLog log,
                                                                    double first_connect_s) {
  RETURN_IF_ERROR(ValidateMqttSettings(settings));
  static std::once_flag init;
  std::call_once(init, [] { mosquitto_lib_init(); });
  std::unique_ptr<MqttPublisher> p(new MqttPublisher());
  p->state_ = std::make_unique<State>();
  State& s = *p->state_;
  s.settings = settings;
  s.broker = *ParseMqttUrl(settings.url);
  s.cell = cell;
  s.results_dir = results_dir;
  s.url = settings.url;
  s.log = std::move(log);
  s.mosq = mosquitto_new(ClientIdOf(settings, cell).c_str(), /*clean_session=*/false, &s);
  if (s.mosq == nullptr) return absl::ResourceExhaustedError("mqtt: cannot create a client");
  RETURN_IF_ERROR(Configure(s));
  const int rc =
      mosquitto_connect_async(s.mosq, s.broker.host.c_str(), s.broker.port, settings.keepalive_s);
  if (rc != MOSQ_ERR_SUCCESS)
    s.Say(s.log.error,
          absl::StrCat("mqtt: cannot reach the broker ", s.url, ": ", mosquitto_strerror(rc),
                       "; inspection goes on, events are sent when it is reachable"));
  s.network = std::thread(NetworkLoop, &s);
  // Results on disk whose event was never acknowledged (a crash, MQTT off).
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(results_dir, ec))
    if (fs::exists(e.path() / "report.json") && !fs::exists(e.path() / kDeliveredMark))
      p->OnStored(e.path().filename().string(), e.path().string());
  std::unique_lock<std::mutex> lock(s.mu);
  if (!s.cv.wait_for(lock, std::chrono::duration<double>(first_connect_s),
                     [&] { return s.answered; }) &&
      rc == MOSQ_ERR_SUCCESS)
    s.Say(s.log.error,
          absl::StrCat("mqtt: cannot reach the broker ", s.url, ": no answer within ",
                       first_connect_s,
                       " s; inspection goes on, events are sent when it is reachable"));
  return p;
}

MqttPublisher::~MqttPublisher() {
  if (!state_) return;
  Stop(0.5);
  if (state_->mosq) mosquitto_destroy(state_->mosq);
}

void MqttPublisher::Enqueue(std::string topic, std::string payload, bool retain, std::string mark) {
  std::lock_guard<std::mutex> lock(state_->mu);
  if (state_->stopped) return;
  state_->queue.push_back({std::move(topic), std::move(payload), retain, std::move(mark)});
  state_->Flush();
}

void MqttPublisher::OnStarted(const std::string& part_id) {
  Enqueue(PartTopic(state_->settings, state_->cell, part_id, "started"),
          StartedPayload(state_->cell, part_id, EventTimeNow()), false, "");
}

void MqttPublisher::OnStored(const std::string& part_id, const std::string& part_results_dir) {
  {
    std::lock_guard<std::mutex> lock(state_->mu);
    if (!state_->results_queued.insert(part_id).second) return;  // once per process
  }
  const fs::path dir(part_results_dir);
  auto report = ReadFileToString((dir / "report.json").string(), std::size_t{64} << 20);
  auto payload =
      report.ok() ? ResultPayload(state_->cell, part_id, part_results_dir, *report, EventTimeNow())
                  : absl::StatusOr<std::string>(report.status());
  if (!payload.ok()) {
    state_->Say(state_->log.error,
                absl::StrCat("mqtt: ", part_id, ": no result event: ", payload.status().message()));
    return;
  }
  Enqueue(PartTopic(state_->settings, state_->cell, part_id, "result"), *std::move(payload), false,
          (dir / kDeliveredMark).string());
}

void MqttPublisher::CalibrationExpired(const std::string& reason) {
  {
    std::lock_guard<std::mutex> lock(state_->mu);
    state_->calibration_expired = true;
    state_->expired_reason = reason;
  }
  Enqueue(StatusTopic(state_->settings, state_->cell),
          state_->StatusNow("calibration_expired", reason), true, "");
}

void MqttPublisher::DiskFull(const std::string& reason) {
  std::string status;
  {
    std::lock_guard<std::mutex> lock(state_->mu);
    state_->disk_full_reason = reason;
    status = state_->StatusHeld();
  }
  Enqueue(StatusTopic(state_->settings, state_->cell), std::move(status), true, "");
}

bool MqttDelivered(const std::string& part_results_dir) {
  return fs::exists(fs::path(part_results_dir) / kDeliveredMark);
}

void MqttPublisher::Stop(double flush_s) {
  State& s = *state_;
  {
    std::unique_lock<std::mutex> lock(s.mu);
    if (s.stopped) return;
    if (!s.calibration_expired)
      s.queue.push_back(
          {StatusTopic(s.settings, s.cell), s.StatusNow("offline", "agent stopped"), true, ""});
    s.Flush();
    s.stopped = true;
    s.cv.wait_for(lock, std::chrono::duration<double>(flush_s),
                  [&] { return s.queue.empty() && s.inflight.empty(); });
    if (!s.queue.empty() || !s.inflight.empty())
      s.Say(s.log.warn, absl::StrCat("mqtt: stopping with ", s.queue.size() + s.inflight.size(),
                                     " events unacknowledged (results are re-sent at the next "
                                     "start)"));
    s.stopping = true;
    s.cv.notify_all();
  }
  mosquitto_disconnect(s.mosq);
  if (s.network.joinable()) s.network.join();
}

std::size_t MqttPublisher::Pending() const {
  std::lock_guard<std::mutex> lock(state_->mu);
  return state_->queue.size() + state_->inflight.size();
}

}  // namespace surfinspect::client
