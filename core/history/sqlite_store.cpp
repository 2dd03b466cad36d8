#include "core/history/sqlite_store.h"

#include <sqlite3.h>

#include <cmath>
#include <map>
#include <set>

#include "absl/functional/function_ref.h"
#include "absl/strings/str_cat.h"
#include "core/history/store_schema.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

// RAII for the two C handles.
using Db = std::unique_ptr<sqlite3, decltype(&sqlite3_close_v2)>;
using Stmt = std::unique_ptr<sqlite3_stmt, decltype(&sqlite3_finalize)>;

class SqliteStore final : public ResultsStore {
 public:
  SqliteStore(Db db, std::string path) : db_(std::move(db)), path_(std::move(path)) {}

  absl::StatusOr<bool> Record(const PartRecord& part) override;
  absl::StatusOr<bool> Contains(const std::string& cell, const std::string& part_id) override;
  absl::StatusOr<std::vector<PartRecord>> Load(const PartSelection& selection) override;
  absl::StatusOr<int> SchemaVersion() override;
  std::string Name() const override { return path_; }

  absl::Status Migrate();

 private:
  absl::Status Error(const std::string& what) const {
    return absl::InternalError(absl::StrCat(path_, ": ", what, ": ", sqlite3_errmsg(db_.get())));
  }
  absl::StatusOr<Stmt> Prepare(const std::string& sql) {
    sqlite3_stmt* s = nullptr;
    if (sqlite3_prepare_v2(db_.get(), sql.c_str(), -1, &s, nullptr) != SQLITE_OK)
      return Error("cannot prepare \"" + sql.substr(0, 40) + "\"");
    return Stmt(s, &sqlite3_finalize);
  }
  absl::Status Exec(const std::string& sql) {
    char* err = nullptr;
    if (sqlite3_exec(db_.get(), sql.c_str(), nullptr, nullptr, &err) != SQLITE_OK) {
      const std::string message = err ? err : "error";
      sqlite3_free(err);
      const bool not_db = sqlite3_errcode(db_.get()) == SQLITE_NOTADB;
      return absl::InternalError(absl::StrCat(path_, not_db ? ": not an SQLite database (" : ": ",
                                              message, not_db ? ")" : ""));
    }
    return absl::OkStatus();
  }
  absl::Status InsertCharacteristics(const PartRecord& part);
  absl::Status InsertTriangles(const PartRecord& part);
  absl::Status LoadCharacteristics(std::vector<PartRecord>& parts, const PartSelection& sel);
  absl::Status LoadTriangles(std::vector<PartRecord>& parts, const PartSelection& sel);
  // Runs `sql` (columns cell, part id, ...) with the selection bound and calls
  // `row` for each row of a part in `parts`; `what` names the rows in errors.
  absl::Status ForEachPartRow(std::vector<PartRecord>& parts, const std::string& sql,
                              const PartSelection& sel, const char* what,
                              absl::FunctionRef<absl::Status(sqlite3_stmt*, PartRecord&)> row);

  Db db_;
  std::string path_;
};

void BindText(sqlite3_stmt* s, int i, const std::string& v) {
  sqlite3_bind_text(s, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
}
void BindDouble(sqlite3_stmt* s, int i, double v) {
  std::isfinite(v) ? sqlite3_bind_double(s, i, v) : sqlite3_bind_null(s, i);  // NaN as NULL
}
std::string ColumnText(sqlite3_stmt* s, int i) {
  const unsigned char* t = sqlite3_column_text(s, i);
  return t ? std::string(reinterpret_cast<const char*>(t), sqlite3_column_bytes(s, i)) : "";
}
double ColumnDouble(sqlite3_stmt* s, int i) {
  return sqlite3_column_type(s, i) == SQLITE_NULL ? NAN : sqlite3_column_double(s, i);
}

// The WHERE clause and its parameters for a selection (cell, since).
std::string PartFilter(const PartSelection& sel, const std::string& table) {
  return std::string(" WHERE 1=1") + (sel.cell.empty() ? "" : " AND " + table + ".cell = :cell") +
         (sel.since_utc.empty() ? "" : " AND p.inspected_utc >= :since");
}
void BindFilter(sqlite3_stmt* s, const PartSelection& sel) {
  if (!sel.cell.empty()) BindText(s, sqlite3_bind_parameter_index(s, ":cell"), sel.cell);
  if (!sel.since_utc.empty()) BindText(s, sqlite3_bind_parameter_index(s, ":since"), sel.since_utc);
}

absl::StatusOr<int> SqliteStore::SchemaVersion() {
  ASSIGN_OR_RETURN(auto tables, Prepare("SELECT name FROM sqlite_master WHERE type = 'table'"));
  std::set<std::string> names;
  int rc;
  while ((rc = sqlite3_step(tables.get())) == SQLITE_ROW) names.insert(ColumnText(tables.get(), 0));
  if (rc != SQLITE_DONE) return Error("cannot list tables");
  if (names.empty()) return 0;
  if (!names.count("schema_version"))
    return absl::FailedPreconditionError(
        absl::StrCat(path_, ": a foreign database (it has tables but no schema_version of ",
                     kStoreApplication, ")"));
  ASSIGN_OR_RETURN(auto v, Prepare("SELECT application, version FROM schema_version"));
  if (sqlite3_step(v.get()) != SQLITE_ROW || ColumnText(v.get(), 0) != kStoreApplication)
    return absl::FailedPreconditionError(absl::StrCat(
        path_, ": a foreign database (schema_version is not ", kStoreApplication, ")"));
  return sqlite3_column_int(v.get(), 1);
}

absl::Status SqliteStore::Migrate() {
  RETURN_IF_ERROR(Exec("PRAGMA journal_mode = WAL"));
  RETURN_IF_ERROR(Exec("PRAGMA foreign_keys = ON; PRAGMA synchronous = NORMAL"));
  RETURN_IF_ERROR(Exec("BEGIN IMMEDIATE"));
  auto version = SchemaVersion();
  absl::Status st = version.ok() ? CheckSchemaVersion(path_, *version) : version.status();
  for (int v = version.ok() ? *version + 1 : 1; st.ok() && v <= LatestSchemaVersion(); ++v) {
    for (const std::string& sql : MigrationStatements(v, {"BLOB", "REAL"}))
      if (st = Exec(sql); !st.ok()) break;
    if (st.ok())
      st = Exec(
          v == 1 ? absl::StrCat("INSERT INTO schema_version VALUES ('", kStoreApplication, "', 1)")
                 : absl::StrCat("UPDATE schema_version SET version = ", v));
  }
  if (!st.ok()) {
    Exec("ROLLBACK").IgnoreError();  // the refusal above is the error to report
    return st;
  }
  return Exec("COMMIT");
}

absl::StatusOr<bool> SqliteStore::Contains(const std::string& cell, const std::string& part_id) {
  ASSIGN_OR_RETURN(auto s, Prepare("SELECT 1 FROM parts WHERE cell = ?1 AND part_id = ?2"));
  BindText(s.get(), 1, cell);
  BindText(s.get(), 2, part_id);
  const int rc = sqlite3_step(s.get());
  if (rc != SQLITE_ROW && rc != SQLITE_DONE) return Error("cannot look up " + part_id);
  return rc == SQLITE_ROW;
}

absl::Status SqliteStore::InsertCharacteristics(const PartRecord& part) {
  ASSIGN_OR_RETURN(auto s, Prepare(InsertCharacteristicSql('?')));
  for (std::size_t i = 0; i < part.characteristics.size(); ++i) {
    const CharacteristicRecord& c = part.characteristics[i];
    sqlite3_stmt* st = s.get();
    sqlite3_reset(st);
    BindText(st, 1, part.cell);
    BindText(st, 2, part.part_id);
    sqlite3_bind_int64(st, 3, static_cast<int64_t>(i));
    BindText(st, 4, c.name);
    BindText(st, 5, c.type);
    BindText(st, 6, c.verdict);
    sqlite3_bind_int64(st, 7, c.points);
    int k = 8;
    for (const double* v : CharacteristicNumbers(c)) BindDouble(st, k++, *v);
    if (sqlite3_step(st) != SQLITE_DONE) return Error("cannot write characteristic " + c.name);
  }
  return absl::OkStatus();
}

absl::Status SqliteStore::InsertTriangles(const PartRecord& part) {
  ASSIGN_OR_RETURN(auto s, Prepare("INSERT INTO triangle_summaries VALUES (?1, ?2, ?3, ?4)"));
  const std::string packed = PackTriangles(part.triangles);
  BindText(s.get(), 1, part.cell);
  BindText(s.get(), 2, part.part_id);
  sqlite3_bind_int64(s.get(), 3, part.num_triangles);
  sqlite3_bind_blob(s.get(), 4, packed.data(), static_cast<int>(packed.size()), SQLITE_TRANSIENT);
  if (sqlite3_step(s.get()) != SQLITE_DONE) return Error("cannot write the triangle summary");
  return absl::OkStatus();
}

absl::StatusOr<bool> SqliteStore::Record(const PartRecord& p) {
  RETURN_IF_ERROR(Exec("BEGIN IMMEDIATE"));
  auto s = Prepare(
      "INSERT INTO parts VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10) "
      "ON CONFLICT (cell, part_id) DO NOTHING");
  absl::Status st = s.status();
  bool written = false;
  if (st.ok()) {
    const std::string* text[] = {&p.cell,      &p.part_id,          &p.inspected_utc,
                                 nullptr,      &p.software_version, &p.plan_hash,
                                 &p.verdict,   &p.defects_json,     &p.calibration_json,
                                 &p.files_json};
    const std::string now = UtcNow();
    for (int i = 0; i < 10; ++i) BindText(s->get(), i + 1, text[i] ? *text[i] : now);
    if (sqlite3_step(s->get()) != SQLITE_DONE) st = Error("cannot write part " + p.part_id);
    written = st.ok() && sqlite3_changes(db_.get()) == 1;
  }
  if (st.ok() && written) st = InsertCharacteristics(p);
  if (st.ok() && written) st = InsertTriangles(p);
  if (!st.ok()) {
    Exec("ROLLBACK").IgnoreError();  // the write's own error is the one to report
    return st;
  }
  RETURN_IF_ERROR(Exec("COMMIT"));
  return written;
}

absl::Status SqliteStore::ForEachPartRow(
    std::vector<PartRecord>& parts, const std::string& sql, const PartSelection& sel,
    const char* what, absl::FunctionRef<absl::Status(sqlite3_stmt*, PartRecord&)> row) {
  std::map<std::string, PartRecord*> by_key;
  for (PartRecord& p : parts) by_key[StoreKey(p.cell, p.part_id)] = &p;
  ASSIGN_OR_RETURN(auto s, Prepare(sql));
  BindFilter(s.get(), sel);
  int rc;
  while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) {
    sqlite3_stmt* r = s.get();
    auto it = by_key.find(StoreKey(ColumnText(r, 0), ColumnText(r, 1)));
    if (it == by_key.end()) continue;
    RETURN_IF_ERROR(row(r, *it->second));
  }
  return rc == SQLITE_DONE ? absl::OkStatus() : Error(absl::StrCat("cannot read ", what));
}

absl::Status SqliteStore::LoadCharacteristics(std::vector<PartRecord>& parts,
                                              const PartSelection& sel) {
  return ForEachPartRow(
      parts,
      SelectCharacteristicsSql() + PartFilter(sel, "c") + " ORDER BY c.cell, c.part_id, c.position",
      sel, "characteristics", [](sqlite3_stmt* r, PartRecord& part) -> absl::Status {
        CharacteristicRecord c;
        c.name = ColumnText(r, 2);
        c.type = ColumnText(r, 3);
        c.verdict = ColumnText(r, 4);
        c.points = sqlite3_column_int64(r, 5);
        int k = 6;
        for (double* v : CharacteristicNumbers(c)) *v = ColumnDouble(r, k++);
        part.characteristics.push_back(std::move(c));
        return absl::OkStatus();
      });
}

absl::Status SqliteStore::LoadTriangles(std::vector<PartRecord>& parts, const PartSelection& sel) {
  return ForEachPartRow(
      parts,
      "SELECT t.cell, t.part_id, t.num_triangles, t.packed FROM triangle_summaries t "
      "JOIN parts p ON p.cell = t.cell AND p.part_id = t.part_id" +
          PartFilter(sel, "t"),
      sel, "triangle summaries", [](sqlite3_stmt* r, PartRecord& part) -> absl::Status {
        part.num_triangles = static_cast<uint32_t>(sqlite3_column_int64(r, 2));
        const char* blob = static_cast<const char*>(sqlite3_column_blob(r, 3));
        auto tri = UnpackTriangles(std::string(blob ? blob : "", sqlite3_column_bytes(r, 3)));
        if (tri.ok()) part.triangles = *std::move(tri);
        return tri.status();
      });
}

absl::StatusOr<std::vector<PartRecord>> SqliteStore::Load(const PartSelection& sel) {
  // One read transaction: a snapshot, whatever a writer does meanwhile.
  RETURN_IF_ERROR(Exec("BEGIN"));
  auto s = Prepare(
      "SELECT p.cell, p.part_id, p.inspected_utc, p.software_version, p.plan_hash, p.verdict, "
      "p.defects_json, p.calibration_json, p.files_json FROM parts p" +
      PartFilter(sel, "p") + " ORDER BY p.inspected_utc, p.cell, p.part_id");
  std::vector<PartRecord> parts;
  absl::Status st = s.status();
  if (st.ok()) BindFilter(s->get(), sel);
  int rc = SQLITE_DONE;
  while (st.ok() && (rc = sqlite3_step(s->get())) == SQLITE_ROW) {
    PartRecord p;
    std::string* fields[] = {&p.cell,      &p.part_id, &p.inspected_utc, &p.software_version,
                             &p.plan_hash, &p.verdict, &p.defects_json,  &p.calibration_json,
                             &p.files_json};
    for (int i = 0; i < 9; ++i) *fields[i] = ColumnText(s->get(), i);
    parts.push_back(std::move(p));
  }
  if (st.ok() && rc != SQLITE_DONE) st = Error("cannot read parts");
  if (st.ok()) KeepLast(parts, sel.last);
  if (st.ok()) st = LoadCharacteristics(parts, sel);
  if (st.ok() && sel.with_triangles) st = LoadTriangles(parts, sel);
  Exec("COMMIT").IgnoreError();  // a read-only transaction: nothing to lose
  if (!st.ok()) return st;
  return parts;
}

}  // namespace

absl::StatusOr<std::unique_ptr<ResultsStore>> OpenSqliteStore(const std::string& path) {
  sqlite3* raw = nullptr;
  const int rc =
      sqlite3_open_v2(path.c_str(), &raw, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr);
  Db db(raw, &sqlite3_close_v2);
  if (rc != SQLITE_OK)
    return absl::NotFoundError(absl::StrCat(path, ": cannot open the results database: ",
                                            raw ? sqlite3_errmsg(raw) : sqlite3_errstr(rc)));
  sqlite3_busy_timeout(db.get(), 10000);
  auto store = std::make_unique<SqliteStore>(std::move(db), path);
  RETURN_IF_ERROR(store->Migrate());
  return std::unique_ptr<ResultsStore>(std::move(store));
}

}  // namespace surfinspect
