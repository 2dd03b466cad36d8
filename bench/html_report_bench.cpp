// The HTML report's cost on top of the error map: BuildHtmlReport (thinning
// to 1 M shown points, packing, base64, the page) for a 2 M-point part on a
// 5 k-triangle wavy sheet, and the page's size (goals: <= 0.5 s, <= ~30 MB).
// The page's time to interactive in headless Chromium is measured by the
// browser test (tests/report/html_browser_test.py prints it).
//
//   build/bin/html_report_bench [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "bench/wavy_sheet.h"
#include "core/pipeline/inspection_report.h"
#include "core/report/html_report.h"

namespace {

using namespace surfinspect;

struct Part {
  TriangleMesh mesh = bench::WavySheet(50, 300);  // 5000 triangles
  PointCloud points;
  std::vector<float> deviation;
  InspectionReport report;
};

// 2 M points on the sheet (1414 x 1414 grid, 0.21 mm pitch), noise of
// 0.015 mm, a 0.4 mm dent, 1% unmatched.
const Part& Get() {
  static const Part part = [] {
    Part p;
    std::mt19937 rng(1);
    std::normal_distribution<float> noise(0, 0.015f);
    const int n = 1414;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double x = 300.0 * (i + 0.5) / n - 150, y = 300.0 * (j + 0.5) / n - 150;
        const double dent = -0.4 * std::exp(-((x - 30) * (x - 30) + y * y) / 50.0);
        const float d = static_cast<float>(dent) + noise(rng);
        const double z = 3.0 * std::sin(x / 20.0) * std::cos(y / 25.0) + d;
        p.points.points.emplace_back(x, y, z);
        p.deviation.push_back((i * 7 + j * 13) % 100 == 0 ? NAN : d);
      }
    p.points.width = static_cast<uint32_t>(p.points.points.size());
    p.points.height = 1;
    p.report = *DecodeReport(
        nlohmann::json{{"schema", "surfinspect.report/2"},
                       {"verdict", "fail"},
                       {"color_range_mm", 0.5},
                       {"tolerance", {{"band_mm", 0.1}, {"reason", "bench"}}},
                       {"points", {{"count", p.points.size()}}},
                       {"statistics", {{"min_mm", -0.45}, {"max_mm", 0.07}}},
                       {"histogram", {{"min_mm", -0.5}, {"max_mm", 0.5}, {"counts", {1, 2, 3}}}},
                       {"defects", {{{"id", 1}, {"kind", "dent"}, {"centroid_mm", {30, 0, 0}}}}}});
    return p;
  }();
  return part;
}

void BM_HtmlReport2M(benchmark::State& state) {
  const Part& p = Get();
  HtmlReportInput in;
  in.report = &p.report;
  in.points_in_part = &p.points;
  in.deviation_mm = &p.deviation;
  in.mesh_in_part = &p.mesh;
  in.context.part_id = "bench";
  std::size_t bytes = 0, shown = 0;
  double payload = 0;
  for (auto _ : state) {
    auto page = BuildHtmlReport(in);
    if (!page.ok()) {
      state.SkipWithError(std::string(page.status().message()).c_str());
      return;
    }
    bytes = page->html.size();
    shown = page->shown_points;
    payload = page->payload_seconds;
    benchmark::DoNotOptimize(page->html.data());
  }
  state.counters["page_MB"] = bytes / 1e6;
  state.counters["shown_points"] = static_cast<double>(shown);
  state.counters["payload_s"] = payload;
  std::fprintf(stderr, "html report, %zu points: %.1f MB page, %zu shown (goal <= 30 MB)\n",
               p.points.size(), bytes / 1e6, shown);
}
BENCHMARK(BM_HtmlReport2M)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

}  // namespace

BENCHMARK_MAIN();
