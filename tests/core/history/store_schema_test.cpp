// The schema's migrations (and a database of an older schema migrated by
// opening it) and the packed triangle summaries.
#include "core/history/store_schema.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include "absl/strings/str_cat.h"
#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

TEST(StoreSchema, MigrationsUseEachDialect) {
  ASSERT_GE(LatestSchemaVersion(), 2);
  std::string all;
  for (int v = 1; v <= LatestSchemaVersion(); ++v)
    for (const std::string& s : MigrationStatements(v, {"BYTEA", "DOUBLE PRECISION"})) all += s;
  EXPECT_NE(all.find("BYTEA"), std::string::npos);
  EXPECT_EQ(all.find("{blob}"), std::string::npos);
  EXPECT_EQ(all.find("{double}"), std::string::npos);
}

// Every number column a backend reads and writes is made by a migration,
// and the INSERT has one parameter per column.
TEST(StoreSchema, NumberColumnsAreMigratedAndBound) {
  std::string all;
  for (int v = 1; v <= LatestSchemaVersion(); ++v)
    for (const std::string& s : MigrationStatements(v, {"BLOB", "REAL"})) all += s + "\n";
  for (const char* column : kCharacteristicNumberColumns)
    EXPECT_NE(all.find(std::string(column) + " REAL"), std::string::npos) << column;
  const std::string insert = InsertCharacteristicSql('$');
  const std::string last = "$" + std::to_string(7 + kCharacteristicNumberColumns.size());
  EXPECT_NE(insert.find(last + ")"), std::string::npos) << insert;
  EXPECT_NE(insert.find("length_upper_mm)"), std::string::npos) << insert;
  CharacteristicRecord c;
  c.length_upper_mm = 0.3;
  EXPECT_EQ(*CharacteristicNumbers(c).back(), 0.3) << "fields in the columns' order";
  EXPECT_NE(SelectCharacteristicsSql().find("c.size_mm"), std::string::npos);
}

// A database made before holes were stored (schema 2, written here by the
// migrations of then): opening it adds the hole columns, its part reads back
// with them NULL, and a new part keeps its hole.
TEST(StoreSchema, ASchema2DatabaseIsMigrated) {
  testing::TempDir dir;
  const std::string db = dir.File("old.db");
  std::string sql;
  for (int v = 1; v <= 2; ++v)
    for (const std::string& s : MigrationStatements(v, {"BLOB", "REAL"})) sql += s + ";";
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &raw), SQLITE_OK);
  const std::string rows = absl::StrCat(
      "INSERT INTO schema_version VALUES ('", kStoreApplication, "', 2);",
      "INSERT INTO parts VALUES ('c', 'old', '2026-01-01T00:00:00Z', '2026-01-01T00:00:00Z', "
      "'0.1', '', 'pass', '[]', '{}', '{}');",
      "INSERT INTO characteristics VALUES ('c', 'old', 0, 'surface', 'surface', 0.01, 0.01, "
      "-0.2, 0.2, 0.05, -0.3, 0.3, 'pass', 1000);");
  EXPECT_EQ(sqlite3_exec(raw, (sql + rows).c_str(), nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(raw);
  auto store = OpenResultsStore(db);
  ASSERT_TRUE(store.ok()) << store.status();
  EXPECT_EQ(*(*store)->SchemaVersion(), LatestSchemaVersion());
  PartRecord fresh;
  fresh.cell = "c";
  fresh.part_id = "new";
  fresh.inspected_utc = "2026-01-02T00:00:00Z";
  fresh.verdict = "pass";
  CharacteristicRecord hole;
  hole.name = "H1";
  hole.type = "hole";
  hole.verdict = "pass";
  hole.size_mm = 8.012, hole.size_deviation_mm = 0.012, hole.true_position_mm = 0.1;
  hole.position_tolerance_mm = 0.3, hole.lower_mm = -0.1, hole.upper_mm = 0.1;
  fresh.characteristics = {hole};
  EXPECT_TRUE(*(*store)->Record(fresh));
  auto parts = (*store)->Load({});
  ASSERT_TRUE(parts.ok()) << parts.status();
  ASSERT_EQ(parts->size(), 2u);
  const CharacteristicRecord& old = (*parts)[0].characteristics.at(0);
  EXPECT_EQ(old.value_mm, 0.01);
  EXPECT_EQ(old.upper_mm, 0.3);
  EXPECT_EQ(old.points, 1000);
  EXPECT_TRUE(std::isnan(old.size_mm) && std::isnan(old.true_position_mm));
  const CharacteristicRecord& back = (*parts)[1].characteristics.at(0);
  EXPECT_EQ(back.size_mm, 8.012);
  EXPECT_EQ(back.true_position_mm, 0.1);
  EXPECT_EQ(back.position_tolerance_mm, 0.3);
  EXPECT_TRUE(std::isnan(back.length_mm));
}

TEST(StoreSchema, NewerVersionIsRefusedByName) {
  EXPECT_TRUE(CheckSchemaVersion("x.db", LatestSchemaVersion()).ok());
  const absl::Status st = CheckSchemaVersion("x.db", LatestSchemaVersion() + 1);
  EXPECT_EQ(st.code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_NE(st.message().find("x.db"), std::string::npos);
  EXPECT_NE(st.message().find("newer"), std::string::npos);
}

TEST(StoreSchema, TrianglesRoundTrip) {
  const std::vector<TriangleStat> t = {{0, 3, 0.5f, -1.f, 2.f}, {4000000000u, 1, NAN, 0, 0}};
  const std::string packed = PackTriangles(t);
  EXPECT_EQ(packed.size(), 40u);
  auto back = UnpackTriangles(packed);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ((*back)[0].triangle_id, 0u);
  EXPECT_EQ((*back)[0].max_mm, 2.f);
  EXPECT_EQ((*back)[1].triangle_id, 4000000000u);
  EXPECT_TRUE(std::isnan((*back)[1].mean_mm));
  EXPECT_FALSE(UnpackTriangles("abc").ok());
}

}  // namespace
}  // namespace surfinspect
