// Tests of the command line's outputs: `flexkin run -o x.npz` and `flexkin render` of it, the
// output format from -o's extension, the refusal of outputs over --max-output-size (run and
// robot) before running, `flexkin validate`'s estimate, and a run whose writes fail leaving
// nothing behind.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "flexkin/result_io.h"
#include "test_util.h"

namespace flexkin {
namespace {

namespace fs = std::filesystem;
using test_util::CliResult;
using test_util::ReadFile;

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "in: " << (text)

std::string Example(const std::string& name) {
  return std::string(FLEXKIN_SOURCE_DIR) + "/examples/" + name;
}

class CliOutputTest : public testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(std::string(FLEXKIN_CLI).empty()) << "the flexkin command line was not built";
    std::string name = (fs::temp_directory_path() / "flexkin_cli_output_XXXXXX").string();
    ASSERT_NE(::mkdtemp(name.data()), nullptr);
    dir_ = name;
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return dir_ + "/" + name; }
  CliResult Cli(const std::string& args) const {
    return test_util::RunCli(FLEXKIN_CLI, dir_, args);
  }
  std::vector<std::string> Files() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename());
    std::sort(names.begin(), names.end());
    return names;
  }
  std::string dir_;
};

TEST_F(CliOutputTest, RunWritesNpzThatRenderDraws) {
  const std::string scenario = Example("fig06_parabola_multi_step.json");
  ASSERT_EQ(Cli("run '" + scenario + "' -o r.json --quiet").exit_code, 0);
  const CliResult r = Cli("run '" + scenario + "' -o r.npz --csv r.csv --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const ResultFile npz = ReadResultFile(Path("r.npz"));
  const ResultFile json = ReadResultFile(Path("r.json"));
  ASSERT_EQ(npz.result.frames.size(), json.result.frames.size());
  for (size_t f = 0; f < npz.result.frames.size(); ++f) {
    EXPECT_EQ(npz.result.frames[f].step, json.result.frames[f].step);
    EXPECT_EQ(npz.result.frames[f].points, json.result.frames[f].points);
    EXPECT_EQ(npz.result.frames[f].link_angles, json.result.frames[f].link_angles);
  }
  EXPECT_EQ(npz.result.metrics.l2_per_step, json.result.metrics.l2_per_step);
  EXPECT_EQ(npz.scenario_name, json.scenario_name);
  EXPECT_EQ(ReadFile(Path("r.csv")).substr(0, 15), "step,point,x,y\n");
  const CliResult render = Cli("render r.npz -o out --formats svg,html");
  ASSERT_EQ(render.exit_code, 0) << render.err;
  EXPECT_TRUE(fs::exists(Path("out/r.svg")));
  EXPECT_TRUE(fs::exists(Path("out/r.html")));
}

TEST_F(CliOutputTest, OtherExtensionsAreRefusedListingTheValidOnes) {
  const CliResult r = Cli("run '" + Example("fig07_straight_link.json") + "' -o r.txt");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "-o: 'r.txt'");
  EXPECT_CONTAINS(r.err, ".json");
  EXPECT_CONTAINS(r.err, ".npz");
  EXPECT_TRUE(Files().empty());
}

TEST_F(CliOutputTest, OutputOverTheLimitIsRefusedBeforeTheRun) {
  const std::string scenario = Example("fig10_planar_curve.json");
  std::ofstream(Path("r.json")) << "old";
  const CliResult r = Cli("run '" + scenario + "' -o r.json --max-output-size 100K");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "--max-output-size");
  EXPECT_CONTAINS(r.err, "over the limit of 100 KiB");
  EXPECT_CONTAINS(r.err, " frames of 81 points");
  EXPECT_CONTAINS(r.err, ".npz");
  EXPECT_EQ(ReadFile(Path("r.json")), "old");
  // The suggested --record-every fits.
  const size_t at = r.err.find("--record-every ");
  ASSERT_NE(at, std::string::npos) << r.err;
  const int every = std::atoi(r.err.c_str() + at + 15);
  ASSERT_GT(every, 1);
  EXPECT_CONTAINS(r.err, "\"record\": {\"every\": " + std::to_string(every) + "}");
  const CliResult fitted = Cli("run '" + scenario + "' -o r.json --max-output-size 100K --quiet " +
                               "--record-every " + std::to_string(every));
  ASSERT_EQ(fitted.exit_code, 0) << fitted.err;
  EXPECT_LE(fs::file_size(Path("r.json")), 100u * 1024 * 3 / 2);
  // A raised limit, or none.
  EXPECT_EQ(Cli("run '" + scenario + "' -o r.json --quiet --max-output-size 10M").exit_code, 0);
  EXPECT_EQ(Cli("run '" + scenario + "' -o r.json --quiet --max-output-size 0").exit_code, 0);
  EXPECT_EQ(Cli("run '" + scenario + "' -o r.json --quiet --max-output-size 10485760").exit_code,
            0);
  const CliResult bad = Cli("run '" + scenario + "' -o r.json --max-output-size 12Q");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_CONTAINS(bad.err, "--max-output-size");
  // The CSV counts as well.
  const CliResult csv = Cli("run '" + scenario + "' -o r.npz --csv r.csv --max-output-size 600K");
  EXPECT_EQ(csv.exit_code, 1);
  EXPECT_CONTAINS(csv.err, "the frames CSV r.csv");
}

// Without --max-output-size the limit is 4 GiB (docs/result-format.md): a result of 11 GiB is
// refused before the run, the estimate and the default limit named, nothing written.
TEST_F(CliOutputTest, TheDefaultLimitIsFourGiB) {
  std::ofstream(Path("big.json"))
      << R"({"curve": {"shape": "line", "start": [0, 0], "direction": [-1, 0],
                                  "links": 100000, "link_length": 0.01},
                        "leader": {"pull": [1, 0], "steps": 5000}})";
  const CliResult r = Cli("run big.json -o big.npz");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "--max-output-size: the result big.npz would be about 11 GiB");
  EXPECT_CONTAINS(r.err, "over the limit of 4.0 GiB");
  EXPECT_CONTAINS(r.err, "--record-every 3");
  EXPECT_EQ(Files(), std::vector<std::string>{"big.json"});
}

TEST_F(CliOutputTest, RobotOutputOverTheLimitIsRefused) {
  const std::string scenario = Example("robot_planar_8link.json");
  const CliResult r = Cli("robot '" + scenario + "' -o t.json --max-output-size 1K");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "--max-output-size");
  EXPECT_CONTAINS(r.err, "over the limit of 1.0 KiB");
  EXPECT_CONTAINS(r.err, "targets, 8 joints");
  EXPECT_FALSE(fs::exists(Path("t.json")));
  const CliResult ok = Cli("robot '" + scenario + "' -o t.json --quiet --max-output-size 100M");
  EXPECT_TRUE(ok.exit_code == 0 || ok.exit_code == 3) << ok.err;
  EXPECT_TRUE(fs::exists(Path("t.json")));
}

TEST_F(CliOutputTest, ValidatePrintsTheEstimate) {
  const CliResult r = Cli("validate '" + Example("fig10_planar_curve.json") + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("ok: ", 0), 0u) << r.out;
  EXPECT_CONTAINS(r.out, "\noutput: ");
  EXPECT_CONTAINS(r.out, " frames (recording every 1 of ");
  EXPECT_CONTAINS(r.out, " as .json, ");
  EXPECT_CONTAINS(r.out, " as .npz");
  EXPECT_CONTAINS(r.out, "in memory");
}

// A write that fails during the run (the file size limit, its signal ignored) exits 4 and leaves
// the old outputs as they were and no temporary files, for both formats.
TEST_F(CliOutputTest, FailedWriteLeavesTheOldOutputs) {
  for (const char* name : {"r.json", "r.npz"}) {
    std::ofstream(Path(name)) << "old";
    const std::string command = "cd '" + dir_ + "' && trap '' XFSZ && ulimit -f 8 && '" +
                                FLEXKIN_CLI + "' run '" + Example("fig10_planar_curve.json") +
                                "' -o " + name + " --quiet > out.txt 2> err.txt";
    const int status = std::system(("bash -c \"" + command + "\"").c_str());
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 4)
        << name << ": " << status << " " << ReadFile(Path("err.txt"));
    EXPECT_CONTAINS(ReadFile(Path("err.txt")), "cannot write '" + std::string(name) + "'");
    EXPECT_EQ(ReadFile(Path(name)), "old");
    fs::remove(Path("out.txt"));
    fs::remove(Path("err.txt"));
  }
  EXPECT_EQ(Files(), (std::vector<std::string>{"r.json", "r.npz"}));
}

}  // namespace
}  // namespace flexkin
