#include "core/history/results_store.h"

#include <chrono>
#include <ctime>
#include <regex>

#include "absl/strings/match.h"
#include "absl/strings/str_format.h"
#include "core/history/postgres_store.h"
#include "core/history/sqlite_store.h"

namespace surfinspect {

bool IsPostgresUrl(const std::string& url_or_path) {
  return absl::StartsWith(url_or_path, "postgresql://") ||
         absl::StartsWith(url_or_path, "postgres://");
}

std::string RedactDatabaseUrl(const std::string& url_or_path) {
  if (!IsPostgresUrl(url_or_path)) return url_or_path;
  // user:password@ in the authority, and password=... among the parameters
  // (RFC 3986 section 3.2.1; libpq's URI form).
  static const std::regex kUserInfo(R"(^(postgres(ql)?://[^:/@?]*):[^@/?]*@)");
  static const std::regex kParam(R"(([?&]password=)[^&]*)");
  std::string out = std::regex_replace(url_or_path, kUserInfo, "$1:***@");
  return std::regex_replace(out, kParam, "$1***");
}

std::string UtcNow() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const auto us =
      std::chrono::duration_cast<std::chrono::microseconds>(now.time_since_epoch()).count() %
      1000000;
  std::tm tm{};
  gmtime_r(&t, &tm);
  return absl::StrFormat("%04d-%02d-%02dT%02d:%02d:%02d.%06dZ", tm.tm_year + 1900, tm.tm_mon + 1,
                         tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, static_cast<int>(us));
}

absl::StatusOr<std::unique_ptr<ResultsStore>> OpenResultsStore(const std::string& url_or_path) {
  if (url_or_path.empty()) return absl::InvalidArgumentError("no results database given");
  if (IsPostgresUrl(url_or_path)) return OpenPostgresStore(url_or_path);
  return OpenSqliteStore(url_or_path);
}

}  // namespace surfinspect
