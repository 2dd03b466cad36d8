// core/types/default_init_vector.h: construction with a value, copies and
// class types behave as in std::vector; only value-less construction of a
// trivial type is left unwritten (which a test cannot read without UB).
#include "core/types/default_init_vector.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>

namespace surfinspect {
namespace {

struct Counted {
  static inline int constructed = 0;
  Counted() { ++constructed; }
  int value = 7;
};

TEST(DefaultInitVector, ValuesAndCopiesAreWritten) {
  DefaultInitVector<uint64_t> v(5, 42);
  v.resize(8, 9);
  v.push_back(3);
  EXPECT_EQ(v, (DefaultInitVector<uint64_t>{42, 42, 42, 42, 42, 9, 9, 9, 3}));
  const DefaultInitVector<uint64_t> copy = v;
  EXPECT_EQ(copy, v);
  DefaultInitVector<std::string> s(2, "ab");
  s.emplace_back(3, 'c');
  EXPECT_EQ(s[2], "ccc");
}

TEST(DefaultInitVector, ClassTypesStillRunTheirConstructor) {
  Counted::constructed = 0;
  DefaultInitVector<Counted> v(4);
  v.resize(6);
  EXPECT_EQ(Counted::constructed, 6);
  for (const Counted& c : v) EXPECT_EQ(c.value, 7);
}

// Every slot written after value-less construction reads back, through
// regrowth that moves the elements.
TEST(DefaultInitVector, WrittenSlotsSurviveGrowth) {
  DefaultInitVector<uint32_t> v(1000);
  for (uint32_t i = 0; i < v.size(); ++i) v[i] = i * 3;
  v.resize(300000);
  for (uint32_t i = 0; i < 1000; ++i) ASSERT_EQ(v[i], i * 3);
}

}  // namespace
}  // namespace surfinspect
