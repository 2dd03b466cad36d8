#include "proto/convert.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

namespace surfinspect::wire {
namespace {

std::string Bytes(const PointCloud& c) {
  return std::string(reinterpret_cast<const char*>(c.points.data()), c.size() * 12);
}

PointCloud Grid(uint32_t w, uint32_t h) {
  PointCloud c = PointCloud::Organized(w, h);
  for (std::size_t i = 0; i < c.size(); ++i)
    if (i % 7 != 3) c.points[i] = Eigen::Vector3f(float(i), -0.5f * float(i), 1e3f + float(i % 13));
  return c;  // every 7th point stays NaN
}

// Chunks of any size, including ones that split a point's 12 bytes, give
// the cloud the one-message path gives, bit for bit (NaN holes included).
TEST(CloudAssembler, ChunksOfAnySizeGiveTheSameCloud) {
  const PointCloud want = Grid(33, 17);
  const std::string bytes = Bytes(want);
  for (std::size_t chunk :
       {std::size_t{1}, std::size_t{5}, std::size_t{12}, std::size_t{1000}, bytes.size()}) {
    CloudAssembler a;
    a.Start(33, 17);
    EXPECT_EQ(a.expected_bytes(), bytes.size());
    for (std::size_t off = 0; off < bytes.size(); off += chunk) {
      EXPECT_FALSE(a.complete());
      ASSERT_TRUE(a.Add(bytes.substr(off, chunk), "view").ok());
    }
    ASSERT_TRUE(a.complete());
    auto got = a.Take("view");
    ASSERT_TRUE(got.ok()) << got.status();
    EXPECT_EQ(got->width, 33u);
    EXPECT_EQ(got->height, 17u);
    EXPECT_EQ(Bytes(*got), bytes);
    EXPECT_EQ(a.received_bytes(), 0u) << "Take empties the assembler";
  }
}

TEST(CloudAssembler, OverrunAndInfinityAreInvalidAndNamed) {
  CloudAssembler a;
  a.Start(2, 1);
  EXPECT_TRUE(a.Add(std::string(20, '\0'), "view 'top'").ok());
  const absl::Status over = a.Add(std::string(5, '\0'), "view 'top'");
  EXPECT_EQ(over.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(over.message().find("view 'top'"), absl::string_view::npos) << over.message();
  EXPECT_EQ(a.received_bytes(), 20u) << "a refused chunk is not half-copied";

  EXPECT_EQ(a.Take("view 'top'").status().code(), absl::StatusCode::kInvalidArgument)
      << "an incomplete cloud is not handed out";

  // An infinity is caught by the chunk that completes its point, even when
  // the point's bytes are split across chunks.
  PointCloud bad = Grid(3, 1);
  bad.points[1].y() = INFINITY;
  const std::string bytes = Bytes(bad);
  a.Start(3, 1);
  ASSERT_TRUE(a.Add(bytes.substr(0, 18), "view 'top'").ok());
  const absl::Status inf = a.Add(bytes.substr(18, 6), "view 'top'");
  EXPECT_EQ(inf.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(inf.message().find("point 1 has an infinite coordinate"), absl::string_view::npos)
      << inf.message();
}

}  // namespace
}  // namespace surfinspect::wire
