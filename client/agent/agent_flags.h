// The cell-agent's command line: its three subcommands (calibrate, run,
// verify) and their flags, filling one AgentArgs. A library, so that tests
// can read the help the agent prints (the results folder's files come from
// the part-file catalogue, client/cell/part_files.h).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "client/agent/agent.h"
#include "client/agent/mqtt_publisher.h"
#include "client/agent/retry.h"

namespace surfinspect::client {

struct AgentArgs {
  std::string cell, gauge_scans;
  AgentPaths paths;
  std::string server, tls_ca, tls_cert, tls_key, token_file;
  int simulate = 0;
  std::string drift;            // --drift SPEC for the simulated parts
  double hole_shift_mm = 0;     // --hole-shift: every third simulated part's first hole moved
  double fixture_error_mm = 0;  // --fixture-error: each simulated part off in its fixture
  std::string db;               // results store; default RESULTS/results.db, "none" = off
  uint64_t seed = 1;
  bool once = false;
  double poll_s = 1.0, timeout_s = 300;
  BackoffSettings backoff;              // max_attempts 0 = keep retrying retryable errors
  std::string robot_drift, status_dir;  // simulated robot's drift "VIEW:MM"; verify's state
  int verify_every = -1;                // parts between drift checks; -1 = cell.json's
  MqttSettings mqtt;                    // flags; each set one overrides cell.json's "mqtt" block
};

struct AgentCommands {
  CLI::App* calibrate = nullptr;
  CLI::App* run = nullptr;
  CLI::App* verify = nullptr;
  CLI::App* prune = nullptr;
};

// The four subcommands and their flags, filling `args`.
AgentCommands AddAgentCommands(CLI::App& app, AgentArgs& args);

}  // namespace surfinspect::client
