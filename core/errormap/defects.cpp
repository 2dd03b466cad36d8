#include "core/errormap/defects.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "absl/strings/str_cat.h"

namespace surfinspect {
namespace {

constexpr std::size_t kBlock = 4096;  // points per parallel task of the median pass

bool Matched(const ErrorMapResult& em, std::size_t i) { return em.triangle_id[i] != UINT32_MAX; }

float Distance(const ErrorMapResult& em, std::size_t i, std::size_t j) {
  return (em.closest_point[i] - em.closest_point[j]).norm();
}

// Matched neighbours of a point on the surface, the point itself included,
// in an order fixed by the data alone (window or cell order, then index).
class Neighbourhood {
 public:
  virtual ~Neighbourhood() = default;
  // The robust-estimate neighbourhood.
  virtual void Local(std::size_t i, std::vector<uint32_t>& out) const = 0;
  // The points i links to (closer than the link distance).
  virtual void Links(std::size_t i, std::vector<uint32_t>& out) const = 0;
  // The footprint area of point i, mm^2.
  virtual double Area(std::size_t i) const = 0;
  // Per point: 1 unless a superset of its neighbourhood (its window, its
  // 27 cells) holds fewer than `need` points of each sign in `hot`, in which
  // case its median cannot pass the threshold (that needs half of its >=
  // min_neighbours points beyond it, on one side).
  virtual std::vector<uint8_t> MayExceed(const std::vector<int8_t>& hot, uint32_t need) const = 0;
};

// Organized grid: the pixels of a square window whose measured points lie
// within reach, for the median; 8-neighbours within the link distance for
// links. Measured (not closest CAD) points: a mixed pixel hanging between two
// surfaces has its closest CAD point on the surface, but few measured points
// near it, so it gets no estimate of its own.
class GridNeighbourhood final : public Neighbourhood {
 public:
  GridNeighbourhood(const ErrorMapResult& em, const PointCloud& cloud, float radius_mm,
                    float link_mm, double spacing_mm)
      : em_(em),
        pts_(cloud.points),
        w_(cloud.width),
        h_(cloud.height),
        half_(std::clamp(static_cast<long>(std::ceil(radius_mm / spacing_mm)), 1L, 4L)),
        radius_(radius_mm),
        link_(link_mm),
        spacing_(spacing_mm) {}
  void Local(std::size_t i, std::vector<uint32_t>& out) const override {
    Window(i, half_, radius_, out);
  }
  void Links(std::size_t i, std::vector<uint32_t>& out) const override { Window(i, 1, link_, out); }
  // Window counts from summed-area tables of each sign (Crow, SIGGRAPH 1984).
  std::vector<uint8_t> MayExceed(const std::vector<int8_t>& hot, uint32_t need) const override {
    const std::size_t W = w_ + 1;
    std::vector<uint32_t> pos(W * (h_ + 1), 0), neg(W * (h_ + 1), 0);
    for (std::size_t r = 0; r < h_; ++r)
      for (std::size_t c = 0; c < w_; ++c) {
        const int8_t v = hot[r * w_ + c];
        const std::size_t k = (r + 1) * W + c + 1;
        pos[k] = pos[k - 1] + pos[k - W] - pos[k - W - 1] + (v > 0);
        neg[k] = neg[k - 1] + neg[k - W] - neg[k - W - 1] + (v < 0);
      }
    std::vector<uint8_t> may(hot.size(), 0);
    for (std::size_t r = 0; r < h_; ++r) {
      const std::size_t r0 = r > std::size_t(half_) ? r - half_ : 0,
                        r1 = std::min<std::size_t>(h_, r + half_ + 1);
      for (std::size_t c = 0; c < w_; ++c) {
        const std::size_t c0 = c > std::size_t(half_) ? c - half_ : 0,
                          c1 = std::min<std::size_t>(w_, c + half_ + 1);
        auto box = [&](const std::vector<uint32_t>& t) {
          return t[r1 * W + c1] - t[r0 * W + c1] - t[r1 * W + c0] + t[r0 * W + c0];
        };
        may[r * w_ + c] = box(pos) >= need || box(neg) >= need;
      }
    }
    return may;
  }
  double Area(std::size_t i) const override {
    const long r = static_cast<long>(i / w_), c = static_cast<long>(i % w_);
    const Eigen::Vector3f du = Difference(i, r, c, 0, 1), dv = Difference(i, r, c, 1, 0);
    if (du.isZero() || dv.isZero()) return spacing_ * spacing_;
    return du.cross(dv).norm();
  }

 private:
  bool Near(std::size_t i, std::size_t j, float reach) const {
    return Matched(em_, j) && (pts_[i] - pts_[j]).norm() <= reach;
  }
  void Window(std::size_t i, long half, float reach, std::vector<uint32_t>& out) const {
    out.clear();
    const long r = static_cast<long>(i / w_), c = static_cast<long>(i % w_);
    for (long rr = std::max(0L, r - half); rr <= std::min<long>(h_ - 1, r + half); ++rr)
      for (long cc = std::max(0L, c - half); cc <= std::min<long>(w_ - 1, c + half); ++cc) {
        const std::size_t j = static_cast<std::size_t>(rr) * w_ + static_cast<std::size_t>(cc);
        if (Near(i, j, reach)) out.push_back(static_cast<uint32_t>(j));
      }
  }
  // Central (else one-sided) difference of the closest points along (dr, dc).
  Eigen::Vector3f Difference(std::size_t i, long r, long c, long dr, long dc) const {
    auto at = [&](long k) -> long {
      const long rr = r + k * dr, cc = c + k * dc;
      if (rr < 0 || cc < 0 || rr >= static_cast<long>(h_) || cc >= static_cast<long>(w_)) return -1;
      const std::size_t j = static_cast<std::size_t>(rr) * w_ + static_cast<std::size_t>(cc);
      return Near(i, j, link_) ? static_cast<long>(j) : -1;
    };
    const long a = at(-1), b = at(1);
    const auto& cp = em_.closest_point;
    if (a >= 0 && b >= 0) return 0.5f * (cp[b] - cp[a]);
    if (b >= 0) return cp[b] - cp[i];
    if (a >= 0) return cp[i] - cp[a];
    return Eigen::Vector3f::Zero();
  }
  const ErrorMapResult& em_;
  const std::vector<Eigen::Vector3f>& pts_;
  uint32_t w_, h_;
  long half_;
  float radius_, link_;
  double spacing_;
};

// Unorganized: cells of edge `radius` over the measured points, so every
// neighbour within the radius is in the 27 cells around a point's own.
class CellNeighbourhood final : public Neighbourhood {
 public:
  CellNeighbourhood(const ErrorMapResult& em, const PointCloud& cloud, float radius_mm,
                    float link_mm)
      : em_(em), pts_(cloud.points), cell_(radius_mm), radius_(radius_mm), link_(link_mm) {
    for (std::size_t i = 0; i < em.triangle_id.size(); ++i)
      if (Matched(em, i)) order_.push_back(static_cast<uint32_t>(i));
    std::vector<uint64_t> keys(order_.size());
    for (std::size_t k = 0; k < order_.size(); ++k) keys[k] = Key(pts_[order_[k]], 0, 0, 0);
    std::vector<uint32_t> perm(order_.size());
    std::iota(perm.begin(), perm.end(), 0u);
    std::sort(perm.begin(), perm.end(), [&](uint32_t a, uint32_t b) {
      return keys[a] != keys[b] ? keys[a] < keys[b] : order_[a] < order_[b];
    });
    std::vector<uint32_t> sorted(order_.size());
    for (std::size_t k = 0; k < perm.size(); ++k) {
      sorted[k] = order_[perm[k]];
      if (k == 0 || keys[perm[k]] != keys[perm[k - 1]]) {
        cells_.emplace(keys[perm[k]], static_cast<uint32_t>(start_.size()));
        start_.push_back(static_cast<uint32_t>(k));
      }
    }
    start_.push_back(static_cast<uint32_t>(sorted.size()));
    order_ = std::move(sorted);
    cell_key_.resize(start_.size() - 1);
    for (const auto& [key, cell] : cells_) cell_key_[cell] = key;
  }
  std::vector<uint8_t> MayExceed(const std::vector<int8_t>& hot, uint32_t need) const override {
    const std::size_t cells = start_.size() - 1;
    std::vector<uint32_t> pos(cells, 0), neg(cells, 0);
    for (std::size_t c = 0; c < cells; ++c)
      for (uint32_t k = start_[c]; k < start_[c + 1]; ++k) {
        pos[c] += hot[order_[k]] > 0;
        neg[c] += hot[order_[k]] < 0;
      }
    std::vector<uint8_t> may(hot.size(), 0);
    for (std::size_t c = 0; c < cells; ++c) {
      uint32_t p = 0, n = 0;
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const auto it = cells_.find(Shift(cell_key_[c], dx, dy, dz));
            if (it == cells_.end()) continue;
            p += pos[it->second];
            n += neg[it->second];
          }
      if (p >= need || n >= need)
        for (uint32_t k = start_[c]; k < start_[c + 1]; ++k) may[order_[k]] = 1;
    }
    return may;
  }
  // Matched points in cell order: the median pass walks them so that
  // consecutive queries hit the same cells.
  const std::vector<uint32_t>& order() const { return order_; }
  void Local(std::size_t i, std::vector<uint32_t>& out) const override { Within(i, radius_, out); }
  void Links(std::size_t i, std::vector<uint32_t>& out) const override { Within(i, link_, out); }
  double Area(std::size_t i) const override {
    std::vector<uint32_t> near;
    Within(i, radius_, near);
    return M_PI * radius_ * radius_ / static_cast<double>(near.size());
  }

 private:
  // The key of the cell (dx, dy, dz) cells away (the clamped edge cells of
  // a coordinate range this wide hold no points).
  static uint64_t Shift(uint64_t key, int dx, int dy, int dz) {
    constexpr uint64_t kMask = (uint64_t{1} << 21) - 1;
    auto axis = [&](int shift, int d) {
      return ((key >> shift & kMask) + static_cast<uint64_t>(static_cast<int64_t>(d))) & kMask;
    };
    return axis(42, dx) << 42 | axis(21, dy) << 21 | axis(0, dz);
  }
  uint64_t Key(const Eigen::Vector3f& p, int dx, int dy, int dz) const {
    auto axis = [&](float v, int d) {
      const long k = static_cast<long>(std::floor(v / cell_)) + d + (1L << 20);
      return static_cast<uint64_t>(std::clamp(k, 0L, (1L << 21) - 1));
    };
    return axis(p.x(), dx) << 42 | axis(p.y(), dy) << 21 | axis(p.z(), dz);
  }
  void Within(std::size_t i, float reach, std::vector<uint32_t>& out) const {
    out.clear();
    const Eigen::Vector3f& p = pts_[i];
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(Key(p, dx, dy, dz));
          if (it == cells_.end()) continue;
          for (uint32_t k = start_[it->second]; k < start_[it->second + 1]; ++k)
            if ((pts_[i] - pts_[order_[k]]).norm() <= reach) out.push_back(order_[k]);
        }
  }
  const ErrorMapResult& em_;
  const std::vector<Eigen::Vector3f>& pts_;
  float cell_, radius_, link_;
  std::vector<uint32_t> order_, start_;
  std::unordered_map<uint64_t, uint32_t> cells_;
  std::vector<uint64_t> cell_key_;
};

double Median(std::vector<double>& v) {
  if (v.empty()) return NAN;
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  if (v.size() % 2) return v[mid];
  return 0.5 *
         (v[mid] + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid)));
}

// Spacing: organized, the median distance from a sample of measured points
// to their right or lower neighbour pixel; unorganized, sqrt of the surface
// area per point, pi R^2 / (points within R = 2 mm), median over a sample,
// so that overlapping views (interleaved, nearest neighbours far closer
// than the sampling) count as the denser sampling they are.
double EstimateSpacing(const ErrorMapResult& em, const PointCloud& cloud) {
  const auto& p = cloud.points;
  std::vector<double> d;
  const std::size_t n = em.triangle_id.size();
  // 2000 samples: the median is then within ~2% of the cloud's.
  const std::size_t stride = std::max<std::size_t>(1, n / 2000);
  if (cloud.organized()) {
    const std::size_t w = cloud.width;
    for (std::size_t i = 0; i + w < n; i += stride) {
      if (!Matched(em, i)) continue;
      double best = INFINITY;
      if ((i + 1) % w != 0 && Matched(em, i + 1)) best = (p[i] - p[i + 1]).norm();
      if (Matched(em, i + w)) best = std::min<double>(best, (p[i] - p[i + w]).norm());
      if (std::isfinite(best) && best > 0) d.push_back(best);
    }
  } else {
    constexpr float kR = 2.0f;
    CellNeighbourhood coarse(em, cloud, kR, kR);
    std::vector<uint32_t> near;
    for (std::size_t k = 0; k < coarse.order().size(); k += stride) {
      coarse.Local(coarse.order()[k], near);
      d.push_back(std::sqrt(M_PI * kR * kR / static_cast<double>(near.size())));
    }
  }
  const double m = Median(d);
  return std::isfinite(m) && m > 0 ? m : 1.0;
}

// The median of the deviations around each matched point that may pass
// the threshold (NaN elsewhere, and where there are too few neighbours).
std::vector<float> RobustDeviation(const ErrorMapResult& em, const Neighbourhood& nb,
                                   const std::vector<uint32_t>& order, float threshold,
                                   int min_neighbours, int threads) {
  std::vector<int8_t> hot(em.deviation_mm.size(), 0);
  for (std::size_t i = 0; i < hot.size(); ++i) {
    const float d = em.deviation_mm[i];  // NaN (unmatched) is neither
    hot[i] = static_cast<int8_t>(d > threshold ? 1 : d < -threshold ? -1 : 0);
  }
  const std::vector<uint8_t> may =
      nb.MayExceed(hot, static_cast<uint32_t>((min_neighbours + 1) / 2));
  std::vector<float> m(em.deviation_mm.size(), NAN);
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, order.size(), kBlock), [&](auto range) {
      std::vector<uint32_t> near;
      std::vector<double> values;
      for (std::size_t k = range.begin(); k != range.end(); ++k) {
        const uint32_t i = order[k];
        if (!may[i]) continue;
        nb.Local(i, near);
        if (near.size() < static_cast<std::size_t>(min_neighbours)) continue;
        values.clear();
        for (uint32_t j : near) values.push_back(em.deviation_mm[j]);
        m[i] = static_cast<float>(Median(values));
      }
    });
  });
  return m;
}

struct UnionFind {
  std::unordered_map<uint32_t, uint32_t> parent;
  uint32_t Find(uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void Unite(uint32_t a, uint32_t b) {
    a = Find(a), b = Find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);  // root = the lowest index
  }
};

// Same-sign candidates linked into patches; each patch's points ascending.
std::vector<std::vector<uint32_t>> Patches(const std::vector<int8_t>& sign,
                                           const std::vector<uint32_t>& candidates,
                                           const Neighbourhood& nb) {
  UnionFind uf;
  for (uint32_t i : candidates) uf.parent[i] = i;
  std::vector<uint32_t> near;
  for (uint32_t i : candidates) {
    nb.Links(i, near);
    for (uint32_t j : near)
      if (j < i && sign[j] == sign[i]) uf.Unite(i, j);
  }
  std::unordered_map<uint32_t, std::size_t> slot;
  std::vector<std::vector<uint32_t>> patches;
  for (uint32_t i : candidates) {  // ascending, so patches are numbered by first point
    const uint32_t root = uf.Find(i);
    auto [it, fresh] = slot.emplace(root, patches.size());
    if (fresh) patches.emplace_back();
    patches[it->second].push_back(i);
  }
  return patches;
}

struct GaussianFit {
  bool ok = false;
  double amplitude = 0, baseline = 0, sigma = 0, rms = 0;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
};

// Levenberg-Marquardt on f(u, v) = c + A exp(-|(u, v) - x0|^2 / (2 s^2)),
// parameters (A, u0, v0, ln s, c); `keep` selects the samples used.
GaussianFit FitGaussian(const std::vector<Eigen::Vector3d>& uvd, const std::vector<char>& keep,
                        GaussianFit start) {
  Eigen::Matrix<double, 5, 1> x(start.amplitude, start.centre.x(), start.centre.y(),
                                std::log(start.sigma), start.baseline);
  auto cost_and_system = [&](const Eigen::Matrix<double, 5, 1>& p, Eigen::Matrix<double, 5, 5>* H,
                             Eigen::Matrix<double, 5, 1>* g) {
    const double s2 = std::exp(2 * p[3]);
    double cost = 0;
    if (H) H->setZero(), g->setZero();
    for (std::size_t k = 0; k < uvd.size(); ++k) {
      if (!keep[k]) continue;
      const double du = uvd[k].x() - p[1], dv = uvd[k].y() - p[2], r2 = du * du + dv * dv;
      const double e = std::exp(-r2 / (2 * s2));
      const double res = p[4] + p[0] * e - uvd[k].z();
      cost += res * res;
      if (!H) continue;
      const Eigen::Matrix<double, 5, 1> J(e, p[0] * e * du / s2, p[0] * e * dv / s2,
                                          p[0] * e * r2 / s2, 1.0);
      H->selfadjointView<Eigen::Lower>().rankUpdate(J);
      *g += J * res;
    }
    if (H) *H = H->selfadjointView<Eigen::Lower>();
    return cost;
  };
  double lambda = 1e-3;
  Eigen::Matrix<double, 5, 5> H;
  Eigen::Matrix<double, 5, 1> g;
  double cost = cost_and_system(x, &H, &g);
  for (int it = 0; it < 50; ++it) {
    Eigen::Matrix<double, 5, 5> A = H;
    A.diagonal() *= 1 + lambda;
    const Eigen::Matrix<double, 5, 1> step = A.ldlt().solve(-g);
    if (!step.allFinite()) break;
    const double trial = cost_and_system(x + step, nullptr, nullptr);
    if (trial < cost) {
      x += step;
      const bool done = cost - trial < 1e-12 * cost;
      cost = cost_and_system(x, &H, &g);
      lambda = std::max(lambda / 10, 1e-9);
      if (done) break;
    } else {
      lambda *= 10;
      if (lambda > 1e8) break;
    }
  }
  const std::size_t used = static_cast<std::size_t>(std::count(keep.begin(), keep.end(), 1));
  GaussianFit f;
  f.amplitude = x[0];
  f.centre = {x[1], x[2]};
  f.sigma = std::exp(x[3]);
  f.baseline = x[4];
  f.rms = used ? std::sqrt(cost / used) : NAN;
  f.ok = x.allFinite() && used >= 8;
  return f;
}

// Points within `reach` of the seed, grown from the patch through links.
std::vector<uint32_t> FitSupport(const ErrorMapResult& em, const Neighbourhood& nb,
                                 const std::vector<uint32_t>& patch, uint32_t seed, double reach) {
  constexpr std::size_t kMaxPoints = 200000;  // bounds the work on a huge patch
  std::unordered_map<uint32_t, char> seen;
  std::vector<uint32_t> out(patch.begin(), patch.end()), near;
  for (uint32_t i : patch) seen[i] = 1;
  for (std::size_t k = 0; k < out.size() && out.size() < kMaxPoints; ++k) {
    nb.Links(out[k], near);
    for (uint32_t j : near)
      if (seen.emplace(j, 1).second && Distance(em, seed, j) <= reach) out.push_back(j);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

const char* DefectKindName(DefectKind kind) { return kind == DefectKind::kDent ? "dent" : "bump"; }

namespace {

// The robust Gaussian fit of one patch's peak into `d` (peak_mm, fit fields).
void FitPeak(const ErrorMapResult& em, const Neighbourhood& nb, const std::vector<float>& median,
             const std::vector<uint32_t>& patch, const Eigen::Vector3f& seed_normal, uint32_t seed,
             double threshold_mm, double spacing_mm, Defect& d) {
  double radius = 0;
  for (uint32_t i : patch) radius = std::max<double>(radius, Distance(em, seed, i));
  const double reach = std::min(2 * radius + 3 * spacing_mm, 30.0);
  const std::vector<uint32_t> support = FitSupport(em, nb, patch, seed, reach);
  const Eigen::Vector3d n = seed_normal.cast<double>().normalized();
  const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
  const Eigen::Vector3d o = em.closest_point[seed].cast<double>();
  std::vector<Eigen::Vector3d> uvd;
  for (uint32_t j : support) {
    const Eigen::Vector3d q = em.closest_point[j].cast<double>() - o;
    uvd.emplace_back(q.dot(u), q.dot(v), em.deviation_mm[j]);
  }
  GaussianFit start;
  start.amplitude = median[seed];
  const double r_eq = std::sqrt(d.area_mm2 / M_PI);
  start.sigma = std::max(
      spacing_mm,
      r_eq / std::sqrt(2 * std::log(std::max(std::abs(start.amplitude) / threshold_mm, 1.5))));
  std::vector<char> keep(uvd.size(), 1);
  GaussianFit fit = FitGaussian(uvd, keep, start);
  if (fit.ok) {  // drop points beyond 5 robust sigma (stray pixels) and refit once
    const double s2 = fit.sigma * fit.sigma;
    std::vector<double> abs_res(uvd.size());
    for (std::size_t k = 0; k < uvd.size(); ++k) {
      const double r2 = (uvd[k].head<2>() - fit.centre).squaredNorm();
      abs_res[k] = std::abs(fit.baseline + fit.amplitude * std::exp(-r2 / (2 * s2)) - uvd[k].z());
    }
    std::vector<double> copy = abs_res;
    const double cut = 5 * 1.4826 * Median(copy);
    for (std::size_t k = 0; k < uvd.size(); ++k) keep[k] = abs_res[k] <= cut;
    fit = FitGaussian(uvd, keep, fit);
  }
  const double peak = fit.baseline + fit.amplitude;
  const bool plausible = fit.ok && fit.centre.norm() <= reach && fit.sigma > 0.25 * spacing_mm &&
                         fit.sigma < reach && (peak < 0) == (median[seed] < 0);
  d.peak_fitted = plausible;
  d.peak_mm = plausible ? peak : median[seed];
  d.fit_sigma_mm = plausible ? fit.sigma : NAN;
  d.fit_rms_mm = plausible ? fit.rms : NAN;
}

// Area, centroid on the surface and extent of one patch into `d`.
void Measure(const ErrorMapResult& em, const Neighbourhood& nb,
             const std::vector<Eigen::Vector3f>& normals, const std::vector<uint32_t>& patch,
             Defect& d) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::vector<double> area(patch.size());
  for (std::size_t k = 0; k < patch.size(); ++k) {
    area[k] = nb.Area(patch[k]);
    d.area_mm2 += area[k];
    sum += area[k] * em.closest_point[patch[k]].cast<double>();
  }
  const Eigen::Vector3d mean = sum / d.area_mm2;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  uint32_t nearest = patch[0];
  double best = INFINITY;
  for (std::size_t k = 0; k < patch.size(); ++k) {
    const Eigen::Vector3d q = em.closest_point[patch[k]].cast<double>() - mean;
    cov += area[k] * q * q.transpose();
    if (q.squaredNorm() < best) best = q.squaredNorm(), nearest = patch[k];
  }
  // Onto the plane of the CAD triangle under the nearest patch point.
  d.triangle_id = em.triangle_id[nearest];
  const Eigen::Vector3d n = normals[d.triangle_id].cast<double>();
  const Eigen::Vector3d on = em.closest_point[nearest].cast<double>();
  d.centroid_mm = mean - (mean - on).dot(n) * n;
  const Eigen::Vector3d axis =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(2);
  double lo = INFINITY, hi = -INFINITY;
  for (uint32_t i : patch) {
    const double s = (em.closest_point[i].cast<double>() - mean).dot(axis);
    lo = std::min(lo, s), hi = std::max(hi, s);
  }
  d.extent_mm = hi - lo;
  d.points = patch.size();
}

absl::Status CheckInput(const ErrorMapResult& em, const PointCloud& cloud, const TriangleMesh& part,
                        const DefectRules& rules, const DefectSettings& s) {
  const std::size_t n = em.deviation_mm.size();
  if (em.triangle_id.size() != n || em.closest_point.size() != n || cloud.size() != n)
    return absl::InvalidArgumentError("defects: error map and cloud sizes differ");
  if (cloud.organized() && std::size_t{cloud.width} * cloud.height != n)
    return absl::InvalidArgumentError("defects: width x height does not match the points");
  for (uint32_t t : em.triangle_id)
    if (t != UINT32_MAX && t >= part.num_triangles())
      return absl::InvalidArgumentError("defects: triangle id beyond the part mesh");
  if (!(rules.threshold_mm > 0) || !std::isfinite(rules.threshold_mm) ||
      !(rules.min_area_mm2 >= 0) || !std::isfinite(rules.min_area_mm2))
    return absl::InvalidArgumentError("defects: threshold_mm must be > 0, min_area_mm2 >= 0");
  if (!(s.spacing_mm >= 0) || !(s.neighbourhood_spacings > 0) || !(s.link_spacings > 0) ||
      !(s.grid_link_spacings > 0) || s.min_neighbours < 1)
    return absl::InvalidArgumentError("defects: bad settings");
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<DefectsResult> FindDefects(const ErrorMapResult& em, const PointCloud& cloud,
                                          const TriangleMesh& part, const DefectRules& rules,
                                          const ResolvedInspectionPlan* plan,
                                          const DefectSettings& settings) {
  if (auto st = CheckInput(em, cloud, part, rules, settings); !st.ok()) return st;
  DefectsResult out;
  out.organized_path = cloud.organized();
  out.spacing_mm = settings.spacing_mm > 0 ? settings.spacing_mm : EstimateSpacing(em, cloud);
  std::unique_ptr<Neighbourhood> nb;
  std::vector<uint32_t> order;
  if (out.organized_path) {
    out.link_mm = settings.grid_link_spacings * out.spacing_mm;
    nb = std::make_unique<GridNeighbourhood>(
        em, cloud, static_cast<float>(settings.neighbourhood_spacings * out.spacing_mm),
        static_cast<float>(out.link_mm), out.spacing_mm);
    for (std::size_t i = 0; i < em.triangle_id.size(); ++i)
      if (Matched(em, i)) order.push_back(static_cast<uint32_t>(i));
  } else {
    out.link_mm = settings.link_spacings * out.spacing_mm;
    auto cells = std::make_unique<CellNeighbourhood>(
        em, cloud, static_cast<float>(settings.neighbourhood_spacings * out.spacing_mm),
        static_cast<float>(out.link_mm));
    order = cells->order();
    nb = std::move(cells);
  }
  const std::vector<float> median =
      RobustDeviation(em, *nb, order, static_cast<float>(rules.threshold_mm),
                      settings.min_neighbours, settings.threads);
  std::vector<int8_t> sign(median.size(), 0);
  std::vector<uint32_t> candidates;
  const float thr = static_cast<float>(rules.threshold_mm);
  for (std::size_t i = 0; i < median.size(); ++i)
    if (std::abs(median[i]) > thr) {
      sign[i] = median[i] > 0 ? 1 : -1;
      candidates.push_back(static_cast<uint32_t>(i));
    }
  out.candidate_points = candidates.size();
  const std::vector<Eigen::Vector3f> normals = part.FaceNormals();
  for (const std::vector<uint32_t>& patch : Patches(sign, candidates, *nb)) {
    Defect d;
    Measure(em, *nb, normals, patch, d);
    if (d.area_mm2 < rules.min_area_mm2) {
      ++out.rejected_patches;
      continue;
    }
    uint32_t seed = patch[0];
    for (uint32_t i : patch)
      if (std::abs(median[i]) > std::abs(median[seed])) seed = i;
    d.kind = median[seed] < 0 ? DefectKind::kDent : DefectKind::kBump;
    FitPeak(em, *nb, median, patch, normals[em.triangle_id[seed]], seed, rules.threshold_mm,
            out.spacing_mm, d);
    if (plan) {
      const int region = plan->FirstRegionOf(d.triangle_id);
      if (region >= 0) d.region = plan->plan.regions[static_cast<std::size_t>(region)].name;
    }
    out.defects.push_back(std::move(d));
  }
  std::stable_sort(out.defects.begin(), out.defects.end(), [](const Defect& a, const Defect& b) {
    return std::abs(a.peak_mm) > std::abs(b.peak_mm);
  });
  for (std::size_t k = 0; k < out.defects.size(); ++k) out.defects[k].id = static_cast<int>(k + 1);
  return out;
}

}  // namespace surfinspect
