#include "client/agent/agent_flags.h"

#include "client/cell/part_files.h"

namespace surfinspect::client {
namespace {

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
                  "results/<part-id>/ with the files cell.json's \"outputs\" names (default: "
                  "results):\n" +
                      PartFilesHelp());
  run->add_option("--archive", p.archive, "processed scans (default: beside the inbox)");
  run->add_option("--quarantine", p.quarantine,
                  "parts that cannot succeed, with error.txt (default: beside the inbox)");
  run->add_option("--simulate", a.simulate, "first drop N simulated parts into the inbox")
      ->check(CLI::Range(0, 10000));
  run->add_option("--drift", a.drift,
                  "with --simulate: a process drift, bow:RATE_MM[:X,Y,R] (grows per part) or "
                  "shift:AMOUNT_MM@PART[:X,Y,R]; its truth goes into truth.json");
  run->add_option("--hole-shift", a.hole_shift_mm,
                  "with --simulate: every third part is made with the CAD's first hole moved MM "
                  "along x in its plane (truth.json \"holes\")")
      ->check(CLI::Range(0.0, 2.0));
  run->add_option("--fixture-error", a.fixture_error_mm,
                  "with --simulate: each part sits off in its fixture by up to MM and MM/2 "
                  "degrees (truth.json \"fixture\"; an rps or best_fit plan recovers it)")
      ->check(CLI::Range(0.0, 2.0));
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

// prune: the folders and the listeners whose records a prune waits for.
void AddPruneOptions(CLI::App* cmd, AgentArgs& a) {
  AgentPaths& p = a.paths;
  cmd->add_option("--cell", a.cell, "cell.json (its \"retention\" rule)")->required();
  cmd->add_option("--cell-dir", p.cell_dir, "default parent of inbox/, results/ and archive/");
  cmd->add_option("--inbox", p.inbox, "the inbox (default: inbox); archive/ defaults beside it");
  cmd->add_option("--results", p.results, "results/<part-id>/ (default: results)");
  cmd->add_option("--archive", p.archive, "processed scans (default: beside the inbox)");
  cmd->add_option("--db", a.db,
                  "results store whose records a prune waits for; default RESULTS/results.db; "
                  "none = off")
      ->envname("SURFINSPECT_DB");
  cmd->add_option("--mqtt", a.mqtt.url,
                  "the broker whose deliveries a prune waits for (default: mqtt.url in cell.json)");
}

}  // namespace

AgentCommands AddAgentCommands(CLI::App& app, AgentArgs& a) {
  AgentCommands c;
  app.require_subcommand(1);
  c.calibrate = app.add_subcommand(
      "calibrate", "Calibrate every viewpoint from its gauge scan; update cell.json");
  AddConnection(c.calibrate, a);
  c.calibrate->add_option("--gauge-scans", a.gauge_scans,
                          "folder of <viewpoint>.pcd (default: gauge_scan in cell.json)");
  c.run = app.add_subcommand("run", "Process complete parts from the inbox");
  AddConnection(c.run, a);
  AddRunOptions(c.run, a);
  AddVerifyOptions(c.run, a);
  c.run->add_option("--gauge-scans", a.gauge_scans,
                    "drift checks read <viewpoint>.pcd here (default: the simulated robot scans)");
  c.verify = app.add_subcommand(
      "verify",
      "Re-scan the gauge at every viewpoint; report and classify the drift since calibration");
  c.verify->add_option("--cell", a.cell, "cell.json (calibrated)")->required();
  c.verify->add_option("--gauge-scans", a.gauge_scans,
                       "folder of fresh <viewpoint>.pcd (default: the simulated robot scans)");
  c.verify->add_option("--seed", a.seed, "random seed (simulated robot)");
  AddVerifyOptions(c.verify, a);
  c.prune = app.add_subcommand(
      "prune", "Apply cell.json's \"retention\" rule now (the running agent applies it too)");
  AddPruneOptions(c.prune, a);
  return c;
}

}  // namespace surfinspect::client
