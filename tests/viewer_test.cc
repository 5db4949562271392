// Tests of the interactive viewer (WriteViewerHtml): the page is self-contained and carries the
// result's data faithfully, bad input is refused without touching the output file, and the page
// works in a real browser (headless Chromium driven by tests/viewer/browser_check.mjs) for a small
// 2D run and the two large runs it must play smoothly: 20 links in 3D over 2650 steps and 80
// links in 2D over 250 steps; links of a radius are drawn as their capsules.
#include "flexkin/viewer.h"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "flexkin/any_scenario.h"
#include "flexkin/chain.h"
#include "flexkin/error.h"
#include "flexkin/result_io.h"
#include "flexkin/run.h"
#include "flexkin/tree_scenario.h"
#include "scenes/scenes.h"
#include "test_util.h"

namespace flexkin {
namespace {

namespace fs = std::filesystem;
using test_util::ExpectInputError;

// A run of a curved chain of `links` links whose leading end follows a smooth wavy path of
// `steps` leader steps of about `step` each.
// A tree result of `kind` (scenes::TreeShape) whose tips (scenes::TreeTips) go round circles for
// `frames` frames, the root fixed where the tips are several, run by RunTree.
TreeResultFile MakeTreeResult(scenes::TreeKind kind, int dim, int frames, const std::string& name) {
  TreeScenario s;
  s.name = name;
  s.tree = scenes::TreeShape(kind, dim);
  s.targets = scenes::TreeTips(kind);
  if (kind == scenes::TreeKind::kBinary10) s.targets = {0};  // the root, driven: a plant
  // TipCircles gives each frame's targets; a scenario holds each target's path.
  const std::vector<Points> circles = scenes::TipCircles(s.tree, s.targets, frames);
  s.paths.assign(s.targets.size(), Points(frames, dim));
  for (int f = 0; f < frames; ++f) {
    for (size_t k = 0; k < s.targets.size(); ++k) s.paths[k].row(f) = circles[f].row(k);
  }
  s.weights.assign(s.targets.size(), 1.0);
  if (s.targets.size() > 1) s.fixed = {0};
  const TreeRunResult run = RunTree(s);
  TreeResultFile out;
  out.name = name;
  out.method = s.method;
  out.dim = dim;
  out.parents = s.tree.parents;
  out.targets = s.targets;
  out.fixed = s.fixed;
  out.frames = run.frames;
  for (size_t f = 0; f < run.reached.size(); ++f) {
    out.reached.push_back(run.reached[f] && run.converged[f]);
  }
  return out;
}

// The torso example (examples/tree_torso.json) run, its goals and pointing goal kept: a page that
// draws the point the head looks at.
TreeResultFile TorsoResult() {
  const AnyScenario any =
      ReadScenarioFile(std::string(FLEXKIN_SOURCE_DIR) + "/examples/tree_torso.json");
  const TreeScenario& s = *any.tree;
  const TreeRunResult run = RunTree(s);
  TreeResultFile out;
  out.name = s.name;
  out.dim = 3;
  out.parents = s.tree.parents;
  out.targets = s.targets;
  out.fixed = s.fixed;
  out.looks = s.looks;
  out.frames = run.frames;
  for (size_t f = 1; f < run.frames.size(); ++f) {
    out.reached.push_back(run.reached[f - 1]);
    Points goal(static_cast<Eigen::Index>(s.targets.size()), 3);
    for (size_t k = 0; k < s.targets.size(); ++k) goal.row(k) = s.paths[k].row(f - 1);
    out.goals.push_back(goal);
  }
  return out;
}

ResultFile MakeResult(int dim, int links, int steps, double step, const std::string& name) {
  const Chain chain = scenes::CurvedChain(dim, links, 1.0, 2.5 / links);
  Points targets(steps, dim);
  for (int s = 1; s <= steps; ++s) {
    const double t = step * s;
    targets(s - 1, 0) = chain.points(0, 0) - t;
    targets(s - 1, 1) = chain.points(0, 1) + 0.6 * std::sin(1.3 * t);
    if (dim == 3) targets(s - 1, 2) = chain.points(0, 2) + 0.5 * (1.0 - std::cos(0.9 * t));
  }
  ResultFile file;
  file.result = Run(chain, targets, RunOptions());
  file.dim = dim;
  file.scenario_name = name;
  return file;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A fresh directory under the system's temporary directory, removed at the end unless
// FLEXKIN_VIEWER_TEST_KEEP is set (to look at the screenshots).
class ViewerTest : public testing::Test {
 protected:
  void SetUp() override {
    std::string name = (fs::temp_directory_path() / "flexkin_viewer_test_XXXXXX").string();
    ASSERT_NE(::mkdtemp(name.data()), nullptr);
    dir_ = name;
  }
  void TearDown() override {
    if (std::getenv("FLEXKIN_VIEWER_TEST_KEEP") != nullptr) {
      std::printf("viewer test output kept in %s\n", dir_.c_str());
    } else if (!dir_.empty()) {
      fs::remove_all(dir_);
    }
  }
  std::string Path(const std::string& name) const { return dir_ + "/" + name; }
  std::string dir_;
};

// The JSON embedded in a page written by WriteViewerHtml.
nlohmann::json EmbeddedData(const std::string& page) {
  const std::string open = "<script type=\"application/json\" id=\"flexkin-data\">";
  const size_t begin = page.find(open);
  EXPECT_NE(begin, std::string::npos);
  const size_t end = page.find("</script>", begin);
  return nlohmann::json::parse(page.substr(begin + open.size(), end - begin - open.size()));
}

TEST_F(ViewerTest, PageIsSelfContainedAndCarriesTheResult) {
  const ResultFile file = MakeResult(2, 12, 60, 0.05, "small </script><b>&</b> 2D");
  ViewerOptions options;
  options.trail_points = {12};
  WriteViewerHtml(file, options, Path("view.html"));
  const std::string page = ReadFile(Path("view.html"));

  EXPECT_EQ(page.rfind("<!DOCTYPE html>", 0), 0u);
  // Nothing to fetch: no links to files or the network, the style and the script inline.
  for (const char* outside : {"http:", "https:", "//cdn", "<link", "src=", "@import", "url("}) {
    EXPECT_EQ(page.find(outside), std::string::npos) << outside;
  }
  EXPECT_NE(page.find("<style>"), std::string::npos);
  EXPECT_NE(page.find("requestAnimationFrame"), std::string::npos);
  // Three elements closed: the data, the script and the style sheet. The scenario name's
  // "</script>" did not close the data early.
  size_t closes = 0;
  for (size_t at = page.find("</"); at != std::string::npos; at = page.find("</", at + 1)) {
    closes += page.compare(at, 9, "</script>") == 0 ? 1 : 0;
  }
  EXPECT_EQ(closes, 2u);

  const nlohmann::json data = EmbeddedData(page);
  const RunResult& r = file.result;
  EXPECT_EQ(data["title"], file.scenario_name);
  EXPECT_EQ(data["method"], "tractrix");
  EXPECT_EQ(data["dim"], 2);
  EXPECT_EQ(data["num_links"], 12);
  EXPECT_EQ(data["num_steps"], 60);
  EXPECT_EQ(data["options"]["trail_points"], nlohmann::json::array({12}));
  ASSERT_EQ(data["steps"].size(), r.frames.size());
  ASSERT_EQ(data["positions"].size(), r.frames.size() * 13 * 2);
  ASSERT_EQ(data["frame_length_error"].size(), r.frames.size());
  for (size_t f = 0; f < r.frames.size(); ++f) {
    EXPECT_EQ(data["steps"][f], r.frames[f].step);
    EXPECT_LE(data["frame_length_error"][f].get<double>(),
              r.metrics.max_relative_length_error * 1.01);
    for (int i = 0; i < 13 * 2; ++i) {
      const double want = r.frames[f].points.data()[i];
      EXPECT_NEAR(data["positions"][f * 26 + i].get<double>(), want, 1e-8 * (1 + std::abs(want)));
    }
  }
  EXPECT_EQ(data["metrics"]["l2_total"].get<double>(), r.metrics.l2_total);
  ASSERT_EQ(data["metrics"]["path_length"].size(), 13u);
  EXPECT_EQ(data["metrics"]["path_length"][12].get<double>(), r.metrics.path_length[12]);
  EXPECT_EQ(data["metrics"]["l2_per_step"].size(), 60u);
}

// Radii for the links of `file` (a few sizes about 2% of the chain's length, every `zero`-th one 0
// where `zero` > 0): links drawn as their capsules.
void GiveLinkRadii(ResultFile* file, int zero = 0) {
  const Eigen::Index n = file->result.lengths.size();
  const double unit = 0.02 * file->result.lengths.sum();
  file->link_radii.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    file->link_radii[i] = zero > 0 && i % zero == zero - 1 ? 0.0 : unit * (0.6 + 0.35 * (i % 3));
  }
}

// The radii of a result's links go into the page's data, "link_radii", one per link with the
// coordinates' digits; a result without them has no such key (and the same page as before).
TEST_F(ViewerTest, PageCarriesTheLinkRadiiWhenTheResultHasThem) {
  ResultFile file = MakeResult(3, 7, 12, 0.05, "capsules");
  for (const int digits : {6, 9, 17}) {
    ViewerOptions options;
    options.digits = digits;
    file.link_radii.resize(0);
    WriteViewerHtml(file, options, Path("plain.html"));
    EXPECT_FALSE(EmbeddedData(ReadFile(Path("plain.html"))).contains("link_radii")) << digits;
    GiveLinkRadii(&file, 4);
    file.link_radii[0] = 1.0 / 3.0;  // more digits than any option keeps
    WriteViewerHtml(file, options, Path("capsules.html"));
    const std::string page = ReadFile(Path("capsules.html"));
    const nlohmann::json data = EmbeddedData(page);
    ASSERT_TRUE(data.contains("link_radii")) << digits;
    ASSERT_EQ(data["link_radii"].size(), 7u) << digits;
    for (int i = 0; i < 7; ++i) {
      const double want = file.link_radii[i];
      const double got = data["link_radii"][i].get<double>();
      if (digits == 17) {
        EXPECT_EQ(got, want) << i;
      } else {
        EXPECT_NEAR(got, want, 0.6 * std::pow(10.0, 1 - digits) * want) << digits << " " << i;
      }
    }
    EXPECT_NE(data["link_radii"][0].get<double>(), 0.0);
    EXPECT_EQ(data["link_radii"][3].get<double>(), 0.0);
    // 1/3 written with `digits` significant digits, as the coordinates are.
    const size_t at = page.find("\"link_radii\":[");
    ASSERT_NE(at, std::string::npos);
    const std::string first = page.substr(at + 14, page.find(',', at) - at - 14);
    EXPECT_EQ(first, digits == 17 ? "0.33333333333333331" : "0." + std::string(digits, '3'))
        << digits;
  }
}

// A tree whose link into point 2 slides (a robot tree's prismatic joint, of length 0 in the first
// frame): the page is written, and its length errors leave that link out.
TEST_F(ViewerTest, ASlidingLinkIsNotALengthError) {
  const TreeResultFile tree = test_util::SlidingTreeResult();
  WriteTreeViewerHtml(tree, ViewerOptions(), Path("lift.html"));
  const nlohmann::json data = EmbeddedData(test_util::ReadFile(Path("lift.html")));
  ASSERT_EQ(data["frame_length_error"].size(), 6u);
  // The other links' lengths to their rounding (the slide added and taken away).
  for (const auto& e : data["frame_length_error"]) EXPECT_LE(e.get<double>(), 4e-16);
  EXPECT_LE(data["metrics"]["max_relative_length_error"].get<double>(), 4e-16);
}

TEST_F(ViewerTest, OptionsAreValidatedNamingTheField) {
  EXPECT_TRUE(ViewerOptions().Validate().empty());
  const ResultFile file = MakeResult(3, 4, 5, 0.1, "");
  const auto expect = [&](auto change, const std::string& field) {
    ViewerOptions options;
    change(options);
    ExpectInputError([&] { WriteViewerHtml(file, options, Path("v.html")); }, field);
    EXPECT_FALSE(fs::exists(Path("v.html"))) << field;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  expect([](ViewerOptions& o) { o.playback_seconds = 0; }, "options.playback_seconds");
  expect([&](ViewerOptions& o) { o.playback_seconds = nan; }, "options.playback_seconds");
  expect([](ViewerOptions& o) { o.trail_points = {1, -1}; }, "options.trail_points[1]");
  expect([](ViewerOptions& o) { o.trail_points = {5}; }, "trail_points[0]");  // 4 links: 0..4
  expect([](ViewerOptions& o) { o.elevation = 91; }, "options.elevation");
  expect([&](ViewerOptions& o) { o.azimuth = nan; }, "options.azimuth");
  expect([](ViewerOptions& o) { o.digits = 5; }, "options.digits");
  ViewerOptions ok;
  ok.trail_points = {0, 4};
  WriteViewerHtml(file, ok, Path("v.html"));
  EXPECT_EQ(EmbeddedData(ReadFile(Path("v.html")))["title"], "flexkin result");
}

TEST_F(ViewerTest, BadResultIsRefusedAndExistingFileLeftUntouched) {
  const ResultFile good = MakeResult(2, 6, 10, 0.05, "bad");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::ofstream(Path("existing.html")) << "the old page";
  const auto expect = [&](auto change, const std::string& field) {
    ResultFile file = good;
    change(file);
    ExpectInputError([&] { WriteViewerHtml(file, ViewerOptions(), Path("new.html")); }, field);
    ExpectInputError([&] { WriteViewerHtml(file, ViewerOptions(), Path("existing.html")); }, field);
    EXPECT_FALSE(fs::exists(Path("new.html"))) << field;
    EXPECT_EQ(ReadFile(Path("existing.html")), "the old page") << field;
  };
  expect([&](ResultFile& f) { f.result.frames.mutable_points(3)(2, 1) = nan; },
         "frames[3].points[2][1]");
  expect([&](ResultFile& f) { f.result.frames.mutable_points(0)(0, 0) = INFINITY; },
         "frames[0].points[0][0]");
  expect([&](ResultFile& f) { f.result.metrics.l2_total = nan; }, "metrics.l2_total");
  expect([&](ResultFile& f) { f.result.metrics.path_length[6] = nan; }, "metrics.path_length[6]");
  expect([&](ResultFile& f) { f.result.lengths[0] = 0; }, "link_lengths[0]");
  expect([&](ResultFile& f) { f.result.frames.Clear(); }, "frames");
  expect([&](ResultFile& f) { f.dim = 4; }, "dim");
  // Nothing else was left in the directory (no temporary files).
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

// Runs `command`, returns its exit status and appends its stdout and stderr to `output`.
int RunCommand(const std::string& command, std::string* output) {
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return -1;
  char buffer[4096];
  size_t got;
  while ((got = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) output->append(buffer, got);
  const int status = ::pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

TEST_F(ViewerTest, PlaysScrubsAndMovesInHeadlessChromium) {
  // What the browser check needs; all of it is installed by scripts/install-deps.sh.
  const std::string source = FLEXKIN_SOURCE_DIR;
  const std::string tools = source + "/tools/node";
  const std::string chromium =
      std::getenv("FLEXKIN_CHROMIUM") ? std::getenv("FLEXKIN_CHROMIUM") : "/usr/bin/chromium";
  std::string ignored;
  ASSERT_EQ(RunCommand("node --version", &ignored), 0)
      << "node is missing: run scripts/install-deps.sh";
  ASSERT_TRUE(fs::exists(tools + "/node_modules/playwright-core/package.json"))
      << "playwright-core is missing from tools/node: run scripts/install-deps.sh";
  ASSERT_TRUE(fs::exists(chromium)) << chromium << " is missing: run scripts/install-deps.sh";

  ViewerOptions options;
  options.playback_seconds = 8.0;
  WriteViewerHtml(MakeResult(2, 10, 80, 0.05, "small 2D"), options, Path("small_2d.html"));
  // The sizes that must play smoothly: the paper's Figs. 12 (3D) and 10 (2D).
  const ResultFile spatial = MakeResult(3, 20, 2650, 0.006, "20 links 3D, 2650 steps");
  ASSERT_EQ(spatial.result.frames.size(), 2651u);
  WriteViewerHtml(spatial, options, Path("spatial_20x2650.html"));
  WriteViewerHtml(MakeResult(2, 80, 250, 0.07, "80 links 2D, 250 steps"), options,
                  Path("planar_80x250.html"));
  // Links of a radius: drawn as their capsules (the check measures their strokes).
  ResultFile capsules_2d = MakeResult(2, 10, 80, 0.05, "capsules 2D");
  GiveLinkRadii(&capsules_2d, 5);
  WriteViewerHtml(capsules_2d, options, Path("capsules_2d.html"));
  ResultFile capsules_3d = MakeResult(3, 8, 120, 0.03, "capsules 3D");
  GiveLinkRadii(&capsules_3d);
  WriteViewerHtml(capsules_3d, options, Path("capsules_3d.html"));
  // Trees: two arms reaching round circles (3D), and a binary tree of depth 10 driven at its
  // root (2D, 2,046 links: the frame rate of a large tree).
  WriteTreeViewerHtml(MakeTreeResult(scenes::TreeKind::kTwoArms, 3, 60, "two arms"), options,
                      Path("tree_arms_3d.html"));
  WriteTreeViewerHtml(MakeTreeResult(scenes::TreeKind::kBinary10, 2, 40, "binary tree"), options,
                      Path("tree_binary_2d.html"));
  WriteTreeViewerHtml(TorsoResult(), options, Path("tree_torso.html"));
  std::printf("page sizes: %ju, %ju, %ju bytes\n",
              static_cast<uintmax_t>(fs::file_size(Path("small_2d.html"))),
              static_cast<uintmax_t>(fs::file_size(Path("spatial_20x2650.html"))),
              static_cast<uintmax_t>(fs::file_size(Path("planar_80x250.html"))));

  // Under the sanitizers the instrumented writers above run; the browser's run of their pages
  // (the page's script is the browser's, not instrumented) is the plain build's.
  if (test_util::kSanitized) {
    GTEST_SKIP() << "the browser check runs in the plain build; here only the page writers";
  }
  std::string output;
  const int status =
      RunCommand("node '" + source + "/tests/viewer/browser_check.mjs' '" + tools + "' '" + dir_ +
                     "' '" + Path("small_2d.html") + "' '" + Path("spatial_20x2650.html") + "' '" +
                     Path("planar_80x250.html") + "' '" + Path("capsules_2d.html") + "' '" +
                     Path("capsules_3d.html") + "' '" + Path("tree_arms_3d.html") + "' '" +
                     Path("tree_binary_2d.html") + "' '" + Path("tree_torso.html") + "'",
                 &output);
  std::printf("%s", output.c_str());
  EXPECT_EQ(status, 0) << output;
  EXPECT_NE(output.find("all viewer checks passed"), std::string::npos);
  for (const char* shot :
       {"small_2d-playing.png", "spatial_20x2650-trails.png", "planar_80x250-dragged.png",
        "capsules_3d-opened.png", "tree_arms_3d-playing.png", "tree_binary_2d-playing.png"}) {
    EXPECT_TRUE(fs::exists(Path(shot))) << shot;
  }
}

}  // namespace
}  // namespace flexkin
