#include "render/legend.h"

#include <algorithm>
#include <limits>

#include "render/canvas.h"
#include "render/snapshot.h"

namespace flexkin::render {
namespace {

constexpr double kSwatch = 30.0, kPad = 9.0, kRow = 19.0, kText = 12.0;  // pixels at ui = 1

}  // namespace

Legend::Legend(double ui, std::vector<LegendEntry> entries)
    : ui_(ui), entries_(std::move(entries)) {
  // Text is measured on a scratch surface: with hinting off (Canvas) the advance widths are
  // the same on every surface.
  cairo_surface_t* scratch = cairo_image_surface_create(CAIRO_FORMAT_RGB24, 1, 1);
  cairo_t* cr = cairo_create(scratch);
  cairo_font_options_t* font = cairo_font_options_create();
  cairo_font_options_set_hint_style(font, CAIRO_HINT_STYLE_NONE);
  cairo_font_options_set_hint_metrics(font, CAIRO_HINT_METRICS_OFF);
  cairo_set_font_options(cr, font);
  cairo_font_options_destroy(font);
  TextStyle text;
  text.size = kText * ui_;
  double widest = 0.0;
  for (const LegendEntry& e : entries_) widest = std::max(widest, TextWidth(cr, e.label, text));
  cairo_destroy(cr);
  cairo_surface_destroy(scratch);
  width_ = (3 * kPad + kSwatch) * ui_ + widest;
  height_ = (2 * kPad + kRow * entries_.size() - 4) * ui_;
}

size_t Legend::PlaceInCorner(const Rect& region, const std::vector<Eigen::Vector2d>& avoid) {
  const double inset = 10 * ui_, margin = 6 * ui_;
  const Eigen::Vector2d corners[4] = {
      {region.right() - inset - width_, region.y + inset},
      {region.x + inset, region.y + inset},
      {region.right() - inset - width_, region.bottom() - inset - height_},
      {region.x + inset, region.bottom() - inset - height_}};
  size_t fewest = std::numeric_limits<size_t>::max();
  for (const Eigen::Vector2d& c : corners) {
    size_t covered = 0;
    for (const Eigen::Vector2d& p : avoid) {
      covered += p.x() > c.x() - margin && p.x() < c.x() + width_ + margin &&
                 p.y() > c.y() - margin && p.y() < c.y() + height_ + margin;
    }
    if (covered < fewest) {
      fewest = covered;
      PlaceAt(c.x(), c.y());
    }
  }
  return fewest;
}

void Legend::PlaceAt(double x, double y) {
  x_ = x;
  y_ = y;
}

void Legend::Draw(cairo_t* cr) const {
  const double ui = ui_;
  cairo_rectangle(cr, x_, y_, width_, height_);
  SetColor(cr, kWhite, 0.92);
  cairo_fill_preserve(cr);
  SetColor(cr, {0.78, 0.78, 0.78});
  cairo_set_line_width(cr, 1.0 * ui);
  cairo_stroke(cr);
  TextStyle text;
  text.size = kText * ui;
  for (size_t i = 0; i < entries_.size(); ++i) {
    const LegendEntry& e = entries_[i];
    const double cy = y_ + (kPad + kRow * i + 6) * ui, x0 = x_ + kPad * ui, x1 = x0 + kSwatch * ui;
    if (e.kind == LegendEntry::kBase) {
      DrawFixedBase(cr, x0 + 0.5 * kSwatch * ui, cy - 5 * ui, 0.8 * ui);
    } else if (e.kind == LegendEntry::kGradient) {
      const int pieces = 12;
      for (int k = 0; k < pieces; ++k) {
        Line(cr, x0 + kSwatch * ui * k / pieces, cy, x0 + kSwatch * ui * (k + 1) / pieces, cy,
             FadeColor((k + 0.5) / pieces), 3.0 * ui);
      }
    } else {
      cairo_save(cr);
      if (e.style.dashed) {
        const double pattern[] = {7.0 * ui, 4.5 * ui};
        cairo_set_dash(cr, pattern, 2, 0.0);
      }
      cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
      Line(cr, x0, cy, x1, cy, e.style.color, e.style.width);
      cairo_restore(cr);
      if (e.dot) Disc(cr, x1, cy, 3.8 * ui, e.style.color);
    }
    DrawText(cr, x1 + kPad * ui, cy, e.label, text);
  }
}

}  // namespace flexkin::render
