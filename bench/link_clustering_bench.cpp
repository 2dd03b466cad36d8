// Link-clustering filter against PCL on the same points with the
// same link distance (the default, 0.5 mm), single thread:
//  * a 1024x768 organized demo scan (noise, 0.3% pulses, stripes): our grid
//    path (8- and 4-neighbours) vs PCL OrganizedConnectedComponentSegmentation
//    with EuclideanClusterComparator (4-neighbours, its only mode);
//  * the same scan's valid points as an unorganized cloud, and 10^6 points of
//    a denser scan: our voxel path vs PCL EuclideanClusterExtraction (kd-tree,
//    tree build included, as our sort is).
// Also our grid path with the inspection preset (0.85 mm), and the floor: one
// read of the 9.4 MB scan. Goals: grid median <= 5 ms; >= 20x the faster PCL
// method. The medians and ratios are printed at the end. Pin to one core:
//   taskset -c 1 build/bin/link_clustering_bench
#include <benchmark/benchmark.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/euclidean_cluster_comparator.h>
#include <pcl/segmentation/extract_clusters.h>
#include <pcl/segmentation/organized_connected_component_segmentation.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <random>

#include "bench/clustering_inputs.h"
#include "core/filter/link_clustering.h"
#include "core/filter/link_clustering_grid.h"
#include "core/filter/link_clustering_unorganized.h"
#include "core/simulation/demo_cell.h"
#include "core/simulation/scan_simulator.h"

namespace {

using namespace surfinspect;
using bench::DemoScan;
using bench::Shuffled;
using bench::ToPcl;

const LinkClusteringSettings kSettings;  // the defaults: 0.5 mm, 50 points, 8 neighbours

struct Data {
  PointCloud scan = DemoScan(1024, 768);
  PointCloud scan_points = Shuffled(scan, SIZE_MAX);
  // 1448 x 1086 over the same field of view: 0.17 mm pitch, ~10^6 hits.
  PointCloud million = Shuffled(DemoScan(1448, 1086), 1'000'000);
  pcl::PointCloud<pcl::PointXYZ>::Ptr pcl_scan = ToPcl(scan);
  pcl::PointCloud<pcl::PointXYZ>::Ptr pcl_scan_points = ToPcl(scan_points);
  pcl::PointCloud<pcl::PointXYZ>::Ptr pcl_million = ToPcl(million);
};
const Data& GetData() {
  static const Data d;
  return d;
}

void Report(benchmark::State& state, const LinkClusteringResult& r) {
  state.counters["points"] = double(r.valid_points);
  state.counters["clusters"] = double(r.clusters.size());
  state.counters["removed"] = double(r.removed);
}

void BM_OursGrid(benchmark::State& state) {
  LinkClusteringSettings s = kSettings;
  s.connectivity = static_cast<int>(state.range(0));
  LinkClusteringResult r;  // reused: the steady state of a scan stream
  for (auto _ : state) {
    if (!ClusterLinksOrganized(GetData().scan, s, r).ok()) state.SkipWithError("failed");
    benchmark::DoNotOptimize(r.labels.data());
  }
  Report(state, r);
}

// The floor: one streaming read of the 9.4 MB scan (sum of all floats).
void BM_ReadScanOnce(benchmark::State& state) {
  const PointCloud& scan = GetData().scan;
  for (auto _ : state) {
    const float* f = scan.points[0].data();
    float acc[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    for (std::size_t i = 0; i + 8 <= 3 * scan.size(); i += 8)
      for (int j = 0; j < 8; ++j) acc[j] += f[i + j];
    benchmark::DoNotOptimize(acc);
  }
}

void BM_OursGridInspectionPreset(benchmark::State& state) {
  LinkClusteringResult r;
  for (auto _ : state) {
    if (!ClusterLinksOrganized(GetData().scan, LinkClusteringSettings::ForInspection(), r).ok())
      state.SkipWithError("failed");
    benchmark::DoNotOptimize(r.labels.data());
  }
  Report(state, r);
}

void BM_OursGridFreshResult(benchmark::State& state) {
  for (auto _ : state) {
    auto r = ClusterLinks(GetData().scan, kSettings);
    benchmark::DoNotOptimize(r);
  }
}

void BM_PclOrganizedComponents(benchmark::State& state) {
  auto comparator = std::make_shared<pcl::EuclideanClusterComparator<pcl::PointXYZ, pcl::Label>>();
  comparator->setInputCloud(GetData().pcl_scan);
  comparator->setDistanceThreshold(static_cast<float>(kSettings.link_distance_mm), false);
  pcl::OrganizedConnectedComponentSegmentation<pcl::PointXYZ, pcl::Label> seg(comparator);
  seg.setInputCloud(GetData().pcl_scan);
  std::size_t clusters = 0;
  for (auto _ : state) {
    pcl::PointCloud<pcl::Label> labels;
    std::vector<pcl::PointIndices> indices;
    seg.segment(labels, indices);
    clusters = indices.size();
    benchmark::DoNotOptimize(labels.data());
  }
  state.counters["clusters"] = double(clusters);
}

void OursUnorganized(benchmark::State& state, const PointCloud& cloud) {
  LinkClusteringResult r;
  for (auto _ : state) {
    if (!ClusterLinksUnorganized(cloud, kSettings, r).ok()) state.SkipWithError("failed");
    benchmark::DoNotOptimize(r.labels.data());
  }
  Report(state, r);
}
void BM_OursUnorganizedScan(benchmark::State& s) { OursUnorganized(s, GetData().scan_points); }
void BM_OursUnorganizedMillion(benchmark::State& s) { OursUnorganized(s, GetData().million); }

void PclEuclidean(benchmark::State& state, const pcl::PointCloud<pcl::PointXYZ>::Ptr& cloud) {
  std::size_t clusters = 0;
  for (auto _ : state) {
    auto tree = std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>();
    pcl::EuclideanClusterExtraction<pcl::PointXYZ> ece;
    ece.setClusterTolerance(kSettings.link_distance_mm);
    ece.setMinClusterSize(1);
    ece.setMaxClusterSize(std::numeric_limits<int>::max());
    ece.setSearchMethod(tree);
    ece.setInputCloud(cloud);
    std::vector<pcl::PointIndices> indices;
    ece.extract(indices);  // builds the kd-tree on the cloud
    clusters = indices.size();
  }
  state.counters["points"] = double(cloud->size());
  state.counters["clusters"] = double(clusters);
}
void BM_PclEuclideanScan(benchmark::State& s) { PclEuclidean(s, GetData().pcl_scan_points); }
void BM_PclEuclideanMillion(benchmark::State& s) { PclEuclidean(s, GetData().pcl_million); }

#define FAST(bm) \
  BENCHMARK(bm)->Unit(benchmark::kMillisecond)->Repetitions(9)->ReportAggregatesOnly(true)
FAST(BM_OursGrid)->Arg(8)->Arg(4);
FAST(BM_OursGridInspectionPreset);
FAST(BM_OursGridFreshResult);
FAST(BM_ReadScanOnce);
FAST(BM_PclOrganizedComponents);
FAST(BM_OursUnorganizedScan);
FAST(BM_OursUnorganizedMillion);
BENCHMARK(BM_PclEuclideanScan)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);
BENCHMARK(BM_PclEuclideanMillion)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);

// Keeps each benchmark's median real time (seconds) for the ratio table.
class MedianReporter : public benchmark::ConsoleReporter {
 public:
  using ConsoleReporter::ConsoleReporter;
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs)
      if (r.aggregate_name == "median")
        median_s[r.run_name.function_name +
                 (r.run_name.args.empty() ? "" : "/" + r.run_name.args)] =
            r.GetAdjustedRealTime() / benchmark::GetTimeUnitMultiplier(r.time_unit);
    ConsoleReporter::ReportRuns(runs);
  }
  std::map<std::string, double> median_s;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  GetData();  // simulate before timing anything
  MedianReporter reporter(isatty(STDOUT_FILENO) ? benchmark::ConsoleReporter::OO_ColorTabular
                                                : benchmark::ConsoleReporter::OO_Tabular);
  benchmark::RunSpecifiedBenchmarks(&reporter);
  const auto& m = reporter.median_s;
  auto get = [&](const char* k) {
    auto it = m.find(k);
    return it == m.end() ? 0.0 : it->second;
  };
  auto ratio = [&](const char* peer, const char* ours) {
    if (get(peer) > 0 && get(ours) > 0)
      std::printf("  %-28s %9.3f ms / %-24s %8.3f ms = %7.1fx\n", peer, 1e3 * get(peer), ours,
                  1e3 * get(ours), get(peer) / get(ours));
  };
  std::printf("\nMedians and ratios (PCL / ours), link %.2f mm:\n", kSettings.link_distance_mm);
  ratio("BM_PclOrganizedComponents", "BM_OursGrid/8");
  ratio("BM_PclOrganizedComponents", "BM_OursGrid/4");
  ratio("BM_PclEuclideanScan", "BM_OursGrid/8");
  ratio("BM_PclEuclideanScan", "BM_OursUnorganizedScan");
  ratio("BM_PclEuclideanMillion", "BM_OursUnorganizedMillion");
  const double ours = get("BM_OursGrid/8");
  const double pcl_grid = get("BM_PclOrganizedComponents"), pcl_ece = get("BM_PclEuclideanScan");
  if (ours > 0)
    std::printf("Grid path (8-nb) median %.3f ms: goal <= 5 ms %s\n", 1e3 * ours,
                ours <= 5e-3 ? "met" : "NOT met");
  if (ours > 0 && pcl_grid > 0 && pcl_ece > 0) {
    const double ratio = std::min(pcl_grid, pcl_ece) / ours;
    std::printf("Faster PCL method / grid path = %.1fx: goal >= 20x %s\n", ratio,
                ratio >= 20 ? "met" : "NOT met");
  }
  benchmark::Shutdown();
  return 0;
}
