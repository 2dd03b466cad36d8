// The results store's speed: recording one part in SQLite (the agent does it
// once per part; budget 20 ms) and the whole trend over 1,000 parts with 50
// characteristics each and the demo part's 4,440-triangle summaries (read,
// SPC, rules, drift lines, trend map, trend.json and trend.html; budget 2 s).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <random>

#include "absl/strings/str_format.h"
#include "core/history/results_store.h"
#include "core/history/trend.h"
#include "core/history/trend_html.h"

namespace surfinspect {
namespace {

constexpr uint32_t kTriangles = 4440;  // the demo part

PartRecord BenchPart(int k, int characteristics) {
  std::mt19937_64 rng(k);
  std::normal_distribution<double> noise(0, 0.015);
  PartRecord p;
  p.cell = "bench";
  p.part_id = absl::StrFormat("part-%06d", k);
  p.inspected_utc =
      absl::StrFormat("2026-12-01T%02d:%02d:%02d.000000Z", k / 3600, k / 60 % 60, k % 60);
  p.software_version = "0.1.0";
  p.verdict = "pass";
  for (int c = 0; c < characteristics; ++c) {
    CharacteristicRecord r;
    r.name = absl::StrFormat("point-%02d", c);
    r.type = "point";
    r.value_mm = r.mean_mm = noise(rng);
    r.lower_mm = -0.1;
    r.upper_mm = 0.1;
    r.verdict = "pass";
    p.characteristics.push_back(r);
  }
  p.num_triangles = kTriangles;
  for (uint32_t t = 0; t < kTriangles; ++t)
    p.triangles.push_back({t, 400, static_cast<float>(noise(rng)), -0.05f, 0.05f});
  return p;
}

std::string TempDb(const std::string& name) {
  const std::string path = absl::StrFormat("/tmp/surfinspect-bench-%d-%s", ::getpid(), name);
  std::filesystem::remove(path);
  std::filesystem::remove(path + "-wal");
  std::filesystem::remove(path + "-shm");
  return path;
}

// One part with 5 characteristics and its triangle summary, one transaction.
void BM_RecordPartSqlite(benchmark::State& state) {
  const std::string db = TempDb("record.db");
  auto store = OpenResultsStore(db);
  if (!store.ok()) state.SkipWithError(std::string(store.status().message()).c_str());
  int k = 0;
  for (auto _ : state) {
    state.PauseTiming();
    const PartRecord part = BenchPart(k++, 5);
    state.ResumeTiming();
    if (!(*store)->Record(part).ok()) state.SkipWithError("record failed");
  }
  std::filesystem::remove(db);
}
BENCHMARK(BM_RecordPartSqlite)->Unit(benchmark::kMillisecond);

void BM_Trend1000PartsX50(benchmark::State& state) {
  const std::string db = TempDb("trend.db");
  auto store = OpenResultsStore(db);
  if (!store.ok()) state.SkipWithError(std::string(store.status().message()).c_str());
  for (int k = 0; k < 1000; ++k) (void)(*store)->Record(BenchPart(k, 50));
  std::size_t bytes = 0;
  for (auto _ : state) {
    auto reader = OpenResultsStore(db);
    PartSelection sel;
    sel.with_triangles = true;
    auto parts = (*reader)->Load(sel);
    auto trend = ComputeTrend(*parts);
    const std::string json = TrendJson(*trend, {}).dump(2);
    const std::string html = TrendHtml(*trend, "bench", "");
    bytes = json.size() + html.size();
    if (trend->characteristics.size() != 50) state.SkipWithError("wrong trend");
  }
  state.counters["output_bytes"] = static_cast<double>(bytes);
  std::filesystem::remove(db);
}
BENCHMARK(BM_Trend1000PartsX50)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace surfinspect

BENCHMARK_MAIN();
