#include "proto/packed_cloud.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <vector>

#include "absl/strings/str_cat.h"
#include "proto/convert.h"

namespace surfinspect::wire {
namespace {

const Eigen::Vector3f kNoData = Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());

absl::Status Invalid(const std::string& field, absl::string_view why) {
  return absl::InvalidArgumentError(absl::StrCat(field, ": ", why));
}

// CloudFromBlocks' blocks start on a byte of valid_bits.
static_assert(kCloudBlock % 8 == 0);

bool BitSet(const std::string& bits, uint64_t i) {
  return (static_cast<uint8_t>(bits[i / 8]) >> (i % 8)) & 1u;
}

// Set bits in bytes [first, last) of `bits`.
uint64_t CountBits(const std::string& bits, uint64_t first, uint64_t last) {
  uint64_t n = 0;
  for (uint64_t b = first; b < last; ++b)
    n += static_cast<uint64_t>(__builtin_popcount(static_cast<uint8_t>(bits[b])));
  return n;
}

}  // namespace

bool IsPackedAway(const Eigen::Vector3f& p) { return std::memcmp(&p, &kNoData, 12) == 0; }

void CloudToRequestProto(const PointCloud& cloud, v1::PointCloud* msg) {
  msg->set_width(cloud.width);
  msg->set_height(cloud.height);
  const uint64_t n = cloud.size();
  std::string bits((n + 7) / 8, '\0');
  uint64_t kept = 0;
  for (uint64_t i = 0; i < n; ++i)
    if (!IsPackedAway(cloud.points[i])) {
      bits[i / 8] = static_cast<char>(static_cast<uint8_t>(bits[i / 8]) | (1u << (i % 8)));
      ++kept;
    }
  if (12 * kept + bits.size() >= 12 * n) {  // nothing to save: the whole grid
    msg->clear_valid_bits();
    msg->mutable_xyz()->assign(reinterpret_cast<const char*>(cloud.points.data()), 12 * n);
    return;
  }
  std::string& xyz = *msg->mutable_xyz();
  xyz.resize(12 * kept);
  char* out = xyz.data();
  for (uint64_t i = 0; i < n; ++i)
    if (BitSet(bits, i)) {
      std::memcpy(out, cloud.points[i].data(), 12);
      out += 12;
    }
  *msg->mutable_valid_bits() = std::move(bits);
}

absl::StatusOr<PointCloud> CloudFromPackedBytes(const std::string& xyz,
                                                const std::string& valid_bits, uint32_t width,
                                                uint32_t height, const std::string& field) {
  const uint64_t n = uint64_t{width} * height;
  if (valid_bits.size() != (n + 7) / 8)
    return Invalid(
        field, absl::StrCat("valid_bits holds ", valid_bits.size(), " bytes but width*height = ", n,
                            " points need ", (n + 7) / 8));
  if (n % 8 != 0 && (static_cast<uint8_t>(valid_bits.back()) >> (n % 8)) != 0)
    return Invalid(field, "valid_bits sets a bit past the last point");
  const uint64_t blocks = (n + kCloudBlock - 1) / kCloudBlock;
  std::vector<uint64_t> offset(blocks + 1, 0);  // first packed point of each block
  for (uint64_t b = 0; b < blocks; ++b)
    offset[b + 1] =
        offset[b] + CountBits(valid_bits, b * kCloudBlock / 8,
                              std::min<uint64_t>(valid_bits.size(), (b + 1) * kCloudBlock / 8));
  if (xyz.size() != 12 * offset[blocks])
    return Invalid(
        field, absl::StrCat("xyz holds ", xyz.size(), " bytes but valid_bits sets ", offset[blocks],
                            " points (", 12 * offset[blocks], " bytes)"));
  return CloudFromBlocks(width, height, field,
                         [&](uint64_t b, uint64_t first, uint64_t last, Eigen::Vector3f* points) {
                           const char* in = xyz.data() + 12 * offset[b];
                           for (uint64_t i = first; i < last; ++i) {
                             if (BitSet(valid_bits, i)) {
                               std::memcpy(points[i].data(), in, 12);
                               in += 12;
                             } else {
                               points[i] = kNoData;
                             }
                           }
                         });
}

}  // namespace surfinspect::wire
