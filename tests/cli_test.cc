// Tests of the flexkin command line (the FLEXKIN_CLI executable), run in a temporary directory:
// documented exit codes, files written, messages naming file and field, and an existing output
// left byte-identical whenever a run fails.
#include <dirent.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "flexkin/colliders.h"
#include "flexkin/result_io.h"
#include "flexkin/scenario.h"
#include "test_util.h"

namespace flexkin {
namespace {

using test_util::CliResult;
using test_util::ReadFile;
using test_util::RunCli;

const std::string kCli = FLEXKIN_CLI;

std::string Example(const std::string& name) {
  return std::string(FLEXKIN_SOURCE_DIR) + "/examples/" + name;
}

bool Exists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

class CliTest : public testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(kCli.empty()) << "FLEXKIN_CLI is empty: the flexkin_cli target was not built "
                                  "(configure with FLEXKIN_BUILD_APPS=ON)";
    ASSERT_TRUE(Exists(kCli)) << "FLEXKIN_CLI does not exist: " << kCli;
    std::string name =
        (std::filesystem::temp_directory_path() / "flexkin_cli_test_XXXXXX").string();
    ASSERT_NE(::mkdtemp(name.data()), nullptr);
    dir_ = name;
  }
  void TearDown() override {
    if (dir_.empty()) return;
    if (DIR* d = ::opendir(dir_.c_str())) {
      while (const dirent* e = ::readdir(d)) {
        const std::string n = e->d_name;
        if (n != "." && n != "..") ::unlink((dir_ + "/" + n).c_str());
      }
      ::closedir(d);
    }
    ::rmdir(dir_.c_str());
  }

  std::string Path(const std::string& name) const { return dir_ + "/" + name; }
  void Write(const std::string& name, const std::string& text) const {
    std::ofstream(Path(name), std::ios::binary) << text;
  }

  // Runs `flexkin ARGS` in the temporary directory.
  CliResult Cli(const std::string& args) const { return RunCli(kCli, dir_, args); }

  std::string dir_;
};

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "in: " << (text)

TEST_F(CliTest, RunWritesResultAndCsvAndPrintsTheReport) {
  const CliResult r = Cli("run '" + Example("fig06_parabola_multi_step.json") +
                          "' -o result.json --csv frames.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_CONTAINS(r.out, "tractrix: 20 links, 5 leader steps");
  EXPECT_EQ(r.err, "");  // no progress when stderr is not a terminal
  const ResultFile result = ReadResultJson(Path("result.json"));
  EXPECT_EQ(result.scenario_name, "fig06_parabola_multi_step");
  EXPECT_EQ(result.result.frames.size(), 6u);
  const std::string csv = ReadFile(Path("frames.csv"));
  EXPECT_EQ(csv.rfind("step,point,x,y\n", 0), 0u);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 6 * 21);
}

TEST_F(CliTest, EveryExampleRuns) {
  for (const char* file :
       {"fig07_straight_link.json", "fig06_parabola_single_step.json",
        "fig06_parabola_multi_step.json", "fig10_planar_curve.json", "fig12_spatial_curve.json"}) {
    const CliResult r = Cli("run '" + Example(file) + "' -o out.json --quiet");
    EXPECT_EQ(r.exit_code, 0) << file << ": " << r.err;
    EXPECT_EQ(r.out, "") << "--quiet printed something";
    EXPECT_GT(ReadResultJson(Path("out.json")).result.num_steps, 0) << file;
  }
}

// A scenario's colliders reach `flexkin run`: the rope of examples/rope_round_post.json slides
// round its post, every link of every frame outside it (sampled at 201 points per link with
// QuerySurface), with the tractrix and ftl; without the post the rope cuts through it.
TEST_F(CliTest, ARopeRoundAPostStaysOutsideIt) {
  const std::string example = Example("rope_round_post.json");
  const Collider post = LoadScenarioFile(example).options.colliders.at(0);
  const auto deepest = [&](const std::string& file) {
    const ResultFile f = ReadResultJson(Path(file));
    double least = 1.0;
    for (const Frame& frame : f.result.frames) {
      for (Eigen::Index i = 1; i < frame.points.rows(); ++i) {
        for (int k = 0; k <= 200; ++k) {
          const Eigen::RowVector2d p =
              frame.points.row(i - 1) +
              (k / 200.0) * (frame.points.row(i) - frame.points.row(i - 1));
          least = std::min(least, QuerySurface(post, Eigen::Vector3d(p.x(), p.y(), 0.0)).distance);
        }
      }
    }
    return least;
  };
  for (const char* method : {"tractrix", "ftl"}) {
    const CliResult r = Cli("run '" + example + "' -o out.json --method " + method);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_CONTAINS(r.out, "1 collider: ");
    EXPECT_GE(deepest("out.json"), -1e-12 * 0.05) << method;
  }
  EXPECT_LT(deepest("out.json"), 1e-3);  // the post is touched
  // The same scenario without its "colliders" (the file's last member).
  const std::string text = ReadFile(example);
  Write("free.json", text.substr(0, text.find(",\n  \"colliders\"")) + "\n}\n");
  ASSERT_EQ(Cli("run free.json -o free_out.json").exit_code, 0);
  EXPECT_LT(deepest("free_out.json"), -0.1 * post.radius) << "without the post the rope cuts it";
}

TEST_F(CliTest, OptionsOverrideTheScenario) {
  const CliResult r = Cli("run '" + Example("fig07_straight_link.json") +
                          "' -o out.json --method ftl --record-every 100 --substeps 3 "
                          "--report full");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_CONTAINS(r.out, "path length per point");
  // The frames were streamed to the file; the report counts them all the same (it said 0).
  EXPECT_CONTAINS(r.out, "recorded frames: 6\n");
  EXPECT_CONTAINS(r.out, "final link angles to the pull");
  const ResultFile f = ReadResultJson(Path("out.json"));
  EXPECT_EQ(f.result.method, Method::kFollowTheLeader);
  EXPECT_EQ(f.result.accuracy.substeps, 3);
  EXPECT_EQ(f.result.frames.size(), 6u);  // steps 0, 100, ..., 500
}

TEST_F(CliTest, ValidateSaysOkWithASummary) {
  const CliResult r = Cli("validate '" + Example("fig12_spatial_curve.json") + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.substr(0, r.out.find('\n') + 1),
            "ok: 3D, 20 links (total length 30), 2650 leader steps, method tractrix, "
            "1 sub-step\n");
  // Then the estimated output (tests/cli_output_test.cc checks it).
  EXPECT_CONTAINS(r.out, "\noutput: 2651 frames");
}

// `run` reads a scenario of any kind through the front door: a robot scenario is tracked as
// `flexkin robot` tracks it, the same files byte for byte (the joint CSV carries no timings); the
// options of chain runs are refused by name, and --method takes the robot's methods.
TEST_F(CliTest, RunOfARobotScenarioIsFlexkinRobot) {
  const std::string scenario = "'" + Example("robot_planar_8link.json") + "'";
  CliResult r = Cli("run " + scenario + " -o run.json --csv run.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_CONTAINS(r.out, "200 steps, 0 not reached");
  r = Cli("robot " + scenario + " -o robot.json --csv robot.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string csv = ReadFile(Path("run.csv"));
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 202);  // header, initial state, 200 steps
  EXPECT_EQ(csv, ReadFile(Path("robot.csv")));

  for (const char* option : {"--substeps 2", "--record-every 2", "--tolerance 1e-3", "--threads 1",
                             "--precision float32", "--report full"}) {
    r = Cli("run " + scenario + " -o other.json " + option);
    EXPECT_EQ(r.exit_code, 1) << option;
    const std::string name = std::string(option).substr(0, std::string(option).find(' '));
    EXPECT_CONTAINS(r.err, name + ": is not available for a robot scenario");
  }
  r = Cli("run " + scenario + " -o other.json --method tractrix");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "--method: unknown fixed-base method \"tractrix\"");
  EXPECT_FALSE(std::filesystem::exists(Path("other.json")));

  // And `flexkin robot` of a chain scenario says how to run it.
  r = Cli("robot '" + Example("fig07_straight_link.json") + "' -o other.json");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "is a chain scenario, not a robot scenario");
  EXPECT_CONTAINS(r.err, "flexkin run");
}

TEST_F(CliTest, ValidateListsEveryProblem) {
  Write("bad.json", R"({"curve": {"shape": "arc", "radius": 1, "links": 0, "link_length": 0.1},
                        "leader": {"pull": [1, 0], "steps": 0}, "method": "fast"})");
  const CliResult r = Cli("validate bad.json");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.out, "bad.json: /curve/links: value 0 is not valid");
  EXPECT_CONTAINS(r.out, "bad.json: /method: unknown method \"fast\"");
  EXPECT_CONTAINS(r.out, "bad.json: /leader/steps: value 0 is not valid");
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 3);
}

TEST_F(CliTest, MalformedScenarioExitsOneAndKeepsTheOldOutput) {
  Write("bad.json", R"({"curve": {"points": [[0, 0], [1, 0]]},
                        "leader": {"pull": [1, 0], "steps": 0}})");
  Write("out.json", "precious");
  const CliResult r = Cli("run bad.json -o out.json");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "bad.json: /leader/steps: value 0 is not valid; expected an integer >= 1");
  EXPECT_EQ(ReadFile(Path("out.json")), "precious");
}

TEST_F(CliTest, JsonSyntaxErrorGivesLineAndColumn) {
  Write("broken.json", "{\n  \"curve\": {\"points\": [[0, 0], [1, 0]]},\n  \"leader\": }\n");
  Write("out.json", "precious");
  const CliResult r = Cli("run broken.json -o out.json");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "broken.json: line 3, column 13: invalid JSON");
  EXPECT_EQ(ReadFile(Path("out.json")), "precious");
}

TEST_F(CliTest, InvalidOptionValueExitsOneNamingTheOption) {
  Write("out.json", "precious");
  const std::string run = "run '" + Example("fig07_straight_link.json") + "' -o out.json ";
  CliResult r = Cli(run + "--substeps 0");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "--substeps: 0 is not valid");
  r = Cli(run + "--method fast");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "--method: unknown method \"fast\"");
  r = Cli(run + "--tolerance -1");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "--tolerance");
  EXPECT_EQ(ReadFile(Path("out.json")), "precious");
}

TEST_F(CliTest, UsageErrorsExitTwo) {
  const std::string scenario = "'" + Example("fig07_straight_link.json") + "'";
  EXPECT_EQ(Cli("").exit_code, 2);
  EXPECT_EQ(Cli("frobnicate").exit_code, 2);
  EXPECT_EQ(Cli("run " + scenario).exit_code, 2);  // no -o
  EXPECT_EQ(Cli("run " + scenario + " -o x.json --no-such-option").exit_code, 2);
  EXPECT_EQ(Cli("run " + scenario + " -o x.json --substeps many").exit_code, 2);
  EXPECT_EQ(Cli("run " + scenario + " -o x.json --report long").exit_code, 2);
  EXPECT_FALSE(Exists(Path("x.json")));
}

TEST_F(CliTest, HelpAndVersionExitZero) {
  CliResult r = Cli("--version");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.out.rfind("flexkin ", 0), 0u) << r.out;
  r = Cli("run --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_CONTAINS(r.out, "Exit codes:");
  EXPECT_CONTAINS(r.out, "--tolerance");
}

TEST_F(CliTest, MissingScenarioExitsFour) {
  const CliResult r = Cli("run missing.json -o out.json");
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_CONTAINS(r.err, "cannot read 'missing.json': No such file or directory");
  EXPECT_FALSE(Exists(Path("out.json")));
  EXPECT_EQ(Cli("validate missing.json").exit_code, 4);
}

TEST_F(CliTest, UnwritableOutputExitsFour) {
  const CliResult r =
      Cli("run '" + Example("fig07_straight_link.json") + "' -o no/such/dir/out.json");
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_CONTAINS(r.err, "cannot write 'no/such/dir/out.json'");
  // An output that is a directory is refused before the run and stays a directory.
  ASSERT_EQ(::mkdir(Path("taken.json").c_str(), 0755), 0);
  EXPECT_EQ(Cli("run '" + Example("fig07_straight_link.json") + "' -o taken.json").exit_code, 4);
  struct stat st;
  EXPECT_TRUE(::stat(Path("taken.json").c_str(), &st) == 0 && S_ISDIR(st.st_mode));
  ::rmdir(Path("taken.json").c_str());
}

TEST_F(CliTest, AccuracyNotMetExitsThreeButWritesTheResult) {
  Write("out.json", "old");
  const CliResult r = Cli("run '" + Example("fig06_parabola_single_step.json") +
                          "' -o out.json --tolerance 1e-300 --max-substeps 4");
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_CONTAINS(r.err, "warning: accuracy target not met");
  const ResultFile f = ReadResultJson(Path("out.json"));
  EXPECT_TRUE(f.result.accuracy.enabled);
  EXPECT_FALSE(f.result.accuracy.met);
}

TEST_F(CliTest, AccuracyMetExitsZero) {
  const CliResult r =
      Cli("run '" + Example("fig06_parabola_single_step.json") + "' -o out.json --tolerance 1e-4");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(ReadResultJson(Path("out.json")).result.accuracy.met);
}

// Method "overall": the result carries the solver's summary; a solve that does not converge is
// reported (exit 5, result written, the failure named), never passed off as a solution.
TEST_F(CliTest, OverallRunWritesTheSolverSummary) {
  Write("overall.json",
        R"({"curve": {"shape": "parabola", "a": 1, "links": 20, "link_length": 0.25},
    "leader": {"pull": [0.49497474683058318, 0.49497474683058318], "steps": 5},
    "method": "overall", "objective": {"squared": 1, "rotation": 0.5}})");
  const CliResult r = Cli("run overall.json -o out.json");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_CONTAINS(r.out, "overall solver: 5/5 steps converged");
  const ResultFile f = ReadResultJson(Path("out.json"));
  EXPECT_EQ(f.result.method, Method::kOverall);
  EXPECT_EQ(f.result.overall.solves, 5);
  EXPECT_EQ(f.result.overall.failures, 0);
  EXPECT_EQ(f.result.weights.rotation, 0.5);
  EXPECT_LE(f.result.overall.constraint_violation, 1e-12);
  EXPECT_LE(f.result.metrics.max_relative_length_error, 1e-12);

  Write("capped.json", R"({"curve": {"shape": "parabola", "a": 1, "links": 20, "link_length": 0.25},
    "leader": {"pull": [0.49497474683058318, 0.49497474683058318], "steps": 1},
    "method": "overall", "solver": {"max_iterations": 1}})");
  const CliResult capped = Cli("run capped.json -o capped_out.json");
  EXPECT_EQ(capped.exit_code, 5);
  EXPECT_CONTAINS(capped.err, "did not converge");
  EXPECT_CONTAINS(capped.err, "max_iterations");
  const ResultFile g = ReadResultJson(Path("capped_out.json"));
  EXPECT_GT(g.result.overall.failures, 0);
}

}  // namespace
}  // namespace flexkin
