#include "core/io/text_parse.h"

#include <gtest/gtest.h>

#include <cmath>

namespace surfinspect {
namespace {

TEST(TextParse, NumbersMustBeWhollyNumeric) {
  uint64_t u = 0;
  EXPECT_TRUE(ParseUint("18446744073709551615", &u));
  EXPECT_EQ(u, UINT64_MAX);
  for (const char* bad : {"", "18446744073709551616", "+1", "-1", " 1", "1x", "0x1"})
    EXPECT_FALSE(ParseUint(bad, &u)) << bad;
  int64_t i = 0;
  EXPECT_TRUE(ParseInt("-9223372036854775808", &i));
  EXPECT_EQ(i, INT64_MIN);
  EXPECT_FALSE(ParseInt("9223372036854775808", &i));
  EXPECT_FALSE(ParseInt("-", &i));
  float f = 0;
  EXPECT_TRUE(ParseFloat("0.1", &f));
  EXPECT_EQ(f, 0.1f);
  EXPECT_TRUE(ParseFloat("1e50", &f));
  EXPECT_TRUE(std::isinf(f));
  EXPECT_TRUE(ParseFloat("NaN", &f));
  EXPECT_TRUE(std::isnan(f));
  for (const char* bad : {"", " 1", "1 ", "1,5", "0x1p3", "1e", "e1", "--1"})
    EXPECT_FALSE(ParseFloat(bad, &f)) << bad;
  double d = 0;
  EXPECT_TRUE(ParseDouble("-2.5e-3", &d));
  EXPECT_EQ(d, -2.5e-3);
}

TEST(TextParse, CheckedArithmeticAndScanners) {
  uint64_t r = 0;
  EXPECT_TRUE(CheckedMul(1ull << 32, (1ull << 32) - 1, &r));
  EXPECT_FALSE(CheckedMul(1ull << 32, 1ull << 32, &r));
  EXPECT_FALSE(CheckedAdd(UINT64_MAX, 1, &r));
  LineScanner lines("a\r\n\nb c\n d");
  std::string_view line;
  std::vector<std::string> got;
  while (lines.Next(&line)) got.emplace_back(line);
  EXPECT_EQ(got, (std::vector<std::string>{"a", "", "b c", " d"}));
  EXPECT_EQ(lines.line_number(), 4u);
  std::vector<std::string_view> tok;
  SplitWhitespace(" \t1  2\r3 ", &tok);
  EXPECT_EQ(tok, (std::vector<std::string_view>{"1", "2", "3"}));
  EXPECT_TRUE(IsBlank(" \t\r"));
  EXPECT_EQ(Excerpt(std::string("a\x01") + std::string(50, 'b'), 5), "a?bbb...");
}

TEST(TextParse, ReadWholeFileNamesTheProblem) {
  EXPECT_EQ(ReadWholeFile("/nonexistent/x.pcd", 10).status().code(), absl::StatusCode::kNotFound);
}

}  // namespace
}  // namespace surfinspect
