// WritePlot: path length per point, link angles over time, link-length error over time, a dynamic
// run's energy over time.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/render.h"
#include "render/axes.h"
#include "render/canvas.h"
#include "render/checks.h"
#include "render/plot_parts.h"
#include "render/snapshot.h"

namespace flexkin {
namespace {

using render::Axes;
using render::ColorBar;
using render::DashedLevel;
using render::kErrorFloor;
using render::LogDecades;
using render::Note;
using render::PlotArea;
using render::Rect;
using render::StrokePolyline;

// x range of the recorded steps; a single step gets a unit-wide range around it.
std::pair<double, double> StepRange(const RunResult& r) {
  const double a = static_cast<double>(r.frames.front().step);
  const double b = static_cast<double>(r.frames.back().step);
  return b > a ? std::make_pair(a, b) : std::make_pair(a - 0.5, a + 0.5);
}

void PathLengthPlot(render::Canvas* canvas, const ResultFile& file) {
  const Eigen::VectorXd& length = file.result.metrics.path_length;
  const Eigen::Index points = file.result.lengths.size() + 1;
  if (length.size() != points) {
    throw InputError("metrics.path_length", "has " + std::to_string(length.size()) +
                                                " values; expected one per point (" +
                                                std::to_string(points) + ")");
  }
  cairo_t* cr = canvas->cr();
  const double ui = canvas->ui();
  const double top = std::max(length.maxCoeff(), 1e-300) * 1.06;
  Axes axes(PlotArea(*canvas, 0.0), -0.5, points - 0.5, 0.0, top);
  axes.SetIntegerX();
  axes.Draw(cr, ui, "point index along the chain (0 = leading end)", "path length");
  std::vector<double> x(points), y(points);
  for (Eigen::Index i = 0; i < points; ++i) {
    x[i] = static_cast<double>(i);
    y[i] = length[i];
  }
  StrokePolyline(cr, axes, x, y, render::kMarker, 1.6 * ui);
  const double radius = std::clamp(axes.plot().w / points * 0.3, 1.6 * ui, 4.0 * ui);
  for (Eigen::Index i = 0; i < points; ++i)
    render::Disc(cr, axes.X(x[i]), axes.Y(y[i]), radius, render::kMarker);
}

void LinkAnglesPlot(render::Canvas* canvas, const ResultFile& file) {
  const RunResult& r = file.result;
  const Eigen::Index links = r.lengths.size();
  for (size_t f = 0; f < r.frames.size(); ++f) {
    if (r.frames[f].link_angles.size() != links) {
      throw InputError("frames[" + std::to_string(f) + "].link_angles",
                       "has " + std::to_string(r.frames[f].link_angles.size()) +
                           " values; expected one per link (" + std::to_string(links) +
                           "); a result whose leading end never moves has no link angles");
    }
  }
  cairo_t* cr = canvas->cr();
  const double ui = canvas->ui();
  const double bar = 86 * ui;  // colour bar and its labels
  const auto [x0, x1] = StepRange(r);
  Axes axes(PlotArea(*canvas, bar), x0, x1, 0.0, 180.0);
  axes.SetYTickStep(30.0);
  axes.Draw(cr, ui, "leader step", "angle to the pull direction (degrees)");
  std::vector<double> x(r.frames.size()), y(r.frames.size());
  cairo_save(cr);
  axes.Clip(cr);
  // Many links: all thin, and five spread along the chain (the first, the last and three
  // between) bold on top, so that single curves can be followed. The last link first, so that
  // the leading links are on top.
  std::vector<Eigen::Index> bold;
  if (links > 8) {
    for (int k = 0; k < 5; ++k)
      bold.push_back(static_cast<Eigen::Index>(std::lround(k * (links - 1) / 4.0)));
  }
  auto draw_link = [&](Eigen::Index i, double width) {
    for (size_t f = 0; f < r.frames.size(); ++f) {
      x[f] = static_cast<double>(r.frames[f].step);
      y[f] = r.frames[f].link_angles[i] * 180.0 / M_PI;
    }
    const render::Rgb color =
        render::Viridis(links == 1 ? 0.0 : static_cast<double>(i) / (links - 1));
    if (x.size() == 1) {
      render::Disc(cr, axes.X(x[0]), axes.Y(y[0]), 3.0 * ui, color);
    } else {
      StrokePolyline(cr, axes, x, y, color, width);
    }
  };
  for (Eigen::Index i = links - 1; i >= 0; --i) draw_link(i, (bold.empty() ? 1.6 : 0.8) * ui);
  for (auto i = bold.rbegin(); i != bold.rend(); ++i) draw_link(*i, 2.4 * ui);
  cairo_restore(cr);

  // The colour bar: link 1 (the leading link) at the bottom.
  std::vector<double> ticks;
  for (Eigen::Index i : bold) ticks.push_back(static_cast<double>(i + 1));
  if (bold.empty()) ticks = render::NiceTicks(1.0, static_cast<double>(links), 6);
  if (ticks.empty() || links == 1) ticks = {1.0};
  ColorBar(cr, axes, ui, static_cast<int>(links), ticks, "link (1 = leading link)");
}

void LengthErrorPlot(render::Canvas* canvas, const ResultFile& file) {
  const RunResult& r = file.result;
  const Eigen::VectorXd errors = FrameLengthErrors(r);
  cairo_t* cr = canvas->cr();
  const double ui = canvas->ui();
  const double high =
      std::max({errors.maxCoeff(), r.metrics.max_relative_length_error, kErrorFloor});
  double low = high;
  for (double e : errors) low = std::min(low, std::max(e, kErrorFloor));
  const auto [y0, y1] = LogDecades(low, high);
  const auto [x0, x1] = StepRange(r);
  Axes axes(PlotArea(*canvas, 0.0), x0, x1, y0, y1, true);
  axes.Draw(cr, ui, "leader step", "max relative link-length error");
  std::vector<double> x(r.frames.size()), y(r.frames.size());
  for (size_t f = 0; f < r.frames.size(); ++f) {
    x[f] = static_cast<double>(r.frames[f].step);
    y[f] = std::max(errors[static_cast<Eigen::Index>(f)], kErrorFloor);
  }
  cairo_save(cr);
  axes.Clip(cr);
  // The worst over every leader step (recorded or not), from the result's metrics.
  const double worst = std::max(r.metrics.max_relative_length_error, kErrorFloor);
  DashedLevel(cr, axes, ui, worst);
  StrokePolyline(cr, axes, x, y, render::kMarker, 1.1 * ui);
  if (x.size() <= 200) {
    for (size_t f = 0; f < x.size(); ++f)
      render::Disc(cr, axes.X(x[f]), axes.Y(y[f]), 2.4 * ui, render::kMarker);
  }
  cairo_restore(cr);
  char buf[96];
  std::snprintf(buf, sizeof buf, "worst over every leader step: %.2e",
                r.metrics.max_relative_length_error);
  Note(cr, ui, axes.plot().right() - 6 * ui, axes.Y(worst) - 5 * ui, buf);
}

// The energy at every frame (recorded or not) against the time, frame f at f / frame_rate; a
// dashed line at the start's energy.
void EnergyPlot(render::Canvas* canvas, const ResultFile& file) {
  const DynamicRunReport& d = file.result.dynamics;
  if (!d.enabled) {
    throw InputError("plot",
                     "value \"energy\" is not valid for this result: it is drawn for "
                     "dynamic runs (a chain scenario with \"dynamics\") only");
  }
  const Eigen::VectorXd& e = d.energy;
  if (e.size() < 1 || !e.allFinite()) {
    throw InputError("dynamics.energy", "has " + std::to_string(e.size()) +
                                            " values, or one not finite; expected finite values, "
                                            "one per frame");
  }
  if (!(d.frame_rate > 0.0) || !std::isfinite(d.frame_rate)) {
    throw InputError("dynamics.frame_rate", "value " + std::to_string(d.frame_rate) +
                                                " is not valid; expected a positive number");
  }
  cairo_t* cr = canvas->cr();
  const double ui = canvas->ui();
  const double t1 = std::max(static_cast<double>(e.size() - 1) / d.frame_rate, 1e-9);
  double lo = e.minCoeff(), hi = e.maxCoeff();
  const double pad = std::max(0.06 * (hi - lo), 1e-9 * std::max(1.0, std::fabs(hi)));
  lo -= pad;
  hi += pad;
  Axes axes(PlotArea(*canvas, 0.0), 0.0, t1, lo, hi);
  axes.Draw(cr, ui, "time (s)", "energy (kinetic + potential, free points' mass 1)");
  std::vector<double> x(e.size()), y(e.size());
  for (Eigen::Index f = 0; f < e.size(); ++f) {
    x[f] = static_cast<double>(f) / d.frame_rate;
    y[f] = e[f];
  }
  cairo_save(cr);
  axes.Clip(cr);
  DashedLevel(cr, axes, ui, e[0]);
  StrokePolyline(cr, axes, x, y, render::kMarker, 1.6 * ui);
  cairo_restore(cr);
  char buf[160];
  std::snprintf(buf, sizeof buf, "%s projection, %d sub-steps: %.4g at the start, %.4g at the end",
                d.projection.c_str(), d.substeps, e[0], e[e.size() - 1]);
  Note(cr, ui, axes.plot().right() - 6 * ui, axes.plot().y + 18 * ui, buf);
}

}  // namespace

void WritePlot(const ResultFile& file, PlotKind kind, const PlotOptions& options,
               const std::string& path) {
  ThrowIfAny(options.Validate());
  render::CheckDrawable(file);
  internal::WritePlot({file}, kind, options, path);
}

void internal::WritePlot(const CheckedDrawing& drawing, PlotKind kind, const PlotOptions& options,
                         const std::string& path) {
  const ResultFile& file = drawing.result;
  const ImageFormat format = ImageFormatFromPath(path);
  render::Canvas canvas(format, options.width, options.height);
  const std::string title = options.title.empty() ? render::PlotTitle(kind) : options.title;
  render::DrawTitle(canvas.cr(), canvas.ui(), canvas.width(), title,
                    render::MainTitle(file, "") + " \u00b7 " + render::RunSummary(file));
  switch (kind) {
    case PlotKind::kPathLength:
      PathLengthPlot(&canvas, file);
      break;
    case PlotKind::kLinkAngles:
      LinkAnglesPlot(&canvas, file);
      break;
    case PlotKind::kLengthError:
      LengthErrorPlot(&canvas, file);
      break;
    case PlotKind::kEnergy:
      EnergyPlot(&canvas, file);
      break;
    case PlotKind::kTargetMiss:
    case PlotKind::kJointAngles:
      throw InputError("plot", std::string("value \"") + PlotKindName(kind) +
                                   "\" is not valid for a chain result: it is drawn for tree "
                                   "results only (WriteTreePlot)");
  }
  render::SaveCanvas(&canvas, path);
}

namespace render {

const char* PlotTitle(PlotKind kind) {
  switch (kind) {
    case PlotKind::kPathLength:
      return "Path length of each point";
    case PlotKind::kLinkAngles:
      return "Angle of each link to the pull";
    case PlotKind::kLengthError:
      return "Link-length error";
    case PlotKind::kEnergy:
      return "Energy";
    case PlotKind::kTargetMiss:
      return "Distance of each target from its goal";
    case PlotKind::kJointAngles:
      return "Joint angles";
  }
  return "";
}

Rect PlotArea(const Canvas& canvas, double extra_right) {
  const double ui = canvas.ui();
  return {80 * ui, 66 * ui, canvas.width() - 80 * ui - 26 * ui - extra_right,
          canvas.height() - 66 * ui - 60 * ui};
}

void StrokePolyline(cairo_t* cr, const Axes& axes, const std::vector<double>& x,
                    const std::vector<double>& y, const Rgb& color, double width) {
  for (size_t i = 0; i < x.size(); ++i) {
    i == 0 ? cairo_move_to(cr, axes.X(x[i]), axes.Y(y[i]))
           : cairo_line_to(cr, axes.X(x[i]), axes.Y(y[i]));
  }
  SetColor(cr, color);
  cairo_set_line_width(cr, width);
  cairo_stroke(cr);
}

void DashedLevel(cairo_t* cr, const Axes& axes, double ui, double y) {
  cairo_save(cr);
  const double dash[] = {6 * ui, 4 * ui};
  cairo_set_dash(cr, dash, 2, 0.0);
  Line(cr, axes.plot().x, axes.Y(y), axes.plot().right(), axes.Y(y), kFinal, 1.3 * ui);
  cairo_restore(cr);
}

void Note(cairo_t* cr, double ui, double x, double y, const char* text) {
  TextStyle note;
  note.size = 11.5 * ui;
  note.color = kFinal;
  note.halign = Align::kEnd;
  note.valign = Align::kEnd;
  DrawText(cr, x, y, text, note);
}

std::pair<double, double> LogDecades(double low, double high) {
  const double y0 = std::pow(10.0, std::floor(std::log10(low)));
  double y1 = std::pow(10.0, std::ceil(std::log10(high) + 1e-9));
  if (y1 <= y0 * 10.0) y1 = y0 * 100.0;
  return {y0, y1};
}

void ColorBar(cairo_t* cr, const Axes& axes, double ui, int count, const std::vector<double>& ticks,
              const std::string& name) {
  const Rect& plot = axes.plot();
  const double bx = plot.right() + 22 * ui, bw = 14 * ui;
  const int pieces = 64;
  for (int k = 0; k < pieces; ++k) {
    cairo_rectangle(cr, bx, plot.bottom() - plot.h * (k + 1) / pieces, bw, plot.h / pieces + 0.5);
    SetColor(cr, Viridis((k + 0.5) / pieces));
    cairo_fill(cr);
  }
  cairo_rectangle(cr, bx, plot.y, bw, plot.h);
  SetColor(cr, kInk);
  cairo_set_line_width(cr, 1.0 * ui);
  cairo_stroke(cr);
  TextStyle label;
  label.size = 11.5 * ui;
  label.color = kMuted;
  for (double t : ticks) {
    if (t != std::floor(t)) continue;
    const double py =
        count == 1 ? plot.bottom() - plot.h / 2 : plot.bottom() - (t - 1.0) / (count - 1) * plot.h;
    Line(cr, bx + bw, py, bx + bw + 4 * ui, py, kInk, 1.0 * ui);
    DrawText(cr, bx + bw + 7 * ui, py, std::to_string(static_cast<long long>(t)), label);
  }
  TextStyle title;
  title.size = 13 * ui;
  title.halign = Align::kCenter;
  title.valign = Align::kEnd;
  title.angle = -M_PI / 2;
  DrawText(cr, bx + bw + 34 * ui, plot.y + plot.h / 2, name, title);
}

}  // namespace render

}  // namespace flexkin
