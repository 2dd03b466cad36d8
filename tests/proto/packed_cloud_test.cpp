#include "proto/packed_cloud.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include "proto/convert.h"

namespace surfinspect::wire {
namespace {

std::string Bytes(const PointCloud& c) {
  return std::string(reinterpret_cast<const char*>(c.points.data()), c.size() * 12);
}

float FloatOfBits(uint32_t bits) {
  float f;
  std::memcpy(&f, &bits, 4);
  return f;
}

// A grid with a fraction `holes` of quiet-NaN points, and a few points of
// the other spellings of "no data" (a signalling NaN, a negative NaN, one
// NaN coordinate), which must travel as they are.
PointCloud Scan(uint32_t w, uint32_t h, double holes, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-500.f, 500.f);
  std::uniform_real_distribution<double> hole(0, 1);
  PointCloud c = PointCloud::Organized(w, h);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (hole(rng) < holes) continue;  // Organized() leaves quiet NaNs
    c.points[i] = Eigen::Vector3f(u(rng), u(rng), u(rng));
    if (i % 101 == 5) c.points[i].x() = nan;
    if (i % 103 == 7) c.points[i] = Eigen::Vector3f::Constant(FloatOfBits(0xffc00000u));
    if (i % 107 == 9) c.points[i] = Eigen::Vector3f::Constant(FloatOfBits(0x7fa00000u));
  }
  return c;
}

// Brute force: the points that are not three quiet NaNs, in grid order.
std::string KeptBytes(const PointCloud& c) {
  std::string out;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const Eigen::Vector3f no_data(nan, nan, nan);
  for (const auto& p : c.points)
    if (std::memcmp(&p, &no_data, 12) != 0) out.append(reinterpret_cast<const char*>(&p), 12);
  return out;
}

// Sizes around a byte of bits and around the 65,536-point blocks of the
// parallel unpacking; every byte of every point comes back.
TEST(PackedCloud, RoundTripRestoresEveryByte) {
  const std::pair<uint32_t, uint32_t> shapes[] = {{1, 1},     {7, 1},     {8, 1},    {9, 3},
                                                  {256, 256}, {257, 255}, {1024, 97}};
  uint32_t seed = 1;
  for (const auto& [w, h] : shapes)
    for (double holes : {0.05, 0.35, 0.99}) {
      const PointCloud in = Scan(w, h, holes, seed++);
      v1::PointCloud msg;
      CloudToRequestProto(in, &msg);
      const std::string kept = KeptBytes(in);
      SCOPED_TRACE(::testing::Message() << w << "x" << h << " holes " << holes);
      if (msg.valid_bits().empty()) {  // only when packing saves nothing
        EXPECT_GE(kept.size() + (in.size() + 7) / 8, 12 * in.size());
        EXPECT_EQ(msg.xyz(), Bytes(in));
      } else {
        EXPECT_EQ(msg.xyz(), kept);
        EXPECT_EQ(msg.valid_bits().size(), (in.size() + 7) / 8);
      }
      auto out = CloudFromProto(msg, "cloud", Limits{});
      ASSERT_TRUE(out.ok()) << out.status();
      EXPECT_EQ(out->width, w);
      EXPECT_EQ(out->height, h);
      EXPECT_EQ(Bytes(*out), Bytes(in));
    }
}

TEST(PackedCloud, WholeGridWhenNothingIsPackedAway) {
  const PointCloud in = Scan(64, 8, 0.0, 3);
  v1::PointCloud msg;
  CloudToRequestProto(in, &msg);
  EXPECT_TRUE(msg.valid_bits().empty());
  EXPECT_EQ(msg.xyz(), Bytes(in));
}

TEST(PackedCloud, AllNoDataSendsOnlyTheBits) {
  const PointCloud in = PointCloud::Organized(20, 10);
  v1::PointCloud msg;
  CloudToRequestProto(in, &msg);
  EXPECT_TRUE(msg.xyz().empty());
  EXPECT_EQ(msg.valid_bits(), std::string(25, '\0'));
  auto out = CloudFromProto(msg, "cloud", Limits{});
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(Bytes(*out), Bytes(in));
}

v1::PointCloud Packed(uint32_t w, uint32_t h) {
  v1::PointCloud msg;
  CloudToRequestProto(Scan(w, h, 0.4, 11), &msg);
  return msg;
}

TEST(PackedCloud, RefusesBitsOfTheWrongLength) {
  v1::PointCloud msg = Packed(10, 3);  // 30 points: 4 bytes of bits
  msg.mutable_valid_bits()->push_back('\0');
  auto out = CloudFromProto(msg, "views[0].cloud", Limits{});
  ASSERT_FALSE(out.ok());
  EXPECT_EQ(out.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(out.status().message().find("views[0].cloud: valid_bits holds 5 bytes"),
            std::string::npos)
      << out.status();
}

TEST(PackedCloud, RefusesABitPastTheLastPoint) {
  v1::PointCloud msg = Packed(10, 3);  // bits 30 and 31 of byte 3 are past the end
  (*msg.mutable_valid_bits())[3] = static_cast<char>(msg.valid_bits()[3] | 0x40);
  msg.mutable_xyz()->append(12, '\0');  // so the count alone would still agree
  auto out = CloudFromProto(msg, "cloud", Limits{});
  ASSERT_FALSE(out.ok());
  EXPECT_NE(out.status().message().find("past the last point"), std::string::npos) << out.status();
}

TEST(PackedCloud, RefusesXyzThatDoesNotMatchTheBits) {
  for (int extra : {-12, 12, 5}) {
    v1::PointCloud msg = Packed(300, 300);
    if (extra < 0)
      msg.mutable_xyz()->resize(msg.xyz().size() - 12);
    else
      msg.mutable_xyz()->append(static_cast<std::size_t>(extra), '\0');
    auto out = CloudFromProto(msg, "cloud", Limits{});
    ASSERT_FALSE(out.ok()) << extra;
    EXPECT_NE(out.status().message().find("but valid_bits sets"), std::string::npos)
        << out.status();
  }
}

// The first infinite point is named by its grid index, as in the whole-grid
// spelling, even when a later block of the parallel pass also has one.
TEST(PackedCloud, NamesTheFirstInfinitePointByItsGridIndex) {
  PointCloud in = Scan(512, 300, 0.3, 21);
  in.points[70000] = Eigen::Vector3f(1.f, std::numeric_limits<float>::infinity(), 2.f);
  in.points[150000] = Eigen::Vector3f(1.f, 2.f, -std::numeric_limits<float>::infinity());
  v1::PointCloud packed, whole;
  CloudToRequestProto(in, &packed);
  ASSERT_FALSE(packed.valid_bits().empty());
  CloudToProto(in, &whole);
  auto a = CloudFromProto(packed, "cloud", Limits{});
  auto b = CloudFromProto(whole, "cloud", Limits{});
  ASSERT_FALSE(a.ok());
  ASSERT_FALSE(b.ok());
  EXPECT_EQ(a.status(), b.status());
  EXPECT_NE(a.status().message().find("point 70000 "), std::string::npos) << a.status();
}

TEST(PackedCloud, ShapeLimitsStillApply) {
  v1::PointCloud msg = Packed(100, 100);
  Limits small;
  small.max_points = 9999;
  auto out = CloudFromProto(msg, "cloud", small);
  ASSERT_FALSE(out.ok());
  EXPECT_EQ(out.status().code(), absl::StatusCode::kResourceExhausted);
}

}  // namespace
}  // namespace surfinspect::wire
