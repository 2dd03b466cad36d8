#include "core/io/lzf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

namespace surfinspect {
namespace {

std::string Bytes(std::initializer_list<int> b) {
  std::string s;
  for (int c : b) s += static_cast<char>(c);
  return s;
}

TEST(LzfDecompress, DecodesLiteralsAndOverlappingReferences) {
  // "abc", then a reference of 2 + 2 = 4 bytes at distance 1 ("cccc"), then a
  // long reference of 7 + 1 + 2 = 10 bytes at distance 3.
  auto out = LzfDecompress(Bytes({2, 'a', 'b', 'c', 2 << 5, 0, 7 << 5, 1, 2}), 17);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(std::string(out->begin(), out->end()), std::string("abc") + std::string(14, 'c'));
}

TEST(LzfDecompress, RefusesStreamsThatLieAboutTheirSize) {
  auto expect = [](const std::string& in, uint64_t size, const char* part) {
    auto out = LzfDecompress(in, size);
    ASSERT_FALSE(out.ok()) << part;
    EXPECT_NE(out.status().message().find(part), std::string::npos) << out.status();
  };
  expect(Bytes({3, 'a', 'b', 'c', 'd', 0xe0, 0xff, 3}), 12, "decodes past its declared size of 12");
  expect(Bytes({3, 'a', 'b', 'c', 'd'}), 3, "decodes past its declared size of 3");
  expect(Bytes({3, 'a', 'b'}), 4, "literal run passes the end");
  expect(Bytes({0, 'a', 0xe0}), 20, "ends inside a reference");
  expect(Bytes({0, 'a', 0x20}), 4, "ends inside a reference");
  expect(Bytes({0, 'a', 0x20, 5}), 4, "points before the block's start");
  expect(Bytes({1, 'a', 'b'}), 3, "decodes to 2 bytes, not its declared 3");
  expect(Bytes({0, 'a'}), 1000, "cannot decode to 1000");
}

void ExpectRoundTrip(const std::string& in, const char* what) {
  const std::string packed = LzfCompress(in);
  EXPECT_LE(packed.size(), in.size() + in.size() / 32 + 1) << what;
  auto out = LzfDecompress(packed, in.size());
  ASSERT_TRUE(out.ok()) << what << ": " << out.status();
  ASSERT_EQ(std::string(out->begin(), out->end()), in) << what;
}

TEST(LzfCompress, RoundTripsEveryKindOfInput) {
  ExpectRoundTrip("", "empty");
  ExpectRoundTrip("a", "one byte");
  ExpectRoundTrip("ab", "two bytes");
  ExpectRoundTrip("aaaa", "a run shorter than a reference's reach");
  std::mt19937 rng(11);
  std::string noise(100000, '\0');
  for (char& c : noise) c = static_cast<char>(rng());
  ExpectRoundTrip(noise, "random bytes");
  // Repeats just inside, at and beyond the 8192-byte reach of a reference.
  for (std::size_t period : {8191u, 8192u, 8193u}) {
    std::string block(period, '\0');
    for (char& c : block) c = static_cast<char>(rng());
    ExpectRoundTrip(block + block + block, "period near the reach");
  }
  std::string floats(3 * 4 * 50000, '\0');
  for (std::size_t i = 0; i < floats.size() / 4; ++i) {
    const float v = i % 9 == 0 ? NAN : 400.f + std::sin(0.001f * static_cast<float>(i));
    std::memcpy(&floats[4 * i], &v, 4);
  }
  ExpectRoundTrip(floats, "a scan's coordinate planes");
}

TEST(LzfCompress, LongRunsBecomeMaximalReferences) {
  const std::string zeros(1 << 20, '\0');
  const std::string packed = LzfCompress(zeros);
  // 264 bytes per 3-byte reference at best: about 1/88.
  EXPECT_LT(packed.size(), zeros.size() / 80);
  ExpectRoundTrip(zeros, "zeros");
}

}  // namespace
}  // namespace surfinspect
