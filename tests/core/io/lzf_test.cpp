#include "core/io/lzf.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace surfinspect
