// The results store's schema, the same for SQLite and PostgreSQL: a list of
// migrations, each taking the database from version k-1 to k, and the
// schema_version table that says where a database is. The statements are
// written once with two dialect words ({blob}, {double}) that each backend
// fills in. Also the packed form of a part's triangle summary.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/history/results_store.h"

namespace surfinspect {

// The application name in schema_version: a database that has tables but
// not this row belongs to someone else.
inline constexpr char kStoreApplication[] = "surfinspect.results";

struct SqlDialect {
  std::string blob;     // "BLOB" / "BYTEA"
  std::string double_;  // "REAL" / "DOUBLE PRECISION"
};

// The statements of migration `version` (1-based) in `dialect`.
std::vector<std::string> MigrationStatements(int version, const SqlDialect& dialect);
// The newest schema version this binary knows.
int LatestSchemaVersion();
// The refusal for a database at `found` when this binary knows `LatestSchemaVersion()`.
absl::Status CheckSchemaVersion(const std::string& database, int found);

// The characteristics table's number columns, and a record's fields (a
// CharacteristicRecord, const or not) in the same order: both backends
// write and read a characteristic through these and the two statements
// below, so a column is listed once.
inline constexpr std::array<const char*, 15> kCharacteristicNumberColumns = {
    "value_mm",
    "mean_mm",
    "min_mm",
    "max_mm",
    "stddev_mm",
    "lower_mm",
    "upper_mm",
    "size_mm",
    "size_deviation_mm",
    "true_position_mm",
    "position_tolerance_mm",
    "length_mm",
    "length_deviation_mm",
    "length_lower_mm",
    "length_upper_mm"};
template <typename R>
auto CharacteristicNumbers(R& c) {
  return std::array{&c.value_mm,
                    &c.mean_mm,
                    &c.min_mm,
                    &c.max_mm,
                    &c.stddev_mm,
                    &c.lower_mm,
                    &c.upper_mm,
                    &c.size_mm,
                    &c.size_deviation_mm,
                    &c.true_position_mm,
                    &c.position_tolerance_mm,
                    &c.length_mm,
                    &c.length_deviation_mm,
                    &c.length_lower_mm,
                    &c.length_upper_mm};
}
// INSERT of one characteristic: parameters 1..7 are cell, part_id,
// position, name, type, verdict and points, then the number columns;
// `mark` is the dialect's parameter sign ('?' SQLite, '$' PostgreSQL).
std::string InsertCharacteristicSql(char mark);
// SELECT of the characteristics joined with their parts (alias p, for the
// caller's WHERE): cell, part_id, name, type, verdict, points, then the
// number columns.
std::string SelectCharacteristicsSql();

// TriangleStat rows as little-endian bytes (20 per triangle) and back.
std::string PackTriangles(const std::vector<TriangleStat>& triangles);
absl::StatusOr<std::vector<TriangleStat>> UnpackTriangles(const std::string& bytes);

// The idempotency key (cell, part id) as one map key.
inline std::string StoreKey(const std::string& cell, const std::string& part_id) {
  return cell + '\n' + part_id;
}

// Applies PartSelection::last to parts already in order (keeps the newest).
template <typename T>
void KeepLast(std::vector<T>& parts, int last) {
  if (last > 0 && parts.size() > static_cast<std::size_t>(last))
    parts.erase(parts.begin(), parts.end() - last);
}

}  // namespace surfinspect
