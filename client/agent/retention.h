// How long a cell keeps its parts' files. At one demo part a minute the
// heavy files (the PLY, the CSV, the HTML with its embedded cloud) fill a
// terabyte in about a week, while the light ones (report.json, the PDF,
// the PNG, the QIF) are the quality record. So each kind has its own rule:
//
//   "retention": {
//     "heavy":   {"days": 30, "gb": 200, "parts": 5000},
//     "light":   {"days": 730},
//     "archive": {"days": 14, "gb": 100}
//   }
//
// heavy: the catalogue's heavy files of RESULTS/<part>/ (part_files.h);
// the folder and its light files stay. light: the whole RESULTS/<part>/.
// archive: ARCHIVE/<part>/, the raw scans. Each limit is optional (absent
// or 0: none): a part older than `days`, or beyond the newest `parts`, or
// beyond the newest `gb` GB (10^9 bytes) of its kind, is pruned, oldest
// first. The results database is never pruned by this. A results folder is
// pruned only once its part is settled: recorded in the database and
// delivered over MQTT, where the cell has them.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

#include "absl/status/statusor.h"
#include "client/agent/inbox.h"
#include "client/cell/cell_config.h"

namespace surfinspect::client {

struct RetentionLimit {
  double days = 0;  // 0 = no age limit
  double gb = 0;    // 0 = no size limit, GB of this kind's files
  int parts = 0;    // 0 = no count limit
  bool any() const { return days > 0 || gb > 0 || parts > 0; }
};

struct RetentionConfig {
  RetentionLimit heavy, light, archive;
  bool any() const { return heavy.any() || light.any() || archive.any(); }
};

// cell.json "retention"; InvalidArgument "<cell.json>: retention.<kind>: ..."
absl::StatusOr<RetentionConfig> RetentionConfigOf(const CellConfig& cell);

// Whether RESULTS/<part> may go: recorded and delivered.
using SettledFn = std::function<bool(const std::string& part_id)>;

struct PruneResult {
  int heavy = 0, light = 0, archive = 0;  // parts pruned of each kind
  int unsettled = 0;                      // parts due but kept: not yet recorded or delivered
  uint64_t bytes = 0;                     // freed
};

// Applies the rules to RESULTS/ and ARCHIVE/ as of `now`.
absl::StatusOr<PruneResult> Prune(const InboxLayout& layout, const RetentionConfig& config,
                                  const SettledFn& settled,
                                  std::chrono::system_clock::time_point now);

// "pruned 3 heavy sets, 1 archived part (412.0 MiB); 2 due but not yet recorded or delivered"
std::string PruneText(const PruneResult& r);

}  // namespace surfinspect::client
