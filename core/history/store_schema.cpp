#include "core/history/store_schema.h"

#include <cstring>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"

namespace surfinspect {
namespace {

// The characteristics columns of CharacteristicRecord's hole fields, in
// its order (each ADD COLUMN its own statement: SQLite takes one a time).
std::vector<std::string> HoleColumns() {
  std::vector<std::string> out;
  for (const char* column :
       {"size_mm", "size_deviation_mm", "true_position_mm", "position_tolerance_mm", "length_mm",
        "length_deviation_mm", "length_lower_mm", "length_upper_mm"})
    out.push_back(absl::StrCat("ALTER TABLE characteristics ADD COLUMN ", column, " {double}"));
  return out;
}

// Migration k is kMigrations[k - 1]. Never edit one that has shipped: add
// the next.
const std::vector<std::vector<std::string>>& Migrations() {
  static const std::vector<std::vector<std::string>> kMigrations = {
      // 1: parts, their characteristics, their triangle summaries.
      {"CREATE TABLE schema_version (application TEXT NOT NULL, version INTEGER NOT NULL)",
       "CREATE TABLE parts (cell TEXT NOT NULL, part_id TEXT NOT NULL, "
       "inspected_utc TEXT NOT NULL, recorded_utc TEXT NOT NULL, software_version TEXT NOT NULL, "
       "plan_hash TEXT NOT NULL, verdict TEXT NOT NULL, defects_json TEXT NOT NULL, "
       "calibration_json TEXT NOT NULL, files_json TEXT NOT NULL, "
       "PRIMARY KEY (cell, part_id))",
       "CREATE TABLE characteristics (cell TEXT NOT NULL, part_id TEXT NOT NULL, "
       "position INTEGER NOT NULL, name TEXT NOT NULL, type TEXT NOT NULL, value_mm {double}, "
       "mean_mm {double}, min_mm {double}, max_mm {double}, stddev_mm {double}, "
       "lower_mm {double}, upper_mm {double}, verdict TEXT NOT NULL, points BIGINT NOT NULL, "
       "PRIMARY KEY (cell, part_id, name), "
       "FOREIGN KEY (cell, part_id) REFERENCES parts (cell, part_id) ON DELETE CASCADE)",
       "CREATE TABLE triangle_summaries (cell TEXT NOT NULL, part_id TEXT NOT NULL, "
       "num_triangles BIGINT NOT NULL, packed {blob} NOT NULL, PRIMARY KEY (cell, part_id), "
       "FOREIGN KEY (cell, part_id) REFERENCES parts (cell, part_id) ON DELETE CASCADE)"},
      // 2: the trend's selections by time and by characteristic.
      {"CREATE INDEX parts_by_time ON parts (inspected_utc, cell, part_id)",
       "CREATE INDEX characteristics_by_name ON characteristics (name)"},
      // 3: holes' and slots' quantities (NULL for the other types, and for
      // parts recorded before), at the end of the row in both databases.
      HoleColumns(),
  };
  return kMigrations;
}

void PutU32(std::string& out, uint32_t v) {
  for (int b = 0; b < 4; ++b) out.push_back(static_cast<char>((v >> (8 * b)) & 0xff));
}
uint32_t GetU32(const char* p) {
  uint32_t v = 0;
  for (int b = 0; b < 4; ++b) v |= uint32_t{static_cast<unsigned char>(p[b])} << (8 * b);
  return v;
}
void PutF32(std::string& out, float f) {
  uint32_t v;
  std::memcpy(&v, &f, 4);
  PutU32(out, v);
}
float GetF32(const char* p) {
  const uint32_t v = GetU32(p);
  float f;
  std::memcpy(&f, &v, 4);
  return f;
}

}  // namespace

std::vector<std::string> MigrationStatements(int version, const SqlDialect& dialect) {
  std::vector<std::string> out;
  for (const std::string& s : Migrations().at(version - 1))
    out.push_back(
        absl::StrReplaceAll(s, {{"{blob}", dialect.blob}, {"{double}", dialect.double_}}));
  return out;
}

std::string InsertCharacteristicSql(char mark) {
  std::string columns = "cell, part_id, position, name, type, verdict, points", values;
  for (const char* c : kCharacteristicNumberColumns) absl::StrAppend(&columns, ", ", c);
  for (std::size_t k = 1; k <= 7 + kCharacteristicNumberColumns.size(); ++k)
    absl::StrAppend(&values, k == 1 ? "" : ", ", std::string(1, mark), k);
  return absl::StrCat("INSERT INTO characteristics (", columns, ") VALUES (", values, ")");
}

std::string SelectCharacteristicsSql() {
  std::string sql = "SELECT c.cell, c.part_id, c.name, c.type, c.verdict, c.points";
  for (const char* c : kCharacteristicNumberColumns) absl::StrAppend(&sql, ", c.", c);
  return sql + " FROM characteristics c JOIN parts p ON p.cell = c.cell AND p.part_id = c.part_id";
}

int LatestSchemaVersion() { return static_cast<int>(Migrations().size()); }

absl::Status CheckSchemaVersion(const std::string& database, int found) {
  if (found > LatestSchemaVersion())
    return absl::FailedPreconditionError(absl::StrCat(
        database, ": results schema version ", found, " is newer than this surfinspect knows (",
        LatestSchemaVersion(), "); use a newer surfinspect"));
  if (found < 0)
    return absl::DataLossError(absl::StrCat(database, ": invalid schema version ", found));
  return absl::OkStatus();
}

std::string PackTriangles(const std::vector<TriangleStat>& triangles) {
  std::string out;
  out.reserve(triangles.size() * 20);
  for (const TriangleStat& t : triangles) {
    PutU32(out, t.triangle_id);
    PutU32(out, t.count);
    PutF32(out, t.mean_mm);
    PutF32(out, t.min_mm);
    PutF32(out, t.max_mm);
  }
  return out;
}

absl::StatusOr<std::vector<TriangleStat>> UnpackTriangles(const std::string& bytes) {
  if (bytes.size() % 20 != 0)
    return absl::DataLossError(
        absl::StrCat("triangle summary of ", bytes.size(), " bytes is not 20 per triangle"));
  std::vector<TriangleStat> out(bytes.size() / 20);
  for (std::size_t i = 0; i < out.size(); ++i) {
    const char* p = bytes.data() + 20 * i;
    out[i] = {GetU32(p), GetU32(p + 4), GetF32(p + 8), GetF32(p + 12), GetF32(p + 16)};
  }
  return out;
}

}  // namespace surfinspect
