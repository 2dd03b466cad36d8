// The only translation unit that includes libpqxx.
#include "core/history/postgres_store.h"

#include <cmath>
#include <cstdlib>
#include <map>
#include <pqxx/pqxx>
#include <set>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/history/store_schema.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

// pg_advisory_xact_lock's key for the migrations ("surf" in ASCII).
constexpr int64_t kMigrationLock = 0x73757266;

// Doubles go over the wire as text with 17 significant digits, which
// round-trips every double (IEEE 754-2008 section 5.12.2); NaN as 'NaN'.
std::string DoubleText(double v) {
  return std::isfinite(v) ? absl::StrFormat("%.17g", v) : std::string("NaN");
}
double TextDouble(const pqxx::field& f) {
  return f.is_null() ? NAN : std::strtod(f.c_str(), nullptr);
}

class PostgresStore final : public ResultsStore {
 public:
  PostgresStore(const std::string& url, std::string name)
      : connection_(url), name_(std::move(name)) {}

  absl::StatusOr<bool> Record(const PartRecord& part) override;
  absl::StatusOr<bool> Contains(const std::string& cell, const std::string& part_id) override;
  absl::StatusOr<std::vector<PartRecord>> Load(const PartSelection& selection) override;
  absl::StatusOr<int> SchemaVersion() override;
  std::string Name() const override { return name_; }
  absl::Status Migrate();

 private:
  absl::Status Failed(const std::string& what, const std::exception& e) const {
    return absl::UnavailableError(absl::StrCat(name_, ": ", what, ": ", e.what()));
  }
  absl::StatusOr<int> VersionIn(pqxx::transaction_base& tx);
  void LoadRows(pqxx::transaction_base& tx, const PartSelection& sel,
                std::vector<PartRecord>& parts);

  pqxx::connection connection_;
  std::string name_;
};

std::string Filter(const PartSelection&) {
  std::string where = " WHERE ($1 = '' OR p.cell = $1) AND ($2 = '' OR p.inspected_utc >= $2)";
  return where;
}

absl::StatusOr<int> PostgresStore::VersionIn(pqxx::transaction_base& tx) {
  std::set<std::string> names;
  for (const auto& row :
       tx.exec("SELECT table_name FROM information_schema.tables WHERE table_schema = "
               "current_schema()"))
    names.insert(row[0].c_str());
  if (names.empty()) return 0;
  if (!names.count("schema_version"))
    return absl::FailedPreconditionError(
        absl::StrCat(name_, ": a foreign database (it has tables but no schema_version of ",
                     kStoreApplication, ")"));
  const pqxx::result r = tx.exec("SELECT application, version FROM schema_version");
  if (r.empty() || std::string(r[0][0].c_str()) != kStoreApplication)
    return absl::FailedPreconditionError(absl::StrCat(
        name_, ": a foreign database (schema_version is not ", kStoreApplication, ")"));
  return r[0][1].as<int>();
}

absl::StatusOr<int> PostgresStore::SchemaVersion() {
  try {
    pqxx::read_transaction tx(connection_);
    return VersionIn(tx);
  } catch (const std::exception& e) {
    return Failed("cannot read the schema version", e);
  }
}

absl::Status PostgresStore::Migrate() {
  try {
    pqxx::work tx(connection_);
    tx.exec_params("SELECT pg_advisory_xact_lock($1)", kMigrationLock);
    ASSIGN_OR_RETURN(auto version, VersionIn(tx));
    RETURN_IF_ERROR(CheckSchemaVersion(name_, version));
    for (int v = version + 1; v <= LatestSchemaVersion(); ++v) {
      for (const std::string& sql : MigrationStatements(v, {"BYTEA", "DOUBLE PRECISION"}))
        tx.exec(sql);
      if (v == 1)
        tx.exec_params("INSERT INTO schema_version VALUES ($1, 1)", kStoreApplication);
      else
        tx.exec_params("UPDATE schema_version SET version = $1", v);
    }
    tx.commit();
    return absl::OkStatus();
  } catch (const std::exception& e) {
    return Failed("cannot create or migrate the schema", e);
  }
}

absl::StatusOr<bool> PostgresStore::Contains(const std::string& cell, const std::string& part_id) {
  try {
    pqxx::read_transaction tx(connection_);
    return !tx.exec_params("SELECT 1 FROM parts WHERE cell = $1 AND part_id = $2", cell, part_id)
                .empty();
  } catch (const std::exception& e) {
    return Failed("cannot look up " + part_id, e);
  }
}

absl::StatusOr<bool> PostgresStore::Record(const PartRecord& p) {
  try {
    pqxx::work tx(connection_);
    const pqxx::result r = tx.exec_params(
        "INSERT INTO parts VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10) "
        "ON CONFLICT (cell, part_id) DO NOTHING",
        p.cell, p.part_id, p.inspected_utc, UtcNow(), p.software_version, p.plan_hash, p.verdict,
        p.defects_json, p.calibration_json, p.files_json);
    if (r.affected_rows() == 0) return false;  // recorded before; the transaction is dropped
    for (std::size_t i = 0; i < p.characteristics.size(); ++i) {
      const CharacteristicRecord& c = p.characteristics[i];
      std::vector<std::string> numbers;
      for (const double* v : CharacteristicNumbers(c)) numbers.push_back(DoubleText(*v));
      tx.exec_params(InsertCharacteristicSql('$'), p.cell, p.part_id, static_cast<int64_t>(i),
                     c.name, c.type, c.verdict, c.points,
                     pqxx::prepare::make_dynamic_params(numbers));
    }
    const std::string packed = PackTriangles(p.triangles);
    tx.exec_params("INSERT INTO triangle_summaries VALUES ($1, $2, $3, $4)", p.cell, p.part_id,
                   static_cast<int64_t>(p.num_triangles),
                   pqxx::binarystring(packed.data(), packed.size()));
    tx.commit();
    return true;
  } catch (const std::exception& e) {
    return Failed("cannot write part " + p.part_id, e);
  }
}

void PostgresStore::LoadRows(pqxx::transaction_base& tx, const PartSelection& sel,
                             std::vector<PartRecord>& parts) {
  for (const auto& row :
       tx.exec_params("SELECT p.cell, p.part_id, p.inspected_utc, p.software_version, p.plan_hash, "
                      "p.verdict, p.defects_json, p.calibration_json, p.files_json FROM parts p" +
                          Filter(sel) + " ORDER BY p.inspected_utc, p.cell, p.part_id",
                      sel.cell, sel.since_utc)) {
    PartRecord p;
    std::string* fields[] = {&p.cell,      &p.part_id, &p.inspected_utc, &p.software_version,
                             &p.plan_hash, &p.verdict, &p.defects_json,  &p.calibration_json,
                             &p.files_json};
    for (int i = 0; i < 9; ++i) *fields[i] = row[i].c_str();
    parts.push_back(std::move(p));
  }
  KeepLast(parts, sel.last);
  std::map<std::string, PartRecord*> by_key;
  for (PartRecord& p : parts) by_key[StoreKey(p.cell, p.part_id)] = &p;
  for (const auto& row : tx.exec_params(
           SelectCharacteristicsSql() + Filter(sel) + " ORDER BY c.cell, c.part_id, c.position",
           sel.cell, sel.since_utc)) {
    auto it = by_key.find(StoreKey(row[0].c_str(), row[1].c_str()));
    if (it == by_key.end()) continue;
    CharacteristicRecord c;
    c.name = row[2].c_str();
    c.type = row[3].c_str();
    c.verdict = row[4].c_str();
    c.points = row[5].as<int64_t>();
    int k = 6;
    for (double* v : CharacteristicNumbers(c)) *v = TextDouble(row[k++]);
    it->second->characteristics.push_back(std::move(c));
  }
}

absl::StatusOr<std::vector<PartRecord>> PostgresStore::Load(const PartSelection& sel) {
  try {
    // REPEATABLE READ: every query of the trend sees one snapshot.
    pqxx::transaction<pqxx::repeatable_read, pqxx::read_only> tx(connection_);
    std::vector<PartRecord> parts;
    LoadRows(tx, sel, parts);
    if (sel.with_triangles) {
      std::map<std::string, PartRecord*> by_key;
      for (PartRecord& p : parts) by_key[StoreKey(p.cell, p.part_id)] = &p;
      for (const auto& row : tx.exec_params(
               "SELECT t.cell, t.part_id, t.num_triangles, t.packed FROM triangle_summaries t "
               "JOIN parts p ON p.cell = t.cell AND p.part_id = t.part_id" +
                   Filter(sel),
               sel.cell, sel.since_utc)) {
        auto it = by_key.find(StoreKey(row[0].c_str(), row[1].c_str()));
        if (it == by_key.end()) continue;
        it->second->num_triangles = row[2].as<uint32_t>();
        const pqxx::binarystring blob(row[3]);
        ASSIGN_OR_RETURN(it->second->triangles, UnpackTriangles(blob.str()));
      }
    }
    return parts;
  } catch (const std::exception& e) {
    return Failed("cannot read parts", e);
  }
}

}  // namespace

absl::StatusOr<std::unique_ptr<ResultsStore>> OpenPostgresStore(const std::string& url) {
  const std::string name = RedactDatabaseUrl(url);
  std::unique_ptr<PostgresStore> store;
  try {
    store = std::make_unique<PostgresStore>(url, name);
  } catch (const std::exception& e) {
    return absl::UnavailableError(
        absl::StrCat(name, ": cannot connect to the results database: ", e.what()));
  }
  RETURN_IF_ERROR(store->Migrate());
  return std::unique_ptr<ResultsStore>(std::move(store));
}

}  // namespace surfinspect
