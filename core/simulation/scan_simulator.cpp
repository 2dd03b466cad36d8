#include "core/simulation/scan_simulator.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "core/distance/embree_handles.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr double kDefectLabelThresholdMm = 1e-3;

// Counter-based randomness: every pixel draws from its own stream, so the
// result does not depend on thread scheduling (SplitMix64, Steele et al.).
struct PixelRng {
  uint64_t state;
  PixelRng(uint64_t seed, uint64_t pixel, uint64_t stream)
      : state(seed * 0x9E3779B97F4A7C15ull ^ (pixel + 1) * 0xBF58476D1CE4E5B9ull ^
              (stream + 1) * 0x94D049BB133111EBull) {}
  uint64_t Next() {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double Uniform() { return (Next() >> 11) * 0x1.0p-53; }  // [0, 1)
  double Gaussian() {                                      // Box-Muller
    const double u1 = std::max(Uniform(), 1e-300), u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }
};

enum Stream : uint64_t { kNoiseStream, kPulseStream, kStripeStream };

// Gaussian deformation (mm, along the outward normal) at surface point f.
double Deformation(const std::vector<SurfaceDefect>& defects, const Eigen::Vector3d& f) {
  double w = 0;
  for (const auto& d : defects) {
    const double sigma = 0.5 * d.radius_mm;
    w -= d.depth_mm * std::exp(-(f - d.center_in_part).squaredNorm() / (2 * sigma * sigma));
  }
  return w;
}

struct RayHit {
  double range = std::numeric_limits<double>::quiet_NaN();  // along the unit ray, mm
  double deviation = 0;                                     // true normal deviation
  uint32_t triangle = UINT32_MAX;
};

}  // namespace

double FocalLengthPixels(const SensorIntrinsics& in) {
  return 0.5 * in.width / std::tan(0.5 * in.horizontal_fov_deg * M_PI / 180.0);
}

Eigen::Isometry3d LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                         const Eigen::Vector3d& down_hint) {
  const Eigen::Vector3d z = (target - eye).normalized();
  Eigen::Vector3d y = down_hint - down_hint.dot(z) * z;
  if (y.norm() < 1e-9) y = z.unitOrthogonal();
  y.normalize();
  const Eigen::Vector3d x = y.cross(z);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear().col(0) = x;
  t.linear().col(1) = y;
  t.linear().col(2) = z;
  t.translation() = eye;
  return t;
}

namespace {

absl::Status CheckScanInputs(const SensorIntrinsics& in, const ScanOptions& opt) {
  if (in.width == 0 || in.height == 0 || uint64_t{in.width} * in.height > 100'000'000)
    return absl::InvalidArgumentError("sensor: width and height must be in 1..1e8 pixels");
  if (!(in.horizontal_fov_deg > 0 && in.horizontal_fov_deg < 170))
    return absl::InvalidArgumentError("sensor: horizontal_fov_deg must be in (0, 170)");
  if (!(in.min_range_mm >= 0 && in.max_range_mm > in.min_range_mm))
    return absl::InvalidArgumentError("sensor: need 0 <= min_range_mm < max_range_mm");
  if (!(opt.noise_sigma_mm >= 0) || !(opt.pulse_fraction >= 0 && opt.pulse_fraction <= 1) ||
      !(opt.pulse_min_mm >= 0 && opt.pulse_max_mm >= opt.pulse_min_mm))
    return absl::InvalidArgumentError("scan options: noise, pulse fraction or range invalid");
  for (const auto& d : opt.defects)
    if (!d.center_in_part.allFinite() || !(d.radius_mm > 0) || !std::isfinite(d.depth_mm))
      return absl::InvalidArgumentError("defect: centre must be finite and radius > 0");
  return absl::OkStatus();
}

// The pinhole camera: unit viewing ray of a pixel centre, sensor frame.
struct Pinhole {
  explicit Pinhole(const SensorIntrinsics& in)
      : f(FocalLengthPixels(in)), cx(0.5 * in.width), cy(0.5 * in.height) {}
  Eigen::Vector3d Ray(uint32_t col, uint32_t row) const {
    return Eigen::Vector3d((col + 0.5 - cx) / f, (row + 0.5 - cy) / f, 1.0).normalized();
  }
  double f, cx, cy;
};

// Moves a hit at ray parameter t (ray origin + t d, plane normal nrm, denom
// = d.nrm) onto the deformed surface p + w(f) n: fixed-point iteration on
// the ray parameter (converges in a few steps because the defects are
// smooth and shallow compared with their radius). Returns the parameter
// change; `deviation` gets w.
double OntoDeformedSurface(const std::vector<SurfaceDefect>& defects, const Eigen::Vector3d& p,
                           const Eigen::Vector3d& d, const Eigen::Vector3d& nrm, double denom,
                           double& deviation) {
  double s = 0, w = 0;
  for (int it = 0; it < 6 && std::abs(denom) > 1e-6; ++it) {
    const Eigen::Vector3d q = p + s * d;
    const Eigen::Vector3d foot = q - (q - p).dot(nrm) * nrm;
    w = Deformation(defects, foot);
    s = w / denom;
  }
  deviation = w;
  return s;
}

// Casts every pixel's ray at the part (in the part frame) with Embree and
// returns the range, true deviation and triangle per pixel.
absl::StatusOr<std::vector<RayHit>> CastRays(const TriangleMesh& mesh_in_part,
                                             const Eigen::Isometry3d& part_from_sensor,
                                             const SensorIntrinsics& in, const ScanOptions& opt) {
  ASSIGN_OR_RETURN(auto device, EmbreeDevice::Create());
  ASSIGN_OR_RETURN(auto scene, EmbreeTriangleScene::Build(device, mesh_in_part));
  const std::vector<Eigen::Vector3f> normals = mesh_in_part.FaceNormals();
  const Eigen::Vector3d origin = part_from_sensor.translation();
  const Pinhole camera(in);
  std::vector<RayHit> hits(std::size_t{in.width} * in.height);
  RTCScene rtc_scene = scene->get();
  tbb::parallel_for(tbb::blocked_range<uint32_t>(0, in.height), [&](const auto& rows) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    for (uint32_t row = rows.begin(); row != rows.end(); ++row)
      for (uint32_t col = 0; col < in.width; ++col) {
        const Eigen::Vector3d d = part_from_sensor.linear() * camera.Ray(col, row);
        RTCRayHit rh{};
        rh.ray.org_x = static_cast<float>(origin.x());
        rh.ray.org_y = static_cast<float>(origin.y());
        rh.ray.org_z = static_cast<float>(origin.z());
        rh.ray.dir_x = static_cast<float>(d.x());
        rh.ray.dir_y = static_cast<float>(d.y());
        rh.ray.dir_z = static_cast<float>(d.z());
        rh.ray.tnear = 0.f;
        rh.ray.tfar = std::numeric_limits<float>::infinity();
        rh.ray.mask = 0xFFFFFFFFu;  // Debian's Embree is built with ray masks: all bits hit
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(rtc_scene, &context, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
        RayHit& h = hits[std::size_t{row} * in.width + col];
        h.triangle = rh.hit.primID;
        // Refine the hit in double against the triangle's plane, so the
        // noise-free point lies on the CAD surface to ~1e-12 mm.
        const auto& tri = mesh_in_part.triangles[h.triangle];
        const Eigen::Vector3d a = mesh_in_part.vertices[tri[0]].cast<double>();
        const Eigen::Vector3d nrm = normals[h.triangle].cast<double>();
        const double denom = d.dot(nrm);
        double t = std::abs(denom) > 1e-12 ? (a - origin).dot(nrm) / denom : rh.ray.tfar;
        if (!opt.defects.empty())
          t += OntoDeformedSurface(opt.defects, origin + t * d, d, nrm, denom, h.deviation);
        h.range = t;
      }
  });
  RETURN_IF_ERROR(device->TakeError());
  return hits;
}

// Marks pixel i as carrying no surface truth (pulse, stripe or no data).
void ClearTruth(SimulatedScan& out, std::size_t i, PixelLabel label) {
  out.labels[i] = label;
  out.true_deviation_mm[i] = kNaN;
  out.triangle_id[i] = UINT32_MAX;
}

// Labels and truth of the hit pixels; returns the range along each ray.
std::vector<double> LabelHits(const std::vector<RayHit>& hits, SimulatedScan& out) {
  const std::size_t n = hits.size();
  out.labels.assign(n, PixelLabel::kNoData);
  out.true_deviation_mm.assign(n, kNaN);
  out.triangle_id.assign(n, UINT32_MAX);
  std::vector<double> range(n, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(hits[i].range)) continue;
    range[i] = hits[i].range;
    out.labels[i] = std::abs(hits[i].deviation) >= kDefectLabelThresholdMm ? PixelLabel::kDefect
                                                                           : PixelLabel::kGood;
    out.true_deviation_mm[i] = static_cast<float>(hits[i].deviation);
    out.triangle_id[i] = hits[i].triangle;
  }
  return range;
}

// Stripes: at a depth discontinuity (a jump to a farther surface or to no
// data) the sensor mixes the two surfaces and reports a short chain of
// points in between, trailing away from the near edge (paper §III).
void AddStripes(const std::vector<RayHit>& hits, const SensorIntrinsics& in, const ScanOptions& opt,
                std::vector<double>& range, SimulatedScan& out) {
  const int dr[4] = {0, 0, 1, -1}, dc[4] = {1, -1, 0, 0};
  auto inside = [&](long r, long c) {
    return r >= 0 && c >= 0 && r < long(in.height) && c < long(in.width);
  };
  for (uint32_t row = 0; row < in.height; ++row)
    for (uint32_t col = 0; col < in.width; ++col) {
      const std::size_t i = std::size_t{row} * in.width + col;
      if (!std::isfinite(hits[i].range)) continue;
      for (int k = 0; k < 4; ++k) {
        const long r1 = long(row) + dr[k], c1 = long(col) + dc[k];
        if (!inside(r1, c1)) continue;
        const double near_range = hits[i].range;
        const double far_range = hits[std::size_t(r1) * in.width + c1].range;
        const bool far_void = !std::isfinite(far_range);
        if (!far_void && far_range - near_range < opt.stripe_min_jump_mm) continue;
        PixelRng rng(opt.seed, i * 4 + k, kStripeStream);
        if (rng.Uniform() >= opt.stripe_probability) continue;
        const uint32_t len =
            2 +
            static_cast<uint32_t>(rng.Uniform() * std::max<uint32_t>(1, opt.stripe_max_length - 1));
        const double far_end = far_void ? near_range + 3.0 + 12.0 * rng.Uniform() : far_range;
        for (uint32_t step = 1; step <= len; ++step) {
          const long r = long(row) + dr[k] * long(step), c = long(col) + dc[k] * long(step);
          if (!inside(r, c)) break;
          const std::size_t j = std::size_t(r) * in.width + c;
          const double frac = (step + 0.5 * rng.Uniform()) / (len + 1.0);
          // Keep >= 1 mm off the near surface: a mixed pixel is between.
          range[j] = near_range + std::max(1.0, frac * (far_end - near_range));
          ClearTruth(out, j, PixelLabel::kStripe);
        }
      }
    }
}

// Pulses (a fraction of the non-stripe pixels jump 2-20 mm along the ray),
// then Gaussian noise along the ray; points outside the working range are
// dropped. Builds the cloud and the counts.
void AddPulsesAndNoise(const std::vector<double>& range, const SensorIntrinsics& in,
                       const ScanOptions& opt, SimulatedScan& out) {
  const Pinhole camera(in);
  for (std::size_t i = 0; i < range.size(); ++i) {
    if (!std::isfinite(range[i])) continue;
    const uint32_t row = static_cast<uint32_t>(i / in.width),
                   col = static_cast<uint32_t>(i % in.width);
    double t = range[i];
    if (out.labels[i] != PixelLabel::kStripe && opt.pulse_fraction > 0) {
      PixelRng rng(opt.seed, i, kPulseStream);
      if (rng.Uniform() < opt.pulse_fraction) {
        const double mag = opt.pulse_min_mm + (opt.pulse_max_mm - opt.pulse_min_mm) * rng.Uniform();
        t += rng.Uniform() < 0.5 ? -mag : mag;
        ClearTruth(out, i, PixelLabel::kPulse);
      }
    }
    if (opt.noise_sigma_mm > 0)
      t += opt.noise_sigma_mm * PixelRng(opt.seed, i, kNoiseStream).Gaussian();
    // Range t is frame-independent (rigid motion), so the point is built in
    // the sensor frame directly: no round trip through the part frame.
    const Eigen::Vector3d p_sensor = t * camera.Ray(col, row);
    if (p_sensor.z() < in.min_range_mm || p_sensor.z() > in.max_range_mm) {
      ClearTruth(out, i, PixelLabel::kNoData);
      continue;
    }
    out.cloud_in_sensor.points[i] = p_sensor.cast<float>();
    ++out.hits;
    out.pulses += out.labels[i] == PixelLabel::kPulse;
    out.stripe_pixels += out.labels[i] == PixelLabel::kStripe;
    out.defect_pixels += out.labels[i] == PixelLabel::kDefect;
  }
}

}  // namespace

absl::StatusOr<SimulatedScan> SimulateScan(const TriangleMesh& mesh_in_part,
                                           const Eigen::Isometry3d& world_from_part,
                                           const Eigen::Isometry3d& world_from_sensor,
                                           const SensorIntrinsics& intrinsics,
                                           const ScanOptions& options) {
  RETURN_IF_ERROR(CheckScanInputs(intrinsics, options));
  // Rays are cast in the part frame; results go back to the sensor frame.
  const Eigen::Isometry3d part_from_sensor = world_from_part.inverse() * world_from_sensor;
  ASSIGN_OR_RETURN(auto hits, CastRays(mesh_in_part, part_from_sensor, intrinsics, options));
  SimulatedScan out;
  out.cloud_in_sensor = PointCloud::Organized(intrinsics.width, intrinsics.height);
  // Range along each pixel's ray, after stripes, pulses and noise.
  std::vector<double> range = LabelHits(hits, out);
  if (options.stripes) AddStripes(hits, intrinsics, options, range, out);
  AddPulsesAndNoise(range, intrinsics, options, out);
  return out;
}

}  // namespace surfinspect
