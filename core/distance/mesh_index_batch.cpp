// Batch closest-point queries over whole clouds (declared in mesh_index.h).
//
// Points are cut into fixed chunks of consecutive positions in a coherent
// visiting order; chunks run in parallel in a task arena of the requested
// size. Inside a chunk each query starts at radius previous distance +
// |p - p_prev|, an upper bound on the answer by the triangle inequality, and
// offers the previous point's triangle first, which usually tightens the
// radius to nearly the answer, so the search prunes from the root instead of
// descending towards an arbitrary first leaf. Chunk boundaries do not depend on the thread count
// and the index breaks ties by triangle id, so results are identical for 1 and N threads and with
// or without the coherent start.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <new>

#include "absl/strings/str_cat.h"
#include "core/distance/mesh_index.h"
#include "core/distance/morton_order.h"
#include "core/types/cancel.h"
#include "core/types/default_init_vector.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

constexpr std::size_t kChunk = 256;  // points per chunk: the unit of work and of cancel polling
// A certificate that fails costs a query a few kernel calls: where they
// keep failing (a mesh fine compared with the points' spacing, triangles
// large compared with their reach), a chunk whose first this many tries
// certified fewer than a quarter stops trying. The answers are the same.
constexpr std::size_t kCertificateProbe = 16;

// One chunk's result, left unconstructed until SearchChunk builds it in
// place: default-constructing 256 results first would store 20 KB per chunk
// that is overwritten unread.
union ResultSlot {
  ResultSlot() {}
  ClosestPoint r;
};

absl::Status CheckInputs(const PointCloud& points, const Eigen::Isometry3d& mesh_from_points,
                         const BatchQuerySettings& settings) {
  RETURN_IF_ERROR(points.Validate());
  if (!(settings.max_distance_mm >= 0))
    return absl::InvalidArgumentError(
        absl::StrCat("closest-point query: max_distance_mm must be >= 0 (or inf), got ",
                     settings.max_distance_mm));
  if (settings.threads < 0 || settings.threads > kMaxQueryThreads)
    return absl::InvalidArgumentError(absl::StrCat("closest-point query: threads must be in [0, ",
                                                   kMaxQueryThreads, "], got ", settings.threads));
  if (!mesh_from_points.matrix().allFinite())
    return absl::InvalidArgumentError("closest-point query: mesh_from_points is not finite");
  return absl::OkStatus();
}

// The searches of one chunk, in visiting order: each query starts at
// radius previous distance + |p - p_prev| with the previous point's triangle
// as its hint (when settings.coherent_start). Counts the queries answered
// by each path.
void SearchChunk(const MeshIndex& index, const BatchQuerySettings& settings,
                 const Eigen::Vector3d* p, const bool* valid, std::size_t count,
                 ResultSlot* results, std::size_t paths[3]) {
  const double max_d = settings.max_distance_mm;
  Eigen::Vector3d prev_p = Eigen::Vector3d::Zero();
  double prev_d = NAN;  // no anchor yet
  uint32_t prev_triangle = UINT32_MAX;
  std::size_t tried = 0, certified = 0;
  bool certify = true;
  for (std::size_t k = 0; k < count; ++k) {
    ClosestPoint* const r = &results[k].r;
    if (!valid[k]) {
      ::new (r) ClosestPoint();
      continue;
    }
    double radius = max_d;
    if (settings.coherent_start && std::isfinite(prev_d))
      radius = std::min(radius, (prev_d + (p[k] - prev_p).norm()) * (1 + 1e-12) + 1e-12);
    // The previous point's triangle, offered first, usually makes the
    // radius nearly exact at once.
    QueryPath path = QueryPath::kTree;
    const uint32_t hint = settings.coherent_start ? prev_triangle : UINT32_MAX;
    // Built in place: assigning would copy a temporary whose fields were
    // just stored one by one, and the copy's wider loads would each wait
    // on a failed store forward (a fifth of this loop's samples under perf).
    ::new (r) ClosestPoint(index.Closest(p[k], radius, hint, &path, certify));
    ++paths[static_cast<int>(path)];
    if (certify && hint != UINT32_MAX) {
      certified += path != QueryPath::kTree;
      if (++tried == kCertificateProbe && 4 * certified < tried) certify = false;
    }
    // The bound holds exactly; this only guards against its rounding.
    if (!r->matched() && radius < max_d) *r = index.Closest(p[k], max_d);
    if (r->matched()) {
      prev_p = p[k];
      prev_d = r->distance_mm;
      prev_triangle = r->triangle_id;
    }
  }
}

}  // namespace

absl::Status QueryClosestEach(const MeshIndex& index, const PointCloud& points,
                              const Eigen::Isometry3d& mesh_from_points,
                              const BatchQuerySettings& settings, const std::atomic<bool>* cancel,
                              absl::FunctionRef<void(std::size_t, const ClosestPoint&)> sink,
                              BatchQueryTiming* timing) {
  RETURN_IF_ERROR(CheckInputs(points, mesh_from_points, settings));
  const std::size_t n = points.size();
  if (n == 0) return absl::OkStatus();
  const auto t0 = std::chrono::steady_clock::now();
  tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
  // A grid is already coherent row by row; anything else gets Morton order.
  DefaultInitVector<uint64_t> order;  // code << 32 | point index
  if (settings.coherent_start && !points.organized() && n <= UINT32_MAX) {
    arena.execute([&] { order = MortonOrder(points, cancel); });
    if (order.empty()) return absl::CancelledError("closest-point query cancelled");
  }
  const auto t1 = std::chrono::steady_clock::now();

  std::atomic<bool> cancelled{false};
  std::atomic<std::size_t> by_ring{0}, by_hint_alone{0};
  // A chunk runs in three passes: gather its points, search them, hand the
  // results to the sink. In Morton order the input is read and the sink
  // writes at random; apart from the searches those cache misses overlap
  // each other instead of each stalling a search (about a fifth of the time
  // on 10^6 points).
  auto run_chunk = [&](std::size_t chunk) {
    const std::size_t begin = chunk * kChunk, count = std::min(n - begin, kChunk);
    auto index_of = [&](std::size_t k) -> std::size_t {
      return order.empty() ? begin + k : static_cast<uint32_t>(order[begin + k]);
    };
    // The copy is its own loop, with nothing that waits on the loaded
    // values, so many of its cache misses are in flight at once.
    std::array<Eigen::Vector3f, kChunk> raw;
    for (std::size_t k = 0; k < count; ++k) raw[k] = points.points[index_of(k)];
    std::array<Eigen::Vector3d, kChunk> p;  // mesh frame
    std::array<bool, kChunk> valid;
    for (std::size_t k = 0; k < count; ++k) {
      valid[k] = PointCloud::IsValid(raw[k]);
      if (valid[k]) p[k] = mesh_from_points * raw[k].cast<double>();
    }
    std::array<ResultSlot, kChunk> results;
    std::size_t paths[3] = {};
    SearchChunk(index, settings, p.data(), valid.data(), count, results.data(), paths);
    by_ring.fetch_add(paths[static_cast<int>(QueryPath::kRing)], std::memory_order_relaxed);
    by_hint_alone.fetch_add(paths[static_cast<int>(QueryPath::kHintAlone)],
                            std::memory_order_relaxed);
    for (std::size_t k = 0; k < count; ++k) sink(index_of(k), results[k].r);
  };

  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t c = range.begin(); c != range.end(); ++c) {
                          if (IsCancelled(cancel)) {
                            cancelled.store(true, std::memory_order_relaxed);
                            return;
                          }
                          run_chunk(c);
                        }
                      });
  });
  if (cancelled.load()) return absl::CancelledError("closest-point query cancelled");
  if (timing) {
    timing->order_seconds = std::chrono::duration<double>(t1 - t0).count();
    timing->search_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    timing->hint_alone_points = by_hint_alone.load();
    timing->certified_points = by_ring.load() + timing->hint_alone_points;
  }
  return absl::OkStatus();
}

absl::StatusOr<std::vector<ClosestPoint>> QueryClosest(const MeshIndex& index,
                                                       const PointCloud& points,
                                                       const Eigen::Isometry3d& mesh_from_points,
                                                       const BatchQuerySettings& settings,
                                                       const std::atomic<bool>* cancel) {
  RETURN_IF_ERROR(CheckInputs(points, mesh_from_points, settings));
  std::vector<ClosestPoint> out;
  try {
    out.resize(points.size());
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError(absl::StrCat(
        "closest-point query: cannot allocate results for ", points.size(), " points"));
  }
  auto st = QueryClosestEach(index, points, mesh_from_points, settings, cancel,
                             [&out](std::size_t i, const ClosestPoint& r) { out[i] = r; });
  if (!st.ok()) return st;
  return out;
}

}  // namespace surfinspect
