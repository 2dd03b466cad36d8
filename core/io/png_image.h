// A plain 8-bit RGB raster and its PNG writer (libpng), used for the filter
// preview and the error-map picture. Written atomically.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace surfinspect {

struct Rgb {
  uint8_t r = 0, g = 0, b = 0;
  bool operator==(const Rgb& o) const { return r == o.r && g == o.g && b == o.b; }
};

static_assert(sizeof(Rgb) == 3, "Rgb rows are handed to libpng as packed bytes");

struct RgbImage {
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<Rgb> pixels;  // row-major, top row first

  RgbImage() = default;
  RgbImage(uint32_t w, uint32_t h, Rgb fill = {})
      : width(w), height(h), pixels(std::size_t{w} * h, fill) {}
  Rgb& at(uint32_t x, uint32_t y) { return pixels[std::size_t{y} * width + x]; }
  const Rgb& at(uint32_t x, uint32_t y) const { return pixels[std::size_t{y} * width + x]; }
  // Clipped to the image.
  void FillRect(int x, int y, int w, int h, Rgb c);
  // Draws text in a built-in 5x7 pixel font (digits, letters, . - + : % / and
  // space), scaled by `scale`; unknown characters draw as blanks.
  void DrawText(int x, int y, const std::string& text, Rgb c, int scale = 1);
};

// The PNG bytes in memory (for RPC responses), and the same written to a
// file atomically.
absl::StatusOr<std::string> EncodePng(const RgbImage& image);
absl::Status WritePng(const std::string& path, const RgbImage& image);

}  // namespace surfinspect
