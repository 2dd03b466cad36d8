// The schema's migrations and the packed triangle summaries.
#include "core/history/store_schema.h"

#include <gtest/gtest.h>

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
