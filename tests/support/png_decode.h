// Decoding PNG bytes with libpng's own reader, so tests check what core
// encodes against code that shares nothing with it.
#pragma once

#include <string>

#include "core/io/png_image.h"

namespace surfinspect::testing {

// 8-bit packed RGB; width 0 on failure.
RgbImage DecodePng(const std::string& bytes);

}  // namespace surfinspect::testing
