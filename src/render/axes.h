#pragma once
// Axes of a plot: ticks at "nice" values, their labels, grid lines, axis labels; linear or
// logarithmic. Also used by the 2D snapshot figures, with equal scales.

#include <cairo.h>

#include <string>
#include <vector>

namespace flexkin::render {

// A rectangle in pixels, y down.
struct Rect {
  double x = 0.0, y = 0.0, w = 0.0, h = 0.0;
  double right() const { return x + w; }
  double bottom() const { return y + h; }
};

// About `target` tick values covering [lo, hi], multiples of 1, 2 or 5 times a power of ten,
// all within [lo, hi] (up to rounding).
std::vector<double> NiceTicks(double lo, double hi, int target);
// A tick value with as many decimals as the tick spacing `step` needs; a true minus sign.
std::string TickLabel(double value, double step);
// 10 to the power `exponent`, with superscript digits ("10⁻¹²").
std::string PowerOfTenLabel(int exponent);

class Axes {
 public:
  // x from x0 to x1 left to right, y from y0 to y1 bottom to top, in `plot`. With `log_y`,
  // y0 and y1 are powers of ten exponents' bounds (both > 0) and y is drawn logarithmically.
  Axes(const Rect& plot, double x0, double x1, double y0, double y1, bool log_y = false);

  // Only integer ticks on x (point and link indices).
  void SetIntegerX() { integer_x_ = true; }
  // y ticks every `step` from y0 instead of NiceTicks (degrees: 30).
  void SetYTickStep(double step) { y_step_ = step; }

  double X(double x) const;
  double Y(double y) const;
  const Rect& plot() const { return plot_; }

  // Grid lines, the frame, ticks and tick labels, and the axis labels. `ui` scales sizes.
  void Draw(cairo_t* cr, double ui, const std::string& x_label, const std::string& y_label) const;
  // Restricts drawing to the plot rectangle (undo with cairo_reset_clip).
  void Clip(cairo_t* cr) const;

 private:
  Rect plot_;
  double x0_, x1_, y0_, y1_;
  bool log_y_;
  bool integer_x_ = false;
  double y_step_ = 0.0;
};

}  // namespace flexkin::render
