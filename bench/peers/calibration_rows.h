// Gauge calibration against PCL and Open3D ICP on the same scan:
// the demo cell's v1 gauge scan (1024x768, 0.015 mm noise, no outliers so
// the peers need no filter), the truth gauge_from_sensor, and two starting
// guesses: the truth moved by 1 mm / 0.5 deg (a case the peers can handle),
// and the demo robot's nominal pose (3 mm / 2 deg off).
//  * ours: MeshIndex::Build + CalibrateViewpoint with its defaults (link
//    filter, coarse rotation search, point-to-plane ICP against the mesh);
//  * PCL IterativeClosestPoint (point-to-point) and
//    IterativeClosestPointWithNormals (point-to-plane LLS), and Open3D
//    RegistrationICP with TransformationEstimationPointToPlane: a random
//    40,000-point subsample of the scan (our ICP's default subsample size)
//    against a dense area-weighted sampling of the gauge mesh with exact face
//    normals, max. 100 iterations, a fixed correspondence gate that covers
//    the starting error (10 mm, resp. 25 mm). Their kd-tree builds are timed.
// Reported: time and final pose error (sensor origin, rotation) vs truth.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/icp.h>

#include <random>

#include "bench/peers/report.h"
#include "core/registration/calibration.h"
#include "core/simulation/demo_cell.h"
#include "core/types/transform.h"
#ifdef SURFINSPECT_HAVE_OPEN3D
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>
#endif

namespace surfinspect::bench {

namespace calibration_detail {

struct Sample {
  std::vector<Eigen::Vector3f> points, normals;
};

// ~density points per mm² on every triangle, uniform by area.
inline Sample SampleMesh(const TriangleMesh& m, double density_per_mm2, uint64_t seed) {
  std::vector<double> cum;
  double area = 0;
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d a = m.vertices[t[0]].cast<double>(), b = m.vertices[t[1]].cast<double>(),
                          c = m.vertices[t[2]].cast<double>();
    area += 0.5 * (b - a).cross(c - a).norm();
    cum.push_back(area);
  }
  const auto n = std::size_t(area * density_per_mm2);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0, 1);
  Sample s;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k =
        std::size_t(std::lower_bound(cum.begin(), cum.end(), u01(rng) * area) - cum.begin());
    const auto& t = m.triangles[std::min(k, m.triangles.size() - 1)];
    const Eigen::Vector3d a = m.vertices[t[0]].cast<double>(), b = m.vertices[t[1]].cast<double>(),
                          c = m.vertices[t[2]].cast<double>();
    double r1 = u01(rng), r2 = u01(rng);
    if (r1 + r2 > 1) r1 = 1 - r1, r2 = 1 - r2;
    s.points.push_back((a + r1 * (b - a) + r2 * (c - a)).cast<float>());
    s.normals.push_back((b - a).cross(c - a).normalized().cast<float>());
  }
  return s;
}

inline std::vector<Eigen::Vector3f> Subsample(const PointCloud& c, std::size_t n, uint64_t seed) {
  std::vector<Eigen::Vector3f> pts;
  c.ForEachValid([&](std::size_t, const Eigen::Vector3f& p) { pts.push_back(p); });
  std::shuffle(pts.begin(), pts.end(), std::mt19937_64(seed));
  if (pts.size() > n) pts.resize(n);
  return pts;
}

inline std::string PoseError(const Eigen::Isometry3d& truth, const Eigen::Isometry3d& est) {
  const PoseDifference d = ComparePoses(truth, est);
  return Fmt("%.3f mm", d.translation_mm) + Fmt(" / %.3f°", d.rotation_deg);
}

struct PeerResult {
  double seconds = 0;
  Eigen::Isometry3d gauge_from_sensor = Eigen::Isometry3d::Identity();
};

// The same stopping rules for both PCL ICP variants: 100 iterations, no
// early stop on small steps, correspondences within the gate.
template <typename Icp, typename Cloud>
void ConfigurePclIcp(Icp& icp, const Cloud& source, const Cloud& target, double gate_mm) {
  icp.setInputSource(source);
  icp.setInputTarget(target);
  icp.setMaxCorrespondenceDistance(gate_mm);
  icp.setMaximumIterations(100);
  icp.setTransformationEpsilon(1e-10);
  icp.setEuclideanFitnessEpsilon(1e-10);
}

inline PeerResult PclPointToPoint(const std::vector<Eigen::Vector3f>& src, const Sample& tgt,
                                  const Eigen::Isometry3d& init, double gate_mm) {
  auto s = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  auto t = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (const auto& p : src) s->push_back({p.x(), p.y(), p.z()});
  for (const auto& p : tgt.points) t->push_back({p.x(), p.y(), p.z()});
  PeerResult r;
  r.seconds = MedianSeconds(1, false, [&] {
    pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> icp;
    ConfigurePclIcp(icp, s, t, gate_mm);
    pcl::PointCloud<pcl::PointXYZ> out;
    icp.align(out, init.matrix().cast<float>());
    r.gauge_from_sensor.matrix() = icp.getFinalTransformation().cast<double>();
  });
  return r;
}

inline PeerResult PclPointToPlane(const std::vector<Eigen::Vector3f>& src, const Sample& tgt,
                                  const Eigen::Isometry3d& init, double gate_mm) {
  using P = pcl::PointNormal;
  auto s = std::make_shared<pcl::PointCloud<P>>();
  auto t = std::make_shared<pcl::PointCloud<P>>();
  auto make = [](const Eigen::Vector3f& p, const Eigen::Vector3f& n) {
    P q;
    q.getVector3fMap() = p;
    q.getNormalVector3fMap() = n;
    q.curvature = 0;
    return q;
  };
  for (const auto& p : src) s->push_back(make(p, Eigen::Vector3f::Zero()));
  for (std::size_t i = 0; i < tgt.points.size(); ++i)
    t->push_back(make(tgt.points[i], tgt.normals[i]));
  PeerResult r;
  r.seconds = MedianSeconds(1, false, [&] {
    pcl::IterativeClosestPointWithNormals<P, P> icp;  // point-to-plane LLS on the target normals
    ConfigurePclIcp(icp, s, t, gate_mm);
    pcl::PointCloud<P> out;
    icp.align(out, init.matrix().cast<float>());
    r.gauge_from_sensor.matrix() = icp.getFinalTransformation().cast<double>();
  });
  return r;
}

#ifdef SURFINSPECT_HAVE_OPEN3D
inline PeerResult Open3dPointToPlane(const std::vector<Eigen::Vector3f>& src, const Sample& tgt,
                                     const Eigen::Isometry3d& init, double gate_mm) {
  namespace reg = open3d::pipelines::registration;
  open3d::geometry::PointCloud s, t;
  for (const auto& p : src) s.points_.push_back(p.cast<double>());
  for (std::size_t i = 0; i < tgt.points.size(); ++i) {
    t.points_.push_back(tgt.points[i].cast<double>());
    t.normals_.push_back(tgt.normals[i].cast<double>());
  }
  PeerResult r;
  r.seconds = MedianSeconds(1, false, [&] {
    const reg::RegistrationResult res = reg::RegistrationICP(
        s, t, gate_mm, init.matrix(), reg::TransformationEstimationPointToPlane(),
        reg::ICPConvergenceCriteria(1e-10, 1e-10, 100));
    r.gauge_from_sensor.matrix() = res.transformation_;
  });
  return r;
}
#endif

}  // namespace calibration_detail

inline void AddCalibrationRows(std::vector<Row>& rows) {
  using namespace calibration_detail;
  const DemoCell cell = MakeDemoCell();
  const DemoViewpoint& vp = cell.viewpoints[0];
  ScanOptions opt;
  opt.noise_sigma_mm = 0.015;
  auto scan =
      SimulateScan(cell.gauge, vp.world_from_gauge, vp.world_from_sensor, cell.intrinsics, opt);
  if (!scan.ok()) {
    rows.push_back(
        {"ICP calibration", "failed: " + std::string(scan.status().message()), "", "", "", "", ""});
    return;
  }
  const PointCloud& cloud = scan->cloud_in_sensor;
  const Eigen::Isometry3d truth =
      vp.world_from_gauge.inverse() * vp.world_from_sensor;  // gauge_from_sensor
  const Sample target = SampleMesh(cell.gauge, 8.0, 5);      // ~0.35 mm spacing
  const std::vector<Eigen::Vector3f> source = Subsample(cloud, 40000, 9);

  Eigen::Isometry3d small = Eigen::Isometry3d::Identity();
  small.translate(Eigen::Vector3d(0.6, -0.48, 0.64));  // 1 mm
  small.rotate(Eigen::AngleAxisd(0.5 * M_PI / 180, Eigen::Vector3d(1, 2, -1).normalized()));
  struct Case {
    std::string name;
    Eigen::Isometry3d init_gauge_from_sensor;
    double gate_mm;
  };
  const Case cases[] = {
      {"1 mm / 0.5° start", truth * small, 10.0},
      {"demo nominal start", vp.world_from_gauge.inverse() * vp.nominal_world_from_sensor, 25.0},
  };
  for (const Case& c : cases) {
    const std::string start = PoseError(truth, c.init_gauge_from_sensor);
    CalibrationResult ours;
    bool ok = true;
    const double t_ours = MedianSeconds(3, true, [&] {
      auto index = MeshIndex::Build(cell.gauge);
      auto r = index.ok() ? CalibrateViewpoint(**index, vp.world_from_gauge, cloud,
                                               vp.world_from_gauge * c.init_gauge_from_sensor, {})
                          : absl::StatusOr<CalibrationResult>(index.status());
      ok = r.ok();
      if (ok) ours = *r;
    });
    const std::string ours_err = ok ? PoseError(truth, ours.gauge_from_sensor) : "failed";
    auto add = [&](const std::string& peer_name, const std::string& peer_time,
                   const std::string& ratio, const std::string& peer_err) {
      rows.push_back(
          {"ICP calibration, gauge scan, " + c.name + " (" + start + ") vs " + peer_name,
           Time(t_ours), peer_time, ratio, "pose error: ours " + ours_err + ", peer " + peer_err,
           "≤ 0.5 s (ours, incl. filter + coarse search)", Verdict(ok && t_ours <= 0.5)});
    };
    auto add_peer = [&](const std::string& name, const PeerResult& p) {
      add(name, Time(p.seconds), Fmt("%.1fx", p.seconds / t_ours),
          PoseError(truth, p.gauge_from_sensor));
    };
    add_peer("PCL ICP point-to-point",
             PclPointToPoint(source, target, c.init_gauge_from_sensor, c.gate_mm));
    add_peer("PCL ICP point-to-plane",
             PclPointToPlane(source, target, c.init_gauge_from_sensor, c.gate_mm));
#ifdef SURFINSPECT_HAVE_OPEN3D
    add_peer("Open3D ICP point-to-plane",
             Open3dPointToPlane(source, target, c.init_gauge_from_sensor, c.gate_mm));
#else
    add("Open3D ICP point-to-plane", "skipped (libopen3d-dev not installed)", "—", "—");
#endif
  }
}

}  // namespace surfinspect::bench
