// Tests of `flexkin robot` (the FLEXKIN_CLI executable): the trajectory JSON and joint CSV of the
// example scenario, exit codes, and bad scenarios refused with the field and no output.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "flexkin/arm.h"
#include "flexkin/robot_scenario.h"
#include "test_util.h"

namespace {

const std::string kCli = FLEXKIN_CLI;
using nlohmann::json;

using flexkin::test_util::ReadFile;

class RobotCliTest : public testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(kCli.empty()) << "FLEXKIN_CLI is empty: configure with FLEXKIN_BUILD_APPS=ON";
    std::string pattern =
        (std::filesystem::temp_directory_path() / "flexkin_robot_cli_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string Path(const std::string& name) const { return dir_ + "/" + name; }
  void Write(const std::string& name, const std::string& text) const {
    std::ofstream(Path(name)) << text;
  }

  // Runs `flexkin robot ARGS`; returns the exit code, stderr in *err.
  int Robot(const std::string& args, std::string* err = nullptr) const {
    const std::string command = "'" + kCli + "' robot " + args + " > '" + Path("out.txt") +
                                "' 2> '" + Path("err.txt") + "'";
    const int status = std::system(command.c_str());
    if (err != nullptr) *err = ReadFile(Path("err.txt"));
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  std::string dir_;
};

// examples/robot_spatial_limits.json: targets made reachable as end effectors of bends within
// the limits (0.25 rad), which the path saturates. Every step is reached, most of them through
// the joint-space step (measured: 81 of 120); the bends stay within the cone.
TEST_F(RobotCliTest, SaturatedLimitsExampleReachesEveryTarget) {
  const std::string scenario =
      std::string(FLEXKIN_SOURCE_DIR) + "/examples/robot_spatial_limits.json";
  ASSERT_EQ(Robot("'" + scenario + "' -o " + Path("t.json")), 0);
  const json t = json::parse(ReadFile(Path("t.json")));
  ASSERT_EQ(t["steps"].size(), 120u);
  EXPECT_EQ(t["summary"]["unreached"], 0);
  int joint_space = 0, limited = 0;
  for (const json& step : t["steps"]) {
    EXPECT_TRUE(step["reached"].get<bool>());
    EXPECT_LE(step["ee_error"].get<double>(), 2.1e-11);  // 2e-10 of a 0.1 m link
    for (const json& bend : step["joint_angles"]) EXPECT_LE(bend.get<double>(), 0.25 + 1e-12);
    joint_space += step["joint_space"].get<bool>() ? 1 : 0;
    limited += step["limited"].get<bool>() ? 1 : 0;
  }
  EXPECT_GT(joint_space, 20);
  EXPECT_GT(limited, 20);
}

TEST_F(RobotCliTest, ExampleScenarioGivesATrajectoryAndAJointCsv) {
  const std::string scenario =
      std::string(FLEXKIN_SOURCE_DIR) + "/examples/robot_planar_8link.json";
  ASSERT_EQ(Robot("'" + scenario + "' -o " + Path("t.json") + " --csv " + Path("j.csv")), 0);
  const json t = json::parse(ReadFile(Path("t.json")));
  EXPECT_EQ(t["format"], "flexkin-robot-trajectory");
  ASSERT_EQ(t["steps"].size(), 200u);
  EXPECT_EQ(t["summary"]["unreached"], 0);
  for (const json& step : t["steps"]) {
    EXPECT_TRUE(step["reached"].get<bool>());
    EXPECT_LE(step["ee_error"].get<double>(), 2.1e-10);
    const json& p = step["points"];
    ASSERT_EQ(p.size(), 9u);
    EXPECT_EQ(p[0][0].get<double>(), 0.0);  // the base, bolted at the origin
    EXPECT_EQ(p[0][1].get<double>(), 0.0);
    for (int k = 1; k < 9; ++k) {
      const double l = std::hypot(p[k][0].get<double>() - p[k - 1][0].get<double>(),
                                  p[k][1].get<double>() - p[k - 1][1].get<double>());
      EXPECT_NEAR(l, 0.07, 1e-15);
    }
    EXPECT_NEAR(p[8][0].get<double>(), step["target"][0].get<double>(), 2.1e-10);
    for (const json& a : step["joint_angles"]) EXPECT_LE(std::abs(a.get<double>()), 1.2 + 1e-12);
  }
  // The CSV: a header, the initial angles (step 0), then one row per step, as in the JSON.
  std::istringstream csv(ReadFile(Path("j.csv")));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "step,joint_0,joint_1,joint_2,joint_3,joint_4,joint_5,joint_6,joint_7");
  int rows = 0;
  while (std::getline(csv, line)) {
    if (rows == 150) {
      std::istringstream cells(line);
      std::string cell;
      std::getline(cells, cell, ',');
      EXPECT_EQ(cell, "150");
      for (int j = 0; j < 8; ++j) {
        std::getline(cells, cell, ',');
        EXPECT_EQ(std::stod(cell), t["steps"][149]["joint_angles"][j].get<double>());
      }
    }
    ++rows;
  }
  EXPECT_EQ(rows, 201);
}

TEST_F(RobotCliTest, SpatialUnreachableTargetIsWrittenAndReported) {
  Write("s.json", R"({"arm": {"dim": 3, "links": 6, "link_length": 1, "initial_angles": 0.2,
    "joint_limits": {"max_bend": 0.5}},
    "path": {"type": "points", "points": [[4.5, 3.2, 0.3], [9, 0, 0]]},
    "solver": {"tolerance": 1e-11}})");
  std::string err;
  EXPECT_EQ(Robot(Path("s.json") + " -o " + Path("t.json") + " --method fixed_point", &err), 3);
  EXPECT_NE(err.find("1 of 2 targets were not reached"), std::string::npos) << err;
  const json t = json::parse(ReadFile(Path("t.json")));
  EXPECT_EQ(t["method"], "fixed_point");
  EXPECT_TRUE(t["steps"][0]["reached"].get<bool>());
  EXPECT_FALSE(t["steps"][1]["reached"].get<bool>());
  EXPECT_TRUE(t["steps"][1]["stretched"].get<bool>());
  EXPECT_NEAR(t["steps"][1]["ee_error"].get<double>(), 3.0, 1e-12);
  EXPECT_EQ(t["steps"][1]["joint_quaternions"].size(), 6u);
}

TEST_F(RobotCliTest, BadScenariosNameTheFieldAndWriteNothing) {
  const std::pair<const char*, const char*> cases[] = {
      {R"({"arm": {"links": 3, "link_length": -1}, "path": {"type": "line", "to": [1, 1], "steps": 3}})",
       "/arm/link_length: value -1"},
      {R"({"arm": {"links": 3, "link_lenght": 1}, "path": {"type": "line", "to": [1, 1], "steps": 3}})",
       "did you mean \"link_length\""},
      {R"({"arm": {"links": 2, "link_length": 1, "joint_limits": {"min": 0.1, "max": 0.2}},
           "path": {"type": "line", "to": [1, 1], "steps": 3}})",
       "/arm/initial_angles/0"},
      {R"({"arm": {"links": 2, "link_length": 1}, "path": {"type": "points", "points": [[1, "x"]]}})",
       "/path/points/0/1"},
      {R"({"arm": {"links": 2, "link_length": 1}, "path": {"type": "spiral"}})", "/path/type"},
      {R"({"arm": {"links": 2, "link_length": 1}, "path": {"type": "line", "to": [1, 1], "steps": 2},
           "solver": {"method": "pinv"}})",
       "/solver/method"},
      {R"({"arm": {"links": 2, "link_length": 1, "dim": 3, "joint_limits": {"max_bend": 4}},
           "path": {"type": "line", "to": [1, 1, 1], "steps": 2}})",
       "/arm/joint_limits/max_bend/0"},
      {R"({"arm": {"links": 2, "link_length": 1}})", "/path: missing"},
  };
  for (const auto& [text, expected] : cases) {
    Write("bad.json", text);
    std::string err;
    EXPECT_EQ(Robot(Path("bad.json") + " -o " + Path("t.json") + " --csv " + Path("j.csv"), &err),
              1)
        << text;
    EXPECT_NE(err.find(expected), std::string::npos) << err;
    EXPECT_FALSE(std::filesystem::exists(Path("t.json")));
    EXPECT_FALSE(std::filesystem::exists(Path("j.csv")));
  }
  // A missing output directory is found before anything is written.
  Write(
      "ok.json",
      R"({"arm": {"links": 2, "link_length": 1}, "path": {"type": "line", "to": [1, 1], "steps": 2}})");
  EXPECT_EQ(Robot(Path("ok.json") + " -o " + Path("t.json") + " --csv " + Path("no/j.csv")), 4);
  EXPECT_FALSE(std::filesystem::exists(Path("t.json")));
}

}  // namespace

namespace {

// A scenario that points at a URDF next to it (a relative path): a 3-link planar arm.
TEST_F(RobotCliTest, ScenarioWithAUrdfArm) {
  Write(
      "arm.urdf",
      R"(<robot name="three"><link name="b"/><link name="l1"/><link name="l2"/><link name="l3"/><link name="t"/>
    <joint name="j0" type="continuous"><parent link="b"/><child link="l1"/><axis xyz="0 0 1"/></joint>
    <joint name="j1" type="continuous"><parent link="l1"/><child link="l2"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/></joint>
    <joint name="j2" type="continuous"><parent link="l2"/><child link="l3"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/></joint>
    <joint name="tj" type="fixed"><parent link="l3"/><child link="t"/><origin xyz="1 0 0"/></joint></robot>)");
  Write("s.json", R"({"urdf": "arm.urdf", "base_link": "b", "tip_link": "t",
    "path": {"type": "points", "points": [[2.5, 0.5], [2.0, 1.0]]}})");
  ASSERT_EQ(Robot(Path("s.json") + " -o " + Path("t.json")), 0);
  const json t = json::parse(ReadFile(Path("t.json")));
  EXPECT_EQ(t["dim"], 2);
  EXPECT_EQ(t["link_lengths"], json({1.0, 1.0, 1.0}));
  ASSERT_EQ(t["steps"].size(), 2u);
  const json& ee = t["steps"][1]["points"][3];
  EXPECT_NEAR(ee[0].get<double>(), 2.0, 1e-9);
  EXPECT_NEAR(ee[1].get<double>(), 1.0, 1e-9);
  // A missing tip link and a missing file: named, nothing written.
  std::filesystem::remove(Path("t.json"));
  Write(
      "bad.json",
      R"({"urdf": "arm.urdf", "tip_link": "hand", "path": {"type": "points", "points": [[2, 1]]}})");
  std::string err;
  EXPECT_EQ(Robot(Path("bad.json") + " -o " + Path("t.json"), &err), 1);
  EXPECT_NE(err.find("/tip_link"), std::string::npos) << err;
  EXPECT_NE(err.find("\"hand\""), std::string::npos) << err;
  Write("gone.json", R"({"urdf": "nowhere.urdf", "path": {"type": "points", "points": [[2, 1]]}})");
  EXPECT_EQ(Robot(Path("gone.json") + " -o " + Path("t.json"), &err), 4);
  EXPECT_NE(err.find("nowhere.urdf"), std::string::npos) << err;
  EXPECT_FALSE(std::filesystem::exists(Path("t.json")));
}

// The joint CSV names its columns by the URDF's joint names (the arm of "arm" has none: joint_i,
// as in ExampleScenarioGivesATrajectoryAndAJointCsv); a name with a comma or a quote is quoted as
// CSV quotes it. Before, the header was "step,joint_0,joint_1,..." whatever the model.
TEST_F(RobotCliTest, JointCsvColumnsAreTheUrdfsJointNames) {
  const std::string scenario =
      std::string(FLEXKIN_SOURCE_DIR) + "/examples/robot_universal_snake.json";
  ASSERT_EQ(Robot("'" + scenario + "' -o " + Path("t.json") + " --csv " + Path("j.csv") + " -q"),
            0);
  std::string header = ReadFile(Path("j.csv"));
  header.resize(header.find('\n'));
  std::string expected = "step";
  for (int m = 0; m < 8; ++m) {
    expected += ",pitch_" + std::to_string(m) + ",yaw_" + std::to_string(m);
  }
  EXPECT_EQ(header, expected);

  Write("arm.urdf", R"(<robot name="two"><link name="b"/><link name="l1"/><link name="l2"/>
    <link name="t"/>
    <joint name="shoulder" type="continuous"><parent link="b"/><child link="l1"/>
      <axis xyz="0 0 1"/></joint>
    <joint name="elbow &quot;1&quot;, left" type="continuous"><parent link="l1"/>
      <child link="l2"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/></joint>
    <joint name="tool" type="fixed"><parent link="l2"/><child link="t"/><origin xyz="1 0 0"/>
    </joint></robot>)");
  Write("s.json", R"({"urdf": "arm.urdf", "path": {"type": "points", "points": [[1.5, 0.5]]}})");
  ASSERT_EQ(Robot(Path("s.json") + " -o " + Path("t.json") + " --csv " + Path("j.csv") + " -q"), 0);
  const std::string csv = ReadFile(Path("j.csv"));
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "step,shoulder,\"elbow \"\"1\"\", left\"");
}

// Method fixed_point on a URDF snake, where its iteration does not contract: the user is told
// before the run what the method is and where it fails, each stalled step stops after a few
// thousand sweeps instead of 100000 (before: 21 of 50 unreached, 2.1 million sweeps, 5.8 s), and
// the unreached targets are reported with exit status 3. Newton reaches every target.
TEST_F(RobotCliTest, FixedPointOnAUrdfSnakeFailsFastAndSaysSo) {
  const std::string scenario = std::string(FLEXKIN_SOURCE_DIR) + "/examples/robot_snake_urdf.json";
  std::string err;
  ASSERT_EQ(Robot("'" + scenario + "' -o " + Path("t.json") + " --method fixed_point -q", &err), 3)
      << err;
  const size_t note = err.find("flexkin: note: method fixed_point is the predecessors' baseline");
  const size_t warning = err.find("targets were not reached (largest end-effector error ");
  EXPECT_NE(note, std::string::npos) << err;
  EXPECT_NE(err.find("the step stops unreached; method newton (the default) is the one to use"),
            std::string::npos)
      << err;
  ASSERT_NE(warning, std::string::npos) << err;
  EXPECT_LT(note, warning);
  EXPECT_NE(err.find("method fixed_point does not converge on every arm: try --method newton"),
            std::string::npos)
      << err;
  const json t = json::parse(ReadFile(Path("t.json")));
  const int unreached = t["summary"]["unreached"].get<int>();
  EXPECT_GT(unreached, 0);
  EXPECT_NE(err.find(std::to_string(unreached) + " of 50 targets"), std::string::npos) << err;
  EXPECT_LE(t["summary"]["max_iterations"].get<int>(), 10000);
  EXPECT_LT(t["summary"]["total_sweeps"].get<int64_t>(), 100000);
  for (const json& step : t["steps"]) {
    if (step["reached"].get<bool>()) continue;
    // Stopped at the end of a window of 1000 sweeps that did not halve the residual.
    EXPECT_EQ(step["iterations"].get<int>() % 1000, 0) << step["step"];
  }
  ASSERT_EQ(Robot("'" + scenario + "' -o " + Path("t.json") + " -q", &err), 0) << err;
  EXPECT_EQ(err.find("fixed_point"), std::string::npos) << err;
}

// `flexkin validate` recognises a robot scenario by its keys and checks it with the robot reader:
// ok with a summary and the estimated sizes of the outputs, or every problem with its JSON
// pointer and exit 1. Chain scenarios are validated as before.
TEST_F(RobotCliTest, ValidateRecognisesRobotScenarios) {
  const std::string examples = std::string(FLEXKIN_SOURCE_DIR) + "/examples/";
  for (const char* name : {"robot_planar_8link.json", "robot_snake_urdf.json"}) {
    const flexkin::test_util::CliResult r =
        flexkin::test_util::RunCli(kCli, dir_, "validate '" + examples + name + "'");
    EXPECT_EQ(r.exit_code, 0) << name << ": " << r.out << r.err;
    EXPECT_EQ(r.out.rfind("ok: robot, ", 0), 0u) << r.out;
    EXPECT_NE(r.out.find("\noutput: "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("trajectory about "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("--csv about "), std::string::npos) << r.out;
  }
  const flexkin::test_util::CliResult planar =
      flexkin::test_util::RunCli(kCli, dir_, "validate '" + examples + "robot_planar_8link.json'");
  EXPECT_NE(planar.out.find("2D, 8 links, revolute joints"), std::string::npos) << planar.out;
  EXPECT_NE(planar.out.find("200 targets"), std::string::npos) << planar.out;
  EXPECT_NE(planar.out.find("201 states"), std::string::npos) << planar.out;

  // Two problems, both listed with their pointers; nothing else is printed.
  Write("bad.json", R"({"format": "flexkin-robot",
    "arm": {"dim": 2, "links": 3, "link_length": -1, "base": [0, 0], "base_direction": [1, 0]},
    "path": {"type": "points", "points": [[1, 0]]}, "solver": {"tolerence": 1e-9}})");
  const flexkin::test_util::CliResult bad =
      flexkin::test_util::RunCli(kCli, dir_, "validate bad.json");
  EXPECT_EQ(bad.exit_code, 1) << bad.out << bad.err;
  EXPECT_NE(bad.out.find("bad.json: /arm/link_length"), std::string::npos) << bad.out;
  EXPECT_NE(bad.out.find("/solver/tolerence"), std::string::npos) << bad.out;
  EXPECT_EQ(bad.out.find("ok:"), std::string::npos) << bad.out;

  const flexkin::test_util::CliResult chain =
      flexkin::test_util::RunCli(kCli, dir_, "validate '" + examples + "fig12_spatial_curve.json'");
  EXPECT_EQ(chain.exit_code, 0) << chain.out << chain.err;
  EXPECT_EQ(chain.out.find("ok: robot"), std::string::npos) << chain.out;
}

// The streamed command writes the joint CSV of the whole-trajectory writer, with --csv.
TEST_F(RobotCliTest, StreamedCsvIsTheLibrarysJointCsv) {
  const std::string scenario =
      std::string(FLEXKIN_SOURCE_DIR) + "/examples/robot_spatial_limits.json";
  ASSERT_EQ(Robot("'" + scenario + "' -o " + Path("t.json") + " --csv " + Path("j.csv")), 0);
  const flexkin::RobotScenario s = flexkin::LoadRobotScenarioFile(scenario);
  const flexkin::ArmTrajectory t = flexkin::TrackPath(s.model, s.path, s.options);
  std::ostringstream csv, trajectory;
  flexkin::WriteRobotJointsCsv(s, t, csv);
  EXPECT_EQ(ReadFile(Path("j.csv")), csv.str());
  flexkin::WriteRobotTrajectoryJson(s, t, trajectory);
  json expected = json::parse(trajectory.str()), actual = json::parse(ReadFile(Path("t.json")));
  expected["summary"].erase("seconds");
  actual["summary"].erase("seconds");
  EXPECT_EQ(actual, expected);
}

}  // namespace
