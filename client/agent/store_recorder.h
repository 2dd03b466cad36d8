// The cell-agent's results-store listener: records each part whose results
// are on disk (AgentHooks::on_stored) from its files, and catches up on
// parts the store missed. The store may be down or unreachable: a failure is
// reported, never fails the part (the files are the primary record), and the
// next part, or the next start, records everything the store lacks.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "absl/status/status.h"
#include "client/cell/part_recorder.h"
#include "core/history/results_store.h"

namespace surfinspect::client {

class StoreRecorder {
 public:
  // `db`: SQLite path or postgresql:// URL; `results_root`: RESULTS/.
  // `on_error` sees each failure's message (the URL without its password).
  StoreRecorder(std::string db, RecordContext context, std::string results_root,
                std::function<void(const std::string&)> on_error);

  // Opens the store if needed and records every part in RESULTS/ it lacks.
  absl::Status CatchUp();
  // The on_stored listener.
  void OnStored(const std::string& part_id, const std::string& dir);

  int recorded() const { return recorded_; }  // parts written by this process
  bool behind() const { return behind_; }     // a part may be missing from the store

 private:
  absl::Status Open();

  std::string db_;
  RecordContext context_;
  std::string results_root_;
  std::function<void(const std::string&)> on_error_;
  std::unique_ptr<ResultsStore> store_;
  bool behind_ = true;
  int recorded_ = 0;
};

}  // namespace surfinspect::client
