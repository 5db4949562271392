// WriteSnapshotFigure: the chain every k-th frame, fading from old (light) to new (dark), the
// leading end's path, the first (dashed) and last (bold) configurations, axes and a legend.
#include "render/snapshot.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "flexkin/render.h"
#include "render/canvas.h"
#include "render/checks.h"

namespace flexkin {
namespace render {

Rect SceneArea(int dim, int width, int height) {
  const double ui = UiScale(width, height);
  const double top = 66 * ui;
  if (dim == 2) return {72 * ui, top, width - 72 * ui - 22 * ui, height - top - 58 * ui};
  return {8 * ui, top, width - 16 * ui, height - top - 8 * ui};
}

void DrawTitle(cairo_t* cr, double ui, int width, const std::string& title,
               const std::string& subtitle) {
  TextStyle style;
  style.size = 17 * ui;
  style.bold = true;
  style.halign = Align::kCenter;
  style.valign = Align::kEnd;
  DrawText(cr, width / 2.0, 28 * ui, title, style);
  style.size = 12 * ui;
  style.bold = false;
  style.color = kMuted;
  DrawText(cr, width / 2.0, 49 * ui, subtitle, style);
}

std::vector<double> LeaderPath(const ResultFile& file) {
  std::vector<double> path;
  for (const Frame& frame : file.result.frames) {
    for (int k = 0; k < file.dim; ++k) path.push_back(frame.points(0, k));
  }
  return path;
}

void DrawPathArrow(cairo_t* cr, const ChainScene& scene, const std::vector<double>& path, int dim,
                   const Rgb& color, double size) {
  const int rows = static_cast<int>(path.size()) / dim;
  std::vector<double> run(rows, 0.0);
  for (int j = 1; j < rows; ++j) {
    run[j] = run[j - 1] + (scene.Pixel(&path[j * dim]) - scene.Pixel(&path[(j - 1) * dim])).norm();
  }
  if (rows < 2 || run.back() < 4 * size) return;
  const int j = static_cast<int>(std::upper_bound(run.begin(), run.end(), run.back() / 2) - run.begin());
  const Eigen::Vector2d a = scene.Pixel(&path[(j - 1) * dim]), b = scene.Pixel(&path[j * dim]);
  const double t = (run.back() / 2 - run[j - 1]) / std::max(run[j] - run[j - 1], 1e-12);
  const Eigen::Vector2d tip = a + t * (b - a), d = (b - a).normalized(), n(-d.y(), d.x());
  const Eigen::Vector2d base = tip - 1.6 * size * d;
  cairo_move_to(cr, tip.x() + 0.6 * size * d.x(), tip.y() + 0.6 * size * d.y());
  cairo_line_to(cr, base.x() + size * n.x(), base.y() + size * n.y());
  cairo_line_to(cr, base.x() - size * n.x(), base.y() - size * n.y());
  cairo_close_path(cr);
  SetColor(cr, color);
  cairo_fill(cr);
}

int AutoHeight(const ResultFile& file, const FigureOptions& options) {
  const int width = options.width;
  int height = (width * 3) / 4;
  // Twice: the text size (UiScale) and so the margins depend on the height.
  for (int pass = 0; pass < 2; ++pass) {
    const double ui = UiScale(width, height);
    const Rect area = SceneArea(file.dim, width, height);
    const ChainScene scene(file, area, ui, options.azimuth, options.elevation);
    // The scene's own margins: none in 2D, 58 ui on the sides and 1.5 x 58 ui in 3D.
    const double side = file.dim == 2 ? 0.0 : 58.0 * ui;
    const double scene_h = (area.w - 2 * side) * scene.aspect() + 1.5 * side;
    height = static_cast<int>(std::lround(height - area.h + scene_h));
    height = std::clamp(height, static_cast<int>(0.4 * width), static_cast<int>(1.2 * width));
  }
  return std::clamp(height, 64, 8192);
}

ChainScene MakeSnapshotScene(const ResultFile& file, const FigureOptions& options) {
  return ChainScene(file, SceneArea(file.dim, options.width, options.height),
                    UiScale(options.width, options.height), options.azimuth, options.elevation);
}

namespace {

// One legend line: a swatch and a label.
struct LegendEntry {
  enum Kind { kLine, kGradient } kind = kLine;
  ChainStyle style;
  bool dot = false;  // a disc at the swatch's right end (the final leading end)
  std::string label;
};

void DrawLegend(cairo_t* cr, double ui, const Rect& region, const std::vector<Eigen::Vector2d>& avoid,
                const std::vector<LegendEntry>& entries) {
  TextStyle text;
  text.size = 12 * ui;
  const double swatch = 30 * ui, pad = 9 * ui, row = 19 * ui;
  double widest = 0.0;
  for (const LegendEntry& e : entries) widest = std::max(widest, TextWidth(cr, e.label, text));
  const double w = pad * 3 + swatch + widest, h = pad * 2 + row * entries.size() - 4 * ui;
  // The corner that covers the fewest drawn points; ties go to the first in this order.
  const double inset = 10 * ui;
  const Eigen::Vector2d corners[4] = {{region.right() - inset - w, region.y + inset},
                                      {region.x + inset, region.y + inset},
                                      {region.right() - inset - w, region.bottom() - inset - h},
                                      {region.x + inset, region.bottom() - inset - h}};
  int best = 0;
  size_t fewest = std::numeric_limits<size_t>::max();
  for (int c = 0; c < 4; ++c) {
    size_t covered = 0;
    for (const Eigen::Vector2d& p : avoid) {
      covered += p.x() > corners[c].x() - 6 * ui && p.x() < corners[c].x() + w + 6 * ui &&
                 p.y() > corners[c].y() - 6 * ui && p.y() < corners[c].y() + h + 6 * ui;
    }
    if (covered < fewest) {
      fewest = covered;
      best = c;
    }
  }
  const double x = corners[best].x(), y = corners[best].y();
  cairo_rectangle(cr, x, y, w, h);
  SetColor(cr, kWhite, 0.92);
  cairo_fill_preserve(cr);
  SetColor(cr, {0.78, 0.78, 0.78});
  cairo_set_line_width(cr, 1.0 * ui);
  cairo_stroke(cr);
  for (size_t i = 0; i < entries.size(); ++i) {
    const LegendEntry& e = entries[i];
    const double cy = y + pad + row * i + 6 * ui, x0 = x + pad, x1 = x0 + swatch;
    if (e.kind == LegendEntry::kGradient) {
      const int pieces = 12;
      for (int k = 0; k < pieces; ++k) {
        Line(cr, x0 + swatch * k / pieces, cy, x0 + swatch * (k + 1) / pieces, cy,
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
    DrawText(cr, x1 + pad, cy, e.label, text);
  }
}

std::string Ordinal(int k) {
  if (k == 1) return "every";
  const int mod100 = k % 100, mod10 = k % 10;
  const char* suffix = (mod100 >= 11 && mod100 <= 13) ? "th"
                       : mod10 == 1                    ? "st"
                       : mod10 == 2                    ? "nd"
                       : mod10 == 3                    ? "rd"
                                                       : "th";
  return "every " + std::to_string(k) + suffix;
}

}  // namespace
}  // namespace render

void WriteSnapshotFigure(const ResultFile& file, const FigureOptions& options,
                         const std::string& path) {
  using namespace render;
  ThrowIfInvalid(options.Validate());
  const ImageFormat format = ImageFormatFromPath(path);
  CheckDrawable(file);

  const std::vector<Frame>& frames = file.result.frames;
  const int num_frames = static_cast<int>(frames.size()), dim = file.dim;
  const int rows = static_cast<int>(frames[0].points.rows());
  const std::vector<int> drawn = SnapshotFrames(num_frames, options.every_k);
  const int every_k = drawn.size() > 1 ? drawn[1] - drawn[0] : 1;
  FigureOptions resolved = options;
  if (resolved.height == 0) resolved.height = AutoHeight(file, options);

  Canvas canvas(format, resolved.width, resolved.height);
  cairo_t* cr = canvas.cr();
  const double ui = canvas.ui();
  const ChainScene scene = MakeSnapshotScene(file, resolved);
  const std::string frames_note =
      num_frames == 1  ? "1 recorded frame"
      : every_k == 1   ? "all " + std::to_string(num_frames) + " recorded frames drawn"
                       : std::to_string(drawn.size()) + " of " + std::to_string(num_frames) +
                           " recorded frames drawn (" + Ordinal(every_k) + ")";
  DrawTitle(cr, ui, canvas.width(), MainTitle(file, options.title),
            RunSummary(file) + " \u00b7 " + frames_note);
  scene.DrawAxes(cr);

  // The leading end's path under the chains, which mostly follow it.
  const std::vector<double> leader = LeaderPath(file);
  const bool show_path = options.show_leader_path && num_frames > 1;
  if (show_path) {
    scene.DrawChains(cr, {leader.data()}, {num_frames}, {{kLeaderPath, 1.5 * ui, false}});
    DrawPathArrow(cr, scene, leader, dim, kLeaderPath, 5.0 * ui);
  }
  // The frames between the first and the last, faded from old to new, in one batch (3D:
  // painter's order over all of them).
  std::vector<const double*> chains;
  std::vector<int> chain_rows;
  std::vector<ChainStyle> styles;
  for (size_t d = 1; d + 1 < drawn.size(); ++d) {
    chains.push_back(frames[drawn[d]].points.data());
    chain_rows.push_back(rows);
    styles.push_back({FadeColor(static_cast<double>(drawn[d]) / (num_frames - 1)), 1.4 * ui, false});
  }
  scene.DrawChains(cr, chains, chain_rows, styles);

  const Points& first = frames.front().points;
  const Points& last = frames.back().points;
  if (num_frames > 1) scene.DrawChains(cr, {first.data()}, {rows}, {{kInitial, 2.0 * ui, true}});
  scene.DrawChains(cr, {last.data()}, {rows}, {{kFinal, 2.6 * ui, false}});
  // Joints of the last configuration when they are far enough apart to be seen.
  if (rows <= 41) {
    for (int i = 1; i < rows; ++i) {
      const Eigen::Vector2d p = scene.Pixel(last.row(i).data());
      Disc(cr, p.x(), p.y(), 2.3 * ui, kFinal);
    }
  }
  if (num_frames > 1) {
    const Eigen::Vector2d p = scene.Pixel(first.row(0).data());
    Ring(cr, p.x(), p.y(), 3.6 * ui, kInitial, 1.6 * ui);
  }
  const Eigen::Vector2d head = scene.Pixel(last.row(0).data());
  Disc(cr, head.x(), head.y(), 4.4 * ui, kFinal);

  if (options.show_legend) {
    std::vector<LegendEntry> entries;
    const long long last_step = frames.back().step;
    if (num_frames > 1) {
      entries.push_back({LegendEntry::kLine, {kInitial, 2.0 * ui, true}, false,
                         "initial (step " + std::to_string(frames.front().step) + ")"});
    }
    if (drawn.size() > 2) {
      entries.push_back({LegendEntry::kGradient, {}, false, Ordinal(every_k) + " frame, old \u2192 new"});
    }
    entries.push_back({LegendEntry::kLine, {kFinal, 2.6 * ui, false}, true,
                       "final (step " + std::to_string(last_step) + ")"});
    if (show_path) entries.push_back({LegendEntry::kLine, {kLeaderPath, 1.7 * ui, false}, false, "leading end's path"});
    std::vector<Eigen::Vector2d> avoid;
    for (int f : drawn) {
      for (int i = 0; i < rows; ++i) avoid.push_back(scene.Pixel(file, f, i));
    }
    for (int f = 0; f < num_frames; ++f) avoid.push_back(scene.Pixel(&leader[f * dim]));
    const Rect region = dim == 2 ? scene.plot() : SceneArea(dim, resolved.width, resolved.height);
    DrawLegend(cr, ui, region, avoid, entries);
  }
  SaveCanvas(&canvas, path);
}

}  // namespace flexkin
