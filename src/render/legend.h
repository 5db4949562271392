#pragma once
// The snapshot figure's legend: measured, placed where it covers the least, drawn.

#include <cairo.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "render/axes.h"
#include "render/scene.h"

namespace flexkin::render {

// One legend line: a swatch and a label.
struct LegendEntry {
  // kGradient: the snapshots' fade; kBase: the fixed base's support (DrawFixedBase)
  enum Kind { kLine, kGradient, kBase } kind = kLine;
  ChainStyle style;  // kLine: the line's look
  bool dot = false;  // a disc at the swatch's right end
  std::string label;
};

class Legend {
 public:
  // Measures the entries (text of 12 ui pixels).
  Legend(double ui, std::vector<LegendEntry> entries);

  double width() const { return width_; }
  double height() const { return height_; }
  // Puts the legend into the corner of `region` (inset a little) that covers the fewest of
  // `avoid` (pixels); ties go to top right, top left, bottom right, bottom left. Returns how
  // many it covers.
  size_t PlaceInCorner(const Rect& region, const std::vector<Eigen::Vector2d>& avoid);
  // Puts its top left corner at (x, y).
  void PlaceAt(double x, double y);
  void Draw(cairo_t* cr) const;

 private:
  double ui_;
  std::vector<LegendEntry> entries_;
  double width_ = 0.0, height_ = 0.0, x_ = 0.0, y_ = 0.0;
};

}  // namespace flexkin::render
