#include "render/canvas.h"

#include <cairo-pdf.h>
#include <cairo-svg.h>

#include <algorithm>
#include <cmath>
#include <ostream>
#include <stdexcept>

#include "io/atomic_file.h"

namespace flexkin::render {
namespace {

cairo_status_t AppendBytes(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

void CheckStatus(cairo_status_t status, const char* what) {
  if (status != CAIRO_STATUS_SUCCESS) {
    throw std::runtime_error(std::string("cairo: ") + what + ": " + cairo_status_to_string(status));
  }
}

// Text without hinting and with grey anti-aliasing whatever the system's fontconfig says, so
// that pictures are the same on every machine with the same fonts (the golden-image tests).
void SetFont(cairo_t* cr, const TextStyle& style) {
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL,
                         style.bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, style.size);
}

}  // namespace

double UiScale(int width, int height) {
  // A wide, short picture gets the text of a 4:3 one of the same width.
  const double h = std::max<double>(height, 0.75 * width);
  return std::clamp(std::sqrt(width * h) / 830.0, 0.7, 3.0);
}

Canvas::Canvas(ImageFormat format, int width, int height)
    : format_(format), width_(width), height_(height) {
  ui_ = UiScale(width, height);
  switch (format) {
    case ImageFormat::kPng:
      surface_ = cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height);
      break;
    case ImageFormat::kSvg:
      surface_ = cairo_svg_surface_create_for_stream(AppendBytes, &bytes_, width, height);
      cairo_svg_surface_restrict_to_version(surface_, CAIRO_SVG_VERSION_1_1);
      cairo_svg_surface_set_document_unit(surface_, CAIRO_SVG_UNIT_PX);
      break;
    case ImageFormat::kPdf:
      surface_ = cairo_pdf_surface_create_for_stream(AppendBytes, &bytes_, width, height);
      cairo_pdf_surface_set_metadata(surface_, CAIRO_PDF_METADATA_CREATOR, "flexkin");
      break;
  }
  cr_ = cairo_create(surface_);
  if (cairo_status(cr_) != CAIRO_STATUS_SUCCESS) {
    const cairo_status_t status = cairo_status(cr_);
    cairo_destroy(cr_);
    cairo_surface_destroy(surface_);
    CheckStatus(status, "creating the surface");
  }
  cairo_font_options_t* font = cairo_font_options_create();
  cairo_font_options_set_hint_style(font, CAIRO_HINT_STYLE_NONE);
  cairo_font_options_set_hint_metrics(font, CAIRO_HINT_METRICS_OFF);
  cairo_font_options_set_antialias(font, CAIRO_ANTIALIAS_GRAY);
  cairo_set_font_options(cr_, font);
  cairo_font_options_destroy(font);
  cairo_set_line_cap(cr_, CAIRO_LINE_CAP_ROUND);
  cairo_set_line_join(cr_, CAIRO_LINE_JOIN_ROUND);
  Clear();
}

Canvas::~Canvas() {
  cairo_destroy(cr_);
  cairo_surface_destroy(surface_);
}

void Canvas::Clear() {
  cairo_save(cr_);
  SetColor(cr_, kWhite);
  cairo_paint(cr_);
  cairo_restore(cr_);
}

std::string Canvas::Finish() {
  CheckStatus(cairo_status(cr_), "drawing");
  if (format_ == ImageFormat::kPng) {
    std::string png;
    CheckStatus(cairo_surface_write_to_png_stream(surface_, AppendBytes, &png), "writing PNG");
    return png;
  }
  cairo_surface_finish(surface_);
  CheckStatus(cairo_surface_status(surface_), "writing the document");
  return std::move(bytes_);
}

const unsigned char* Canvas::Pixels() {
  cairo_surface_flush(surface_);
  return cairo_image_surface_get_data(surface_);
}

int Canvas::Stride() const { return cairo_image_surface_get_stride(surface_); }

void SaveCanvas(Canvas* canvas, const std::string& path) {
  const std::string bytes = canvas->Finish();
  WriteFileAtomically(path, [&](std::ostream& out) {
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  });
}

double TextWidth(cairo_t* cr, const std::string& text, const TextStyle& style) {
  cairo_save(cr);
  SetFont(cr, style);
  cairo_text_extents_t extents;
  cairo_text_extents(cr, text.c_str(), &extents);
  cairo_restore(cr);
  return extents.x_advance;
}

double DrawText(cairo_t* cr, double x, double y, const std::string& text, const TextStyle& style) {
  cairo_save(cr);
  SetFont(cr, style);
  cairo_text_extents_t extents;
  cairo_text_extents(cr, text.c_str(), &extents);
  cairo_font_extents_t font;
  cairo_font_extents(cr, &font);
  const double w = extents.x_advance;
  const double dx = style.halign == Align::kStart    ? 0.0
                    : style.halign == Align::kCenter ? -w / 2
                                                     : -w;
  // Vertical anchors from the font's ascent (capital height is about 0.73 of the size).
  const double cap = 0.73 * style.size;
  const double dy = style.valign == Align::kStart    ? cap
                    : style.valign == Align::kCenter ? cap / 2
                                                     : 0.0;
  cairo_translate(cr, x, y);
  cairo_rotate(cr, -style.angle);
  cairo_move_to(cr, dx, dy);
  SetColor(cr, style.color);
  cairo_show_text(cr, text.c_str());
  cairo_restore(cr);
  return w;
}

void SetColor(cairo_t* cr, const Rgb& color, double alpha) {
  if (alpha >= 1.0) {
    cairo_set_source_rgb(cr, color.r, color.g, color.b);
  } else {
    cairo_set_source_rgba(cr, color.r, color.g, color.b, alpha);
  }
}

void Line(cairo_t* cr, double x0, double y0, double x1, double y1, const Rgb& color, double width) {
  cairo_move_to(cr, x0, y0);
  cairo_line_to(cr, x1, y1);
  SetColor(cr, color);
  cairo_set_line_width(cr, width);
  cairo_stroke(cr);
}

void Disc(cairo_t* cr, double x, double y, double radius, const Rgb& fill) {
  cairo_new_sub_path(cr);
  cairo_arc(cr, x, y, radius, 0.0, 2.0 * M_PI);
  SetColor(cr, fill);
  cairo_fill(cr);
}

void Ring(cairo_t* cr, double x, double y, double radius, const Rgb& color, double width) {
  cairo_new_sub_path(cr);
  cairo_arc(cr, x, y, radius, 0.0, 2.0 * M_PI);
  SetColor(cr, kWhite);
  cairo_fill_preserve(cr);
  SetColor(cr, color);
  cairo_set_line_width(cr, width);
  cairo_stroke(cr);
}

}  // namespace flexkin::render

#if defined(__SANITIZE_ADDRESS__)
// Under AddressSanitizer (make test-sanitize): fontconfig, which cairo uses to find the font,
// leaves a few blocks (about 1 KB, once per process) unreachable at exit. They are not ours to
// free; LeakSanitizer reads this hook of every program that draws with Canvas.
extern "C" const char* __lsan_default_suppressions() { return "leak:libfontconfig.so\n"; }
extern "C" const char* __lsan_default_options() { return "print_suppressions=0"; }
#endif
