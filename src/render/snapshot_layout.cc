// LayoutSnapshot: the figure's height (when automatic), the scene, and where the legend goes.
#include <algorithm>
#include <cmath>
#include <string>

#include "render/canvas.h"
#include "render/snapshot.h"

namespace flexkin::render {
namespace {

// A Rect narrowed by `right` pixels.
Rect Narrowed(Rect r, double right) {
  r.w -= right;
  return r;
}

}  // namespace

int AutoHeight(const ResultFile& file, int width, double azimuth, double elevation,
               double reserve) {
  int height = (width * 3) / 4;
  // Twice: the text size (UiScale) and so the margins depend on the height.
  for (int pass = 0; pass < 2; ++pass) {
    const double ui = UiScale(width, height);
    const Rect area = Narrowed(SceneArea(file.dim, width, height), reserve * ui);
    const ChainScene scene(file, area, ui, azimuth, elevation);
    // The scene's own margins: none in 2D, 58 ui on the sides and 1.5 x 58 ui in 3D.
    const double side = file.dim == 2 ? 0.0 : 58.0 * ui;
    const double scene_h = (area.w - 2 * side) * scene.aspect() + 1.5 * side;
    height = static_cast<int>(std::lround(height - area.h + scene_h));
    height = std::clamp(height, static_cast<int>(0.4 * width), static_cast<int>(1.2 * width));
  }
  return std::clamp(height, 64, 8192);
}

namespace {

std::string Ordinal(int k) {
  if (k == 1) return "every";
  const int mod100 = k % 100, mod10 = k % 10;
  const char* suffix = (mod100 >= 11 && mod100 <= 13) ? "th"
                       : mod10 == 1                   ? "st"
                       : mod10 == 2                   ? "nd"
                       : mod10 == 3                   ? "rd"
                                                      : "th";
  return "every " + std::to_string(k) + suffix;
}

std::vector<LegendEntry> LegendEntries(const ResultFile& file, const Look& look,
                                       const FigureOptions& options, const std::vector<int>& drawn,
                                       double ui) {
  const Frames& frames = file.result.frames;
  std::vector<LegendEntry> entries;
  if (frames.size() > 1) {
    entries.push_back({LegendEntry::kLine,
                       {kInitial, 2.0 * ui, true},
                       false,
                       "initial (step " + std::to_string(frames.front().step) + ")"});
  }
  if (drawn.size() > 2) {
    entries.push_back({LegendEntry::kGradient,
                       {},
                       false,
                       Ordinal(drawn[1] - drawn[0]) + " frame, old \u2192 new"});
  }
  entries.push_back({LegendEntry::kLine,
                     {kFinal, 2.6 * ui, false},
                     true,
                     "final (step " + std::to_string(frames.back().step) + ")"});
  if (options.show_leader_path && frames.size() > 1) {
    entries.push_back(
        {LegendEntry::kLine, {kLeaderPath, 1.5 * ui, false}, false, look.lead + "'s path"});
  }
  if (look.fixed_tail) entries.push_back({LegendEntry::kBase, {}, false, "fixed base"});
  return entries;
}

// Points every 3 ui-pixels along the lines the figure draws (chains, leader path, 3D box): what
// the legend should not cover.
std::vector<Eigen::Vector2d> DrawnLines(const ResultFile& file, const ChainScene& scene,
                                        const std::vector<int>& drawn, double ui) {
  std::vector<Eigen::Vector2d> samples;
  auto sample = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    const int pieces = 1 + static_cast<int>((b - a).norm() / (3.0 * ui));
    for (int k = 0; k <= pieces; ++k)
      samples.push_back(a + (b - a) * (static_cast<double>(k) / pieces));
  };
  const int rows = static_cast<int>(file.result.frames[0].points.rows());
  for (int f : drawn) {
    for (int i = 0; i + 1 < rows; ++i) sample(scene.Pixel(file, f, i), scene.Pixel(file, f, i + 1));
  }
  for (size_t f = 0; f + 1 < file.result.frames.size(); ++f) {
    sample(scene.Pixel(file, static_cast<int>(f), 0),
           scene.Pixel(file, static_cast<int>(f) + 1, 0));
  }
  // 3D: the box's edges (corners that differ in one coordinate).
  const std::vector<Eigen::Vector2d> box = scene.BoxCorners();
  for (size_t a = 0; a < box.size(); ++a) {
    for (size_t b = a + 1; b < box.size(); ++b) {
      const size_t differ = a ^ b;
      if (differ == 1 || differ == 2 || differ == 4) sample(box[a], box[b]);
    }
  }
  return samples;
}

}  // namespace

SnapshotLayout LayoutSnapshot(const ResultFile& file, const FigureOptions& options) {
  return LayoutSnapshot(file, options, ChainLook(file));
}

SnapshotLayout LayoutSnapshot(const ResultFile& file, const FigureOptions& options,
                              const Look& look) {
  FigureOptions resolved = options;
  if (resolved.height == 0)
    resolved.height = AutoHeight(file, options.width, options.azimuth, options.elevation, 0.0);
  const std::vector<int> drawn =
      SnapshotFrames(static_cast<int>(file.result.frames.size()), options.every_k);
  double ui = UiScale(resolved.width, resolved.height);
  Rect area = SceneArea(file.dim, resolved.width, resolved.height);
  SnapshotLayout layout{
      resolved, drawn, ChainScene(file, area, ui, options.azimuth, options.elevation), {}};
  if (!options.show_legend) return layout;

  Legend legend(ui, LegendEntries(file, look, options, drawn, ui));
  const Rect region = file.dim == 2 ? layout.scene.plot() : area;
  if (legend.PlaceInCorner(region, DrawnLines(file, layout.scene, drawn, ui)) > 0) {
    // Beside the plot: narrower scene, legend at the top right.
    const double reserve = legend.width() / ui + 16.0;
    if (options.height == 0) {
      layout.options.height =
          AutoHeight(file, options.width, options.azimuth, options.elevation, reserve);
      ui = UiScale(resolved.width, layout.options.height);
      legend = Legend(ui, LegendEntries(file, look, options, drawn, ui));
    }
    area = Narrowed(SceneArea(file.dim, resolved.width, layout.options.height), reserve * ui);
    layout.scene = ChainScene(file, area, ui, options.azimuth, options.elevation);
    legend.PlaceAt(resolved.width - legend.width() - 10 * ui, layout.scene.plot().y);
    if (file.dim == 3) legend.PlaceAt(resolved.width - legend.width() - 10 * ui, area.y + 10 * ui);
  }
  layout.legend = legend;
  return layout;
}

}  // namespace flexkin::render
