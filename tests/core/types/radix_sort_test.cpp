// core/types/radix_sort.cpp against std::stable_sort.
#include "core/types/radix_sort.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <numeric>
#include <random>
#include <vector>

namespace surfinspect {
namespace {

TEST(RadixSort, MatchesStableSortForEveryKeyWidth) {
  std::mt19937_64 rng(3);
  for (int key_bits : {1, 5, 11, 12, 22, 31, 33, 63}) {
    for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{17}, std::size_t{5000}}) {
      // Few distinct keys at small widths, so ties (and stability) matter.
      const uint64_t mask = key_bits == 64 ? ~uint64_t{0} : (uint64_t{1} << key_bits) - 1;
      std::vector<uint64_t> keys(n);
      for (auto& k : keys) k = rng() & mask;
      std::vector<uint32_t> values(n);
      std::iota(values.begin(), values.end(), 0u);
      std::vector<uint32_t> expected = values;
      std::stable_sort(expected.begin(), expected.end(),
                       [&](uint32_t a, uint32_t b) { return keys[a] < keys[b]; });
      std::vector<uint64_t> expected_keys(n);
      for (std::size_t i = 0; i < n; ++i) expected_keys[i] = keys[expected[i]];
      ASSERT_TRUE(RadixSortPairs(keys, values, key_bits));
      EXPECT_EQ(values, expected) << key_bits << " bits, n " << n;
      EXPECT_EQ(keys, expected_keys) << key_bits << " bits, n " << n;
    }
  }
}

TEST(RadixSort, StopsWhenCancelled) {
  std::vector<uint64_t> keys = {3, 1, 2};
  std::vector<uint32_t> values = {0, 1, 2};
  std::atomic<bool> cancel{true};
  EXPECT_FALSE(RadixSortPairs(keys, values, 2, &cancel));
  cancel = false;
  EXPECT_TRUE(RadixSortPairs(keys, values, 2, &cancel));
  EXPECT_EQ(values, (std::vector<uint32_t>{1, 2, 0}));
}

// The packed form gives RadixSortPairs' order, with few distinct keys so
// stability shows, and past the cancel stride (2^16 items).
TEST(RadixSort, PackedMatchesThePairSort) {
  std::mt19937_64 rng(5);
  for (int key_bits : {1, 11, 12, 31, 32})
    for (std::size_t n : {std::size_t{0}, std::size_t{3}, std::size_t{5000}, std::size_t{200000}}) {
      const uint64_t mask = (uint64_t{1} << key_bits) - 1;
      std::vector<uint64_t> keys(n);
      DefaultInitVector<uint64_t> packed(n);
      std::vector<uint32_t> values(n);
      for (std::size_t i = 0; i < n; ++i) {
        keys[i] = rng() & mask & (key_bits > 11 ? 0xfff0f : mask);
        values[i] = static_cast<uint32_t>(rng());
        packed[i] = keys[i] << 32 | values[i];
      }
      ASSERT_TRUE(RadixSortPairs(keys, values, key_bits));
      ASSERT_TRUE(RadixSortPacked(packed, key_bits));
      for (std::size_t i = 0; i < n; ++i) {
        ASSERT_EQ(packed[i] >> 32, keys[i]) << key_bits << " bits, item " << i;
        ASSERT_EQ(static_cast<uint32_t>(packed[i]), values[i]) << key_bits << " bits, item " << i;
      }
    }
}

// Chunked passes on 1, 2, 3 and 5 threads give std::stable_sort's order by
// key, on sizes that split into chunks of unequal length, with a key that
// leaves some digits the same for every item (a skipped pass) and one that
// does not.
TEST(RadixSort, PackedGivesTheStableOrderOnAnyNumberOfThreads) {
  std::mt19937_64 rng(9);
  for (std::size_t n : {std::size_t{131072}, std::size_t{700001}})
    for (const uint64_t key_mask : {uint64_t{0x3fffffff}, uint64_t{0x400003ff}, uint64_t{0x7}}) {
      DefaultInitVector<uint64_t> input(n);
      for (std::size_t i = 0; i < n; ++i) input[i] = (rng() & key_mask) << 32 | i;
      std::vector<uint64_t> want(input.begin(), input.end());
      std::stable_sort(want.begin(), want.end(),
                       [](uint64_t a, uint64_t b) { return (a >> 32) < (b >> 32); });
      for (int threads : {1, 2, 3, 5}) {
        DefaultInitVector<uint64_t> items = input;
        bool ok = false;
        tbb::task_arena(threads).execute([&] { ok = RadixSortPacked(items, 31); });
        ASSERT_TRUE(ok);
        ASSERT_TRUE(std::equal(items.begin(), items.end(), want.begin()))
            << ::testing::Message() << n << " items, key mask " << key_mask << ", " << threads
            << " threads";
      }
    }
}

TEST(RadixSort, PackedStopsWhenCancelled) {
  DefaultInitVector<uint64_t> items = {uint64_t{3} << 32, uint64_t{1} << 32 | 1};
  std::atomic<bool> cancel{true};
  EXPECT_FALSE(RadixSortPacked(items, 2, &cancel));
  cancel = false;
  ASSERT_TRUE(RadixSortPacked(items, 2, &cancel));
  EXPECT_EQ(items[0], uint64_t{1} << 32 | 1);
}

}  // namespace
}  // namespace surfinspect
