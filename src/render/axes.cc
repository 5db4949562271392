#include "render/axes.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "render/canvas.h"

namespace flexkin::render {

std::vector<double> NiceTicks(double lo, double hi, int target) {
  std::vector<double> ticks;
  if (!(hi > lo) || target < 1) return ticks;
  const double raw = (hi - lo) / target;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  double step = power;
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    step = m * power;
    if (step >= raw) break;
  }
  const double eps = 1e-9 * step;
  for (double k = std::ceil((lo - eps) / step); k * step <= hi + eps; k += 1.0) {
    const double v = k * step;
    ticks.push_back(std::abs(v) < eps ? 0.0 : v);
  }
  return ticks;
}

std::string TickLabel(double value, double step) {
  const int decimals = std::clamp(static_cast<int>(std::ceil(-std::log10(step) - 1e-9)), 0, 12);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, std::abs(value));
  const bool negative =
      value < 0.0 && std::string(buf).find_first_not_of("0.") != std::string::npos;
  return (negative ? "\u2212" : "") + std::string(buf);
}

std::string PowerOfTenLabel(int exponent) {
  static const char* kSuper[] = {"\u2070", "\u00b9", "\u00b2", "\u00b3", "\u2074",
                                 "\u2075", "\u2076", "\u2077", "\u2078", "\u2079"};
  std::string digits = std::to_string(std::abs(exponent));
  std::string label = "10";
  if (exponent < 0) label += "\u207b";
  for (char c : digits) label += kSuper[c - '0'];
  return label;
}

Axes::Axes(const Rect& plot, double x0, double x1, double y0, double y1, bool log_y)
    : plot_(plot), x0_(x0), x1_(x1), y0_(y0), y1_(y1), log_y_(log_y) {
  if (log_y_) {
    y0_ = std::log10(y0);
    y1_ = std::log10(y1);
  }
}

double Axes::X(double x) const { return plot_.x + (x - x0_) / (x1_ - x0_) * plot_.w; }

double Axes::Y(double y) const {
  const double v = log_y_ ? std::log10(y) : y;
  return plot_.bottom() - (v - y0_) / (y1_ - y0_) * plot_.h;
}

void Axes::Clip(cairo_t* cr) const {
  cairo_rectangle(cr, plot_.x, plot_.y, plot_.w, plot_.h);
  cairo_clip(cr);
}

void Axes::Draw(cairo_t* cr, double ui, const std::string& x_label,
                const std::string& y_label) const {
  const double tick = 5.0 * ui;
  TextStyle label;
  label.size = 11.5 * ui;
  label.color = kMuted;

  // x: ticks below the frame.
  std::vector<double> xt = NiceTicks(x0_, x1_, std::max(2, static_cast<int>(plot_.w / (90 * ui))));
  if (integer_x_ && xt.size() > 1 && xt[1] - xt[0] < 1.0)
    xt = NiceTicks(x0_, x1_, static_cast<int>(x1_ - x0_));
  const double x_step = xt.size() > 1 ? xt[1] - xt[0] : 1.0;
  for (double v : xt) {
    const double px = X(v);
    Line(cr, px, plot_.y, px, plot_.bottom(), kGrid, 1.0 * ui);
    Line(cr, px, plot_.bottom(), px, plot_.bottom() + tick, kInk, 1.0 * ui);
    label.halign = Align::kCenter;
    label.valign = Align::kStart;
    DrawText(cr, px, plot_.bottom() + tick + 4 * ui, TickLabel(v, x_step), label);
  }

  // y: ticks left of the frame; decades on a log axis (every 2nd, 3rd, ... if there are many).
  std::vector<std::pair<double, std::string>> yt;
  if (log_y_) {
    const int lo = static_cast<int>(std::ceil(y0_ - 1e-9)),
              hi = static_cast<int>(std::floor(y1_ + 1e-9));
    const int every = std::max(1, (hi - lo + 1 + 7) / 8);
    for (int e = lo; e <= hi; ++e) {
      if ((e - lo) % every == 0) yt.emplace_back(std::pow(10.0, e), PowerOfTenLabel(e));
    }
  } else {
    std::vector<double> v = NiceTicks(y0_, y1_, std::max(2, static_cast<int>(plot_.h / (60 * ui))));
    if (y_step_ > 0.0) {
      v.clear();
      for (double y = y0_; y <= y1_ + 1e-9 * y_step_; y += y_step_) v.push_back(y);
    }
    const double y_step = v.size() > 1 ? v[1] - v[0] : 1.0;
    for (double y : v) yt.emplace_back(y, TickLabel(y, y_step));
  }
  double widest = 0.0;
  for (const auto& [v, text] : yt) {
    const double py = Y(v);
    Line(cr, plot_.x, py, plot_.right(), py, kGrid, 1.0 * ui);
    Line(cr, plot_.x - tick, py, plot_.x, py, kInk, 1.0 * ui);
    label.halign = Align::kEnd;
    label.valign = Align::kCenter;
    widest = std::max(widest, DrawText(cr, plot_.x - tick - 4 * ui, py, text, label));
  }

  cairo_rectangle(cr, plot_.x, plot_.y, plot_.w, plot_.h);
  SetColor(cr, kInk);
  cairo_set_line_width(cr, 1.2 * ui);
  cairo_stroke(cr);

  TextStyle name;
  name.size = 13 * ui;
  name.halign = Align::kCenter;
  name.valign = Align::kStart;
  DrawText(cr, plot_.x + plot_.w / 2, plot_.bottom() + tick + 22 * ui, x_label, name);
  name.valign = Align::kEnd;
  name.angle = M_PI / 2;
  DrawText(cr, plot_.x - tick - widest - 12 * ui, plot_.y + plot_.h / 2, y_label, name);
}

}  // namespace flexkin::render
