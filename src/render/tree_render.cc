// WriteTreeFigure and WriteTreeAnimation: a tree result drawn as a chain result is (docs/trees.md,
// "Pictures"), each link a line from its parent's point; the driven points' paths beneath.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/render.h"
#include "flexkin/tree_scenario.h"
#include "render/canvas.h"
#include "render/checks.h"
#include "render/legend.h"
#include "render/scene.h"
#include "render/snapshot.h"
#include "render/video.h"

namespace flexkin {
namespace render {
namespace {

// The tree as polylines of point indices, together covering every link once: the first runs
// from the root through first children (lowest index) to a leaf; every other child c of a point
// p on a polyline starts one at p, through c and its first children.
std::vector<std::vector<int>> TreePolylines(const std::vector<int>& parents) {
  const std::vector<std::vector<int>> children = TreeChildren(parents);
  std::vector<std::vector<int>> lines;
  std::vector<std::pair<int, int>> starts = {{-1, TreeRoot(parents)}};  // (from, first point)
  for (size_t s = 0; s < starts.size(); ++s) {
    std::vector<int> line;
    if (starts[s].first >= 0) line.push_back(starts[s].first);
    for (int i = starts[s].second;; i = children[i].front()) {
      line.push_back(i);
      for (size_t k = 1; k < children[i].size(); ++k) starts.emplace_back(i, children[i][k]);
      if (children[i].empty()) break;
    }
    if (line.size() >= 2) lines.push_back(std::move(line));
  }
  return lines;
}

// The tree's frames as a chain result's (what the scene fits, AutoHeight, MainTitle): frame f at
// step f; then, so that the scene holds them too, a frame for each point looked at (every row
// that point).
ResultFile TreeShell(const TreeResultFile& tree) {
  ResultFile shell;
  shell.dim = tree.dim;
  shell.scenario_name = tree.name;
  int64_t step = 0;
  for (const Points& frame : tree.frames) shell.result.frames.Add(step++, frame);
  for (size_t k = 0; k < tree.looks.size() && !tree.goals.empty(); ++k) {
    if (!tree.looks[k]) continue;
    for (const Points& goal : tree.goals) {
      const Points at = goal.row(static_cast<Eigen::Index>(k)).replicate(tree.frames[0].rows(), 1);
      shell.result.frames.Add(step++, at);
    }
  }
  return shell;
}

// Lines to draw in one batch (3D: painter's order over all of them), their coordinates owned.
class Batch {
 public:
  void AddTree(const Points& points, const std::vector<std::vector<int>>& lines,
               const ChainStyle& style) {
    for (const std::vector<int>& line : lines) {
      std::vector<double> xy;
      for (const int i : line) {
        for (Eigen::Index k = 0; k < points.cols(); ++k) xy.push_back(points(i, k));
      }
      Add(std::move(xy), static_cast<int>(line.size()), style);
    }
  }
  // The path of the goal of target k over frames 1..last (goals[f - 1]).
  void AddGoalPath(const std::vector<Points>& goals, int k, int last, const ChainStyle& style) {
    std::vector<double> xy;
    for (int f = 1; f <= last; ++f) {
      for (Eigen::Index c = 0; c < goals[f - 1].cols(); ++c) xy.push_back(goals[f - 1](k, c));
    }
    if (last >= 2) Add(std::move(xy), last, style);
  }
  // The segment from point `i` of `points` to the goal of target k in `goal`.
  void AddGaze(const Points& points, int i, const Points& goal, int k, const ChainStyle& style) {
    std::vector<double> xy(points.row(i).data(), points.row(i).data() + points.cols());
    xy.insert(xy.end(), goal.row(k).data(), goal.row(k).data() + goal.cols());
    Add(std::move(xy), 2, style);
  }
  // The path of point `i` over frames 0..last.
  void AddPath(const std::vector<Points>& frames, int i, int last, const ChainStyle& style) {
    std::vector<double> xy;
    for (int f = 0; f <= last; ++f) {
      for (Eigen::Index k = 0; k < frames[f].cols(); ++k) xy.push_back(frames[f](i, k));
    }
    Add(std::move(xy), last + 1, style);
  }
  void Draw(cairo_t* cr, const ChainScene& scene) const {
    std::vector<const double*> data;
    for (const std::vector<double>& c : coordinates_) data.push_back(c.data());
    scene.DrawChains(cr, data, rows_, styles_);
  }

 private:
  void Add(std::vector<double> xy, int rows, const ChainStyle& style) {
    coordinates_.push_back(std::move(xy));
    rows_.push_back(rows);
    styles_.push_back(style);
  }
  std::vector<std::vector<double>> coordinates_;
  std::vector<int> rows_;
  std::vector<ChainStyle> styles_;
};

// "tree · tractrix passes · 3D · 2047 points · 1 target · 120 frames, all reached".
// Whether target k of `tree` is a pointing goal whose goals the file holds.
bool LooksAt(const TreeResultFile& tree, size_t k) {
  return k < tree.looks.size() && tree.looks[k] && !tree.goals.empty();
}

// The points looked at: each pointing goal's path of goals up to frame `last`, and the gaze from
// its point to its goal at frame `last` (> 0).
void AddLooks(const TreeResultFile& tree, int last, double ui, Batch* batch) {
  for (size_t k = 0; k < tree.targets.size() && last > 0; ++k) {
    if (!LooksAt(tree, k)) continue;
    const int kk = static_cast<int>(k);
    batch->AddGoalPath(tree.goals, kk, last, {kLookedAt, 1.3 * ui, true});
    batch->AddGaze(tree.frames[last], tree.targets[k], tree.goals[last - 1], kk,
                   {Mix(kLookedAt, kWhite, 0.3), 1.0 * ui, true});
  }
}

void DrawLookedAt(cairo_t* cr, const ChainScene& scene, const TreeResultFile& tree, int last,
                  double ui) {
  for (size_t k = 0; k < tree.targets.size() && last > 0; ++k) {
    if (!LooksAt(tree, k)) continue;
    const Eigen::Vector2d p = scene.Pixel(tree.goals[last - 1].row(k).data());
    Ring(cr, p.x(), p.y(), 4.0 * ui, kLookedAt, 1.8 * ui);
  }
}

void DrawTreeJoints(cairo_t* cr, const ChainScene& scene, const TreeResultFile& tree,
                    const Points& points, double ui) {
  if (points.rows() <= 41) {
    for (Eigen::Index i = 0; i < points.rows(); ++i) {
      const Eigen::Vector2d p = scene.Pixel(points.row(i).data());
      Disc(cr, p.x(), p.y(), 2.3 * ui, kFinal);
    }
  }
  for (const int t : tree.targets) {
    const Eigen::Vector2d p = scene.Pixel(points.row(t).data());
    Disc(cr, p.x(), p.y(), 4.4 * ui, kFinal);
  }
}

void DrawFixedPoints(cairo_t* cr, const ChainScene& scene, const TreeResultFile& tree, double ui) {
  for (const int i : tree.fixed) {
    const Eigen::Vector2d p = scene.Pixel(tree.frames.front().row(i).data());
    DrawFixedBase(cr, p.x(), p.y(), ui);
  }
}

void DrawTreeFigure(const TreeResultFile& tree, const FigureOptions& options,
                    const std::string& path) {
  const ImageFormat format = ImageFormatFromPath(path);
  const ResultFile shell = TreeShell(tree);
  FigureOptions o = options;
  if (o.height == 0) o.height = AutoHeight(shell, o.width, o.azimuth, o.elevation, 0.0);
  const int num_frames = static_cast<int>(tree.frames.size());
  const std::vector<int> drawn = SnapshotFrames(num_frames, o.every_k);
  const std::vector<std::vector<int>> lines = TreePolylines(tree.parents);

  Canvas canvas(format, o.width, o.height);
  cairo_t* cr = canvas.cr();
  const double ui = canvas.ui();
  const Rect area = SceneArea(tree.dim, o.width, o.height);
  const ChainScene scene(shell, area, ui, o.azimuth, o.elevation);
  const int every = drawn.size() > 1 ? drawn[1] - drawn[0] : 1;
  DrawTitle(cr, ui, canvas.width(), MainTitle(shell, o.title),
            TreeResultSummary(tree) +
                (drawn.size() > 2
                     ? (every == 1 ? std::string(" \u00b7 every frame drawn")
                                   : " \u00b7 1 frame in " + std::to_string(every) + " drawn")
                     : ""));
  scene.DrawAxes(cr);

  const bool paths = o.show_leader_path && num_frames > 1;
  if (paths) {
    Batch batch;
    for (const int t : tree.targets) {
      batch.AddPath(tree.frames, t, num_frames - 1, {kLeaderPath, 1.5 * ui, false});
    }
    AddLooks(tree, num_frames - 1, ui, &batch);
    batch.Draw(cr, scene);
    DrawLookedAt(cr, scene, tree, num_frames - 1, ui);
    for (const int t : tree.targets) {
      std::vector<double> xy;
      for (const Points& p : tree.frames) {
        for (int k = 0; k < tree.dim; ++k) xy.push_back(p(t, k));
      }
      DrawPathArrow(cr, scene, xy, tree.dim, kLeaderPath, 5.0 * ui);
    }
  }
  Batch between;
  for (size_t d = 1; d + 1 < drawn.size(); ++d) {
    between.AddTree(tree.frames[drawn[d]], lines,
                    {FadeColor(static_cast<double>(drawn[d]) / (num_frames - 1)), 1.2 * ui, false});
  }
  between.Draw(cr, scene);
  Batch ends;
  if (num_frames > 1) ends.AddTree(tree.frames.front(), lines, {kInitial, 1.8 * ui, true});
  ends.AddTree(tree.frames.back(), lines, {kFinal, 2.4 * ui, false});
  ends.Draw(cr, scene);
  DrawTreeJoints(cr, scene, tree, tree.frames.back(), ui);
  DrawFixedPoints(cr, scene, tree, ui);

  if (o.show_legend) {
    std::vector<LegendEntry> entries;
    if (num_frames > 1)
      entries.push_back(
          {LegendEntry::kLine, {kInitial, 1.8 * ui, true}, false, "initial (frame 0)"});
    if (drawn.size() > 2) {
      entries.push_back({LegendEntry::kGradient, {}, false, "frames between, old \u2192 new"});
    }
    entries.push_back({LegendEntry::kLine,
                       {kFinal, 2.4 * ui, false},
                       true,
                       "final (frame " + std::to_string(num_frames - 1) + ")"});
    if (paths) {
      entries.push_back(
          {LegendEntry::kLine,
           {kLeaderPath, 1.5 * ui, false},
           false,
           tree.targets.size() == 1 ? "driven point's path" : "driven points' paths"});
    }
    bool looks = false;
    for (size_t k = 0; k < tree.targets.size(); ++k) looks = looks || LooksAt(tree, k);
    if (paths && looks) {
      entries.push_back({LegendEntry::kLine,
                         {kLookedAt, 1.3 * ui, true},
                         false,
                         "points looked at, and the gaze"});
    }
    if (!tree.fixed.empty()) {
      entries.push_back(
          {LegendEntry::kBase, {}, false, tree.fixed.size() == 1 ? "fixed point" : "fixed points"});
    }
    Legend legend(ui, entries);
    // Avoid the drawn links' ends and the paths' points.
    std::vector<Eigen::Vector2d> avoid;
    for (const int f : drawn) {
      for (Eigen::Index i = 0; i < tree.frames[f].rows(); ++i) {
        avoid.push_back(scene.Pixel(tree.frames[f].row(i).data()));
      }
    }
    for (const int t : tree.targets) {
      for (const Points& p : tree.frames) avoid.push_back(scene.Pixel(p.row(t).data()));
    }
    legend.PlaceInCorner(tree.dim == 2 ? scene.plot() : area, avoid);
    legend.Draw(cr);
  }
  SaveCanvas(&canvas, path);
}

void DrawTreeAnimation(const TreeResultFile& tree, const AnimationOptions& options,
                       const std::string& path) {
  const ResultFile shell = TreeShell(tree);
  int width = 0, height = 0;
  AnimationSize(
      options, [&](int w) { return AutoHeight(shell, w, options.azimuth, options.elevation, 0.0); },
      &width, &height);
  const int num_frames = static_cast<int>(tree.frames.size());
  const std::vector<int> drawn = AnimationFrames(num_frames, options);
  const std::vector<std::vector<int>> lines = TreePolylines(tree.parents);
  const double ui = UiScale(width, height);
  const ChainScene scene(shell, SceneArea(tree.dim, width, height), ui, options.azimuth,
                         options.elevation);

  // What stays: title, axes, the driven points' whole paths faintly, the first frame, the
  // fixed points.
  Canvas background(ImageFormat::kPng, width, height);
  {
    cairo_t* cr = background.cr();
    DrawTitle(cr, ui, width, MainTitle(shell, options.title), TreeResultSummary(tree));
    scene.DrawAxes(cr);
    Batch batch;
    for (const int t : tree.targets) {
      batch.AddPath(tree.frames, t, num_frames - 1,
                    {Mix(kLeaderPath, kWhite, 0.65), 1.2 * ui, true});
    }
    batch.AddTree(tree.frames.front(), lines, {Mix(kInitial, kWhite, 0.55), 1.4 * ui, true});
    batch.Draw(cr, scene);
    DrawFixedPoints(cr, scene, tree, ui);
  }
  // What moves: the driven points' paths so far, three fading ghosts, the tree, the counter.
  WritePictures(
      options, background, static_cast<int>(drawn.size()),
      [&](int d, Canvas* picture) {
        cairo_t* cr = picture->cr();
        const int f = drawn[d];
        Batch batch;
        if (f > 0) {
          for (const int t : tree.targets) {
            batch.AddPath(tree.frames, t, f, {kLeaderPath, 1.8 * ui, false});
          }
        }
        constexpr int kGhosts = 3;
        for (int g = kGhosts; g >= 1; --g) {
          if (d < g) continue;
          batch.AddTree(tree.frames[drawn[d - g]], lines,
                        {FadeColor(0.15 + 0.6 * (kGhosts - g) / kGhosts), 1.0 * ui, false});
        }
        batch.AddTree(tree.frames[f], lines, {kFinal, 2.2 * ui, false});
        AddLooks(tree, f, ui, &batch);
        batch.Draw(cr, scene);
        DrawTreeJoints(cr, scene, tree, tree.frames[f], ui);
        DrawLookedAt(cr, scene, tree, f, ui);
        DrawCounter(cr, ui, width, height,
                    "frame " + std::to_string(f) + " of " + std::to_string(num_frames - 1));
      },
      path);
}

}  // namespace

std::string TreeResultSummary(const TreeResultFile& tree) {
  const bool passes = !(tree.targets.size() == 1 && tree.fixed.empty());
  const std::string method =
      tree.robot ? std::string("robot tree \u00b7 ") + std::to_string(tree.joints.size()) +
                       " joints, joint-space Gauss-Newton"
                 : std::string("tree \u00b7 ") + MethodName(tree.method) +
                       (passes && tree.method != Method::kOverall ? " passes" : "");
  std::string s = method + " \u00b7 " + std::to_string(tree.dim) + "D \u00b7 " +
                  std::to_string(tree.parents.size()) + " points \u00b7 " +
                  std::to_string(tree.targets.size()) +
                  (tree.targets.size() == 1 ? " target" : " targets");
  if (!tree.fixed.empty()) s += " \u00b7 " + std::to_string(tree.fixed.size()) + " fixed";
  const int missed =
      static_cast<int>(std::count(tree.reached.begin(), tree.reached.end(), char(0)));
  s += " \u00b7 " + std::to_string(tree.frames.size()) + " frames";
  if (tree.frames.size() > 1) {
    s += missed == 0 ? ", all reached" : ", " + std::to_string(missed) + " not reached";
  }
  return s;
}
}  // namespace render

void WriteTreeFigure(const TreeResultFile& tree, const FigureOptions& options,
                     const std::string& path) {
  ThrowIfAny(options.Validate());
  ThrowIfAny(ValidateTreeResult(tree));
  internal::WriteTreeFigure(tree, options, path);
}

void internal::WriteTreeFigure(const TreeResultFile& tree, const FigureOptions& options,
                               const std::string& path) {
  render::DrawTreeFigure(tree, options, path);
}

void WriteTreeAnimation(const TreeResultFile& tree, const AnimationOptions& options,
                        const std::string& path) {
  ThrowIfAny(options.Validate());
  ThrowIfAny(ValidateTreeResult(tree));
  internal::WriteTreeAnimation(tree, options, path);
}

void internal::WriteTreeAnimation(const TreeResultFile& tree, const AnimationOptions& options,
                                  const std::string& path) {
  render::DrawTreeAnimation(tree, options, path);
}

}  // namespace flexkin
