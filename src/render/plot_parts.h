#pragma once
// The pieces a chain's plots (plots.cc) and a tree's (tree_plots.cc) are drawn with.

#include <cairo.h>

#include <string>
#include <utility>
#include <vector>

#include "flexkin/render.h"
#include "render/axes.h"
#include "render/canvas.h"
#include "render/style.h"

namespace flexkin::render {

// The title of a plot of `kind` ("Link-length error").
const char* PlotTitle(PlotKind kind);

// Relative errors below this are drawn at it on the log axis (exact zeros included).
constexpr double kErrorFloor = 1e-17;

// The plot's rectangle on the canvas, `extra_right` left free beside it (a colour bar).
Rect PlotArea(const Canvas& canvas, double extra_right);

// The polyline through (x[i], y[i]) in the axes' coordinates.
void StrokePolyline(cairo_t* cr, const Axes& axes, const std::vector<double>& x,
                    const std::vector<double>& y, const Rgb& color, double width);

// A dashed red line across the plot at value y (the caller has clipped to the axes).
void DashedLevel(cairo_t* cr, const Axes& axes, double ui, double y);

// A note in red, its bottom right corner at (x, y).
void Note(cairo_t* cr, double ui, double x, double y, const char* text);

// The powers of ten a log axis spans to hold values from `low` to `high` (each at least
// kErrorFloor): at least two decades.
std::pair<double, double> LogDecades(double low, double high);

// The colour bar right of the plot: Viridis from item 1 at the bottom to item `count` at the top,
// a tick and its number at each of `ticks` (1-based; others skipped), `name` along its side.
void ColorBar(cairo_t* cr, const Axes& axes, double ui, int count, const std::vector<double>& ticks,
              const std::string& name);

}  // namespace flexkin::render
