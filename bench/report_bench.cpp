// report.pdf generation time (goal: <= 1 s) for a 2 M-point part: a merged
// (unorganized) cloud drawn as three views, and a 1632 x 1232 organized single
// view drawn as its sensor grid, each with 40 characteristics and 12 defects.
// Counts the whole RenderPdfReport call: the map rasters, the PDF's drawing,
// its compressed images and embedded font subsets. The PDF's size is the
// `bytes` counter.
//
//   build/bin/report_bench [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "core/pipeline/inspection_report.h"
#include "core/report/pdf_report.h"

namespace {

using namespace surfinspect;

// A hat-shaped sheet part, 300 x 200 mm with 40 mm walls: a top, four walls
// and a flange, so each of the three views shows something.
Eigen::Vector3f HatPoint(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0, 1);
  const float s = u(rng), t = u(rng);
  switch (static_cast<int>(u(rng) * 4)) {
    case 0:
      return {300 * s - 150, 200 * t - 100, 40};  // top
    case 1:
      return {300 * s - 150, u(rng) < 0.5f ? -100.f : 100.f, 40 * t};  // long walls
    case 2:
      return {u(rng) < 0.5f ? -150.f : 150.f, 200 * s - 100, 40 * t};  // short walls
    default:
      return {380 * s - 190, 280 * t - 140, 0};  // flange
  }
}

float Deviation(const Eigen::Vector3f& p, std::mt19937& rng) {
  std::normal_distribution<float> noise(0, 0.02f);
  if (std::uniform_real_distribution<float>(0, 1)(rng) < 0.002f) return NAN;  // unmatched
  return 0.15f * std::sin(p.x() / 30) * std::cos(p.y() / 40) + noise(rng);
}

nlohmann::json Report(const std::vector<float>& dev) {
  ErrorMapResult r;
  r.deviation_mm = dev;
  r.tolerance_mm = 0.1;
  r.color_range_mm = 0.25;
  r.histogram.min_mm = -0.25;
  r.histogram.max_mm = 0.25;
  r.histogram.counts.assign(41, 0);
  for (float d : dev) {
    if (std::isnan(d)) continue;
    ++r.stats.matched;
    const int k = static_cast<int>(std::floor((d + 0.25) / 0.5 * 41));
    if (k >= 0 && k < 41) ++r.histogram.counts[k];
  }
  r.stats.count = r.stats.valid = dev.size();
  r.verdict.reason = "synthetic";
  nlohmann::json j = ErrorMapReportJson(r, ErrorMapSettings{});
  j["verdict"] = "fail";
  j["characteristics"] = nlohmann::json::array();
  for (int i = 0; i < 40; ++i)
    j["characteristics"].push_back({{"name", "region-" + std::to_string(i)},
                                    {"type", i % 4 ? "region" : "point"},
                                    {"verdict", i % 7 ? "pass" : "fail"},
                                    {"reason", "r"},
                                    {"tolerance_mm", {{"lower", -0.1}, {"upper", 0.1}}},
                                    {"points", 1000 + i},
                                    {"min_mm", -0.05},
                                    {"max_mm", 0.07},
                                    {"mean_mm", 0.001 * i},
                                    {"value_mm", 0.002 * i},
                                    {"fraction_within", 0.99}});
  j["defects"] = nlohmann::json::array();
  for (int i = 1; i <= 12; ++i)
    j["defects"].push_back({{"id", i},
                            {"kind", i % 2 ? "dent" : "bump"},
                            {"centroid_mm", {-120 + 20 * i, 10.0 * (i % 5), 40}},
                            {"area_mm2", 20.0},
                            {"extent_mm", 5.0},
                            {"peak_mm", -0.2},
                            {"points", 300},
                            {"region", "region-" + std::to_string(i)}});
  return j;
}

struct Part {
  PointCloud cloud;
  std::vector<float> deviation;
  InspectionReport report;
};

const Part& Get(bool organized) {
  static Part parts[2];
  Part& p = parts[organized];
  if (!p.cloud.points.empty()) return p;
  std::mt19937 rng(7);
  constexpr uint32_t kW = 1632, kH = 1232;  // 2.01 M points
  std::vector<Eigen::Vector3f> pts;
  pts.reserve(std::size_t{kW} * kH);
  for (uint32_t i = 0; i < kW * kH; ++i) {
    const Eigen::Vector3f q =
        organized ? Eigen::Vector3f(300.f * (i % kW) / kW - 150, 200.f * (i / kW) / kH - 100,
                                    2 * std::sin(0.05f * (i % kW)))
                  : HatPoint(rng);
    pts.push_back(q);
    p.deviation.push_back(Deviation(q, rng));
  }
  if (organized) {
    p.cloud.width = kW;
    p.cloud.height = kH;
    p.cloud.points = std::move(pts);
  } else {
    p.cloud = PointCloud::Unorganized(std::move(pts));
  }
  p.report = *DecodeReport(Report(p.deviation));
  return p;
}

void RunPdf(benchmark::State& state, bool organized) {
  const Part& p = Get(organized);
  PdfReportInput in;
  in.part_id = "bench-part";
  in.cell = "bench-cell";
  in.report = &p.report;
  in.points_in_part = &p.cloud;
  in.deviation_mm = &p.deviation;
  std::size_t bytes = 0;
  for (auto _ : state) {
    auto pdf = RenderPdfReport(in);
    if (!pdf.ok()) state.SkipWithError(std::string(pdf.status().message()).c_str());
    bytes = pdf.ok() ? pdf->size() : 0;
    benchmark::DoNotOptimize(bytes);
  }
  state.counters["points"] = static_cast<double>(p.cloud.size());
  state.counters["bytes"] = static_cast<double>(bytes);
}

void BM_PdfReportMerged2M(benchmark::State& state) { RunPdf(state, false); }
void BM_PdfReportGrid2M(benchmark::State& state) { RunPdf(state, true); }
BENCHMARK(BM_PdfReportMerged2M)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_PdfReportGrid2M)->Unit(benchmark::kMillisecond)->Iterations(5);

}  // namespace

BENCHMARK_MAIN();
