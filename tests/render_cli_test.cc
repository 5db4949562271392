// Tests of `flexkin render` (the FLEXKIN_CLI executable): the files each format writes, the
// documented exit codes, messages naming the file, the option or the field, and no output file
// written or changed when the input is bad.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "flexkin/result_io.h"
#include "flexkin/robot_scenario.h"
#include "render_test_util.h"

namespace flexkin {
namespace {

using render_test::Exists;
using render_test::WriteFile;
using test_util::CliResult;
using test_util::ReadFile;
using test_util::RunCli;

const std::string kCli = FLEXKIN_CLI;

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "in: " << (text)

class RenderCliTest : public testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(kCli.empty()) << "FLEXKIN_CLI is empty: configure with FLEXKIN_BUILD_APPS=ON";
    ASSERT_FALSE(dir_.dir().empty());
    WriteResultJson(render_test::SmallScene(2).result, dir_.Path("run.json"), "small");
  }

  std::string Path(const std::string& name) const { return dir_.Path(name); }

  // Runs `flexkin ARGS` in the temporary directory.
  CliResult Cli(const std::string& args) const { return RunCli(kCli, dir_.dir(), args); }

  // The files in OUTDIR `name`, sorted; empty if it does not exist.
  std::vector<std::string> Outputs(const std::string& name) const {
    std::vector<std::string> files;
    if (!Exists(Path(name))) return files;
    for (const auto& e : std::filesystem::directory_iterator(Path(name))) {
      files.push_back(e.path().filename().string());
    }
    std::sort(files.begin(), files.end());
    return files;
  }

  render_test::TempDir dir_;
};

TEST_F(RenderCliTest, DefaultFormatsAreFiguresAndPlots) {
  const CliResult r = Cli("render run.json -o out");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(Outputs("out"), (std::vector<std::string>{"run.png", "run.svg", "run_length_error.png",
                                                      "run_length_error.svg", "run_link_angles.png",
                                                      "run_link_angles.svg", "run_path_length.png",
                                                      "run_path_length.svg"}));
  EXPECT_CONTAINS(r.out, "wrote out/run.svg\n");
  EXPECT_EQ(ReadFile(Path("out/run.png")).substr(1, 3), "PNG");
}

TEST_F(RenderCliTest, EveryFormatWithOptions) {
  const CliResult r = Cli(
      "render run.json -o out --formats gif,pdf,mp4 --every 2 --width 320 --height 240 --fps 12 "
      "--title 'A title' --azimuth 10 --elevation 45 --max-frames 50 --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(Outputs("out"), (std::vector<std::string>{"run.gif", "run.mp4", "run.pdf"}));
  EXPECT_EQ(ReadFile(Path("out/run.pdf")).rfind("%PDF-", 0), 0u);
}

TEST_F(RenderCliTest, OutputDirectoryDefaultsToTheResults) {
  const CliResult r = Cli("render run.json --formats svg -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(Exists(Path("run.svg")));
}

TEST_F(RenderCliTest, TruncatedResultExitsOneAndWritesNothing) {
  const std::string text = ReadFile(Path("run.json"));
  WriteFile(Path("cut.json"), text.substr(0, text.size() / 2));
  const CliResult r = Cli("render cut.json -o out");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "flexkin: error: cut.json: line ");
  EXPECT_TRUE(Outputs("out").empty());
}

TEST_F(RenderCliTest, WrongVersionExitsOneNamingIt) {
  std::string text = ReadFile(Path("run.json"));
  const size_t at = text.find("\"version\": 1");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 12, "\"version\": 7");
  WriteFile(Path("v7.json"), text);
  const CliResult r = Cli("render v7.json -o out");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "v7.json: /version");
  EXPECT_TRUE(Outputs("out").empty());
}

TEST_F(RenderCliTest, NanOrHugeNumberExitsOneAndLeavesOldOutputs) {
  std::string text = ReadFile(Path("run.json"));
  const size_t at = text.find("\"points\": [[");
  ASSERT_NE(at, std::string::npos);
  std::string nan = text, huge = text;
  nan.insert(at + 12, "NaN, 0], [");
  huge.insert(at + 12, "1e999, 0], [");
  WriteFile(Path("nan.json"), nan);
  WriteFile(Path("huge.json"), huge);
  ASSERT_EQ(Cli("render run.json -o out --formats svg -q").exit_code, 0);
  const std::string before = ReadFile(Path("out/run.svg"));
  std::filesystem::rename(Path("out/run.svg"), Path("out/nan.svg"));
  WriteFile(Path("out/huge.svg"), "precious");
  CliResult r = Cli("render nan.json -o out --formats svg");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "nan.json: line ");
  r = Cli("render huge.json -o out --formats svg");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "huge.json: /frames/0/points/0/0");
  EXPECT_EQ(ReadFile(Path("out/nan.svg")), before);
  EXPECT_EQ(ReadFile(Path("out/huge.svg")), "precious");
  EXPECT_EQ(Outputs("out"), (std::vector<std::string>{"huge.svg", "nan.svg"}));
}

TEST_F(RenderCliTest, UnknownFormatExitsOneListingTheFormats) {
  CliResult r = Cli("render run.json -o out --formats svg,jpeg");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err,
                  "--formats: unknown format \"jpeg\"; expected a comma-separated list of svg, "
                  "png, pdf, plots, mp4, gif, html, gltf, glb");
  r = Cli("render run.json -o out --formats ''");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(Outputs("out").empty());
}

// The viewer and the glTF export through the command: the files are there and are what their
// writers make (their content is tested in viewer_test and gltf_test).
TEST_F(RenderCliTest, WritesTheViewerAndTheGltfFiles) {
  const CliResult r = Cli("render run.json -o out --formats html,gltf,glb -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(Outputs("out"), (std::vector<std::string>{"run.glb", "run.gltf", "run.html"}));
  EXPECT_EQ(ReadFile(Path("out/run.html")).rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_EQ(ReadFile(Path("out/run.glb")).substr(0, 4), "glTF");
  EXPECT_CONTAINS(ReadFile(Path("out/run.gltf")), "\"version\": \"2.0\"");
}

TEST_F(RenderCliTest, InvalidSizesExitOneNamingTheOption) {
  CliResult r = Cli("render run.json -o out --width 0");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "--width: 0 is not valid; expected an integer from 64 to 8192");
  r = Cli("render run.json -o out --height -3");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "--height: -3 is not valid");
  r = Cli("render run.json -o out --fps 0 --formats gif");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "--fps: 0 is not valid");
  r = Cli("render run.json -o out --every -1");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "--every: -1 is not valid");
  EXPECT_TRUE(Outputs("out").empty());
}

TEST_F(RenderCliTest, UsageErrorsExitTwo) {
  EXPECT_EQ(Cli("render").exit_code, 2);
  EXPECT_EQ(Cli("render run.json --width wide").exit_code, 2);
  EXPECT_EQ(Cli("render run.json --no-such-option").exit_code, 2);
  const CliResult help = Cli("render --help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_CONTAINS(help.out, "--formats");
  EXPECT_CONTAINS(help.out, "Exit codes:");
}

TEST_F(RenderCliTest, MissingResultOrUnwritableOutputExitsFour) {
  CliResult r = Cli("render missing.json -o out");
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_CONTAINS(r.err, "cannot read 'missing.json'");
  WriteFile(Path("plain"), "a file, not a directory");
  r = Cli("render run.json -o plain");
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_EQ(ReadFile(Path("plain")), "a file, not a directory");
}

// Robot trajectories (`flexkin robot -o`, docs/robot-format.md) drawn as chains: the end effector
// leads, the base is fixed (docs/rendering.md, "Robot trajectories"). Before, `flexkin render`
// refused them with "/format: ... expected \"flexkin-result\"".
class RenderTrajectoryTest : public RenderCliTest {
 protected:
  void SetUp() override {
    RenderCliTest::SetUp();
    const std::string examples = std::string(FLEXKIN_SOURCE_DIR) + "/examples/";
    CliResult r = Cli("robot '" + examples + "robot_planar_8link.json' -o planar.json -q");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = Cli("robot '" + examples + "robot_universal_snake.json' -o snake.json -q");
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
};

// A closed triangle of three vertices filled in the ink colour: the fixed base's support.
int Supports(const std::string& svg) {
  int count = 0;
  for (const render_test::SvgPath& p : render_test::SvgPaths(svg)) {
    // cairo ends a closed path with a move back to its start: 4 vertices.
    count += p.closed && !p.curved && p.vertices.size() == 4 && p.vertices[0] == p.vertices[3] &&
             p.style.find("fill:rgb(13%,13%,13%)") != std::string::npos;
  }
  return count;
}

TEST_F(RenderTrajectoryTest, DrawsTheFigureByDefaultWithTheFixedBase) {
  const CliResult r = Cli("render planar.json -o out");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(Outputs("out"), (std::vector<std::string>{"planar.png", "planar.svg"}));
  EXPECT_EQ(ReadFile(Path("out/planar.png")).substr(1, 3), "PNG");
  const std::string svg = ReadFile(Path("out/planar.svg"));
  EXPECT_EQ(Supports(svg), 2);  // the base, and its swatch in the legend
}

TEST_F(RenderTrajectoryTest, DrawsASpatialArmWithSharedJointsInEveryTrajectoryFormat) {
  const CliResult r = Cli("render snake.json -o out --formats svg,png,pdf,mp4,gif,html -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(Outputs("out"), (std::vector<std::string>{"snake.gif", "snake.html", "snake.mp4",
                                                      "snake.pdf", "snake.png", "snake.svg"}));
  EXPECT_EQ(Supports(ReadFile(Path("out/snake.svg"))), 2);
  const std::string html = ReadFile(Path("out/snake.html"));
  EXPECT_CONTAINS(html, "\"robot\":{\"links\":16,\"targets\":60,\"unreached\":0,");
}

TEST_F(RenderTrajectoryTest, ChainOnlyFormatsAreRefusedNamingTheAvailableOnes) {
  for (const char* format : {"plots", "gltf", "glb"}) {
    const CliResult r = Cli(std::string("render planar.json -o out --formats svg,") + format);
    EXPECT_EQ(r.exit_code, 1) << format;
    EXPECT_CONTAINS(r.err, std::string("flexkin: error: --formats: format \"") + format +
                               "\" is not available for robot trajectories");
    EXPECT_CONTAINS(r.err, "expected formats among svg, png, pdf, mp4, gif, html");
  }
  EXPECT_TRUE(Outputs("out").empty());
}

TEST_F(RenderTrajectoryTest, ABrokenTrajectoryIsRefusedNamingTheField) {
  std::string text = ReadFile(Path("planar.json"));
  const size_t at = text.find("\"target\":[");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 10, "\"target\":[\"x\",");
  WriteFile(Path("bad.json"), text);
  const CliResult r = Cli("render bad.json -o out");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "flexkin: error: bad.json: /steps/0/target");
  EXPECT_TRUE(Outputs("out").empty());
}

// The chain the pictures draw: one frame per state, each state's points in reverse (the end
// effector first, the base last), steps 0 to T, lengths from the points.
TEST_F(RenderTrajectoryTest, TheChainIsTheStatesReversed) {
  const RobotTrajectoryFile t = ReadRobotTrajectoryFile(Path("snake.json"));
  ASSERT_EQ(t.states.size(), 61u);
  ASSERT_EQ(t.targets.rows(), 60);
  EXPECT_EQ(t.method, "newton");
  EXPECT_EQ(t.unreached, 0);
  const ResultFile file = RobotTrajectoryAsResult(t);
  ASSERT_EQ(file.result.frames.size(), t.states.size());
  EXPECT_EQ(file.dim, 3);
  EXPECT_EQ(file.result.num_steps, 60);
  const Eigen::Index g = t.states[0].rows();
  ASSERT_EQ(file.result.lengths.size(), g - 1);
  for (size_t s = 0; s < t.states.size(); ++s) {
    EXPECT_EQ(file.result.frames[s].step, static_cast<int64_t>(s));
    for (Eigen::Index i = 0; i < g; ++i) {
      EXPECT_EQ(file.result.frames[s].points.row(i), t.states[s].row(g - 1 - i));
    }
    EXPECT_EQ(t.states[s].row(0).transpose(), t.base) << "the base is fixed";
  }
  EXPECT_TRUE(ValidateResult(file.result, file.dim).empty());
  EXPECT_TRUE(IsRobotTrajectoryFile(Path("snake.json")));
  EXPECT_FALSE(IsRobotTrajectoryFile(Path("run.json")));
  EXPECT_FALSE(IsRobotTrajectoryFile(Path("missing.json")));
}

}  // namespace
}  // namespace flexkin
