#include "core/plan/surface_neighbourhood.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "core/types/percentile.h"

namespace surfinspect {
namespace {

bool Matched(const ErrorMapResult& em, std::size_t i) { return em.triangle_id[i] != UINT32_MAX; }

// Organized grid: the pixels of a square window whose scanned points lie
// within reach, for the median; 8-neighbours within the link distance for
// links. Scanned (not closest CAD) points: a mixed pixel hanging between two
// surfaces has its closest CAD point on the surface, but few scanned points
// near it, so it gets no estimate of its own.
class GridNeighbourhood final : public SurfaceNeighbourhood {
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
  std::vector<uint32_t> MatchedOrder() const override {
    std::vector<uint32_t> order;
    for (std::size_t i = 0; i < pts_.size(); ++i)
      if (Matched(em_, i)) order.push_back(static_cast<uint32_t>(i));
    return order;
  }
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

// Unorganized: cells of edge `radius` over the scanned points, so every
// neighbour within the radius is in the 27 cells around a point's own.
class CellNeighbourhood final : public SurfaceNeighbourhood {
 public:
  CellNeighbourhood(const ErrorMapResult& em, const PointCloud& cloud, float radius_mm,
                    float link_mm)
      : pts_(cloud.points), cell_(radius_mm), radius_(radius_mm), link_(link_mm) {
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
  std::vector<uint32_t> MatchedOrder() const override { return order_; }
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
  const std::vector<Eigen::Vector3f>& pts_;
  float cell_, radius_, link_;
  std::vector<uint32_t> order_, start_;
  std::unordered_map<uint64_t, uint32_t> cells_;
  std::vector<uint64_t> cell_key_;
};

}  // namespace

std::unique_ptr<SurfaceNeighbourhood> MakeGridNeighbourhood(const ErrorMapResult& em,
                                                            const PointCloud& cloud,
                                                            float radius_mm, float link_mm,
                                                            double spacing_mm) {
  return std::make_unique<GridNeighbourhood>(em, cloud, radius_mm, link_mm, spacing_mm);
}

std::unique_ptr<SurfaceNeighbourhood> MakeCellNeighbourhood(const ErrorMapResult& em,
                                                            const PointCloud& cloud,
                                                            float radius_mm, float link_mm) {
  return std::make_unique<CellNeighbourhood>(em, cloud, radius_mm, link_mm);
}

double EstimateSurfaceSpacing(const ErrorMapResult& em, const PointCloud& cloud) {
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
    const std::vector<uint32_t> order = coarse.MatchedOrder();
    std::vector<uint32_t> near;
    for (std::size_t k = 0; k < order.size(); k += stride) {
      coarse.Local(order[k], near);
      d.push_back(std::sqrt(M_PI * kR * kR / static_cast<double>(near.size())));
    }
  }
  const double m = MedianInPlace(d);
  return std::isfinite(m) && m > 0 ? m : 1.0;
}

}  // namespace surfinspect
