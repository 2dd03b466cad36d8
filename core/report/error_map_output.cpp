#include "core/report/error_map_output.h"

#include <fcntl.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstring>

#include "absl/strings/str_cat.h"
#include "core/io/atomic_file.h"
#include "core/types/default_init_vector.h"
#include "core/types/round_half_away.h"
#include "core/types/status_macros.h"

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

}  // namespace

absl::Status WriteErrorMapPly(const std::string& path, const PointCloud& points,
                              const ErrorMapResult& result, const std::string& frame_name) {
  RETURN_IF_ERROR(CheckSizes(points, result));
  return WriteFileAtomically(path, [&](const std::string& tmp) -> absl::Status {
    BufferedFile out(tmp);
    out.Append(absl::StrCat(
        "ply\nformat binary_little_endian 1.0\n",
        "comment surfinspect error map: deviation in mm, + above the CAD surface, nan unmatched\n"
        "comment units: mm\n",
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
  RETURN_IF_ERROR(CheckSizes(points, result));
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

}  // namespace surfinspect
