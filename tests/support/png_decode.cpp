#include "tests/support/png_decode.h"

#include <png.h>

namespace surfinspect::testing {

RgbImage DecodePng(const std::string& bytes) {
  png_image img{};
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&img, bytes.data(), bytes.size())) return {};
  img.format = PNG_FORMAT_RGB;
  RgbImage out(img.width, img.height);
  if (!png_image_finish_read(&img, nullptr, out.pixels.data(), 0, nullptr)) return {};
  return out;
}

}  // namespace surfinspect::testing
