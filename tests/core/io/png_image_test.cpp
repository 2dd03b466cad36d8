#include "core/io/png_image.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/support/png_decode.h"
#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

RgbImage Gradient(uint32_t w, uint32_t h) {
  RgbImage img(w, h);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x)
      img.at(x, y) = {static_cast<uint8_t>(x * 37), static_cast<uint8_t>(y * 11),
                      static_cast<uint8_t>((x ^ y) * 5)};
  return img;
}

std::size_t CountColour(const RgbImage& img, Rgb c) {
  std::size_t n = 0;
  for (const Rgb& p : img.pixels) n += p == c ? 1 : 0;
  return n;
}

TEST(PngImage, EncodedBytesDecodeToTheSamePixels) {
  for (auto [w, h] : {std::pair<uint32_t, uint32_t>{1, 1}, {17, 5}, {300, 200}}) {
    const RgbImage img = Gradient(w, h);
    auto bytes = EncodePng(img);
    ASSERT_TRUE(bytes.ok()) << bytes.status();
    EXPECT_EQ(bytes->substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    const RgbImage back = testing::DecodePng(*bytes);
    EXPECT_EQ(back.width, w);
    EXPECT_EQ(back.height, h);
    EXPECT_TRUE(back.pixels == img.pixels) << w << "x" << h;
  }
}

TEST(PngImage, WritePngWritesTheSameBytesToAFile) {
  testing::TempDir dir;
  const RgbImage img = Gradient(64, 48);
  ASSERT_TRUE(WritePng(dir.File("map.png"), img).ok());
  const std::string file = testing::ReadBytes(dir.File("map.png"));
  EXPECT_EQ(file, *EncodePng(img));
  const RgbImage back = testing::DecodePng(file);
  EXPECT_EQ(back.width, 64u);
  EXPECT_EQ(back.height, 48u);
  EXPECT_TRUE(back.pixels == img.pixels);
}

TEST(PngImage, EmptyImagesAndBadPathsAreErrors) {
  EXPECT_EQ(EncodePng(RgbImage()).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(EncodePng(RgbImage(0, 5)).status().code(), absl::StatusCode::kInvalidArgument);
  RgbImage short_rows(4, 4);
  short_rows.pixels.pop_back();
  EXPECT_EQ(EncodePng(short_rows).status().code(), absl::StatusCode::kInvalidArgument);

  testing::TempDir dir;
  const absl::Status empty = WritePng(dir.File("e.png"), RgbImage());
  EXPECT_EQ(empty.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(empty.message().find(dir.File("e.png")), std::string::npos) << empty;
  const absl::Status bad_path = WritePng(dir.File("missing/dir/x.png"), Gradient(4, 4));
  EXPECT_FALSE(bad_path.ok());
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(PngImage, FillRectIsClippedToTheImage) {
  const Rgb red{255, 0, 0};
  RgbImage img(10, 8);
  img.FillRect(-3, 6, 5, 10, red);  // covers x 0..1, y 6..7
  EXPECT_EQ(CountColour(img, red), 4u);
  EXPECT_EQ(img.at(1, 7), red);
  EXPECT_EQ(img.at(2, 7), Rgb{});
  EXPECT_EQ(img.at(1, 5), Rgb{});
  img.FillRect(20, 20, 5, 5, red);  // entirely outside
  img.FillRect(3, 3, 0, 4, red);    // zero width
  EXPECT_EQ(CountColour(img, red), 4u);
  img.FillRect(-100, -100, 1000, 1000, red);
  EXPECT_EQ(CountColour(img, red), 80u);
}

TEST(PngImage, DrawTextRendersTheFiveBySevenGlyphs) {
  const Rgb ink{0, 0, 0};
  // '1' is rows {4, 12, 4, 4, 4, 4, 14} (bit 4 = leftmost column): 10 pixels.
  RgbImage one(20, 20, {255, 255, 255});
  one.DrawText(2, 3, "1", ink);
  EXPECT_EQ(CountColour(one, ink), 10u);
  EXPECT_EQ(one.at(2 + 2, 3), ink);  // row 0: column 2 only
  EXPECT_FALSE(one.at(2 + 1, 3) == ink);
  EXPECT_EQ(one.at(2 + 1, 3 + 1), ink);  // row 1: columns 1 and 2
  for (int col = 1; col <= 3; ++col) EXPECT_EQ(one.at(2 + col, 3 + 6), ink);  // row 6

  // Scale 3 draws each glyph pixel as a 3x3 block.
  RgbImage big(40, 40, {255, 255, 255});
  big.DrawText(0, 0, "1", ink, 3);
  EXPECT_EQ(CountColour(big, ink), 90u);

  // Upper case reuses the lower-case glyph; unknown characters are blanks
  // that still advance the pen by 6 * scale.
  RgbImage lower(40, 10), upper(40, 10), shifted(40, 10), plain(40, 10);
  const Rgb white{255, 255, 255};
  lower.DrawText(0, 0, "ab", white);
  upper.DrawText(0, 0, "AB", white);
  EXPECT_TRUE(lower.pixels == upper.pixels);
  shifted.DrawText(0, 0, "#1", white);
  plain.DrawText(6, 0, "1", white);
  EXPECT_TRUE(shifted.pixels == plain.pixels);
  EXPECT_EQ(CountColour(plain, white), 10u);
}

}  // namespace
}  // namespace surfinspect
