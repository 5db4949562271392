// Tests of scenario files: the paper's examples load with the documented sizes and run, every
// form of "curve" and "leader" maps to the right chain, targets and options, and every malformed
// document gives an InputError whose field is the JSON pointer of the problem.
#include "flexkin/scenario.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <system_error>
#include <vector>

#include "flexkin/colliders.h"
#include "flexkin/error.h"
#include "flexkin/run.h"
#include "io/json_file.h"      // ParseJsonText, ReadJsonFile
#include "io/scenario_json.h"  // ParseScenario, ValidateScenario of a parsed document
#include "schema_test_util.h"
#include "test_util.h"

namespace flexkin {
namespace {

using nlohmann::json;

std::string Example(const std::string& name) {
  return std::string(FLEXKIN_SOURCE_DIR) + "/examples/" + name;
}

// Sum and largest of the leader's step lengths, the first from the chain's leading end.
std::pair<double, double> StepLengths(const Scenario& s) {
  Eigen::VectorXd from = s.chain.points.row(0).transpose();
  double total = 0.0, longest = 0.0;
  for (Eigen::Index i = 0; i < s.leader_steps.rows(); ++i) {
    const double d = (s.leader_steps.row(i).transpose() - from).norm();
    total += d;
    longest = std::fmax(longest, d);
    from = s.leader_steps.row(i).transpose();
  }
  return {total, longest};
}

Scenario Parse(const std::string& text) { return ParseScenario(ParseJsonText(text)); }

TEST(ScenarioExampleTest, Fig07StraightLink) {
  const Scenario s = LoadScenarioFile(Example("fig07_straight_link.json"));
  ASSERT_EQ(s.chain.num_links(), 1);
  EXPECT_EQ(s.chain.points.row(0), Eigen::RowVector2d(0, 0));
  EXPECT_EQ(s.chain.points.row(1), Eigen::RowVector2d(0, 1));
  ASSERT_EQ(s.leader_steps.rows(), 500);
  EXPECT_EQ(s.leader_steps.row(499), Eigen::RowVector2d(-5, 0));
  EXPECT_NEAR(StepLengths(s).second, 0.01, 1e-15);
  EXPECT_EQ(s.options.method, Method::kTractrix);
}

TEST(ScenarioExampleTest, Fig06ParabolaSingleAndMultiStep) {
  const double component = 0.7 / std::sqrt(2.0);
  for (const auto& [file, steps] :
       {std::pair<std::string, int>{"fig06_parabola_single_step.json", 1},
        {"fig06_parabola_multi_step.json", 5}}) {
    SCOPED_TRACE(file);
    const Scenario s = LoadScenarioFile(Example(file));
    ASSERT_EQ(s.chain.num_links(), 20);
    EXPECT_EQ(s.chain.lengths, Eigen::VectorXd::Constant(20, 0.25));
    EXPECT_EQ(s.chain.points.row(0), Eigen::RowVector2d(0, 0));
    for (Eigen::Index i = 0; i <= 20; ++i) {
      EXPECT_NEAR(s.chain.points(i, 1), s.chain.points(i, 0) * s.chain.points(i, 0), 1e-14);
    }
    ASSERT_EQ(s.leader_steps.rows(), steps);
    // The 17-digit literal reads back as the double 0.7 / sqrt(2).
    EXPECT_EQ(s.leader_steps.row(steps - 1), Eigen::RowVector2d(component, component));
    EXPECT_NEAR(StepLengths(s).second, 0.7 / steps, 1e-15);
  }
}

TEST(ScenarioExampleTest, Fig10PlanarCurve) {
  const Scenario s = LoadScenarioFile(Example("fig10_planar_curve.json"));
  ASSERT_EQ(s.chain.dim(), 2);
  ASSERT_EQ(s.chain.num_links(), 80);
  EXPECT_EQ(s.chain.lengths, Eigen::VectorXd::Constant(80, 0.05));
  EXPECT_NEAR(s.chain.lengths.sum(), 4.0, 1e-13);
  EXPECT_EQ(s.leader_steps.rows(), 250);
  const auto [total, longest] = StepLengths(s);
  EXPECT_NEAR(total, 18.75, 1e-11);
  EXPECT_LE(longest, 0.075 * (1 + 1e-12));
}

TEST(ScenarioExampleTest, Fig12SpatialCurve) {
  const Scenario s = LoadScenarioFile(Example("fig12_spatial_curve.json"));
  ASSERT_EQ(s.chain.dim(), 3);
  ASSERT_EQ(s.chain.num_links(), 20);
  EXPECT_EQ(s.chain.lengths, Eigen::VectorXd::Constant(20, 1.5));
  EXPECT_EQ(s.leader_steps.rows(), 2650);
  const auto [total, longest] = StepLengths(s);
  EXPECT_NEAR(total, 265.0, 1e-10);
  EXPECT_LE(longest, 0.1 * (1 + 1e-12));
}

TEST(ScenarioExampleTest, EveryExampleRunsAndKeepsItsLengths) {
  for (const char* file :
       {"fig07_straight_link.json", "fig06_parabola_single_step.json",
        "fig06_parabola_multi_step.json", "fig10_planar_curve.json", "fig12_spatial_curve.json"}) {
    SCOPED_TRACE(file);
    const Scenario s = LoadScenarioFile(Example(file));
    EXPECT_FALSE(s.name.empty());
    EXPECT_FALSE(s.description.empty());
    const RunResult r = flexkin::Run(s.chain, s.leader_steps, s.options);
    EXPECT_EQ(r.num_steps, s.leader_steps.rows());
    EXPECT_LT(r.metrics.max_relative_length_error, 1e-12);
  }
}

TEST(ScenarioFormTest, PointsPathAndOptions) {
  const Scenario s = Parse(R"({
    "name": "n", "description": "d",
    "curve": {"points": [[0, 0, 0], [1, 0, 0], [1, 2, 0]]},
    "leader": {"path": [[0, 0, 1], [0, 1, 1]], "substeps": 8},
    "method": "ftl", "record": {"every": 3},
    "accuracy": {"tolerance": 1e-7, "max_substeps": 512}})");
  EXPECT_EQ(s.name, "n");
  EXPECT_EQ(s.description, "d");
  EXPECT_EQ(s.chain.lengths, Eigen::Vector2d(1, 2));
  EXPECT_EQ(s.leader_steps, (Points(2, 3) << 0, 0, 1, 0, 1, 1).finished());
  EXPECT_EQ(s.options.method, Method::kFollowTheLeader);
  EXPECT_EQ(s.options.substeps, 8);
  EXPECT_EQ(s.options.record_every, 3);
  EXPECT_EQ(s.options.tolerance, 1e-7);
  EXPECT_EQ(s.options.max_substeps, 512);
}

TEST(ScenarioFormTest, DefaultsAndALargeSubstepsRaisesTheCap) {
  const Scenario s = Parse(R"({"curve": {"points": [[0, 0], [1, 0]]},
                               "leader": {"pull": [1, 1], "substeps": 100000}})");
  const RunOptions defaults;
  EXPECT_EQ(s.options.method, defaults.method);
  EXPECT_EQ(s.options.record_every, 1);
  EXPECT_EQ(s.options.tolerance, 0.0);
  EXPECT_EQ(s.options.substeps, 100000);
  EXPECT_EQ(s.options.max_substeps, 100000);
  ASSERT_EQ(s.leader_steps.rows(), 1);  // "steps" defaults to 1
  EXPECT_EQ(s.leader_steps.row(0), Eigen::RowVector2d(1, 1));
}

TEST(ScenarioFormTest, GeneratedShapes) {
  const Scenario line = Parse(R"({"curve": {"shape": "line", "start": [1, 2, 3],
      "direction": [0, 0, -2], "links": 4, "link_length": 0.5}, "leader": {"pull": [1, 0, 0]}})");
  EXPECT_EQ(line.chain.points.row(4), Eigen::RowVector3d(1, 2, 1));
  const Scenario line2 = Parse(R"({"curve": {"shape": "line", "links": 2, "link_length": 1},
                                   "leader": {"pull": [1, 0]}})");
  EXPECT_EQ(line2.chain.points.row(2), Eigen::RowVector2d(2, 0));  // from the origin along +x
  const Scenario parabola = Parse(R"({"curve": {"shape": "parabola", "a": 2, "side": "-x",
      "links": 3, "link_length": 0.1}, "leader": {"pull": [1, 0]}})");
  EXPECT_LT(parabola.chain.points(3, 0), 0.0);
  EXPECT_NEAR(parabola.chain.points(3, 1), 2 * std::pow(parabola.chain.points(3, 0), 2), 1e-15);
  const Scenario arc = Parse(R"({"curve": {"shape": "arc", "radius": 2, "center": [1, 1],
      "start_angle": 1.5707963267948966, "turn": "cw", "links": 5, "link_length": 0.3},
      "leader": {"pull": [1, 0]}})");
  EXPECT_NEAR(arc.chain.points(0, 0), 1.0, 1e-15);
  EXPECT_NEAR(arc.chain.points(0, 1), 3.0, 1e-15);
  EXPECT_GT(arc.chain.points(1, 0), 1.0);  // clockwise from the top goes toward +x
  const Scenario helix = Parse(R"({"curve": {"shape": "helix", "radius": 1, "pitch": -2,
      "center": [0, 0, 5], "links": 7, "link_length": 0.4}, "leader": {"pull": [0, 0, 1]}})");
  EXPECT_EQ(helix.chain.dim(), 3);
  EXPECT_EQ(helix.chain.points(0, 2), 5.0);
  EXPECT_LT(helix.chain.points(7, 2), 5.0);
  EXPECT_EQ(helix.chain.lengths, Eigen::VectorXd::Constant(7, 0.4));
}

struct BadCase {
  const char* what;
  const char* text;     // the scenario
  const char* pointer;  // expected InputError::field()
  const char* message;  // expected in the message
};

// A valid document to start from; each case changes one thing.
#define CURVE R"("curve": {"points": [[0, 0], [1, 0], [2, 0]]})"
#define LEADER R"("leader": {"pull": [-1, 0], "steps": 2})"

const BadCase kBadCases[] = {
    {"root not an object", "[1, 2]", "", "expected an object"},
    {"missing curve", "{" LEADER "}", "/curve", "missing; expected"},
    {"missing leader", "{" CURVE "}", "/leader", "missing; expected"},
    {"unknown top-level key", "{" CURVE "," LEADER R"(, "methd": "ftl"})", "/methd",
     "did you mean \"method\""},
    {"unknown curve key", R"({"curve": {"points": [[0, 0], [1, 0]], "closed": true},)" LEADER "}",
     "/curve/closed", "unknown key"},
    {"unknown record key", "{" CURVE "," LEADER R"(, "record": {"evry": 2}})", "/record/evry",
     "did you mean \"every\""},
    {"key with a slash", "{" CURVE "," LEADER R"(, "a/b~": 1})", "/a~1b~0", "unknown key"},
    {"curve not an object", R"({"curve": [[0, 0], [1, 0]],)" LEADER "}", "/curve", "an array"},
    {"points and shape", R"({"curve": {"points": [[0, 0], [1, 0]], "shape": "line"},)" LEADER "}",
     "/curve", "both"},
    {"one point", R"({"curve": {"points": [[0, 0]]},)" LEADER "}", "/curve/points",
     "has 1 point; expected an array of at least 2 points"},
    {"zero-length link", R"({"curve": {"points": [[0, 0], [1, 0], [1, 0]]},)" LEADER "}",
     "/curve/points/2", "zero length"},
    {"mixed dimensions", R"({"curve": {"points": [[0, 0], [1, 0, 0]]},)" LEADER "}",
     "/curve/points/1", "expected an array of 2 numbers"},
    {"4D point", R"({"curve": {"points": [[0, 0, 0, 0], [1, 0, 0, 0]]},)" LEADER "}",
     "/curve/points/0", "expected an array of 2 or 3 numbers"},
    {"number as a string", R"({"curve": {"points": [[0, "1"], [1, 0]]},)" LEADER "}",
     "/curve/points/0/1", "(a string) is not valid; expected a finite number"},
    {"NaN as a string", "{" CURVE "," LEADER R"(, "accuracy": {"tolerance": "NaN"}})",
     "/accuracy/tolerance", R"(value "NaN" (a string) is not valid)"},
    {"negative tolerance", "{" CURVE "," LEADER R"(, "accuracy": {"tolerance": -1}})",
     "/accuracy/tolerance", "value -1 is not valid; expected a finite number >= 0"},
    {"unknown shape", R"({"curve": {"shape": "circle", "links": 3, "link_length": 1},)" LEADER "}",
     "/curve/shape", R"(value "circle" is not valid; expected one of "line")"},
    {"links as a string",
     R"({"curve": {"shape": "line", "links": "3", "link_length": 1},)" LEADER "}", "/curve/links",
     "(a string)"},
    {"links fractional",
     R"({"curve": {"shape": "line", "links": 2.5, "link_length": 1},)" LEADER "}", "/curve/links",
     "value 2.5 is not valid"},
    {"links too many",
     R"({"curve": {"shape": "line", "links": 1e12, "link_length": 1},)" LEADER "}", "/curve/links",
     "expected an integer from 1 to 10000000"},
    {"missing link_length", R"({"curve": {"shape": "line", "links": 3},)" LEADER "}",
     "/curve/link_length", "missing; expected"},
    {"zero link_length", R"({"curve": {"shape": "line", "links": 3, "link_length": 0},)" LEADER "}",
     "/curve/link_length", "value 0 is not valid; expected a finite number > 0"},
    {"arc radius too small",
     R"({"curve": {"shape": "arc", "radius": 0.2, "links": 3, "link_length": 1},)" LEADER "}",
     "/curve/radius", "expected radius >= 0.5"},
    {"helix without pitch",
     R"({"curve": {"shape": "helix", "radius": 1, "links": 3, "link_length": 1},)" LEADER "}",
     "/curve/pitch", "missing; expected"},
    {"parabola key on an arc",
     R"({"curve": {"shape": "arc", "radius": 1, "a": 1, "links": 3, "link_length": 1},)" LEADER "}",
     "/curve/a", "unknown key"},
    {"bad side", R"({"curve": {"shape": "parabola", "a": 1, "side": "left", "links": 3,
     "link_length": 1},)" LEADER "}",
     "/curve/side", R"(expected one of "+x" or "-x")"},
    {"zero direction", R"({"curve": {"shape": "line", "direction": [0, 0], "links": 3,
     "link_length": 1},)" LEADER "}",
     "/curve/direction", "nonzero"},
    {"steps 0", "{" CURVE R"(, "leader": {"pull": [1, 0], "steps": 0}})", "/leader/steps",
     "value 0 is not valid; expected an integer >= 1"},
    {"steps negative", "{" CURVE R"(, "leader": {"pull": [1, 0], "steps": -3}})", "/leader/steps",
     "value -3 is not valid"},
    {"pull of the wrong dimension", "{" CURVE R"(, "leader": {"pull": [1, 0, 0]}})", "/leader/pull",
     "expected an array of 2 numbers (the curve is 2D)"},
    {"path of the wrong dimension", "{" CURVE R"(, "leader": {"path": [[1, 0], [1, 0, 0]]}})",
     "/leader/path/1", "expected an array of 2 numbers"},
    {"empty path", "{" CURVE R"(, "leader": {"path": []}})", "/leader/path",
     "has 0 points; expected an array of at least 1 point"},
    {"negative max_step", "{" CURVE R"(, "leader": {"path": [[1, 0]], "max_step": -0.1}})",
     "/leader/max_step", "value -0.1 is not valid; expected a finite number > 0"},
    {"tiny max_step", "{" CURVE R"(, "leader": {"path": [[1, 0]], "max_step": 1e-12}})",
     "/leader/max_step", "at most 10000000"},
    {"path not moving", "{" CURVE R"(, "leader": {"path": [[0, 0]], "max_step": 0.1}})",
     "/leader/path", "no leader step"},
    {"steps with a path", "{" CURVE R"(, "leader": {"path": [[1, 0]], "steps": 3}})",
     "/leader/steps", "only valid with \"pull\""},
    {"max_step with a pull", "{" CURVE R"(, "leader": {"pull": [1, 0], "max_step": 3}})",
     "/leader/max_step", "only valid with \"path\""},
    {"path and pull", "{" CURVE R"(, "leader": {"pull": [1, 0], "path": [[1, 0]]}})", "/leader",
     "both"},
    {"substeps 0", "{" CURVE R"(, "leader": {"pull": [1, 0], "substeps": 0}})", "/leader/substeps",
     "value 0 is not valid"},
    {"unknown method", "{" CURVE "," LEADER R"(, "method": "fabrik"})", "/method",
     R"(unknown method "fabrik"; expected "tractrix", "ftl", "min_rotation", "min_joint_angle", "overall" or "follow_path")"},
    {"method in the wrong case", "{" CURVE "," LEADER R"(, "method": "Tractrix"})", "/method",
     R"(unknown method "Tractrix"; expected "tractrix", "ftl", "min_rotation", "min_joint_angle", "overall" or "follow_path" (did you mean "tractrix"?))"},
    {"objective without the overall method",
     "{" CURVE "," LEADER R"(, "objective": {"squared": 1}})", "/objective",
     R"(is used only with "method": "overall")"},
    {"solver without the overall method",
     "{" CURVE "," LEADER R"(, "solver": {"max_iterations": 5}})", "/solver",
     R"(is used only with "method": "overall")"},
    {"unknown objective term",
     "{" CURVE "," LEADER R"(, "method": "overall", "objective": {"rotaton": 1}})",
     "/objective/rotaton", "unknown key"},
    {"negative objective weight",
     "{" CURVE "," LEADER R"(, "method": "overall", "objective": {"rotation": -1}})",
     "/objective/rotation", "value -1 is not valid"},
    {"all objective weights zero",
     "{" CURVE "," LEADER R"(, "method": "overall", "objective": {"squared": 0}})", "/objective",
     "all weights are 0"},
    {"l2 with the joint-angle term",
     "{" CURVE "," LEADER R"(, "method": "overall", "objective": {"l2": 1, "joint_angle": 1}})",
     "/objective/joint_angle", "cannot be combined with the L2 metric"},
    {"negative l2 weight",
     "{" CURVE "," LEADER R"(, "method": "overall", "objective": {"l2_weighted": -2}})",
     "/objective/l2_weighted", "value -2 is not valid"},
    {"solver max_iterations 0",
     "{" CURVE "," LEADER R"(, "method": "overall", "solver": {"max_iterations": 0}})",
     "/solver/max_iterations", "value 0 is not valid"},
    {"accuracy control with the overall method",
     "{" CURVE "," LEADER R"(, "method": "overall", "accuracy": {"tolerance": 1e-6}})",
     "/accuracy/tolerance", "tractrix and ftl"},
    {"method not a string", "{" CURVE "," LEADER R"(, "method": 1})", "/method", "a number"},
    {"name not a string", "{" CURVE "," LEADER R"(, "name": null})", "/name", "null"},
    {"max_substeps below substeps",
     "{" CURVE R"(, "leader": {"pull": [1, 0], "substeps": 8}, "accuracy": {"max_substeps": 4}})",
     "/accuracy/max_substeps", "must be >= substeps"},
    {"huge literal", R"({"curve": {"points": [[0, 0], [1e999, 0]]},)" LEADER "}",
     "/curve/points/1/0", "1e999 (line 1, column 32) is too large"},
    {"huge negative literal", "{" CURVE "," LEADER R"(, "accuracy": {"tolerance": -1e400}})",
     "/accuracy/tolerance", "-1e400"},
};

class BadScenarioTest : public testing::TestWithParam<BadCase> {};

TEST_P(BadScenarioTest, InputErrorNamesTheField) {
  const BadCase& c = GetParam();
  try {
    ParseScenario(ParseJsonText(c.text));
    FAIL() << "accepted: " << c.text;
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), c.pointer) << e.what();
    const std::string what = e.what();
    EXPECT_NE(what.find(c.message), std::string::npos) << what;
    if (*c.pointer != '\0') EXPECT_EQ(what.rfind(std::string(c.pointer) + ": ", 0), 0u) << what;
  }
  // ValidateScenario reports the same problem (unless the JSON text itself is refused).
  json doc;
  try {
    doc = ParseJsonText(c.text);
  } catch (const InputError&) {
    return;
  }
  const Problems problems = ValidateScenario(doc);
  ASSERT_FALSE(problems.empty());
  EXPECT_EQ(problems.front().field, c.pointer);
}

INSTANTIATE_TEST_SUITE_P(Scenario, BadScenarioTest, testing::ValuesIn(kBadCases),
                         [](const testing::TestParamInfo<BadCase>& info) {
                           std::string name = info.param.what;
                           for (char& ch : name) ch = std::isalnum(ch) ? ch : '_';
                           return name;
                         });

TEST(ScenarioValidateTest, ListsEveryProblemNotJustTheFirst) {
  const json doc = ParseJsonText(R"({
    "curve": {"shape": "arc", "radius": -1, "links": 0, "link_length": 0.1, "colour": 1},
    "leader": {"pull": [1, 0], "steps": 0},
    "method": "fast", "record": {"every": 0}})");
  std::vector<std::string> pointers;
  for (const Problem& p : ValidateScenario(doc)) pointers.push_back(p.field);
  for (const char* expected :
       {"/curve/colour", "/curve/radius", "/curve/links", "/method", "/record/every"}) {
    EXPECT_NE(std::find(pointers.begin(), pointers.end(), expected), pointers.end()) << expected;
  }
  EXPECT_TRUE(ValidateScenario(ReadJsonFile(Example("fig10_planar_curve.json"))).empty());
}

TEST(ScenarioJsonTextTest, SyntaxErrorGivesLineAndColumnAndReason) {
  try {
    ParseJsonText("{\n  \"curve\": {\"points\": [[0, 0], [1, 0]]},\n  \"leader\": {pull: 1}\n}");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "");
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("line 3, column 14: invalid JSON: ", 0), 0u) << what;
    EXPECT_NE(what.find("object key"), std::string::npos) << what;
  }
  try {
    ParseJsonText("{\"a\": [1, 2");  // the end of input is column 12
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 1, column 12"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("end of input"), std::string::npos) << e.what();
  }
}

TEST(ScenarioLoadTest, MissingFileIsASystemErrorNamingThePath) {
  const std::string path = "/nonexistent-dir/scenario.json";
  try {
    LoadScenarioFile(path);
    FAIL() << "no error";
  } catch (const std::system_error& e) {
    EXPECT_EQ(e.code(), std::errc::no_such_file_or_directory);
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

// The public functions take text and paths: the same scenario and the same problems as the parsed
// document, and text that is not JSON is one problem, the one ParseScenarioText throws.
TEST(ScenarioTextTest, TextAndFileFunctionsAgreeWithTheDocument) {
  const std::string path = Example("fig10_planar_curve.json");
  const std::string text = ReadTextFile(path);
  const Scenario from_text = ParseScenarioText(text), from_file = LoadScenarioFile(path);
  const Scenario from_json = ParseScenario(ParseJsonText(text));
  EXPECT_EQ(from_text.chain.points, from_json.chain.points);
  EXPECT_EQ(from_file.chain.points, from_json.chain.points);
  EXPECT_EQ(from_text.leader_steps, from_json.leader_steps);
  EXPECT_EQ(from_file.leader_steps, from_json.leader_steps);
  EXPECT_TRUE(ValidateScenarioText(text).empty());
  EXPECT_TRUE(ValidateScenarioFile(path).empty());

  const std::string bad = R"({"curve": {"shape": "arc", "radius": -1, "links": 0,
    "link_length": 0.1}, "leader": {"pull": [1, 0], "steps": 0}, "method": "fast"})";
  const Problems from_doc = ValidateScenario(ParseJsonText(bad));
  const Problems listed = ValidateScenarioText(bad);
  ASSERT_EQ(listed.size(), from_doc.size());
  ASSERT_GE(listed.size(), 3u);
  for (size_t i = 0; i < listed.size(); ++i) EXPECT_EQ(listed[i].Text(), from_doc[i].Text());

  const std::string not_json = "{\"curve\": [1,";
  const Problems syntax = ValidateScenarioText(not_json);
  ASSERT_EQ(syntax.size(), 1u);
  EXPECT_EQ(syntax[0].field, "");
  EXPECT_EQ(syntax[0].message.rfind("line 1, column ", 0), 0u) << syntax[0].message;
  EXPECT_NE(syntax[0].message.find("invalid JSON"), std::string::npos) << syntax[0].message;
  try {
    ParseScenarioText(not_json);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem().Text(), syntax[0].Text());
  }
  EXPECT_THROW(ValidateScenarioFile("/nonexistent-dir/scenario.json"), std::system_error);
}

// The keys the reader accepts at `pointer` of `doc`.
std::set<std::string> AcceptedKeys(const json& doc, const std::string& pointer) {
  return test_util::AcceptedKeys(
      doc, pointer, [](const std::string& text) { return ValidateScenario(json::parse(text)); });
}
using test_util::SchemaKeys;

// docs/schema/scenario.schema.json lists exactly the keys the parser accepts, everywhere.
TEST(ScenarioSchemaTest, SchemaAndParserAcceptTheSameKeys) {
  const json schema =
      ReadJsonFile(std::string(FLEXKIN_SOURCE_DIR) + "/docs/schema/scenario.schema.json");
  const json& defs = schema["$defs"];
  json doc = ParseJsonText(R"({"curve": {"points": [[0, 0], [1, 0]]}, "leader": {"pull": [1, 0]},
                               "record": {}, "accuracy": {}})");
  EXPECT_EQ(AcceptedKeys(doc, ""), SchemaKeys(schema));
  EXPECT_EQ(AcceptedKeys(doc, "/curve"), SchemaKeys(defs["pointsCurve"]));
  EXPECT_EQ(AcceptedKeys(doc, "/record"), SchemaKeys(schema["properties"]["record"]));
  EXPECT_EQ(AcceptedKeys(doc, "/accuracy"), SchemaKeys(schema["properties"]["accuracy"]));
  std::set<std::string> leader = SchemaKeys(defs["pullLeader"]);
  for (const std::string& key : SchemaKeys(defs["pathLeader"])) leader.insert(key);
  EXPECT_EQ(AcceptedKeys(doc, "/leader"), leader);
  for (const char* shape : {"line", "parabola", "arc", "helix"}) {
    doc["curve"] = {{"shape", shape}, {"links", 1}, {"link_length", 1}};
    EXPECT_EQ(AcceptedKeys(doc, "/curve"), SchemaKeys(defs[std::string(shape) + "Curve"])) << shape;
  }
  doc["curve"] = {{"points", {{0, 0}, {1, 0}}}};
  for (const auto& [shape, def] :
       std::vector<std::pair<std::string, std::string>>{{"sphere", "sphereCollider"},
                                                        {"capsule", "capsuleCollider"},
                                                        {"cylinder", "cylinderCollider"},
                                                        {"box", "boxCollider"},
                                                        {"ellipsoid", "ellipsoidCollider"},
                                                        {"half_space", "halfSpaceCollider"}}) {
    doc["colliders"] = json::array({{{"shape", shape}}});
    EXPECT_EQ(AcceptedKeys(doc, "/colliders/0"), SchemaKeys(defs[def])) << shape;
  }
}

// Colliders in a scenario: each shape read into the collider it names (2D shapes in the plane
// z = 0), and every mistake named by its JSON pointer.
TEST(ScenarioCollidersTest, ShapesAreReadAndMistakesNamed) {
  const Scenario s = ParseScenarioText(R"({
    "curve": {"points": [[0, 0], [0, -1], [0, -2]]}, "leader": {"pull": [0, 1]},
    "colliders": [
      {"shape": "sphere", "center": [3, 0], "radius": 0.5},
      {"shape": "capsule", "from": [2, 2], "to": [4, 2], "radius": 0.25},
      {"shape": "cylinder", "from": [-3, 0], "to": [-3, 2], "radius": 0.5},
      {"shape": "box", "center": [5, 5], "half_extents": [1, 2], "angle": 0.5},
      {"shape": "ellipsoid", "center": [-5, 5], "semi_axes": [1, 0.5]},
      {"shape": "half_space", "point": [0, -10], "normal": [0, 2]}]})");
  const std::vector<Collider>& c = s.options.colliders;
  ASSERT_EQ(c.size(), 6u);
  EXPECT_EQ(c[0].shape, ColliderShape::kSphere);
  EXPECT_NEAR(QuerySurface(c[0], Eigen::Vector3d(3, 1, 0)).distance, 0.5, 1e-15);
  EXPECT_EQ(c[1].shape, ColliderShape::kCapsule);
  EXPECT_NEAR(c[1].half_length, 1.0, 1e-15);
  EXPECT_NEAR(QuerySurface(c[1], Eigen::Vector3d(5, 2, 0)).distance, 0.75, 1e-15);
  EXPECT_NEAR(QuerySurface(c[2], Eigen::Vector3d(-3, 3, 0)).distance, 1.0, 1e-15);
  EXPECT_NEAR(QuerySurface(c[3], Eigen::Vector3d(5, 5, 0)).distance, -1.0, 1e-15);
  EXPECT_NEAR(QuerySurface(c[4], Eigen::Vector3d(-5, 6, 0)).distance, 0.5, 1e-12);
  EXPECT_NEAR(QuerySurface(c[5], Eigen::Vector3d(7, -9, 0)).distance, 1.0, 1e-15);
  for (const Collider& collider : c) EXPECT_TRUE(CheckCollider(collider, "/c").empty());

  const auto problems = ValidateScenario(ParseJsonText(R"({
    "curve": {"points": [[0, 0], [0, -1]]}, "leader": {"pull": [0, 1]},
    "colliders": [
      {"shape": "sphere", "center": [3, 0, 1], "radius": 0},
      {"shape": "cube"},
      {"shape": "cylinder", "from": [1, 1], "to": [1, 1], "radius": 1},
      {"shape": "box", "center": [5, 5], "half_extents": [1, -2], "rotation": [1, 0, 0, 0]},
      {"shape": "half_space", "point": [0, 0], "normal": [0, 0]},
      {"shape": "sphere", "centre": [0, 0], "radius": 1}]})"));
  std::set<std::string> fields;
  for (const Problem& p : problems) fields.insert(p.field);
  EXPECT_EQ(fields, (std::set<std::string>{
                        "/colliders/0/center", "/colliders/0/radius", "/colliders/1/shape",
                        "/colliders/2/to", "/colliders/3/half_extents/1", "/colliders/3/rotation",
                        "/colliders/4/normal", "/colliders/5/center", "/colliders/5/centre"}))
      << problems.size();
}

TEST(ScenarioSummaryTest, NamesDimensionLinksStepsAndMethod) {
  const Scenario s = LoadScenarioFile(Example("fig06_parabola_multi_step.json"));
  EXPECT_EQ(ScenarioSummary(s),
            "2D, 20 links (total length 5), 5 leader steps, method tractrix, 1 sub-step");
}

}  // namespace
}  // namespace flexkin
