// Tree results drawn (flexkin/draw.h Draw, DrawFile; flexkin/render.h WriteTreeFigure): every
// format trees are drawn in, the final tree where its points are, and bad input refused by name
// with nothing written.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "flexkin/draw.h"
#include "flexkin/gltf.h"
#include "flexkin/tree.h"
#include "flexkin/tree_scenario.h"
#include "png_test_util.h"
#include "render/canvas.h"
#include "render/scene.h"
#include "render/snapshot.h"
#include "render_test_util.h"
#include "test_util.h"

namespace flexkin {
namespace {

using render_test::ReadPng;
using render_test::TempDir;

// Two arms of three links on a shoulder above a fixed base (2D), the hands driven round small
// circles by the passes: 13 frames.
TreeResultFile TwoArms() {
  Tree tree;
  tree.points.resize(8, 2);
  tree.points << 0, 0, 0, 1, 1, 1.3, 2, 1.2, 2.8, 1.6, -1, 1.3, -2, 1.1, -2.9, 1.5;
  tree.parents = {-1, 0, 1, 2, 3, 1, 5, 6};
  TreeResultFile out;
  out.name = "two arms";
  out.dim = 2;
  out.parents = tree.parents;
  out.targets = {4, 7};
  out.fixed = {0};
  std::vector<Points> paths(2, Points(12, 2));
  for (int f = 0; f < 12; ++f) {
    const double a = 2.0 * M_PI * (f + 1) / 12;
    for (int k = 0; k < 2; ++k) {
      const int t = out.targets[k];
      paths[k](f, 0) = tree.points(t, 0) + 0.4 * (std::cos(a + k) - std::cos(k));
      paths[k](f, 1) = tree.points(t, 1) + 0.4 * (std::sin(a + k) - std::sin(k));
    }
  }
  TreeScenario scenario;
  scenario.tree = tree;
  scenario.targets = out.targets;
  scenario.paths = paths;
  scenario.weights = {1.0, 1.0};
  scenario.fixed = out.fixed;
  const TreeRunResult run = RunTree(scenario);
  out.frames = run.frames;
  for (size_t f = 0; f < run.reached.size(); ++f) {
    out.reached.push_back(run.reached[f] && run.converged[f]);
    Points goals(2, 2);
    for (int k = 0; k < 2; ++k) goals.row(k) = paths[k].row(static_cast<Eigen::Index>(f));
    out.goals.push_back(goals);
  }
  return out;
}

TEST(TreeDrawTest, EveryFormatOfTreesIsWritten) {
  EXPECT_EQ(FormatNamesOf(DrawnKind::kTreeResult),
            "svg, png, pdf, plots, mp4, gif, html, gltf, glb");
  TempDir dir;
  const TreeResultFile tree = TwoArms();
  DrawOptions options;
  options.base = dir.Path("out/arms");
  options.formats = ParseOutputFormats("svg,png,pdf,gif,html,glb", "formats");
  options.animation.max_frames = 6;
  const std::vector<std::string> written = Draw(tree, options);
  ASSERT_EQ(written.size(), 6u);
  for (const std::string& path : written) {
    EXPECT_GT(std::filesystem::file_size(path), 1000u) << path;
  }
  // The glTF's joints on the tree's points (its own tests: gltf_test's GltfTree).
  const GltfJointMotion motion = ReadGltfJointPositions(dir.Path("out/arms.glb"));
  ASSERT_EQ(motion.positions.size(), tree.frames.size());
  EXPECT_LT(
      (motion.positions.back().row(3) - tree.frames.back().row(motion.joint_points[3])).norm(),
      1e-6);
  // The viewer's data: the tree's topology, and each frame's length error over its links (the
  // browser's checks: viewer_test's tree pages).
  {
    std::ifstream in(dir.Path("out/arms.html"));
    const std::string page((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string open = "<script type=\"application/json\" id=\"flexkin-data\">";
    const size_t at = page.find(open);
    ASSERT_NE(at, std::string::npos);
    const size_t end = page.find("</script>", at);
    const nlohmann::json data =
        nlohmann::json::parse(page.substr(at + open.size(), end - at - open.size()));
    EXPECT_EQ(data["tree"]["parents"].get<std::vector<int>>(), tree.parents);
    EXPECT_EQ(data["tree"]["link_points"].get<std::vector<int>>(),
              (std::vector<int>{1, 2, 3, 4, 5, 6, 7}));
    EXPECT_EQ(data["tree"]["targets"].get<std::vector<int>>(), tree.targets);
    EXPECT_EQ(data["tree"]["fixed"].get<std::vector<int>>(), tree.fixed);
    // Some frames put a hand beyond its arm's reach: the page counts them.
    const auto missed = std::count(tree.reached.begin(), tree.reached.end(), char(0));
    EXPECT_GT(missed, 0);
    EXPECT_EQ(data["tree"]["not_reached"].get<int64_t>(), missed);
    EXPECT_EQ(data["num_links"], 7);
    EXPECT_TRUE(data["tree"]["looks"].empty());  // no pointing goal
    ASSERT_EQ(data["frame_length_error"].size(), tree.frames.size());
    for (const auto& e : data["frame_length_error"]) EXPECT_LT(e.get<double>(), 1e-12);
    // Each point's path length: the distances it moved from frame to frame.
    double travelled = 0.0;
    for (size_t f = 1; f < tree.frames.size(); ++f) {
      travelled += (tree.frames[f].row(4) - tree.frames[f - 1].row(4)).norm();
    }
    EXPECT_NEAR(data["metrics"]["path_length"][4].get<double>(), travelled, 1e-12 * travelled);
    EXPECT_EQ(data["metrics"]["path_length"][0].get<double>(), 0.0);  // the fixed base
  }
  // A trail on a point the tree does not have: the option's problem, by its name.
  options.formats = ParseOutputFormats("html", "formats");
  options.viewer.trail_points = {8};
  options.base = dir.Path("refused/arms");
  try {
    Draw(tree, options);
    ADD_FAILURE() << "a trail on point 8 of 8 points was drawn";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "viewer.trail_points[0]") << e.what();
  }
  options.viewer.trail_points = {};
  // A plot option out of range: refused by its name, before anything is written.
  options.formats = ParseOutputFormats("plots", "formats");
  options.base = dir.Path("refused/arms");
  options.plot.width = 10;
  try {
    Draw(tree, options);
    ADD_FAILURE() << "a plot 10 wide was drawn";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "plot.width") << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir.Path("refused")));
}

// ---- Plots of tree results ----

// A link that slides (a robot tree's prismatic joint): of length 0 in the first frame and longer
// in each after it. Declared as sliding, the result is valid, drawn, plotted and exported to glTF
// (tests/gltf_test.cc, GltfTree.SlidingLinksStretchTheirCapsules, checks what it holds).
TEST(TreeDrawTest, SlidingLinksAreDrawnPlottedAndExported) {
  TempDir dir;
  const TreeResultFile tree = test_util::SlidingTreeResult();
  EXPECT_TRUE(ValidateTreeResult(tree).empty()) << ValidateTreeResult(tree).front().Text();
  TreeResultFile undeclared = tree;
  undeclared.sliding.clear();
  const Problems problems = ValidateTreeResult(undeclared);
  ASSERT_FALSE(problems.empty());
  EXPECT_EQ(problems.front().field, "frames[0][2]");
  DrawOptions options;
  options.base = dir.Path("lift");
  options.formats = ParseOutputFormats("svg,png,plots", "formats");
  const std::vector<std::string> written = Draw(tree, options);
  EXPECT_EQ(written.size(), 6u);  // the figure and two plots, each as SVG and PNG
  for (const std::string& path : written) EXPECT_GT(std::filesystem::file_size(path), 1000u);
  const std::string gltf = dir.Path("lift.glb");
  WriteTreeGltf(tree, GltfOptions(), gltf);
  const GltfJointMotion motion = ReadGltfJointPositions(gltf);
  ASSERT_EQ(motion.positions.size(), tree.frames.size());
  for (size_t f = 0; f < tree.frames.size(); ++f) {
    for (size_t j = 0; j < motion.joint_points.size(); ++j) {
      EXPECT_LT((motion.positions[f].row(j) - tree.frames[f].row(motion.joint_points[j])).norm(),
                1e-6)
          << "frame " << f << " joint " << j;
    }
  }
}

TEST(TreePlotTest, PlotsOfATreeAreWrittenAsSvgAndPng) {
  TempDir dir;
  const TreeResultFile tree = TwoArms();
  EXPECT_EQ(TreePlotKinds(tree),
            (std::vector<PlotKind>{PlotKind::kPathLength, PlotKind::kLengthError,
                                   PlotKind::kTargetMiss}));
  DrawOptions options;
  options.base = dir.Path("arms");
  options.formats = ParseOutputFormats("plots", "formats");
  const std::vector<std::string> written = Draw(tree, options);
  std::vector<std::string> expected;
  for (const char* plot : {"path_length", "length_error", "target_miss"}) {
    for (const char* extension : {".svg", ".png"}) {
      expected.push_back(dir.Path("arms_" + std::string(plot) + extension));
    }
  }
  EXPECT_EQ(written, expected);
  for (const std::string& path : written) EXPECT_GT(std::filesystem::file_size(path), 1000u);
}

TEST(TreePlotTest, PathLengthHasOneMarkerPerPointAtTheDistanceItTravelled) {
  TempDir dir;
  const TreeResultFile tree = TwoArms();
  WriteTreePlot(tree, PlotKind::kPathLength, PlotOptions(), dir.Path("p.svg"));
  const std::vector<Eigen::Vector2d> marks =
      render_test::Discs(render_test::SvgPaths(test_util::ReadFile(dir.Path("p.svg"))));
  ASSERT_EQ(marks.size(), tree.parents.size());
  std::vector<double> travelled(tree.parents.size(), 0.0);
  for (size_t v = 0; v < travelled.size(); ++v) {
    for (size_t f = 1; f < tree.frames.size(); ++f) {
      travelled[v] += (tree.frames[f].row(v) - tree.frames[f - 1].row(v)).norm();
    }
  }
  EXPECT_EQ(travelled[0], 0.0);  // the fixed base
  // Left to right by index, equally spaced; up in proportion to the distance.
  const double dx = marks[1].x() - marks[0].x();
  const double per_unit = (marks[4].y() - marks[0].y()) / travelled[4];
  EXPECT_GT(dx, 0.0);
  EXPECT_LT(per_unit, 0.0);
  for (size_t v = 0; v < marks.size(); ++v) {
    EXPECT_NEAR(marks[v].x() - marks[0].x(), dx * v, 0.02) << v;
    EXPECT_NEAR(marks[v].y() - marks[0].y(), per_unit * travelled[v], 0.05) << v;
  }
}

TEST(TreePlotTest, TargetMissDrawsOneLinePerTargetThroughItsMissesOnALogScale) {
  TempDir dir;
  TreeResultFile tree = TwoArms();
  double longest = 0.0;
  for (size_t v = 1; v < tree.parents.size(); ++v) {
    longest =
        std::max(longest, (tree.frames[0].row(v) - tree.frames[0].row(tree.parents[v])).norm());
  }
  // Known misses: every hand on its goal (drawn at the floor, 1e-17), but hand 1 (point 4) 1e-6
  // of the longest link off it at frame 3 and hand 2 (point 7) 1e-3 off at frame 6.
  for (size_t f = 1; f < tree.frames.size(); ++f) {
    for (int k = 0; k < 2; ++k) tree.frames[f].row(tree.targets[k]) = tree.goals[f - 1].row(k);
  }
  tree.frames[3](4, 0) += 1e-6 * longest;
  tree.frames[6](7, 1) -= 1e-3 * longest;
  WriteTreePlot(tree, PlotKind::kTargetMiss, PlotOptions(), dir.Path("m.svg"));
  // The two lines (open, of more than two vertices; cairo joins a line's collinear pieces, so
  // each is the floor, its one peak and the floor again), the last target's drawn first.
  std::vector<render_test::SvgPath> lines;
  for (const render_test::SvgPath& p :
       render_test::SvgPaths(test_util::ReadFile(dir.Path("m.svg")))) {
    if (!p.closed && !p.curved && p.vertices.size() > 2) lines.push_back(p);
  }
  ASSERT_EQ(lines.size(), 2u);
  struct Peak {
    double x0 = 0, x = 0, y = 1e300, floor = -1e300;
  };
  std::vector<Peak> peaks(2);
  for (int k = 0; k < 2; ++k) {
    Peak& p = peaks[k];
    p.x0 = lines[1 - k].vertices.front().first;
    for (const auto& [x, y] : lines[1 - k].vertices) {
      if (y < p.y) p.y = y, p.x = x;
      p.floor = std::max(p.floor, y);
    }
  }
  EXPECT_NEAR(peaks[0].floor, peaks[1].floor, 1e-6);
  // Frame 3 and frame 6 from frame 1 (the first drawn): x 2 and 5 frames on.
  EXPECT_NEAR((peaks[1].x - peaks[1].x0) / (peaks[0].x - peaks[0].x0), 2.5,
              1e-3);  // SVG rounds to 1e-3 px
  // 11 decades from the floor (1e-17) up to 1e-6, 3 more up to 1e-3.
  const double decade = (peaks[0].floor - peaks[0].y) / 11.0;
  EXPECT_GT(decade, 10.0);
  EXPECT_NEAR(peaks[0].y - peaks[1].y, 3.0 * decade, 1e-3 * decade);
}

TEST(TreePlotTest, PlotsATreeHasNoDataForAreRefusedByName) {
  TempDir dir;
  TreeResultFile tree = TwoArms();
  for (PlotKind kind : {PlotKind::kLinkAngles, PlotKind::kEnergy, PlotKind::kJointAngles}) {
    test_util::ExpectInputError(
        [&] { WriteTreePlot(tree, kind, PlotOptions(), dir.Path("x.svg")); }, "plot",
        "path_length, length_error, target_miss");
  }
  tree.goals.clear();  // a file without goals: no misses to draw
  test_util::ExpectInputError(
      [&] { WriteTreePlot(tree, PlotKind::kTargetMiss, PlotOptions(), dir.Path("x.svg")); }, "plot",
      "path_length, length_error");
  tree.frames[3](2, 1) = std::nan("");
  test_util::ExpectInputError(
      [&] { WriteTreePlot(tree, PlotKind::kPathLength, PlotOptions(), dir.Path("x.svg")); },
      "frames[3][2][1]", "");
  EXPECT_FALSE(std::filesystem::exists(dir.Path("x.svg")));
  // A chain result has no targets' misses.
  ResultFile chain;
  chain.dim = 2;
  chain.result.lengths = Eigen::VectorXd::Ones(1);
  Points p(2, 2);
  p << 0, 0, 1, 0;
  chain.result.frames.Add(0, p);
  chain.result.metrics.path_length = Eigen::VectorXd::Zero(2);
  test_util::ExpectInputError(
      [&] { WritePlot(chain, PlotKind::kTargetMiss, PlotOptions(), dir.Path("c.svg")); }, "plot",
      "tree results only");
}

// The final tree is drawn where its points are: the pixel at each point of the last frame (a
// joint's disc) has the final configuration's colour; the fixed point's support is under point 0.
TEST(TreeDrawTest, TheFinalTreeIsWhereItsPointsAre) {
  TempDir dir;
  const TreeResultFile tree = TwoArms();
  FigureOptions figure;
  figure.width = 900;
  figure.height = 700;
  figure.show_legend = false;
  const std::string path = dir.Path("arms.png");
  WriteTreeFigure(tree, figure, path);
  const render_test::Image image = ReadPng(path);
  ASSERT_EQ(image.width, 900);
  ResultFile shell;  // the frames the scene fits, as the figure's
  shell.dim = 2;
  for (size_t f = 0; f < tree.frames.size(); ++f) shell.result.frames.Add(f, tree.frames[f]);
  const double ui = render::UiScale(900, 700);
  const render::ChainScene scene(shell, render::SceneArea(2, 900, 700), ui, figure.azimuth,
                                 figure.elevation);
  const Points& last = tree.frames.back();
  for (Eigen::Index i = 1; i < last.rows(); ++i) {
    const Eigen::Vector2d p = scene.Pixel(last.row(i).data());
    const std::array<int, 3> rgb = image.Rgb(static_cast<int>(std::lround(p.x() - 0.5)),
                                             static_cast<int>(std::lround(p.y() - 0.5)));
    // kFinal (0.70, 0.09, 0.17): red well above green and blue.
    EXPECT_GT(rgb[0], 140) << "point " << i;
    EXPECT_LT(rgb[1], 80) << "point " << i;
    EXPECT_LT(rgb[2], 90) << "point " << i;
  }
  const Eigen::Vector2d base = scene.Pixel(last.row(0).data());
  const std::array<int, 3> support =
      image.Rgb(static_cast<int>(base.x()), static_cast<int>(base.y() + 6 * ui));
  EXPECT_LT(support[0] + support[1] + support[2], 200);  // the support's dark triangle
}

TEST(TreeDrawTest, BadTreesAreRefusedByNameWithNothingWritten) {
  TempDir dir;
  DrawOptions options;
  options.base = dir.Path("bad/t");
  auto problem = [&](const TreeResultFile& tree) {
    try {
      Draw(tree, options);
    } catch (const InputError& e) {
      return e.problem().field;
    }
    return std::string("(drawn)");
  };
  TreeResultFile tree = TwoArms();
  tree.frames[3](5, 1) = NAN;
  EXPECT_EQ(problem(tree), "frames[3][5][1]");
  tree = TwoArms();
  tree.parents[2] = 3;  // a cycle
  EXPECT_EQ(problem(tree).rfind("parents[", 0), 0u);
  tree = TwoArms();
  tree.targets[1] = 8;
  EXPECT_EQ(problem(tree), "targets[1]");
  tree = TwoArms();
  tree.reached.pop_back();
  EXPECT_EQ(problem(tree), "reached");
  tree = TwoArms();
  tree.frames[2].conservativeResize(7, 2);
  EXPECT_EQ(problem(tree), "frames[2]");
  EXPECT_FALSE(std::filesystem::exists(dir.Path("bad")));

  // A damaged file, by DrawFile: named by the file and its JSON pointer.
  const std::string file = dir.Path("t.json");
  {
    TreeScenario s;
    const TreeResultFile good = TwoArms();
    s.name = good.name;
    s.tree = Tree{good.frames[0], good.parents};
    s.targets = good.targets;
    s.fixed = good.fixed;
    TreeRunResult r;
    r.frames = good.frames;
    r.reached = r.converged = std::vector<char>(good.reached.size(), 1);
    r.passes.assign(good.reached.size(), 1);
    r.residual.assign(good.reached.size(), 0.0);
    WriteTreeResult(file, s, r);
  }
  nlohmann::json j = nlohmann::json::parse(std::ifstream(file));
  j["frames"][4][2][0] = "x";
  std::ofstream(file) << j.dump();
  options.base = dir.Path("bad/t");
  try {
    DrawFile(file, options);
    ADD_FAILURE() << "a damaged tree result was drawn";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), file + ": /frames/4/2/0") << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir.Path("bad")));
}

}  // namespace
}  // namespace flexkin
