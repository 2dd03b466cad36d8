// The results store against both real backends: core/history/sqlite_store.cpp
// on a file and core/history/postgres_store.cpp on a PostgreSQL 15 server the
// test starts itself (tests/support/postgres_server.h). One suite runs on
// each: round trip, idempotency, selections, migrations, SPC on the stored
// values, concurrent writers, kill -9 in the middle of a write; then both
// must give the same trend.json. Also covers core/history/results_store.cpp.
#include "core/history/results_store.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <random>
#include <set>
#include <thread>

#include "absl/strings/str_format.h"
#include "core/history/store_schema.h"
#include "core/history/trend.h"
#include "tests/support/postgres_server.h"
#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

using testing::PostgresServer;
using testing::TempDir;

constexpr int kProfiles = 3;                     // surface, region, point
constexpr int kCharacteristics = kProfiles + 1;  // and a hole

PartRecord MakePart(const std::string& cell, int k, uint32_t triangles = 50) {
  std::mt19937_64 rng(k * 7919 + std::hash<std::string>()(cell));
  std::normal_distribution<double> noise(0, 0.015);
  PartRecord p;
  p.cell = cell;
  p.part_id = absl::StrFormat("part-%04d", k);
  p.inspected_utc = absl::StrFormat("2026-12-01T08:%02d:%02d.%06dZ", k / 60 % 60, k % 60, k);
  p.software_version = "0.1.0";
  p.plan_hash = "abc";
  p.verdict = k % 5 == 0 ? "fail" : "pass";
  p.defects_json = R"([{"id":1,"kind":"dent"}])";
  p.calibration_json = R"({"viewpoints":[]})";
  p.files_json = R"({"report":"r.json"})";
  const char* names[kProfiles] = {"surface", "ridge", "ridge-centre"};
  for (int c = 0; c < kProfiles; ++c) {
    CharacteristicRecord r;
    r.name = names[c];
    r.type = c == 2 ? "point" : c == 1 ? "region" : "surface";
    r.value_mm = (c == 2 ? 0.005 * (k % 1000) : 0) + noise(rng);
    r.mean_mm = r.value_mm;
    r.min_mm = r.value_mm - 0.1;
    r.max_mm = k == 3 ? NAN : r.value_mm + 0.1;  // a NULL survives the trip
    r.stddev_mm = 0.01;
    r.lower_mm = c == 1 ? -0.15 : -0.1;
    r.upper_mm = -r.lower_mm;
    r.verdict = "pass";
    r.points = 1000 + k;
    p.characteristics.push_back(r);
  }
  // A hole, not measured on part 3 (its measured fields NULL).
  CharacteristicRecord h;
  h.name = "H1";
  h.type = "hole";
  h.lower_mm = -0.1, h.upper_mm = 0.1, h.position_tolerance_mm = 0.3;
  h.verdict = k == 3 ? "not_measured" : "pass";
  if (k != 3) {
    h.size_deviation_mm = noise(rng);
    h.size_mm = 8 + h.size_deviation_mm;
    h.true_position_mm = std::abs(noise(rng)) + 0.002 * k;
    h.points = 200;
  }
  p.characteristics.push_back(h);
  p.num_triangles = triangles;
  for (uint32_t t = 0; t < triangles; t += 1 + (k % 3))
    p.triangles.push_back({t, 3, static_cast<float>(noise(rng)), -1.f, 1.f});
  return p;
}

std::unique_ptr<ResultsStore> Open(const std::string& url) {
  auto store = OpenResultsStore(url);
  EXPECT_TRUE(store.ok()) << store.status();
  return store.ok() ? *std::move(store) : nullptr;
}

void ExpectSame(const PartRecord& a, const PartRecord& b) {
  EXPECT_EQ(a.part_id, b.part_id);
  EXPECT_EQ(a.inspected_utc, b.inspected_utc);
  EXPECT_EQ(a.defects_json, b.defects_json);
  EXPECT_EQ(a.calibration_json, b.calibration_json);
  ASSERT_EQ(a.characteristics.size(), b.characteristics.size());
  for (std::size_t i = 0; i < a.characteristics.size(); ++i) {
    const CharacteristicRecord &x = a.characteristics[i], &y = b.characteristics[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.type, y.type);
    EXPECT_EQ(x.verdict, y.verdict);
    EXPECT_EQ(x.points, y.points);
    const auto xs = CharacteristicNumbers(x), ys = CharacteristicNumbers(y);
    for (std::size_t k = 0; k < xs.size(); ++k)  // bit-exact, and a NULL survives the trip
      EXPECT_TRUE(*xs[k] == *ys[k] || (std::isnan(*xs[k]) && std::isnan(*ys[k])))
          << x.name << " " << kCharacteristicNumberColumns[k] << ": " << *xs[k] << " vs " << *ys[k];
  }
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (std::size_t i = 0; i < a.triangles.size(); ++i) {
    EXPECT_EQ(a.triangles[i].triangle_id, b.triangles[i].triangle_id);
    EXPECT_EQ(a.triangles[i].mean_mm, b.triangles[i].mean_mm);
  }
}

// Round trip, idempotency, selections, reopening, and SPC on what is stored
// against the textbook formulas computed here on the values as written.
void RoundTripSuite(const std::string& url) {
  auto store = Open(url);
  ASSERT_TRUE(store);
  EXPECT_EQ(*store->SchemaVersion(), LatestSchemaVersion());
  std::vector<PartRecord> written;
  for (int k = 0; k < 30; ++k) {
    written.push_back(MakePart(k % 10 == 9 ? "other" : "cell-a", k));
    EXPECT_EQ(*store->Record(written.back()), true);
  }
  EXPECT_EQ(*store->Record(written[4]), false);  // the same key again: nothing changes
  EXPECT_TRUE(*store->Contains("cell-a", "part-0004"));
  EXPECT_FALSE(*store->Contains("cell-b", "part-0004"));
  PartSelection all;
  all.with_triangles = true;
  auto loaded = store->Load(all);
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  ASSERT_EQ(loaded->size(), 30u);
  for (int k = 0; k < 30; ++k) ExpectSame((*loaded)[k], written[k]);
  PartSelection sel;
  sel.cell = "cell-a";
  sel.last = 5;
  auto last = store->Load(sel);
  ASSERT_EQ(last->size(), 5u);
  EXPECT_EQ(last->back().part_id, "part-0028");
  EXPECT_EQ(last->front().part_id, "part-0024");  // 9, 19 and 29 are the other cell's
  EXPECT_TRUE(last->front().triangles.empty());   // not asked for
  sel = {};
  sel.since_utc = "2026-12-01T08:00:25";
  EXPECT_EQ(store->Load(sel)->size(), 5u);
  store.reset();
  store = Open(url);  // reopening migrates nothing and keeps everything
  EXPECT_EQ(store->Load({})->size(), 30u);
  // SPC of ridge-centre on cell-a from the database = the textbook on the written values.
  sel = {};
  sel.cell = "cell-a";
  auto trend = ComputeTrend(*store->Load(sel), "ridge-centre");
  ASSERT_TRUE(trend.ok());
  std::vector<double> x;
  for (const PartRecord& p : written)
    if (p.cell == "cell-a") x.push_back(p.characteristics[2].value_mm);
  double mean = 0, mr = 0, ss = 0;
  for (double v : x) mean += v / x.size();
  for (std::size_t i = 1; i < x.size(); ++i) mr += std::abs(x[i] - x[i - 1]) / (x.size() - 1);
  for (double v : x) ss += (v - mean) * (v - mean);
  const double sw = mr / 1.128, so = std::sqrt(ss / (x.size() - 1));
  const SpcResult& s = *trend->characteristics[0].spc;
  EXPECT_NEAR(s.cp, 0.2 / (6 * sw), 1e-9);
  EXPECT_NEAR(s.cpk, std::min(0.1 - mean, mean + 0.1) / (3 * sw), 1e-9);
  EXPECT_NEAR(s.pp, 0.2 / (6 * so), 1e-9);
  EXPECT_NEAR(s.ppk, std::min(0.1 - mean, mean + 0.1) / (3 * so), 1e-9);
  EXPECT_NEAR(s.individuals.upper, mean + 3 * sw, 1e-12);
  EXPECT_NEAR(s.moving_range.upper, 3.267 * mr, 1e-12);
}

// Runs `body` in a child process; returns its pid.
pid_t Child(const std::function<int()>& body) {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(body());
  return pid;
}

int Wait(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// Two writers for two cells, 20 parts each, and both racing to record the
// same 5 parts of a third: nothing lost, nothing doubled.
void ConcurrentWriters(const std::string& url) {
  ASSERT_TRUE(Open(url));  // schema made first, so the children only write
  std::vector<pid_t> pids;
  for (const std::string cell : {"cell-a", "cell-b"})
    pids.push_back(Child([url, cell] {
      auto store = OpenResultsStore(url);
      if (!store.ok()) return 10;
      for (int k = 0; k < 20; ++k)
        for (const PartRecord& p : {MakePart(cell, k), MakePart("shared", k % 5)})
          if (!(*store)->Record(p).ok()) return 11;
      return 0;
    }));
  for (pid_t pid : pids) EXPECT_EQ(Wait(pid), 0);
  auto store = Open(url);
  auto parts = store->Load({});
  ASSERT_TRUE(parts.ok());
  std::map<std::string, int> per_cell;
  std::set<std::string> keys;
  for (const PartRecord& p : *parts) {
    ++per_cell[p.cell];
    EXPECT_TRUE(keys.insert(p.cell + "/" + p.part_id).second) << p.part_id;
    EXPECT_EQ(p.characteristics.size(), static_cast<std::size_t>(kCharacteristics));
  }
  EXPECT_EQ(per_cell["cell-a"], 20);
  EXPECT_EQ(per_cell["cell-b"], 20);
  EXPECT_EQ(per_cell["shared"], 5);
}

// A writer killed with SIGKILL in the middle of its parts leaves only whole
// parts; writing everything again (the restart) records each missing part
// once and the others not at all.
void KillMidWrite(const std::string& url) {
  ASSERT_TRUE(Open(url));
  constexpr uint32_t kTriangles = 300000;  // a 6 MB summary: each write takes a while
  const pid_t pid = Child([url] {
    auto store = OpenResultsStore(url);
    if (!store.ok()) return 10;
    for (int k = 0; k < 200; ++k)
      if (!(*store)->Record(MakePart("killed", k, kTriangles)).ok()) return 11;
    return 0;
  });
  // Kill as soon as the second part is in: the writer is then in the middle
  // of the third (each write takes tens of ms; the poll is every 5 ms).
  {
    auto watcher = Open(url);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (std::chrono::steady_clock::now() < deadline) {
      auto there = watcher->Contains("killed", "part-0001");
      if (there.ok() && *there) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  ::kill(pid, SIGKILL);
  EXPECT_EQ(Wait(pid), 128 + SIGKILL);
  auto store = Open(url);
  PartSelection sel;
  sel.cell = "killed";
  sel.with_triangles = true;
  auto parts = store->Load(sel);
  ASSERT_TRUE(parts.ok()) << parts.status();
  ASSERT_GT(parts->size(), 0u) << "killed before the first part; make the writes longer";
  ASSERT_LT(parts->size(), 200u) << "the writer finished; kill it sooner";
  for (const PartRecord& p : *parts) {
    EXPECT_EQ(p.characteristics.size(), static_cast<std::size_t>(kCharacteristics)) << p.part_id;
    const int k = std::stoi(p.part_id.substr(5));
    EXPECT_EQ(p.triangles.size(), MakePart("killed", k, kTriangles).triangles.size()) << p.part_id;
  }
  const std::size_t before = parts->size();
  int written = 0;
  for (int k = 0; k < static_cast<int>(before) + 3; ++k)
    written += *store->Record(MakePart("killed", k, 10));
  EXPECT_EQ(written, 3);
  sel.with_triangles = false;
  EXPECT_EQ(store->Load(sel)->size(), before + 3);
}

std::string TrendJsonOf(const std::string& url) {
  auto store = Open(url);
  for (int k = 0; k < 30; ++k) EXPECT_TRUE(store->Record(MakePart("same", k)).ok());
  PartSelection sel;
  sel.cell = "same";
  sel.with_triangles = true;
  auto trend = ComputeTrend(*store->Load(sel));
  EXPECT_TRUE(trend.ok()) << trend.status();
  return TrendJson(*trend, {{"cell", "same"}}).dump(2);
}

TEST(SqliteStore, RoundTripIdempotencySelectionsAndSpc) {
  TempDir dir;
  RoundTripSuite(dir.File("results.db"));
}

TEST(SqliteStore, ConcurrentWriters) {
  TempDir dir;
  ConcurrentWriters(dir.File("results.db"));
}

TEST(SqliteStore, KillMidWriteLeavesWholePartsOnly) {
  TempDir dir;
  KillMidWrite(dir.File("results.db"));
}

// surfinspect trend reads while the agent writes: WAL lets it.
TEST(SqliteStore, ReaderDuringWrites) {
  TempDir dir;
  const std::string db = dir.File("results.db");
  ASSERT_TRUE(Open(db));
  const pid_t pid = Child([db] {
    auto store = OpenResultsStore(db);
    if (!store.ok()) return 10;
    for (int k = 0; k < 60; ++k)
      if (!(*store)->Record(MakePart("w", k, 20000)).ok()) return 11;
    return 0;
  });
  auto reader = Open(db);
  std::size_t seen = 0;
  int reads = 0;
  for (;; ++reads) {
    auto parts = reader->Load({});
    ASSERT_TRUE(parts.ok()) << parts.status();
    EXPECT_GE(parts->size(), seen);
    seen = parts->size();
    for (const PartRecord& p : *parts)
      ASSERT_EQ(p.characteristics.size(), static_cast<std::size_t>(kCharacteristics));
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid) {
      EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
      break;
    }
  }
  EXPECT_GT(reads, 1);
  EXPECT_EQ(reader->Load({})->size(), 60u);
}

void ExecSqlite(const std::string& path, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  EXPECT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
}

TEST(SqliteStore, BadDatabasesAreNamed) {
  TempDir dir;
  testing::WriteBytes(dir.File("text.db"), "this is not a database, it is a text file\n");
  auto st = OpenResultsStore(dir.File("text.db")).status();
  EXPECT_NE(st.message().find(dir.File("text.db")), std::string::npos) << st;
  EXPECT_NE(st.message().find("not an SQLite database"), std::string::npos) << st;
  ExecSqlite(dir.File("foreign.db"), "CREATE TABLE invoices (id INTEGER)");
  st = OpenResultsStore(dir.File("foreign.db")).status();
  EXPECT_NE(st.message().find("foreign database"), std::string::npos) << st;
  ExecSqlite(dir.File("other.db"),
             "CREATE TABLE schema_version (application TEXT, version INT);"
             "INSERT INTO schema_version VALUES ('someone.else', 1)");
  st = OpenResultsStore(dir.File("other.db")).status();
  EXPECT_NE(st.message().find("foreign database"), std::string::npos) << st;
  ASSERT_TRUE(Open(dir.File("newer.db")));
  ExecSqlite(dir.File("newer.db"), "UPDATE schema_version SET version = 99");
  st = OpenResultsStore(dir.File("newer.db")).status();
  EXPECT_EQ(st.code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_NE(st.message().find("schema version 99 is newer"), std::string::npos) << st;
  st = OpenResultsStore(dir.File("no/such/folder/x.db")).status();
  EXPECT_NE(st.message().find("no/such/folder/x.db"), std::string::npos) << st;
}

TEST(ResultsStore, UrlsAreLoggedWithoutPassword) {
  EXPECT_EQ(RedactDatabaseUrl("postgresql://qa:s3cret@db.plant:5432/results"),
            "postgresql://qa:***@db.plant:5432/results");
  EXPECT_EQ(RedactDatabaseUrl("postgres://db/results?user=qa&password=s3cret&sslmode=require"),
            "postgres://db/results?user=qa&password=***&sslmode=require");
  EXPECT_EQ(RedactDatabaseUrl("postgresql://qa@db/results"), "postgresql://qa@db/results");
  EXPECT_EQ(RedactDatabaseUrl("results/results.db"), "results/results.db");
  // A server that is not there: the error names the URL, never the password.
  const auto st = OpenResultsStore("postgresql://qa:s3cret@127.0.0.1:1/results").status();
  EXPECT_FALSE(st.ok());
  EXPECT_EQ(std::string(st.message()).find("s3cret"), std::string::npos) << st;
  EXPECT_NE(st.message().find("postgresql://qa:***@127.0.0.1:1/results"), std::string::npos);
}

// One server for the whole PostgreSQL suite (initdb takes seconds).
TEST(PostgresStore, SuiteConcurrencyKillAndSameTrendAsSqlite) {
  PostgresServer pg;
  ASSERT_TRUE(pg.available()) << pg.error();
  {
    SCOPED_TRACE("round trip");
    RoundTripSuite(pg.Url("roundtrip"));
  }
  {
    SCOPED_TRACE("two writers");
    ConcurrentWriters(pg.Url("concurrent"));
  }
  {
    SCOPED_TRACE("kill -9");
    KillMidWrite(pg.Url("killed"));
  }
  TempDir dir;
  EXPECT_EQ(TrendJsonOf(pg.Url("same")), TrendJsonOf(dir.File("same.db")));
  // A foreign database and a newer schema, named.
  const std::string psql = "/usr/lib/postgresql/15/bin/psql -q -d ";
  ASSERT_EQ(
      std::system((psql + pg.Url("foreign") + " -c 'CREATE TABLE invoices (id INT)'").c_str()), 0);
  auto st = OpenResultsStore(pg.Url("foreign")).status();
  EXPECT_NE(st.message().find("foreign database"), std::string::npos) << st;
  EXPECT_NE(st.message().find("/foreign"), std::string::npos) << st;
  ASSERT_TRUE(Open(pg.Url("newer")));
  ASSERT_EQ(
      std::system((psql + pg.Url("newer") + " -c 'UPDATE schema_version SET version = 7'").c_str()),
      0);
  st = OpenResultsStore(pg.Url("newer")).status();
  EXPECT_NE(st.message().find("schema version 7 is newer"), std::string::npos) << st;
}

}  // namespace
}  // namespace surfinspect
