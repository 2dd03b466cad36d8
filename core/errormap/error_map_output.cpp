#include "core/errormap/error_map_output.h"

#include <fcntl.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "core/io/atomic_file.h"
#include "core/types/default_init_vector.h"
#include "core/types/round_half_away.h"

namespace surfinspect {
namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "the PLY writer copies host floats as binary_little_endian");

// Appends to a temporary file through a 1 MiB buffer, or straight from the
// caller's bytes when they are a quarter of that or more (the PLY's blocks of
// rows: one copy fewer); the first failure sticks and is reported by
// Close(). Each write is handed to the disk at once (sync_file_range), so
// the fsync before the rename (core/io/atomic_file.h) waits for the last
// one only, not for the whole file's writeback.
class BufferedFile {
 public:
  explicit BufferedFile(const std::string& path) : path_(path), f_(std::fopen(path.c_str(), "wb")) {
    buf_.reserve(kFlushAt + 4096);
  }
  ~BufferedFile() {
    if (f_) std::fclose(f_);
  }
  void Append(const void* data, std::size_t n) {
    if (n >= kFlushAt / 4) {
      Flush();
      Write(data, n);
      return;
    }
    buf_.append(static_cast<const char*>(data), n);
    if (buf_.size() >= kFlushAt) Flush();
  }
  void Append(const std::string& s) { Append(s.data(), s.size()); }
  absl::Status Close() {
    if (!f_) return absl::PermissionDeniedError(absl::StrCat("cannot create ", path_));
    Flush();
    const bool closed = std::fclose(f_) == 0;
    f_ = nullptr;
    if (!ok_ || !closed) return absl::DataLossError(absl::StrCat("write failed: ", path_));
    return absl::OkStatus();
  }

 private:
  static constexpr std::size_t kFlushAt = std::size_t{1} << 20;
  void Flush() {
    if (!buf_.empty()) Write(buf_.data(), buf_.size());
    buf_.clear();
  }
  void Write(const void* data, std::size_t n) {
    if (!f_ || n == 0) return;
    if (std::fwrite(data, 1, n, f_) != n || std::fflush(f_) != 0) ok_ = false;
    // A hint: its failure is the fsync's to report.
    if (ok_) ::sync_file_range(::fileno(f_), flushed_, off64_t(n), SYNC_FILE_RANGE_WRITE);
    flushed_ += off64_t(n);
  }
  std::string path_;
  std::FILE* f_;
  std::string buf_;
  off64_t flushed_ = 0;  // bytes handed to the file so far
  bool ok_ = true;
};

absl::Status CheckSizes(const PointCloud& points, const ErrorMapResult& result) {
  if (result.deviation_mm.size() != points.size())
    return absl::InvalidArgumentError(absl::StrCat("error map output: ", points.size(),
                                                   " points but ", result.deviation_mm.size(),
                                                   " deviations"));
  return absl::OkStatus();
}

void AppendNumber(std::string& line, float v) {
  if (std::isnan(v)) {
    line += "nan";
    return;
  }
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof(buf), v);  // shortest round-trip form
  line.append(buf, res.ptr);
}

// JSON has no NaN: a missing number is null in the object itself, not only
// once dumped, so the server's serialisation sees the same thing.
nlohmann::json Num(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json Stats(const ComponentStats& c) {
  return {{"mean_mm", Num(c.mean_mm)},
          {"rms_mm", Num(c.rms_mm)},
          {"min_mm", Num(c.min_mm)},
          {"max_mm", Num(c.max_mm)}};
}

// The binary rows (x y z, deviation twice, rgb) of the valid points in
// [from, to), in place of `out`'s contents (sized for every point first,
// without zeroing, then cut to the rows written).
void EncodePlyRows(const PointCloud& points, const ErrorMapResult& result, std::size_t from,
                   std::size_t to, DefaultInitVector<char>& out) {
  constexpr std::size_t kRow = 23;
  out.resize((to - from) * kRow);
  char* row = out.data();
  for (std::size_t i = from; i < to; ++i) {
    const Eigen::Vector3f& p = points.points[i];
    if (!PointCloud::IsValid(p)) continue;
    const float d = result.deviation_mm[i];
    const Rgb c = DeviationColor(d, result.tolerance_mm, result.color_range_mm);
    std::memcpy(row, p.data(), 12);
    std::memcpy(row + 12, &d, 4);
    std::memcpy(row + 16, &d, 4);
    row[20] = static_cast<char>(c.r);
    row[21] = static_cast<char>(c.g);
    row[22] = static_cast<char>(c.b);
    row += kRow;
  }
  out.resize(static_cast<std::size_t>(row - out.data()));
}

// Each piece of the colour scale blends two colours, each channel rounded
// from x + (y - x) w, halves away from zero; the constant pieces (beyond the
// scale) blend a colour with itself at weight 0. DeviationColor picks the
// piece and the weight by index: on a part's deviations the sign and the
// band go either way at random, and branches on them are mispredicted. A
// piece holds x and y - x per channel as doubles (exact: small integers).
struct Piece {
  double from[3], step[3];
  constexpr Piece(Rgb a, Rgb b)
      : from{double(a.r), double(a.g), double(a.b)},
        step{double(b.r) - a.r, double(b.g) - a.g, double(b.b) - a.b} {}
};
constexpr Piece kPieces[8] = {
    {{40, 190, 90}, {150, 215, 60}},  // in the band, t >= 0: to warm green
    {{40, 190, 90}, {40, 190, 170}},  // in the band, t < 0: to cool green
    {{255, 235, 0}, {255, 140, 0}},   // above, first half of the ramp
    {{255, 140, 0}, {215, 0, 0}},     // above, second half
    {{0, 230, 230}, {0, 120, 255}},   // below, first half
    {{0, 120, 255}, {0, 0, 190}},     // below, second half
    {{120, 0, 50}, {120, 0, 50}},     // above, beyond the scale
    {{50, 0, 120}, {50, 0, 120}},     // below, beyond the scale
};

}  // namespace

// In the band: t = d / tol, from the mid green towards the warm (t >= 0) or
// the cool green, by |t|. Outside: s = (|d| - tol) / (range - tol), the
// yellow-orange-red ramp above or the cyan-blue ramp below, each in two
// halves (weights 2s and 2s - 1); beyond s = 1, a darker constant colour.
Rgb DeviationColor(double d, double tol, double range) {
  if (std::isnan(d)) return kUnmatchedGrey;
  const double ad = std::abs(d);
  const double t = tol > 0 ? d / tol : 0.0;
  const double s = range > tol ? (ad - tol) / (range - tol) : 1.0;
  const int band = ad <= tol, beyond = s > 1, second_half = !(s < 0.5), below = !(d > 0);
  const int ramp = beyond ? 6 + below : 2 + 2 * below + second_half;
  const Piece& piece = kPieces[band ? int{t < 0} : ramp];
  // Selected by index, not by a conditional: the compiler branches on those.
  const double ramp_weights[3] = {2 * s, 2 * s - 1, 0.0};
  const double weights[2] = {ramp_weights[beyond ? 2 : second_half], std::abs(t)};
  const double w = weights[band];
  auto mix = [&](int c) {
    return static_cast<uint8_t>(RoundHalfAwayFromZero(piece.from[c] + piece.step[c] * w));
  };
  return {mix(0), mix(1), mix(2)};
}

absl::Status WriteErrorMapPly(const std::string& path, const PointCloud& points,
                              const ErrorMapResult& result, const std::string& frame_name) {
  if (auto st = CheckSizes(points, result); !st.ok()) return st;
  return WriteFileAtomically(path, [&](const std::string& tmp) -> absl::Status {
    BufferedFile out(tmp);
    out.Append(absl::StrCat(
        "ply\nformat binary_little_endian 1.0\n",
        "comment surfinspect error map: deviation in mm, + above the CAD surface, nan unmatched\n",
        "comment frame: ", frame_name, "\nelement vertex ", points.CountValid(),
        "\nproperty float x\nproperty float y\nproperty float z\n"
        "property float scalar_deviation\nproperty float quality\n"
        "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n"));
    // The rows are encoded in parallel, a group of blocks at a time, in
    // point order (the colour is most of a row's cost); each group is
    // written while the next one is encoded.
    constexpr std::size_t kBlock = std::size_t{1} << 15, kGroup = 8;
    std::vector<DefaultInitVector<char>> encoded(kGroup), writing(kGroup);
    auto encode = [&](std::size_t first) {
      tbb::parallel_for(std::size_t{0}, kGroup, [&](std::size_t b) {
        const std::size_t from = std::min(points.size(), first + b * kBlock);
        EncodePlyRows(points, result, from, std::min(points.size(), from + kBlock), encoded[b]);
      });
    };
    auto write = [&] {
      for (const DefaultInitVector<char>& r : writing) out.Append(r.data(), r.size());
    };
    encode(0);
    for (std::size_t next = kBlock * kGroup;; next += kBlock * kGroup) {
      std::swap(encoded, writing);
      if (next >= points.size()) break;
      tbb::parallel_invoke(write, [&] { encode(next); });
    }
    write();
    return out.Close();
  });
}

absl::Status WriteErrorMapCsv(const std::string& path, const PointCloud& points,
                              const ErrorMapResult& result) {
  if (auto st = CheckSizes(points, result); !st.ok()) return st;
  const bool split = result.deviation_xyz_mm.size() == points.size() &&
                     result.normal_deviation_mm.size() == points.size();
  return WriteFileAtomically(path, [&](const std::string& tmp) -> absl::Status {
    BufferedFile out(tmp);
    out.Append(split ? std::string("x,y,z,deviation,dx,dy,dz,normal_deviation\n")
                     : std::string("x,y,z,deviation\n"));
    std::string line;
    for (std::size_t i = 0; i < points.size(); ++i) {
      line.clear();
      const bool valid = PointCloud::IsValid(points.points[i]);
      for (int a = 0; a < 3; ++a) {
        AppendNumber(line, valid ? points.points[i][a] : NAN);
        line += ',';
      }
      AppendNumber(line, result.deviation_mm[i]);
      if (split) {
        for (int a = 0; a < 3; ++a) {
          line += ',';
          AppendNumber(line, result.deviation_xyz_mm[i][a]);
        }
        line += ',';
        AppendNumber(line, result.normal_deviation_mm[i]);
      }
      line += '\n';
      out.Append(line);
    }
    return out.Close();
  });
}

nlohmann::json ErrorMapReportJson(const ErrorMapResult& r, const ErrorMapSettings& settings) {
  const ErrorMapStats& s = r.stats;
  nlohmann::json j;
  j["units"] = "mm";
  j["sign"] = "+ above the CAD surface (side of the CCW face normals), - below";
  j["settings"] = {{"tolerance_mm", settings.tolerance_mm},
                   {"max_distance_mm", Num(settings.max_distance_mm)},  // null = unlimited
                   {"allowed_fraction_outside", settings.allowed_fraction_outside},
                   {"histogram_bins", settings.histogram_bins},
                   {"split_components", settings.split_components}};
  j["points"] = {{"count", s.count},
                 {"valid", s.valid},
                 {"matched", s.matched},
                 {"unmatched_valid", s.valid - s.matched}};
  j["statistics"] = {{"min_mm", Num(s.min_mm)},   {"max_mm", Num(s.max_mm)},
                     {"mean_mm", Num(s.mean_mm)}, {"stddev_mm", Num(s.stddev_mm)},
                     {"rms_mm", Num(s.rms_mm)},   {"p1_mm", Num(s.p1_mm)},
                     {"p5_mm", Num(s.p5_mm)},     {"p50_mm", Num(s.p50_mm)},
                     {"p95_mm", Num(s.p95_mm)},   {"p99_mm", Num(s.p99_mm)}};
  const Verdict& v = r.verdict;
  j["tolerance"] = {{"band_mm", r.tolerance_mm},
                    {"within", v.within},
                    {"above", v.above},
                    {"below", v.below},
                    {"fraction_within", Num(v.fraction_within)},
                    {"fraction_outside", Num(v.fraction_outside)},
                    {"allowed_fraction_outside", settings.allowed_fraction_outside},
                    {"verdict", v.pass ? "pass" : "fail"},
                    {"reason", v.reason}};
  const Histogram& h = r.histogram;
  j["histogram"] = {
      {"min_mm", h.min_mm}, {"max_mm", h.max_mm},           {"bin_width_mm", h.bin_width_mm()},
      {"counts", h.counts}, {"below_range", h.below_range}, {"above_range", h.above_range}};
  j["color_range_mm"] = r.color_range_mm;
  if (!r.deviation_xyz_mm.empty())
    j["components"] = {{"frame", "part"},
                       {"x", Stats(r.component_stats[0])},
                       {"y", Stats(r.component_stats[1])},
                       {"z", Stats(r.component_stats[2])},
                       {"normal", Stats(r.component_stats[3])}};
  j["timing"] = {{"query_seconds", r.query_seconds},
                 {"order_seconds", r.order_seconds},
                 {"statistics_seconds", r.statistics_seconds},
                 {"certified_points", r.certified_points},
                 {"hint_alone_points", r.hint_alone_points}};
  return j;
}

}  // namespace surfinspect
