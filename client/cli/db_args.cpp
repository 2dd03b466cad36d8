#include "client/cli/db_args.h"

#include <cstdlib>
#include <filesystem>

#include "client/cli/commands.h"

namespace surfinspect::cli {

void AddDbOption(CLI::App* cmd, std::string& db, const std::string& what) {
  cmd->add_option("--db", db,
                  what +
                      ": SQLite file or postgresql://user@host:port/db (password from "
                      "PGPASSWORD or PGPASSFILE, never here)")
      ->envname("SURFINSPECT_DB");
}

std::unique_ptr<ResultsStore> OpenStore(const std::string& db, bool must_exist) {
  const char* env = std::getenv("SURFINSPECT_DB");
  const bool from_env = env != nullptr && db == env;
  if (!from_env && RedactDatabaseUrl(db) != db)
    throw CommandFailed(RedactDatabaseUrl(db) +
                        ": a password on the command line is refused (others can read it); "
                        "use PGPASSWORD, PGPASSFILE or passfile=FILE, or SURFINSPECT_DB");
  if (must_exist && !IsPostgresUrl(db) && !std::filesystem::exists(db))
    throw CommandFailed(db + ": no such results database");
  return Take(OpenResultsStore(db));
}

}  // namespace surfinspect::cli
