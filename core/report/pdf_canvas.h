// A4 portrait PDF pages drawn with cairo, text laid out by pango in DejaVu
// Sans (embedded as a font subset, so the text is selectable and searchable).
// Coordinates are PDF points (1/72 in) from the page's top-left corner.
// Text is always set as plain UTF-8 (never pango markup, invalid bytes
// replaced), so strings from outside render literally. The only file that
// includes cairo or pango headers is pdf_canvas.cpp.
#pragma once

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "core/io/png_image.h"

namespace surfinspect {

class PdfCanvas {
 public:
  static constexpr double kPageWidth = 595.276;  // A4: 210 mm
  static constexpr double kPageHeight = 841.89;  // A4: 297 mm

  struct Font {
    double size = 9;  // pt
    bool bold = false;
    Rgb color{0, 0, 0};
  };

  // `title` goes into the document's metadata.
  static absl::StatusOr<std::unique_ptr<PdfCanvas>> Create(const std::string& title);
  ~PdfCanvas();
  PdfCanvas(const PdfCanvas&) = delete;
  PdfCanvas& operator=(const PdfCanvas&) = delete;

  // Draws `text` with its top-left at (x, y), wrapped at word or character
  // boundaries to `width` when width > 0; right-aligned within `width` when
  // `right`. Returns the height used.
  double Text(double x, double y, const std::string& text, const Font& font, double width = 0,
              bool right = false);
  // The height Text would use, without drawing.
  double TextHeight(const std::string& text, const Font& font, double width = 0);
  void Rect(double x, double y, double w, double h, Rgb fill);
  void Line(double x0, double y0, double x1, double y1, double line_width, Rgb color,
            bool dashed = false);
  // The raster scaled into the box (x, y, w, h), drawn with its own pixels
  // (nearest-neighbour, no smoothing).
  void Image(const RgbImage& image, double x, double y, double w, double h);
  void NewPage();
  int page() const { return page_; }

  // Ends the document; Internal naming cairo's status if it failed.
  absl::StatusOr<std::string> Finish();

 private:
  struct Impl;
  explicit PdfCanvas(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
  int page_ = 1;
};

}  // namespace surfinspect
