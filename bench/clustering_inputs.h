// The link-clustering benchmarks' inputs, shared by the Google Benchmark
// program and the peer table: a simulated demo scan, the same points
// unorganized, and the same points as a PCL cloud for the peers.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <memory>
#include <random>
#include <vector>

#include "core/simulation/demo_cell.h"
#include "core/simulation/scan_simulator.h"

namespace surfinspect::bench {

// Viewpoint 3 of the demo cell at width x height, with noise, pulses and
// stripes; an empty cloud if the simulation fails.
inline PointCloud DemoScan(uint32_t width, uint32_t height) {
  const DemoCell cell = MakeDemoCell();
  SensorIntrinsics in = cell.intrinsics;
  in.width = width;
  in.height = height;
  ScanOptions opt;
  opt.noise_sigma_mm = 0.015;
  opt.pulse_fraction = 0.003;
  opt.stripes = true;
  auto scan =
      SimulateScan(cell.part, cell.world_from_part, cell.viewpoints[2].world_from_sensor, in, opt);
  if (!scan.ok()) return {};
  return std::move(scan->cloud_in_sensor);
}

// Valid points in a fixed random order (an unorganized cloud has no order).
inline PointCloud Shuffled(const PointCloud& c, std::size_t max_points) {
  std::vector<Eigen::Vector3f> pts;
  c.ForEachValid([&](std::size_t, const Eigen::Vector3f& p) { pts.push_back(p); });
  std::shuffle(pts.begin(), pts.end(), std::mt19937(1));
  if (pts.size() > max_points) pts.resize(max_points);
  return PointCloud::Unorganized(std::move(pts));
}

inline pcl::PointCloud<pcl::PointXYZ>::Ptr ToPcl(const PointCloud& c) {
  auto out = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  out->resize(c.size());
  out->width = c.width;
  out->height = c.height;
  out->is_dense = false;
  for (std::size_t i = 0; i < c.size(); ++i)
    (*out)[i] = pcl::PointXYZ(c.points[i].x(), c.points[i].y(), c.points[i].z());
  return out;
}

}  // namespace surfinspect::bench
