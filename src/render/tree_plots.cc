// WriteTreePlot: a tree result's plots (docs/trees.md, "Plots"): the path length of each point,
// each frame's link-length error, each target's miss and a robot tree's joint angles, against the
// frame.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/render.h"
#include "flexkin/tree_scenario.h"
#include "render/axes.h"
#include "render/canvas.h"
#include "render/checks.h"
#include "render/plot_parts.h"
#include "render/snapshot.h"

namespace flexkin {
namespace render {
namespace {

// The x range of frames 0 .. count - 1; a single frame gets a unit-wide range around it.
std::pair<double, double> FrameRange(size_t count) {
  return count > 1 ? std::make_pair(0.0, static_cast<double>(count - 1))
                   : std::make_pair(-0.5, 0.5);
}

// The points with a parent (each the trailing end of its link) and, at frame 0, their links'
// lengths; links that slide (a robot tree's prismatic joints) are not among them.
struct TreeLinks {
  std::vector<int> ends;
  std::vector<double> lengths;
  double longest = 0.0;
};
TreeLinks LinksOf(const TreeResultFile& tree) {
  TreeLinks links;
  const Points& first = tree.frames.front();
  for (size_t v = 0; v < tree.parents.size(); ++v) {
    if (tree.parents[v] < 0) continue;
    const int i = static_cast<int>(v);
    if (std::find(tree.sliding.begin(), tree.sliding.end(), i) != tree.sliding.end()) continue;
    links.ends.push_back(i);
    links.lengths.push_back((first.row(i) - first.row(tree.parents[v])).norm());
    links.longest = std::max(links.longest, links.lengths.back());
  }
  return links;
}

// Whether target k has a position goal drawn in the miss plot (not a pointing goal).
bool PositionTarget(const TreeResultFile& tree, size_t k) {
  return !(k < tree.looks.size() && tree.looks[k]);
}

void TreePathLengthPlot(Canvas* canvas, const TreeResultFile& tree) {
  const size_t points = tree.parents.size();
  std::vector<double> x(points), y(points, 0.0);
  for (size_t v = 0; v < points; ++v) {
    x[v] = static_cast<double>(v);
    for (size_t f = 1; f < tree.frames.size(); ++f) {
      y[v] += (tree.frames[f].row(static_cast<Eigen::Index>(v)) -
               tree.frames[f - 1].row(static_cast<Eigen::Index>(v)))
                  .norm();
    }
  }
  cairo_t* cr = canvas->cr();
  const double ui = canvas->ui();
  const double top = std::max(*std::max_element(y.begin(), y.end()), 1e-300) * 1.06;
  Axes axes(PlotArea(*canvas, 0.0), -0.5, static_cast<double>(points) - 0.5, 0.0, top);
  axes.SetIntegerX();
  axes.Draw(cr, ui, "point index (targets red, fixed points grey)", "path length");
  // Points by index are not a path along the body: markers only, no line between them.
  const double radius = std::clamp(axes.plot().w / points * 0.3, 1.6 * ui, 4.0 * ui);
  for (size_t v = 0; v < points; ++v) {
    const int i = static_cast<int>(v);
    const bool target =
        std::find(tree.targets.begin(), tree.targets.end(), i) != tree.targets.end();
    const bool fixed = std::find(tree.fixed.begin(), tree.fixed.end(), i) != tree.fixed.end();
    Disc(cr, axes.X(x[v]), axes.Y(y[v]), radius, target ? kFinal : fixed ? kMuted : kMarker);
  }
}

void TreeLengthErrorPlot(Canvas* canvas, const TreeResultFile& tree) {
  const TreeLinks links = LinksOf(tree);
  const size_t frames = tree.frames.size();
  std::vector<double> x(frames), y(frames, 0.0);
  for (size_t f = 0; f < frames; ++f) {
    x[f] = static_cast<double>(f);
    for (size_t k = 0; k < links.ends.size(); ++k) {
      const int v = links.ends[k];
      const double d = (tree.frames[f].row(v) - tree.frames[f].row(tree.parents[v])).norm();
      y[f] = std::max(y[f], std::fabs(d - links.lengths[k]) / links.lengths[k]);
    }
  }
  const double worst = *std::max_element(y.begin(), y.end());
  for (double& e : y) e = std::max(e, kErrorFloor);
  cairo_t* cr = canvas->cr();
  const double ui = canvas->ui();
  const auto [y0, y1] =
      LogDecades(*std::min_element(y.begin(), y.end()), std::max(worst, kErrorFloor));
  const auto [x0, x1] = FrameRange(frames);
  Axes axes(PlotArea(*canvas, 0.0), x0, x1, y0, y1, true);
  axes.Draw(cr, ui, "frame", "max relative link-length error (to frame 0)");
  cairo_save(cr);
  axes.Clip(cr);
  DashedLevel(cr, axes, ui, std::max(worst, kErrorFloor));
  StrokePolyline(cr, axes, x, y, kMarker, 1.1 * ui);
  if (frames <= 200) {
    for (size_t f = 0; f < frames; ++f) Disc(cr, axes.X(x[f]), axes.Y(y[f]), 2.4 * ui, kMarker);
  }
  cairo_restore(cr);
  char buf[96];
  std::snprintf(buf, sizeof buf, "worst over every frame: %.2e", worst);
  Note(cr, ui, axes.plot().right() - 6 * ui, axes.Y(std::max(worst, kErrorFloor)) - 5 * ui, buf);
}

void TargetMissPlot(Canvas* canvas, const TreeResultFile& tree) {
  const double longest = LinksOf(tree).longest;
  const size_t frames = tree.frames.size();
  std::vector<size_t> drawn;
  for (size_t k = 0; k < tree.targets.size(); ++k) {
    if (PositionTarget(tree, k)) drawn.push_back(k);
  }
  // misses[d][f - 1]: target drawn[d]'s miss at frame f >= 1, relative to the longest link.
  std::vector<std::vector<double>> misses(drawn.size(), std::vector<double>(frames - 1));
  double high = kErrorFloor, low = std::numeric_limits<double>::infinity();
  for (size_t d = 0; d < drawn.size(); ++d) {
    const Eigen::Index k = static_cast<Eigen::Index>(drawn[d]);
    for (size_t f = 1; f < frames; ++f) {
      const double miss =
          (tree.frames[f].row(tree.targets[drawn[d]]) - tree.goals[f - 1].row(k)).norm() / longest;
      misses[d][f - 1] = std::max(miss, kErrorFloor);
      high = std::max(high, misses[d][f - 1]);
      low = std::min(low, misses[d][f - 1]);
    }
  }
  cairo_t* cr = canvas->cr();
  const double ui = canvas->ui();
  const double bar = drawn.size() > 1 ? 86 * ui : 0.0;
  // The tolerance of the passes and of Newton (1e-10 of the longest link) stays in view.
  const auto [y0, y1] = LogDecades(std::min(low, 1e-11), std::max(high, 1e-9));
  const auto [x0, x1] = FrameRange(frames);
  Axes axes(PlotArea(*canvas, bar), x0, x1, y0, y1, true);
  axes.Draw(cr, ui, "frame", "distance from its goal (of the longest link)");
  std::vector<double> x(frames - 1);
  for (size_t f = 1; f < frames; ++f) x[f - 1] = static_cast<double>(f);
  cairo_save(cr);
  axes.Clip(cr);
  DashedLevel(cr, axes, ui, 1e-10);
  for (size_t d = drawn.size(); d-- > 0;) {
    const Rgb color =
        drawn.size() == 1 ? kMarker : Viridis(static_cast<double>(d) / (drawn.size() - 1));
    if (x.size() == 1) {
      Disc(cr, axes.X(x[0]), axes.Y(misses[d][0]), 3.0 * ui, color);
    } else {
      StrokePolyline(cr, axes, x, misses[d], color, 1.6 * ui);
    }
  }
  cairo_restore(cr);
  if (drawn.size() > 1) {
    ColorBar(cr, axes, ui, static_cast<int>(drawn.size()),
             NiceTicks(1.0, static_cast<double>(drawn.size()), 6), "target (1 = first)");
  }
  const long long missed = std::count(tree.reached.begin(), tree.reached.end(), char(0));
  const size_t looks = tree.targets.size() - drawn.size();
  char buf[160];
  std::snprintf(buf, sizeof buf, "1e-10: the tolerance \u00b7 %lld of %zu frames not reached%s",
                missed, frames - 1, looks > 0 ? " \u00b7 pointing goals not drawn" : "");
  Note(cr, ui, axes.plot().right() - 6 * ui, axes.Y(1e-10) - 5 * ui, buf);
}

// The turning joints' angles; sliding joints (their values are lengths) are left out.
void JointAnglesPlot(Canvas* canvas, const TreeResultFile& tree) {
  const size_t frames = tree.angles.size();
  const Eigen::Index joints = tree.angles.front().size();
  const auto slides = [&](Eigen::Index j) {
    return static_cast<size_t>(j) < tree.prismatic.size() && tree.prismatic[j] != 0;
  };
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Eigen::VectorXd& a : tree.angles) {
    for (Eigen::Index j = 0; j < joints; ++j) {
      if (slides(j)) continue;
      lo = std::min(lo, a[j] * 180.0 / M_PI);
      hi = std::max(hi, a[j] * 180.0 / M_PI);
    }
  }
  if (!(lo <= hi)) lo = hi = 0.0;  // every joint slides
  const double pad = std::max(0.06 * (hi - lo), 1.0);
  cairo_t* cr = canvas->cr();
  const double ui = canvas->ui();
  const auto [x0, x1] = FrameRange(frames);
  Axes axes(PlotArea(*canvas, 86 * ui), x0, x1, lo - pad, hi + pad);
  axes.Draw(cr, ui, "frame",
            tree.prismatic.empty() ? "joint angle (degrees)"
                                   : "joint angle (degrees; sliding joints not drawn)");
  std::vector<double> x(frames), y(frames);
  for (size_t f = 0; f < frames; ++f) x[f] = static_cast<double>(f);
  cairo_save(cr);
  axes.Clip(cr);
  for (Eigen::Index j = joints - 1; j >= 0; --j) {
    if (slides(j)) continue;
    for (size_t f = 0; f < frames; ++f) y[f] = tree.angles[f][j] * 180.0 / M_PI;
    const Rgb color = Viridis(joints == 1 ? 0.0 : static_cast<double>(j) / (joints - 1));
    if (frames == 1) {
      Disc(cr, axes.X(x[0]), axes.Y(y[0]), 3.0 * ui, color);
    } else {
      StrokePolyline(cr, axes, x, y, color, 1.6 * ui);
    }
  }
  cairo_restore(cr);
  std::vector<double> ticks = NiceTicks(1.0, static_cast<double>(joints), 6);
  if (ticks.empty() || joints == 1) ticks = {1.0};
  ColorBar(cr, axes, ui, static_cast<int>(joints), ticks, "joint (1 = first in the file)");
}

}  // namespace
}  // namespace render

std::vector<PlotKind> TreePlotKinds(const TreeResultFile& tree) {
  std::vector<PlotKind> kinds = {PlotKind::kPathLength, PlotKind::kLengthError};
  bool position = false;
  for (size_t k = 0; k < tree.targets.size(); ++k) position |= render::PositionTarget(tree, k);
  if (!tree.goals.empty() && tree.frames.size() > 1 && position) {
    kinds.push_back(PlotKind::kTargetMiss);
  }
  if (tree.robot && !tree.angles.empty() && tree.angles.front().size() > 0) {
    kinds.push_back(PlotKind::kJointAngles);
  }
  return kinds;
}

void WriteTreePlot(const TreeResultFile& tree, PlotKind kind, const PlotOptions& options,
                   const std::string& path) {
  ThrowIfAny(options.Validate());
  ThrowIfAny(ValidateTreeResult(tree));
  const std::vector<PlotKind> kinds = TreePlotKinds(tree);
  if (std::find(kinds.begin(), kinds.end(), kind) == kinds.end()) {
    std::string valid;
    for (const PlotKind k : kinds) valid += (valid.empty() ? "" : ", ") + std::string(NameOf(k));
    throw InputError(Problem("plot",
                             std::string("value \"") + PlotKindName(kind) +
                                 "\" is not drawn for this tree result (target_miss needs the "
                                 "goals of position targets, joint_angles a robot tree's "
                                 "angles; link_angles and energy are chains'); expected one of " +
                                 valid,
                             std::string("\"") + PlotKindName(kind) + "\"", valid));
  }
  internal::WriteTreePlot(tree, kind, options, path);
}

void internal::WriteTreePlot(const TreeResultFile& tree, PlotKind kind, const PlotOptions& options,
                             const std::string& path) {
  const ImageFormat format = ImageFormatFromPath(path);
  render::Canvas canvas(format, options.width, options.height);
  const std::string title = options.title.empty() ? render::PlotTitle(kind) : options.title;
  const std::string name = tree.name.empty() ? std::string("flexkin result") : tree.name;
  render::DrawTitle(canvas.cr(), canvas.ui(), canvas.width(), title,
                    name + " \u00b7 " + render::TreeResultSummary(tree));
  switch (kind) {
    case PlotKind::kPathLength:
      render::TreePathLengthPlot(&canvas, tree);
      break;
    case PlotKind::kLengthError:
      render::TreeLengthErrorPlot(&canvas, tree);
      break;
    case PlotKind::kTargetMiss:
      render::TargetMissPlot(&canvas, tree);
      break;
    case PlotKind::kJointAngles:
      render::JointAnglesPlot(&canvas, tree);
      break;
    case PlotKind::kLinkAngles:
    case PlotKind::kEnergy:
      break;  // refused by WriteTreePlot
  }
  render::SaveCanvas(&canvas, path);
}

}  // namespace flexkin
