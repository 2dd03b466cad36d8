// The --db option of errormap, inspect and trend: a results database, an
// SQLite path or a postgresql:// URL (core/history/results_store.h). Its
// password comes from PGPASSWORD or a password file (PGPASSFILE, passfile=),
// or the whole URL from SURFINSPECT_DB; a URL with a password on the command
// line is refused, and URLs are only ever printed without their password.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <string>

#include "core/history/results_store.h"

namespace surfinspect::cli {

void AddDbOption(CLI::App* cmd, std::string& db, const std::string& what);
// Opens (and migrates) the store, or throws CommandFailed naming it.
// `must_exist`: an SQLite path that is not there is an error, not created.
std::unique_ptr<ResultsStore> OpenStore(const std::string& db, bool must_exist);

}  // namespace surfinspect::cli
