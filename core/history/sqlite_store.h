// The results store in an SQLite file (libsqlite3): the embedded default.
// WAL journal, so one writer and any number of readers (surfinspect trend)
// work at once; a busy database is waited for up to 10 s.
#pragma once

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "core/history/results_store.h"

namespace surfinspect {

// Opens (creating when missing) and migrates the database at `path`.
absl::StatusOr<std::unique_ptr<ResultsStore>> OpenSqliteStore(const std::string& path);

}  // namespace surfinspect
