// WriteSnapshotFigure: the chain every k-th frame, fading from old (light) to new (dark), the
// leading end's path, the first (dashed) and last (bold) configurations, axes and a legend.
#include "render/snapshot.h"

#include <algorithm>
#include <cmath>
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

void DrawFixedBase(cairo_t* cr, double x, double y, double ui) {
  const double half = 7.0 * ui, h = 10.0 * ui, ground = y + h;
  cairo_save(cr);
  cairo_move_to(cr, x, y);
  cairo_line_to(cr, x + half, ground);
  cairo_line_to(cr, x - half, ground);
  cairo_close_path(cr);
  SetColor(cr, kInk);
  cairo_fill(cr);
  cairo_set_line_width(cr, 1.4 * ui);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
  cairo_move_to(cr, x - 1.4 * half, ground);
  cairo_line_to(cr, x + 1.4 * half, ground);
  for (int k = 0; k < 5; ++k) {  // the hatching under the ground line
    const double hx = x - 1.4 * half + (k + 0.5) * 0.56 * half;
    cairo_move_to(cr, hx + 0.25 * half, ground);
    cairo_line_to(cr, hx - 0.25 * half, ground + 0.45 * h);
  }
  cairo_stroke(cr);
  cairo_restore(cr);
}

void DrawPathArrow(cairo_t* cr, const ChainScene& scene, const std::vector<double>& path, int dim,
                   const Rgb& color, double size) {
  const int rows = static_cast<int>(path.size()) / dim;
  std::vector<double> run(rows, 0.0);
  for (int j = 1; j < rows; ++j) {
    run[j] = run[j - 1] + (scene.Pixel(&path[j * dim]) - scene.Pixel(&path[(j - 1) * dim])).norm();
  }
  if (rows < 2 || run.back() < 4 * size) return;
  const int j =
      static_cast<int>(std::upper_bound(run.begin(), run.end(), run.back() / 2) - run.begin());
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

void DrawSnapshotFigure(const ResultFile& file, const Look& look, const FigureOptions& options,
                        const std::string& path) {
  const ImageFormat format = ImageFormatFromPath(path);

  const Frames& frames = file.result.frames;
  const int num_frames = static_cast<int>(frames.size()), dim = file.dim;
  const int rows = static_cast<int>(frames[0].points.rows());
  const SnapshotLayout layout = LayoutSnapshot(file, options, look);
  const std::vector<int>& drawn = layout.drawn;
  const ChainScene& scene = layout.scene;
  const int every_k = drawn.size() > 1 ? drawn[1] - drawn[0] : 1;

  Canvas canvas(format, layout.options.width, layout.options.height);
  cairo_t* cr = canvas.cr();
  const double ui = canvas.ui();
  const std::string frames_note =
      num_frames == 1 ? "1 recorded frame"
      : every_k == 1  ? "all " + std::to_string(num_frames) + " recorded frames drawn"
                      : std::to_string(drawn.size()) + " of " + std::to_string(num_frames) +
                           " recorded frames drawn (every " + std::to_string(every_k) + ")";
  DrawTitle(cr, ui, canvas.width(), MainTitle(file, options.title),
            look.summary + " \u00b7 " + frames_note);
  scene.DrawAxes(cr);
  // Keyframed colliders where they are at the last frame drawn (docs/rendering.md).
  scene.DrawColliders(cr, StaticColliders(file.colliders));
  scene.DrawColliders(cr, MovingCollidersAt(file.colliders, double(frames[drawn.back()].step)));

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
    styles.push_back(
        {FadeColor(static_cast<double>(drawn[d]) / (num_frames - 1)), 1.4 * ui, false});
  }
  scene.DrawChains(cr, chains, chain_rows, styles);

  const Points& first = frames.front().points;
  const Points& last = frames.back().points;
  // Links with a radius: the last configuration's capsules, under its lines.
  if (file.link_radii.size() > 0) {
    scene.DrawCapsules(cr, last.data(), rows, file.link_radii, Mix(kFinal, kWhite, 0.72));
  }
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
  if (look.fixed_tail) {
    const Eigen::Vector2d base = scene.Pixel(last.row(rows - 1).data());
    DrawFixedBase(cr, base.x(), base.y(), ui);
  }

  if (layout.legend) layout.legend->Draw(cr);
  SaveCanvas(&canvas, path);
}

}  // namespace render

void WriteSnapshotFigure(const ResultFile& file, const FigureOptions& options,
                         const std::string& path) {
  ThrowIfAny(options.Validate());
  render::CheckDrawable(file);
  internal::WriteSnapshotFigure({file}, options, path);
}

void WriteSnapshotFigure(const RobotTrajectoryFile& trajectory, const FigureOptions& options,
                         const std::string& path) {
  ThrowIfAny(options.Validate());
  const ResultFile result = RobotTrajectoryAsResult(trajectory);
  render::CheckDrawable(result);
  internal::WriteSnapshotFigure({result, &trajectory}, options, path);
}

void internal::WriteSnapshotFigure(const CheckedDrawing& drawing, const FigureOptions& options,
                                   const std::string& path) {
  render::DrawSnapshotFigure(drawing.result, render::LookOf(drawing), options, path);
}

}  // namespace flexkin
