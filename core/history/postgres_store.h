// The results store in PostgreSQL (libpqxx 6.4): for a plant, where many
// cells and agents write one database. Each part is one transaction; the
// migrations run under an advisory lock, so agents that start together
// migrate once. The URL is libpq's (postgresql://user@host:port/db); the
// password comes from PGPASSWORD or a password file (PGPASSFILE, or
// passfile= in the URL), as libpq reads them.
#pragma once

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "core/history/results_store.h"

namespace surfinspect {

absl::StatusOr<std::unique_ptr<ResultsStore>> OpenPostgresStore(const std::string& url);

}  // namespace surfinspect
