#include "core/errormap/error_map_output.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "core/io/atomic_file.h"
#include "core/types/round_half_away.h"

namespace surfinspect {
namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "the PLY writer copies host floats as binary_little_endian");

// Appends to a temporary file through a 1 MiB buffer; the first failure
// sticks and is reported by Close().
class BufferedFile {
 public:
  explicit BufferedFile(const std::string& path) : path_(path), f_(std::fopen(path.c_str(), "wb")) {
    buf_.reserve(kFlushAt + 4096);
  }
  ~BufferedFile() {
    if (f_) std::fclose(f_);
  }
  void Append(const void* data, std::size_t n) {
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
    if (f_ && !buf_.empty() && std::fwrite(buf_.data(), 1, buf_.size(), f_) != buf_.size())
      ok_ = false;
    buf_.clear();
  }
  std::string path_;
  std::FILE* f_;
  std::string buf_;
  bool ok_ = true;
};

Rgb Lerp(Rgb a, Rgb b, double t) {
  auto mix = [t](uint8_t x, uint8_t y) {
    return static_cast<uint8_t>(RoundHalfAwayFromZero(x + (static_cast<double>(y) - x) * t));
  };
  return {mix(a.r, b.r), mix(a.g, b.g), mix(a.b, b.b)};
}

Rgb Ramp(Rgb at0, Rgb at_half, Rgb at1, double s) {
  return s < 0.5 ? Lerp(at0, at_half, 2 * s) : Lerp(at_half, at1, 2 * s - 1);
}

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
// [from, to).
void AppendPlyRows(const PointCloud& points, const ErrorMapResult& result, std::size_t from,
                   std::size_t to, std::string& out) {
  out.reserve(out.size() + (to - from) * 23);
  char record[23];
  for (std::size_t i = from; i < to; ++i) {
    const Eigen::Vector3f& p = points.points[i];
    if (!PointCloud::IsValid(p)) continue;
    const float d = result.deviation_mm[i];
    const Rgb c = DeviationColor(d, result.tolerance_mm, result.color_range_mm);
    std::memcpy(record, p.data(), 12);
    std::memcpy(record + 12, &d, 4);
    std::memcpy(record + 16, &d, 4);
    record[20] = static_cast<char>(c.r);
    record[21] = static_cast<char>(c.g);
    record[22] = static_cast<char>(c.b);
    out.append(record, sizeof(record));
  }
}

}  // namespace

Rgb DeviationColor(double d, double tol, double range) {
  if (std::isnan(d)) return kUnmatchedGrey;
  if (std::abs(d) <= tol) {
    const double t = tol > 0 ? d / tol : 0.0;  // -1..1: cool to warm green
    return Lerp(Rgb{40, 190, 90}, t >= 0 ? Rgb{150, 215, 60} : Rgb{40, 190, 170}, std::abs(t));
  }
  const double s = range > tol ? (std::abs(d) - tol) / (range - tol) : 1.0;
  if (s > 1) return d > 0 ? Rgb{120, 0, 50} : Rgb{50, 0, 120};  // beyond the scale
  return d > 0 ? Ramp({255, 235, 0}, {255, 140, 0}, {215, 0, 0}, s)
               : Ramp({0, 230, 230}, {0, 120, 255}, {0, 0, 190}, s);
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
    // The rows are encoded in parallel, a group of blocks at a time, and
    // appended in point order (the colour is most of a row's cost).
    constexpr std::size_t kBlock = std::size_t{1} << 15, kGroup = 16;
    std::vector<std::string> rows(kGroup);
    for (std::size_t first = 0; first < points.size(); first += kBlock * kGroup) {
      tbb::parallel_for(std::size_t{0}, kGroup, [&](std::size_t b) {
        const std::size_t from = std::min(points.size(), first + b * kBlock);
        AppendPlyRows(points, result, from, std::min(points.size(), from + kBlock), rows[b]);
      });
      for (std::string& r : rows) {
        out.Append(r);
        r.clear();
      }
    }
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
