#include "core/report/pdf_canvas.h"

#include <cairo-pdf.h>
#include <cairo.h>
#include <glib.h>
#include <pango/pangocairo.h>

#include <cstring>
#include <vector>

#include "absl/strings/str_cat.h"

namespace surfinspect {
namespace {

cairo_status_t AppendTo(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

void SetColor(cairo_t* cr, Rgb c) {
  cairo_set_source_rgb(cr, c.r / 255.0, c.g / 255.0, c.b / 255.0);
}

// Pango needs valid UTF-8 without NULs: invalid bytes and NULs become U+FFFD.
std::string ValidUtf8(const std::string& s) {
  std::string no_nul;
  for (char ch : s) no_nul += ch == '\0' ? std::string("\xEF\xBF\xBD") : std::string(1, ch);
  gchar* valid = g_utf8_make_valid(no_nul.data(), static_cast<gssize>(no_nul.size()));
  std::string out(valid);
  g_free(valid);
  return out;
}

}  // namespace

struct PdfCanvas::Impl {
  std::string bytes;
  cairo_surface_t* surface = nullptr;
  cairo_t* cr = nullptr;
  PangoLayout* layout = nullptr;
  PangoFontDescription* regular = nullptr;
  PangoFontDescription* bold = nullptr;
  ~Impl() {
    if (regular) pango_font_description_free(regular);
    if (bold) pango_font_description_free(bold);
    if (layout) g_object_unref(layout);
    if (cr) cairo_destroy(cr);
    if (surface) cairo_surface_destroy(surface);
  }
  // The layout holding `text` in `font`, wrapped to `width` (pt) when > 0.
  PangoLayout* Layout(const std::string& text, const Font& font, double width, bool right) {
    PangoFontDescription* desc = font.bold ? bold : regular;
    pango_font_description_set_absolute_size(desc, font.size * PANGO_SCALE);
    pango_layout_set_font_description(layout, desc);
    pango_layout_set_width(layout, width > 0 ? static_cast<int>(width * PANGO_SCALE) : -1);
    pango_layout_set_wrap(layout, PANGO_WRAP_WORD_CHAR);
    pango_layout_set_alignment(layout, right ? PANGO_ALIGN_RIGHT : PANGO_ALIGN_LEFT);
    const std::string valid = ValidUtf8(text);
    pango_layout_set_text(layout, valid.data(), static_cast<int>(valid.size()));
    return layout;
  }
};

PdfCanvas::PdfCanvas(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
PdfCanvas::~PdfCanvas() = default;

absl::StatusOr<std::unique_ptr<PdfCanvas>> PdfCanvas::Create(const std::string& title) {
  auto impl = std::make_unique<Impl>();
  impl->surface =
      cairo_pdf_surface_create_for_stream(AppendTo, &impl->bytes, kPageWidth, kPageHeight);
  if (cairo_surface_status(impl->surface) != CAIRO_STATUS_SUCCESS)
    return absl::InternalError(
        absl::StrCat("pdf: ", cairo_status_to_string(cairo_surface_status(impl->surface))));
  cairo_pdf_surface_set_metadata(impl->surface, CAIRO_PDF_METADATA_TITLE, ValidUtf8(title).c_str());
  cairo_pdf_surface_set_metadata(impl->surface, CAIRO_PDF_METADATA_CREATOR, "surfinspect");
  impl->cr = cairo_create(impl->surface);
  impl->layout = pango_cairo_create_layout(impl->cr);
  impl->regular = pango_font_description_from_string("DejaVu Sans");
  impl->bold = pango_font_description_from_string("DejaVu Sans Bold");
  return std::unique_ptr<PdfCanvas>(new PdfCanvas(std::move(impl)));
}

double PdfCanvas::Text(double x, double y, const std::string& text, const Font& font, double width,
                       bool right) {
  PangoLayout* layout = impl_->Layout(text, font, width, right);
  cairo_move_to(impl_->cr, x, y);
  SetColor(impl_->cr, font.color);
  pango_cairo_show_layout(impl_->cr, layout);
  int w = 0, h = 0;
  pango_layout_get_size(layout, &w, &h);
  return static_cast<double>(h) / PANGO_SCALE;
}

double PdfCanvas::TextHeight(const std::string& text, const Font& font, double width) {
  int w = 0, h = 0;
  pango_layout_get_size(impl_->Layout(text, font, width, false), &w, &h);
  return static_cast<double>(h) / PANGO_SCALE;
}

void PdfCanvas::Rect(double x, double y, double w, double h, Rgb fill) {
  SetColor(impl_->cr, fill);
  cairo_rectangle(impl_->cr, x, y, w, h);
  cairo_fill(impl_->cr);
}

void PdfCanvas::Line(double x0, double y0, double x1, double y1, double line_width, Rgb color,
                     bool dashed) {
  cairo_t* cr = impl_->cr;
  const double dash[] = {2.0, 2.0};
  cairo_set_dash(cr, dash, dashed ? 2 : 0, 0);
  SetColor(cr, color);
  cairo_set_line_width(cr, line_width);
  cairo_move_to(cr, x0, y0);
  cairo_line_to(cr, x1, y1);
  cairo_stroke(cr);
  cairo_set_dash(cr, dash, 0, 0);
}

void PdfCanvas::Image(const RgbImage& image, double x, double y, double w, double h) {
  if (image.width == 0 || image.height == 0) return;
  cairo_surface_t* img = cairo_image_surface_create(
      CAIRO_FORMAT_RGB24, static_cast<int>(image.width), static_cast<int>(image.height));
  cairo_surface_flush(img);
  unsigned char* data = cairo_image_surface_get_data(img);
  const int stride = cairo_image_surface_get_stride(img);
  for (uint32_t row = 0; row < image.height; ++row) {
    auto* out = reinterpret_cast<uint32_t*>(data + static_cast<std::size_t>(row) * stride);
    for (uint32_t col = 0; col < image.width; ++col) {
      const Rgb c = image.at(col, row);
      out[col] = (uint32_t{c.r} << 16) | (uint32_t{c.g} << 8) | c.b;
    }
  }
  cairo_surface_mark_dirty(img);
  cairo_t* cr = impl_->cr;
  cairo_save(cr);
  cairo_translate(cr, x, y);
  cairo_scale(cr, w / image.width, h / image.height);
  cairo_set_source_surface(cr, img, 0, 0);
  cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_NEAREST);
  cairo_paint(cr);
  cairo_restore(cr);
  cairo_surface_destroy(img);
}

void PdfCanvas::NewPage() {
  cairo_show_page(impl_->cr);
  ++page_;
}

// cairo_surface_finish emits the last page unless it is blank.
absl::StatusOr<std::string> PdfCanvas::Finish() {
  cairo_surface_finish(impl_->surface);
  const cairo_status_t st = cairo_surface_status(impl_->surface);
  if (st != CAIRO_STATUS_SUCCESS)
    return absl::InternalError(absl::StrCat("pdf: ", cairo_status_to_string(st)));
  return std::move(impl_->bytes);
}

}  // namespace surfinspect
