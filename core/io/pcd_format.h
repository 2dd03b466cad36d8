// PCD (Point Cloud Data, PCL's format) parsed from a byte buffer by our own
// code: the header strictly (known keys only, each once, numbers that are
// wholly numeric, FIELDS/SIZE/TYPE/COUNT of one length, WIDTH*HEIGHT ==
// POINTS, sizes computed with overflow checks) and the data section in all
// three encodings: ascii, binary and binary_compressed (LZF, see lzf.h).
//
// The x, y and z fields may be float32 or float64 (converted to float);
// other fields are read past and dropped. The grid (WIDTH x HEIGHT) and NaN
// pixels are kept; values come out bit-identical to PCL's reader. Nothing is
// allocated beyond what the buffer's size can hold.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "core/io/read_limits.h"
#include "core/types/point_cloud.h"

namespace surfinspect {

enum class PcdData { kAscii, kBinary, kBinaryCompressed };

struct PcdField {
  std::string name;
  uint32_t size = 0;    // bytes per element: 1, 2, 4 or 8
  char type = 'F';      // 'F' float, 'I' signed, 'U' unsigned
  uint32_t count = 1;   // elements per point
  uint64_t offset = 0;  // byte offset inside a binary point record
};

// A PCD's VIEWPOINT: the sensor's pose as PCL keeps it (sensor_origin_,
// sensor_orientation_), a translation in the points' units and a rotation
// quaternion, in the file's order. Reported, never applied to the points
// (PCL's reader does not apply it either).
struct PcdViewpoint {
  double tx = 0, ty = 0, tz = 0;
  double qw = 1, qx = 0, qy = 0, qz = 0;
};

struct PcdHeader {
  std::vector<PcdField> fields;
  uint32_t width = 0, height = 0;
  uint64_t points = 0;
  uint64_t point_step = 0;        // bytes per point record
  uint64_t values_per_point = 0;  // numbers per ascii data line
  PcdData data = PcdData::kBinary;
  std::size_t data_offset = 0;            // first byte after the DATA line
  std::optional<PcdViewpoint> viewpoint;  // when the header has a VIEWPOINT line
};

// Errors are INVALID_ARGUMENT ("NAME: why"), or RESOURCE_EXHAUSTED when the
// declared count exceeds `limits`.
absl::StatusOr<PcdHeader> ParsePcdHeader(std::string_view bytes, const CloudReadLimits& limits,
                                         std::string_view name);

// The header of the PCD file at `path`, read from the file's first bytes
// (a header must end within 64 KiB); the data section is not read.
// NOT_FOUND when the file cannot be opened.
absl::StatusOr<PcdHeader> ReadPcdHeader(const std::string& path,
                                        const CloudReadLimits& limits = {});

absl::StatusOr<PointCloud> ParsePcd(std::string_view bytes, const CloudReadLimits& limits = {},
                                    std::string_view name = "<pcd>");

}  // namespace surfinspect
