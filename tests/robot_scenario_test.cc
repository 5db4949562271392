// Tests of robot scenario files (include/flexkin/robot_scenario.h): the examples load with their
// documented sizes, every problem is listed with its JSON pointer and the first one is thrown,
// numbers are read as in scenario files, URDF arms go through the injected loader (none: a clear
// error), the schema lists the keys the reader accepts, and the writers' files are consistent.
#include "flexkin/robot_scenario.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "flexkin/arm.h"
#include "flexkin/error.h"
#include "flexkin/scenario.h"
#include "flexkin/urdf.h"
#include "io/json_file.h"  // ReadJsonFile, ReadTextFile
#include "schema_test_util.h"
#include "test_util.h"

namespace flexkin {
namespace {

using nlohmann::json;

std::string Example(const std::string& name) {
  return std::string(FLEXKIN_SOURCE_DIR) + "/examples/" + name;
}

std::vector<std::string> Fields(const Problems& problems) {
  std::vector<std::string> fields;
  for (const Problem& p : problems) fields.push_back(p.field);
  return fields;
}

std::string AllText(const Problems& problems) {
  std::string text;
  for (const Problem& p : problems) text += p.Text() + "\n";
  return text;
}

// A fresh directory, removed with its files at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::string pattern =
        (std::filesystem::temp_directory_path() / "flexkin_robot_scenario_XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string operator/(const std::string& name) const { return path_ + "/" + name; }
  const std::string& path() const { return path_; }
  void Write(const std::string& name, const std::string& text) const {
    std::ofstream(*this / name) << text;
  }

 private:
  std::string path_;
};

TEST(RobotScenarioExampleTest, EveryExampleLoadsAndValidates) {
  const RobotScenarioOptions urdf = UrdfRobotScenarioOptions();
  int examples = 0;
  for (const auto& entry : std::filesystem::directory_iterator(Example(""))) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("robot_", 0) != 0 || entry.path().extension() != ".json") continue;
    ++examples;
    const Problems problems = ValidateRobotScenarioFile(entry.path().string(), urdf);
    EXPECT_TRUE(problems.empty()) << name << ": " << AllText(problems);
    const RobotScenario s = LoadRobotScenarioFile(entry.path().string(), urdf);
    EXPECT_FALSE(s.name.empty()) << name;
    EXPECT_TRUE(s.model.Validate().empty()) << name;
    EXPECT_GE(s.path.rows(), 1) << name;
    EXPECT_EQ(s.path.cols(), s.model.dim) << name;
  }
  EXPECT_GE(examples, 5);
}

TEST(RobotScenarioExampleTest, Planar8LinkHasTheDocumentedValues) {
  const RobotScenario s = LoadRobotScenarioFile(Example("robot_planar_8link.json"));
  EXPECT_EQ(s.name, "planar 8-link arm, 70 mm links, end effector on a circle");
  EXPECT_EQ(s.model.dim, 2);
  EXPECT_EQ(s.model.link_lengths, Eigen::VectorXd::Constant(8, 0.07));
  EXPECT_EQ(s.model.base, Eigen::Vector2d(0, 0));
  EXPECT_EQ(s.model.base_direction, Eigen::Vector2d(0, 1));
  EXPECT_EQ(s.model.joint_min, Eigen::VectorXd::Constant(8, -1.2));
  EXPECT_EQ(s.model.joint_max, Eigen::VectorXd::Constant(8, 1.2));
  EXPECT_EQ(s.model.initial.angle[7], 0.3);
  EXPECT_EQ(s.model.initial.azimuth.size(), 0);
  EXPECT_EQ(s.options.method, FixedBaseMethod::kNewton);
  EXPECT_EQ(s.options.tolerance, 1e-10);
  // The circle through the end effector's initial position about the center, 200 steps, the
  // last one back at the start.
  ASSERT_EQ(s.path.rows(), 200);
  const Eigen::Vector2d center(-0.2, 0.42);
  const Eigen::VectorXd ee = ForwardKinematics(s.model, s.model.initial).row(8).transpose();
  for (int i = 0; i < 200; ++i) {
    EXPECT_NEAR((s.path.row(i).transpose() - center).norm(), (ee - center).norm(), 1e-15);
  }
  EXPECT_NEAR((s.path.row(199).transpose() - ee).norm(), 0.0, 1e-15);
}

// The URDF arm is read by the loader it is given; the example's snake has 16 revolute joints.
TEST(RobotScenarioExampleTest, UrdfExampleNeedsTheLoader) {
  const RobotScenario s =
      LoadRobotScenarioFile(Example("robot_snake_urdf.json"), UrdfRobotScenarioOptions());
  EXPECT_EQ(s.model.dim, 3);
  EXPECT_EQ(s.model.num_links(), 16);
  EXPECT_TRUE(s.model.has_axes());
  EXPECT_EQ(s.path.rows(), 50);
  // Without one: a clear InputError naming the field, and the same as the one problem listed.
  try {
    LoadRobotScenarioFile(Example("robot_snake_urdf.json"));
    FAIL() << "read a URDF arm without a loader";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "/urdf");
    EXPECT_NE(e.message().find("no URDF loader"), std::string::npos) << e.what();
    EXPECT_NE(e.message().find("UrdfRobotScenarioOptions"), std::string::npos) << e.what();
    const Problems problems = ValidateRobotScenarioFile(Example("robot_snake_urdf.json"));
    ASSERT_EQ(problems.size(), 1u) << AllText(problems);
    EXPECT_EQ(problems[0].Text(), e.problem().Text());
  }
}

// The injected loader gets the URDF path (relative to the scenario file's directory, or to
// options.directory) and the chain's links, and its errors are placed at the scenario's keys.
TEST(RobotScenarioUrdfTest, LoaderGetsThePathAndTheChainAndItsErrorsArePlaced) {
  TempDir dir;
  dir.Write("s.json", R"({"urdf": "arms/a.urdf", "base_link": "b", "tip_link": "t",
                          "path": {"type": "points", "points": [[1, 1]]}})");
  std::string seen_path;
  UrdfChain seen_chain;
  RobotScenarioOptions options;
  options.urdf_loader = [&](const std::string& path, const UrdfChain& chain) {
    seen_path = path;
    seen_chain = chain;
    return StraightArm(2, 3, 1.0);
  };
  const RobotScenario s = LoadRobotScenarioFile(dir / "s.json", options);
  EXPECT_EQ(seen_path, dir / "arms/a.urdf");
  EXPECT_EQ(seen_chain.base_link, "b");
  EXPECT_EQ(seen_chain.tip_link, "t");
  EXPECT_EQ(s.model.num_links(), 3);
  // From text: relative to options.directory ("" = the working directory).
  ParseRobotScenarioText(ReadTextFile(dir / "s.json"), options);
  EXPECT_EQ(seen_path, "arms/a.urdf");
  options.directory = "/somewhere";
  ParseRobotScenarioText(ReadTextFile(dir / "s.json"), options);
  EXPECT_EQ(seen_path, "/somewhere/arms/a.urdf");
  options.directory.clear();

  options.urdf_loader = [](const std::string&, const UrdfChain&) -> ArmModel {
    throw InputError("tip_link", "no link \"t\" in the URDF");
  };
  const Problems tip = ValidateRobotScenarioFile(dir / "s.json", options);
  ASSERT_EQ(tip.size(), 1u);
  EXPECT_EQ(tip[0].Text(), "/tip_link: no link \"t\" in the URDF");
  options.urdf_loader = [](const std::string&, const UrdfChain&) -> ArmModel {
    throw InputError("joint \"j2\"", "is prismatic; expected revolute or continuous");
  };
  try {
    LoadRobotScenarioFile(dir / "s.json", options);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "/urdf");
    EXPECT_EQ(e.message(), dir / "arms/a.urdf" +
                               ": joint \"j2\": is prismatic; expected revolute or continuous");
  }
  // A URDF file that cannot be read is a file error, as everywhere.
  EXPECT_THROW(LoadRobotScenarioFile(dir / "s.json", UrdfRobotScenarioOptions()),
               std::system_error);
}

// Every problem of a document, each at its JSON pointer; loading throws the first.
TEST(RobotScenarioValidateTest, ListsEveryProblemWithItsPointer) {
  const std::string text = R"({
    "format": "flexkin-robt", "colour": 1,
    "arm": {"dim": 2, "links": 3.5, "link_lenght": 1, "base": [0, "0"], "initial_angles": [0, 0]},
    "path": {"type": "line", "to": [1, 2, 3], "steps": 0},
    "solver": {"method": "fixed-point", "tolerance": -1, "restarts": 1.5}})";
  const Problems problems = ValidateRobotScenarioText(text);
  const std::vector<std::string> fields = Fields(problems);
  for (const char* expected :
       {"/colour", "/format", "/arm/link_lenght", "/arm/links", "/arm/link_length", "/arm/base/1",
        "/path/to", "/path/steps", "/solver/method", "/solver/tolerance", "/solver/restarts"}) {
    EXPECT_NE(std::find(fields.begin(), fields.end(), expected), fields.end())
        << expected << " not in\n"
        << AllText(problems);
  }
  const std::string all = AllText(problems);
  EXPECT_NE(all.find("/arm/link_lenght: unknown key \"link_lenght\"; valid keys here are"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("(did you mean \"link_length\"?)"), std::string::npos) << all;
  EXPECT_NE(all.find("/solver/method: unknown fixed-base method \"fixed-point\""),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("(did you mean \"fixed_point\"?)"), std::string::npos) << all;
  EXPECT_NE(all.find("/path/to: value [1,2,3] has 3 coordinates; expected an array of 2 numbers "
                     "(the arm is 2D)"),
            std::string::npos)
      << all;
  try {
    ParseRobotScenarioText(text);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem().Text(), problems.front().Text());
  }
}

// Numbers are read as in scenario files: an integer may be written 5.0 but not 5.5, a number
// given as a string is refused, and the messages have the same shape.
TEST(RobotScenarioValidateTest, NumbersAreReadAsInScenarioFiles) {
  const RobotScenario s = ParseRobotScenarioText(R"({"arm": {"dim": 2.0, "links": 5.0,
    "link_length": 1}, "path": {"type": "line", "to": [2, 1], "steps": 4.0},
    "solver": {"max_iterations": 20.0, "restarts": 0.0}})");
  EXPECT_EQ(s.model.num_links(), 5);
  EXPECT_EQ(s.path.rows(), 4);
  EXPECT_EQ(s.options.max_iterations, 20);
  EXPECT_EQ(s.options.restarts, 0);

  const auto robot_problem = [](const std::string& arm) {
    const Problems p = ValidateRobotScenarioText(
        R"({"arm": )" + arm + R"(, "path": {"type": "points", "points": [[1, 1]]}})");
    return p.empty() ? Problem() : p.front();
  };
  const auto scenario_problem = [](const std::string& links) {
    const Problems p = ValidateScenarioText(R"({"curve": {"shape": "line", "links": )" + links +
                                            R"(, "link_length": 1}, "leader": {"pull": [1, 0]}})");
    return p.empty() ? Problem() : p.front();
  };
  for (const char* links : {"5.5", "\"5\"", "0", "-1", "true", "1e300"}) {
    const Problem robot =
        robot_problem(R"({"links": )" + std::string(links) + R"(, "link_length": 1})");
    const Problem scenario = scenario_problem(links);
    EXPECT_EQ(robot.field, "/arm/links") << links;
    EXPECT_EQ(scenario.field, "/curve/links") << links;
    // The same message up to the range (the arms' and the curves' bounds differ).
    const auto shape = [](std::string m) { return m.substr(0, m.find(" from 1 to ")); };
    EXPECT_EQ(shape(robot.message), shape(scenario.message)) << links;
    EXPECT_EQ(robot.value, scenario.value) << links;
  }
  EXPECT_EQ(robot_problem(R"({"links": 5.5, "link_length": 1})").message,
            "value 5.5 is not valid; expected an integer from 1 to 1048576");
  EXPECT_EQ(robot_problem(R"({"links": 2, "link_length": "1"})").Text(),
            "/arm/link_length: value \"1\" (a string) is not valid; expected a finite number > 0");
  EXPECT_EQ(robot_problem(R"({"links": 2, "link_length": 1, "initial_angles": [0.1]})").Text(),
            "/arm/initial_angles: value [0.1] has 1 number; expected a finite number or an array "
            "of 2 numbers (one per joint)");
}

struct BadCase {
  const char* what;
  const char* text;     // the scenario
  const char* pointer;  // expected field of the first problem
  const char* message;  // expected in its message
};

#define ARM R"("arm": {"links": 2, "link_length": 1})"
#define PATH R"("path": {"type": "line", "to": [1, 1], "steps": 2})"

const BadCase kBadCases[] = {
    {"root not an object", "[1]", "", "(an array) is not valid; expected an object"},
    {"not JSON", "{\"arm\": ", "", ": invalid JSON: "},
    {"missing path", "{" ARM "}", "/path", "missing; expected an object"},
    {"missing arm", "{" PATH "}", "/arm", "missing; expected an object"},
    {"wrong format", "{" ARM "," PATH R"(, "format": "flexkin-result"})", "/format",
     R"(value "flexkin-result" is not valid; expected "flexkin-robot")"},
    {"arm and urdf", R"({"urdf": "a.urdf",)" ARM "," PATH "}", "/arm", "not both"},
    {"base_link without urdf", "{" ARM "," PATH R"(, "base_link": "b"})", "/base_link",
     "belongs to a URDF arm"},
    {"empty urdf", R"({"urdf": "",)" PATH "}", "/urdf", "expected a URDF file name"},
    {"link_length and link_lengths",
     R"({"arm": {"link_lengths": [1, 2], "link_length": 1},)" PATH "}", "/arm/link_length",
     "not valid with \"link_lengths\""},
    {"links differ from link_lengths", R"({"arm": {"link_lengths": [1, 2], "links": 3},)" PATH "}",
     "/arm/links", "value 3 differs from the 2 link_lengths"},
    {"negative link length", R"({"arm": {"link_lengths": [1, -2]},)" PATH "}",
     "/arm/link_lengths/1", "value -2 is not valid; expected a finite number > 0"},
    {"no link lengths", R"({"arm": {"link_lengths": []},)" PATH "}", "/arm/link_lengths",
     "has 0 numbers; expected an array of at least 1 number > 0"},
    {"dim 4", R"({"arm": {"dim": 4, "links": 2, "link_length": 1},)" PATH "}", "/arm/dim",
     "value 4 is not valid; expected an integer from 2 to 3"},
    {"zero base direction",
     R"({"arm": {"links": 2, "link_length": 1, "base_direction": [0, 0]},)" PATH "}",
     "/arm/base_direction", "is zero"},
    {"limits outside pi",
     R"({"arm": {"links": 2, "link_length": 1, "joint_limits": {"min": -4, "max": 1}},)" PATH "}",
     "/arm/joint_limits", "joint 0: limits [-4, 1] rad are not valid"},
    {"max_bend on a planar arm",
     R"({"arm": {"links": 2, "link_length": 1, "joint_limits": {"max_bend": 1}},)" PATH "}",
     "/arm/joint_limits/max_bend", "unknown key"},
    {"initial angle outside the limits",
     R"({"arm": {"links": 2, "link_length": 1, "joint_limits": {"min": 0.1, "max": 0.2}},)" PATH
     "}",
     "/arm/initial_angles/0", "outside the joint's limits"},
    {"bend limit above pi",
     R"({"arm": {"dim": 3, "links": 2, "link_length": 1, "joint_limits": {"max_bend": [1, 4]}},
         "path": {"type": "line", "to": [1, 1, 1], "steps": 2}})",
     "/arm/joint_limits/max_bend/1", "expected 0 < max_bend <= pi"},
    {"azimuths of a planar arm",
     R"({"arm": {"links": 2, "link_length": 1, "initial_azimuths": 0},)" PATH "}",
     "/arm/initial_azimuths", "planar arms (dim 2) have no azimuths"},
    {"point of the wrong size",
     R"({)" ARM R"(, "path": {"type": "points", "points": [[1, 1], [1, 1, 1]]}})", "/path/points/1",
     "expected an array of 2 numbers (the arm is 2D)"},
    {"no points", R"({)" ARM R"(, "path": {"type": "points", "points": []}})", "/path/points",
     "has 0 points; expected an array of at least 1 point"},
    {"path type", R"({)" ARM R"(, "path": {"type": "spiral"}})", "/path/type",
     R"(expected one of "points", "line" or "circle")"},
    {"path without type", R"({)" ARM R"(, "path": {"points": [[1, 1]]}})", "/path/type",
     "missing; expected one of"},
    {"line key on points",
     R"({)" ARM R"(, "path": {"type": "points", "points": [[1, 1]], "steps": 2}})", "/path/steps",
     "unknown key"},
    {"steps zero", R"({)" ARM R"(, "path": {"type": "line", "to": [1, 1], "steps": 0}})",
     "/path/steps", "value 0 is not valid; expected an integer >= 1"},
    {"circle about the end effector",
     R"({)" ARM R"(, "path": {"type": "circle", "center": [2, 0], "steps": 4}})", "/path/center",
     "the circle needs a radius"},
    {"normal of a planar circle",
     R"({)" ARM
     R"(, "path": {"type": "circle", "center": [1, 0], "steps": 4, "normal": [0, 0, 1]}})",
     "/path/normal", "only valid for spatial arms"},
    {"normal along the radius",
     R"({"arm": {"dim": 3, "links": 2, "link_length": 1},
         "path": {"type": "circle", "center": [1, 0, 0], "steps": 4, "normal": [1, 0, 0]}})",
     "/path/normal", "along the radius"},
    {"solver method", "{" ARM "," PATH R"(, "solver": {"method": "pinv"}})", "/solver/method",
     R"(unknown fixed-base method "pinv"; expected "newton" or "fixed_point")"},
    {"tolerance 1", "{" ARM "," PATH R"(, "solver": {"tolerance": 1}})", "/solver/tolerance",
     "value 1 is not valid; expected 0 < tolerance < 1"},
    {"edge margin", "{" ARM "," PATH R"(, "solver": {"edge_margin": 0.5}})", "/solver/edge_margin",
     "expected 0 <= edge_margin < 0.5"},
    {"restarts negative", "{" ARM "," PATH R"(, "solver": {"restarts": -1}})", "/solver/restarts",
     "expected an integer >= 0"},
};

class BadRobotScenarioTest : public testing::TestWithParam<BadCase> {};

TEST_P(BadRobotScenarioTest, FirstProblemNamesTheField) {
  const BadCase& c = GetParam();
  const Problems problems = ValidateRobotScenarioText(c.text);
  ASSERT_FALSE(problems.empty()) << "accepted: " << c.text;
  EXPECT_EQ(problems.front().field, c.pointer) << AllText(problems);
  EXPECT_NE(problems.front().message.find(c.message), std::string::npos) << AllText(problems);
  try {
    ParseRobotScenarioText(c.text);
    FAIL() << "accepted: " << c.text;
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem().Text(), problems.front().Text());
  }
}

INSTANTIATE_TEST_SUITE_P(RobotScenario, BadRobotScenarioTest, testing::ValuesIn(kBadCases),
                         [](const testing::TestParamInfo<BadCase>& info) {
                           std::string name = info.param.what;
                           for (char& ch : name) ch = std::isalnum(ch) ? ch : '_';
                           return name;
                         });

// The keys the reader accepts at `pointer` of `doc`.
std::set<std::string> AcceptedKeys(const json& doc, const std::string& pointer) {
  return test_util::AcceptedKeys(
      doc, pointer, [](const std::string& text) { return ValidateRobotScenarioText(text); });
}
using test_util::SchemaKeys;

// docs/schema/robot.schema.json lists exactly the keys the reader accepts, everywhere.
TEST(RobotScenarioSchemaTest, SchemaAndReaderAcceptTheSameKeys) {
  const json schema =
      ReadJsonFile(std::string(FLEXKIN_SOURCE_DIR) + "/docs/schema/robot.schema.json");
  json doc = {{"arm", {{"links", 2}, {"link_length", 1}, {"joint_limits", json::object()}}},
              {"path", {{"type", "points"}, {"points", {{1, 1}}}}},
              {"solver", json::object()}};
  EXPECT_EQ(AcceptedKeys(doc, ""), SchemaKeys(schema));
  const json& arm = schema["properties"]["arm"];
  EXPECT_EQ(AcceptedKeys(doc, "/arm"), SchemaKeys(arm));
  EXPECT_EQ(AcceptedKeys(doc, "/solver"), SchemaKeys(schema["properties"]["solver"]));
  // Joint limits: min and max for planar arms, max_bend for spatial ones.
  std::set<std::string> limits = AcceptedKeys(doc, "/arm/joint_limits");
  doc["arm"]["dim"] = 3;
  doc["path"]["points"] = {{1, 1, 0}};
  for (const std::string& key : AcceptedKeys(doc, "/arm/joint_limits")) limits.insert(key);
  EXPECT_EQ(limits, SchemaKeys(arm["properties"]["joint_limits"]));
  // The path: one branch of the schema per type.
  for (const json& branch : schema["properties"]["path"]["oneOf"]) {
    const std::string type = branch["properties"]["type"]["const"];
    doc["path"] = {{"type", type}};
    EXPECT_EQ(AcceptedKeys(doc, "/path"), SchemaKeys(branch)) << type;
  }
}

// A spatial arm with revolute joints about axes (as from a URDF): joint angles, no azimuths.
ArmModel AxesArm() {
  ArmModel m = StraightArm(3, 4, 0.25);
  m.joint_axes.resize(4, 3);
  for (int j = 0; j < 4; ++j) {
    m.joint_axes.row(j) = j % 2 == 0 ? Eigen::RowVector3d::UnitY() : Eigen::RowVector3d::UnitZ();
  }
  m.initial.azimuth.resize(0);
  return m;
}

// Cells per line of a CSV text.
std::vector<size_t> CellsPerLine(const std::string& csv) {
  std::vector<size_t> cells;
  std::istringstream in(csv);
  std::string line;
  while (std::getline(in, line)) cells.push_back(std::count(line.begin(), line.end(), ',') + 1);
  return cells;
}

// The trajectory JSON has the documented keys and one step per line; the CSV one cell per column
// on every line, for planar, spherical and axis arms alike.
TEST(RobotTrajectoryWriterTest, JsonAndCsvAreConsistent) {
  RobotScenario planar;
  planar.model = StraightArm(2, 3, 1.0);
  planar.path = Points(2, 2);
  planar.path << 2.5, 1.0, 2.0, 1.5;
  planar.name = "planar";
  RobotScenario spherical;
  spherical.model = StraightArm(3, 3, 1.0);
  spherical.path = Points(1, 3);
  spherical.path << 2.5, 1.0, 0.5;
  RobotScenario axes;
  axes.model = AxesArm();
  axes.path = Points(1, 3);
  axes.path << 0.8, 0.2, 0.3;
  for (const RobotScenario* s : {&planar, &spherical, &axes}) {
    const ArmTrajectory t = TrackPath(s->model, s->path, s->options);
    std::ostringstream out;
    WriteRobotTrajectoryJson(*s, t, out);
    const std::string text = out.str();
    const json doc = json::parse(text);
    EXPECT_EQ(doc["format"], kRobotTrajectoryFormat);
    EXPECT_EQ(doc["version"], kRobotTrajectoryVersion);
    EXPECT_EQ(doc.contains("scenario"), !s->name.empty());
    EXPECT_EQ(doc["dim"], s->model.dim);
    EXPECT_EQ(doc["method"], "newton");
    ASSERT_EQ(doc["steps"].size(), static_cast<size_t>(s->path.rows()));
    EXPECT_EQ(doc["steps"][0]["step"], 1);
    EXPECT_EQ(doc["initial"]["points"].size(), static_cast<size_t>(s->model.num_links() + 1));
    EXPECT_EQ(doc["steps"][0].contains("joint_azimuths"), s->model.joint() == ArmJoint::kSpherical);
    EXPECT_EQ(doc["steps"][0].contains("joint_quaternions"), s->model.dim == 3);
    // One key per line, one step per line.
    EXPECT_EQ(static_cast<size_t>(std::count(text.begin(), text.end(), '\n')),
              doc.size() + doc["steps"].size() + 3);  // and "{", "]" and "}"

    std::ostringstream csv;
    WriteRobotJointsCsv(*s, t, csv);
    const std::vector<size_t> cells = CellsPerLine(csv.str());
    ASSERT_EQ(cells.size(), static_cast<size_t>(s->path.rows() + 2));  // header, step 0, steps
    const size_t columns =
        1 + s->model.num_links() * (s->model.joint() == ArmJoint::kSpherical ? 2 : 1);
    for (size_t line = 0; line < cells.size(); ++line) EXPECT_EQ(cells[line], columns) << line;
  }
  // A trajectory of another path is refused before anything is written.
  const ArmTrajectory t = TrackPath(planar.model, planar.path, planar.options);
  RobotScenario other = planar;
  other.path = planar.path.topRows(1);
  std::ostringstream out;
  EXPECT_THROW(WriteRobotTrajectoryJson(other, t, out), InputError);
  EXPECT_THROW(WriteRobotJointsCsv(other, t, out), InputError);
  EXPECT_EQ(out.str(), "");
}

// The path versions write whole files, and nothing where the directory is missing.
TEST(RobotTrajectoryWriterTest, FilesAreWrittenWholeOrNotAtAll) {
  TempDir dir;
  const RobotScenario s = LoadRobotScenarioFile(Example("robot_planar_8link.json"));
  const ArmTrajectory t = TrackPath(s.model, s.path, s.options);
  WriteRobotTrajectoryJson(s, t, dir / "t.json");
  WriteRobotJointsCsv(s, t, dir / "j.csv");
  std::ostringstream json_text, csv_text;
  WriteRobotTrajectoryJson(s, t, json_text);
  WriteRobotJointsCsv(s, t, csv_text);
  EXPECT_EQ(ReadTextFile(dir / "t.json"), json_text.str());
  EXPECT_EQ(ReadTextFile(dir / "j.csv"), csv_text.str());
  EXPECT_THROW(WriteRobotTrajectoryJson(s, t, dir / "no/t.json"), std::system_error);
  EXPECT_THROW(WriteRobotJointsCsv(s, t, dir / "no/j.csv"), std::system_error);
  EXPECT_FALSE(std::filesystem::exists(dir / "no"));
}

// TrackPath with a sink gives the numbers of the plain TrackPath, and the streaming writers
// (RobotTrajectoryWriter, RobotJointsCsvWriter) write what the whole-trajectory writers write: the
// same JSON value (same number of lines) and the same CSV text, for every example.
TEST(RobotTrajectoryStreamTest, StreamedFilesEqualTheWholeTrajectoryWritersForEveryExample) {
  int examples = 0;
  for (const auto& entry : std::filesystem::directory_iterator(Example(""))) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("robot_", 0) != 0 || entry.path().extension() != ".json") continue;
    ++examples;
    const std::string path = entry.path().string();
    SCOPED_TRACE(path);
    const RobotScenario s = LoadRobotScenarioFile(path, UrdfRobotScenarioOptions());
    TempDir dir;
    RobotTrajectoryWriter json_writer(s, dir / "t.json");
    RobotJointsCsvWriter csv_writer(s, dir / "j.csv");
    ArmStepFanOut both({&json_writer, &csv_writer});
    const ArmTrajectory streamed = TrackPath(s.model, s.path, s.options, &both);
    EXPECT_TRUE(streamed.steps.empty());
    EXPECT_EQ(streamed.num_steps, s.path.rows());
    EXPECT_FALSE(std::filesystem::exists(dir / "t.json"));  // until Commit
    json_writer.Commit(streamed);
    csv_writer.Commit(streamed);

    ArmTrajectory whole = TrackPath(s.model, s.path, s.options);
    ASSERT_EQ(whole.steps.size(), static_cast<size_t>(s.path.rows()));
    EXPECT_EQ(whole.num_steps, s.path.rows());
    // The same numbers with and without a sink; only the wall time differs.
    EXPECT_EQ(whole.max_ee_error, streamed.max_ee_error);
    EXPECT_EQ(whole.max_base_error, streamed.max_base_error);
    EXPECT_EQ(whole.unreached, streamed.unreached);
    EXPECT_EQ(whole.max_iterations, streamed.max_iterations);
    EXPECT_EQ(whole.total_sweeps, streamed.total_sweeps);
    EXPECT_EQ(whole.total_passes, streamed.total_passes);
    whole.seconds = streamed.seconds;
    std::ostringstream json_text, csv_text;
    WriteRobotTrajectoryJson(s, whole, json_text);
    WriteRobotJointsCsv(s, whole, csv_text);
    const std::string file = ReadTextFile(dir / "t.json");
    EXPECT_EQ(json::parse(file), json::parse(json_text.str()));
    EXPECT_EQ(ReadTextFile(dir / "j.csv"), csv_text.str());
    // One key per line and one step per line, as the whole-trajectory writer.
    const std::string text = json_text.str();
    EXPECT_EQ(std::count(file.begin(), file.end(), '\n'),
              std::count(text.begin(), text.end(), '\n'));
    // The path versions of the whole-trajectory writers write the same.
    WriteRobotTrajectoryJson(s, whole, dir / "w.json");
    EXPECT_EQ(ReadTextFile(dir / "w.json"), json_text.str());
  }
  EXPECT_GE(examples, 5);
}

}  // namespace
}  // namespace flexkin
