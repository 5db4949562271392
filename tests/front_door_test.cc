// The front door (flexkin/any_scenario.h): every kind of scenario read once and told apart in the
// library; and the one table of link rules (src/sequential/rule_table.h): every engine takes its
// rule from it and refuses by name a rule it cannot run.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <system_error>
#include <tuple>
#include <vector>

#include "flexkin/any_scenario.h"
#include "flexkin/chain.h"
#include "flexkin/error.h"
#include "flexkin/groom.h"
#include "flexkin/propagate.h"
#include "flexkin/result_io.h"
#include "flexkin/robot_scenario.h"
#include "flexkin/scenario.h"
#include "flexkin/strands.h"
#include "flexkin/urdf.h"
#include "io/atomic_file.h"  // ReadTextFile
#include "sequential/rule_table.h"
#include "sequential/sweep.h"
#include "test_util.h"

namespace flexkin {
namespace {

std::string Example(const std::string& name) {
  return std::string(FLEXKIN_SOURCE_DIR) + "/examples/" + name;
}

ScenarioReadOptions WithUrdf() {
  ScenarioReadOptions options;
  options.robot = UrdfRobotScenarioOptions();
  return options;
}

std::vector<std::string> ExampleScenarios() {
  std::vector<std::string> paths;
  for (const auto& entry : std::filesystem::directory_iterator(FLEXKIN_SOURCE_DIR "/examples")) {
    if (entry.path().extension() == ".json") paths.push_back(entry.path().string());
  }
  return paths;
}

// Every shipped scenario: one read gives the kind the per-kind readers agree on, no problem, and
// the scenario each kind's own loader builds.
TEST(AnyScenarioTest, EveryExampleIsReadAsItsKind) {
  const std::vector<std::string> paths = ExampleScenarios();
  ASSERT_GE(paths.size(), 15u);
  int kinds[std::size(Vocabulary<ScenarioKind>::kEntries)] = {};
  for (const std::string& path : paths) {
    SCOPED_TRACE(path);
    const AnyScenario s = ReadScenarioFile(path, WithUrdf());
    ASSERT_TRUE(s.valid()) << s.problems.front().Text();
    ++kinds[static_cast<int>(s.kind)];
    const std::string text = ReadTextFile(path);
    EXPECT_EQ(ScenarioKindOfText(text), s.kind);
    switch (s.kind) {
      case ScenarioKind::kChain: {
        ASSERT_TRUE(s.chain.has_value());
        EXPECT_FALSE(s.groom || s.robot);
        const Scenario direct = LoadScenarioFile(path);
        EXPECT_EQ(s.chain->chain.points, direct.chain.points);
        EXPECT_EQ(s.chain->leader_steps, direct.leader_steps);
        EXPECT_EQ(s.Summary(), ScenarioSummary(direct));
        break;
      }
      case ScenarioKind::kGroom: {
        ASSERT_TRUE(s.groom.has_value());
        EXPECT_TRUE(IsGroomText(text));
        EXPECT_EQ(s.Summary(), GroomSummary(LoadGroomFile(path)));
        break;
      }
      case ScenarioKind::kRobot: {
        ASSERT_TRUE(s.robot.has_value());
        EXPECT_TRUE(IsRobotScenarioText(text));
        const RobotScenario direct = LoadRobotScenarioFile(path, UrdfRobotScenarioOptions());
        EXPECT_EQ(s.robot->path, direct.path);
        EXPECT_EQ(s.Summary(), RobotScenarioSummary(direct));
        break;
      }
      case ScenarioKind::kTree: {
        ASSERT_TRUE(s.tree.has_value());
        EXPECT_FALSE(s.chain || s.groom || s.robot);
        EXPECT_EQ(s.Summary(), TreeSummary(*s.tree));
        EXPECT_GT(s.tree->frames(), 0);
        break;
      }
    }
  }
  // Every kind has an example.
  for (const int count : kinds) EXPECT_GT(count, 0);
}

// Every problem is listed, the same as each kind's own validator lists, for each kind.
TEST(AnyScenarioTest, ListsEveryProblemOfEachKind) {
  const std::string chain =
      R"({"curve": {"shape": "line", "links": 0, "link_length": -1}, "leader": {"pull": [1, 0]},
          "method": "fabrik"})";
  const std::string groom = R"({"strands": [{"points": [[0, 0, 0]]}], "substeps": 0})";
  const std::string robot = R"({"arm": {"links": [1, 1]}, "path": [[1, 0, 0, 0]]})";
  for (const auto& [text, kind, expected] :
       {std::tuple{chain, ScenarioKind::kChain, ValidateScenarioText(chain)},
        std::tuple{groom, ScenarioKind::kGroom, ValidateGroomText(groom)},
        std::tuple{robot, ScenarioKind::kRobot, ValidateRobotScenarioText(robot)}}) {
    SCOPED_TRACE(text);
    const AnyScenario s = ReadScenarioText(text);
    EXPECT_EQ(s.kind, kind);
    EXPECT_FALSE(s.chain || s.groom || s.robot || s.tree);
    EXPECT_EQ(s.Summary(), "");
    ASSERT_GE(s.problems.size(), 2u);
    ASSERT_EQ(s.problems.size(), expected.size());
    for (size_t i = 0; i < expected.size(); ++i)
      EXPECT_EQ(s.problems[i].Text(), expected[i].Text());
    EXPECT_THROW(s.ThrowIfInvalid(), InputError);
  }
}

TEST(AnyScenarioTest, TextThatIsNotJsonIsOneProblem) {
  const AnyScenario s = ReadScenarioText("{\"curve\": ");
  ASSERT_EQ(s.problems.size(), 1u);
  EXPECT_EQ(s.problems[0].field, "");
  EXPECT_NE(s.problems[0].message.find("invalid JSON"), std::string::npos);
}

TEST(AnyScenarioTest, UnreadableFileIsASystemError) {
  EXPECT_THROW(ReadScenarioFile(Example("no_such_file.json")), std::system_error);
}

// A key given twice in one object was read as its last value ("links": 30); now it is refused at
// the pointer of the repeated key, for every kind of file.
TEST(AnyScenarioTest, DuplicateKeysAreRefused) {
  const AnyScenario s = ReadScenarioText(
      R"({"curve": {"shape": "line", "links": 25, "links": 30, "link_length": 1},
          "leader": {"pull": [1, 0]}})");
  ASSERT_EQ(s.problems.size(), 1u);
  EXPECT_EQ(s.problems[0].field, "/curve/links");
  EXPECT_NE(s.problems[0].message.find("\"links\" appears more than once"), std::string::npos)
      << s.problems[0].message;
  EXPECT_EQ(ValidateScenarioText(R"({"leader": {}, "leader": {}})").front().field, "/leader");
  EXPECT_EQ(ValidateGroomText(R"({"strands": [], "motion": {"fps": 1, "fps": 2}})").front().field,
            "/motion/fps");
  // The same key in different objects is fine.
  EXPECT_TRUE(ReadScenarioText(R"({"curve": {"shape": "line", "links": 2, "link_length": 1},
                                    "leader": {"pull": [1, 0], "substeps": 2},
                                    "record": {"every": 1}})")
                  .valid());
}

TEST(AnyScenarioTest, MethodNamesGetASuggestion) {
  const Problems problems = ValidateScenarioText(
      R"({"curve": {"shape": "line", "links": 2, "link_length": 1}, "leader": {"pull": [1, 0]},
          "method": "Tractrix"})");
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].message.find("(did you mean \"tractrix\"?)"), std::string::npos)
      << problems[0].message;
}

// The table: orders, and which methods each engine runs.
TEST(RuleTableTest, OrdersAndEnginesComeFromTheTable) {
  EXPECT_EQ(MethodOrder(Method::kTractrix), 2);
  EXPECT_EQ(MethodOrder(Method::kFollowTheLeader), 1);
  EXPECT_EQ(MethodOrder(Method::kMinRotation), 0);
  EXPECT_EQ(MethodOrder(Method::kMinJointAngle), 0);
  EXPECT_EQ(MethodOrder(Method::kOverall), 0);
  EXPECT_EQ(StrandMethodNames(), (std::vector<std::string>{"tractrix", "ftl"}));
  EXPECT_EQ(internal::RuleNamesOn(internal::kWholeChainEngine),
            (std::vector<std::string>{"min_rotation", "min_joint_angle"}));
  EXPECT_FALSE(internal::RuleRunsOn(Method::kOverall, ~0u));
  EXPECT_FALSE(internal::RuleRunsOn(Method::kFollowPath, ~0u));
  for (const auto& entry : Vocabulary<Method>::kEntries) {
    // Every method but overall and follow_path (which places points on the head's path, not
    // link by link from their old places) is a link rule of some engine.
    EXPECT_EQ(internal::RuleRunsOn(entry.value, ~0u),
              entry.value != Method::kOverall && entry.value != Method::kFollowPath)
        << entry.name;
  }
}

// Before the table, the one-pass sweep ran every method other than tractrix as follow-the-leader:
// min_rotation given to it moved the chain by the ftl rule. Now it is refused by name.
TEST(RuleTableTest, AnEngineRefusesARuleItCannotRun) {
  Points points(4, 2);
  points << 0, 0, -1, 0, -2, 0, -3, 0;
  const Eigen::VectorXd lengths = Eigen::VectorXd::Ones(3);
  const double heads[2] = {0.5, 0.5};
  try {
    internal::SweepsScalar(Method::kMinRotation, 2, heads, 1, lengths.data(), lengths.data(), 3,
                           points.data());
    FAIL() << "min_rotation ran on the one-pass sweep";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "method");
    EXPECT_NE(std::string(e.what()).find(
                  "\"min_rotation\" is not valid; expected \"tractrix\" or \"ftl\" (the methods "
                  "of the sequential sweep)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(points(1, 0), -1.0);  // untouched
}

TEST(RuleTableTest, StrandMethodsAreParsedFromTheTable) {
  EXPECT_EQ(ParseStrandMethod("ftl", "--method"), Method::kFollowTheLeader);
  try {
    ParseStrandMethod("min_rotation", "--method");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "--method");
    EXPECT_NE(std::string(e.what()).find("(the methods of the strand engine)"), std::string::npos);
  }
  try {
    ParseStrandMethod("ftll", "method");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean \"ftl\""), std::string::npos) << e.what();
  }
  StrandOptions options;
  options.method = Method::kOverall;
  const Problems problems = options.Validate();
  ASSERT_FALSE(problems.empty());
  EXPECT_EQ(problems[0].field, "method");
  EXPECT_NE(problems[0].message.find("\"tractrix\" or \"ftl\""), std::string::npos);
}

// The whole-chain rules keep running through MoveLeader, taken from the table: min_rotation
// translates the chain.
TEST(RuleTableTest, WholeChainRulesRunThroughMoveLeader) {
  Chain chain = MakeChain((Points(3, 2) << 0, 0, -1, 0, -1, 1).finished());
  const Points before = chain.points;
  Eigen::Vector2d target(0.25, 0.5);
  MoveLeader(Method::kMinRotation, target, 3, &chain);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(chain.points(i, 0), before(i, 0) + 0.25, 1e-15);
    EXPECT_NEAR(chain.points(i, 1), before(i, 1) + 0.5, 1e-15);
  }
  EXPECT_THROW(MakeStepper(Method::kOverall, chain), InputError);
}

}  // namespace
// A scenario option added in the library once (the leader's "closed") reaches every front end
// through the parser: here the library's view; python/tests/test_front_end.py checks Python and
// the command line, neither of which was changed for it.
TEST(FrontDoorTest, AClosedPathReturnsExactlyToItsStart) {
  const std::string curve = R"("curve": {"points": [[0.25, 0.5], [0, 0.5], [-0.5, 0.5]]})";
  const Scenario plain =
      ParseScenarioText("{" + curve + R"(, "leader": {"path": [[1, 0.5], [1, 1.5]]}})");
  const Scenario closed = ParseScenarioText(
      "{" + curve + R"(, "leader": {"path": [[1, 0.5], [1, 1.5]], "closed": true}})");
  ASSERT_EQ(closed.leader_steps.rows(), plain.leader_steps.rows() + 1);
  EXPECT_EQ(Points(closed.leader_steps.topRows(2)), plain.leader_steps);
  EXPECT_EQ(Points(closed.leader_steps.bottomRows(1)), Points(plain.chain.points.topRows(1)));
  // Resampled: every vertex kept, the way back split too, its last step the start exactly.
  const Scenario resampled = ParseScenarioText(
      "{" + curve + R"(, "leader": {"path": [[1, 0.5]], "max_step": 0.25, "closed": true}})");
  ASSERT_EQ(resampled.leader_steps.rows(), 6);  // 0.75 out and 0.75 back, 3 steps each
  EXPECT_EQ(resampled.leader_steps(2, 0), 1.0);
  EXPECT_EQ(Points(resampled.leader_steps.bottomRows(1)), Points(plain.chain.points.topRows(1)));
  // With a pull, or not a boolean: a problem naming the key, from the same reader every front
  // end uses.
  const AnyScenario pull = ReadScenarioText(
      "{" + curve + R"(, "leader": {"pull": [1, 0], "steps": 4, "closed": true}})");
  ASSERT_FALSE(pull.problems.empty());
  EXPECT_EQ(pull.problems.front().field, "/leader/closed");
  const AnyScenario word =
      ReadScenarioText("{" + curve + R"(, "leader": {"path": [[1, 0.5]], "closed": "yes"}})");
  ASSERT_FALSE(word.problems.empty());
  EXPECT_EQ(word.problems.front().field, "/leader/closed");
}

// The one call that runs any kind into its files: a chain's result file holds what Run gives, a
// groom refuses a CSV, an invalid scenario its first problem, before any file is made.
class RunScenarioToFilesTest : public test_util::TempDirTest {};

TEST_F(RunScenarioToFilesTest, RunsEachKindIntoItsFiles) {
  const AnyScenario chain = ReadScenarioText(
      R"({"curve": {"points": [[0, 0], [-1, 0], [-2, 0.5]]}, "leader": {"pull": [1, 1], "steps": 5}})");
  const ScenarioRunReport report =
      RunScenarioToFiles(chain, {Path("c.npz"), Path("c.csv")}, nullptr);
  EXPECT_EQ(report.kind, ScenarioKind::kChain);
  EXPECT_TRUE(report.chain.frames.empty());  // streamed to the files
  const RunResult direct =
      flexkin::Run(chain.chain->chain, chain.chain->leader_steps, chain.chain->options);
  const ResultFile back = ReadResultFile(Path("c.npz"));
  EXPECT_EQ(back.result.frames.points_data(), direct.frames.points_data());
  EXPECT_TRUE(std::filesystem::exists(Path("c.csv")));
  int64_t calls = 0;
  RunScenarioToFiles(chain, {Path("d.json"), ""}, [&](int64_t, int64_t) { ++calls; });
  EXPECT_GE(calls, 1);

  const AnyScenario groom =
      ReadScenarioFile(std::string(FLEXKIN_SOURCE_DIR) + "/examples/groom_grass_2d.json");
  ASSERT_TRUE(groom.valid());
  test_util::ExpectInputError(
      [&] {
        RunScenarioToFiles(groom, {Path("g.npz"), Path("g.csv")});
      },
      "csv", "strand file");
  test_util::ExpectInputError(
      [&] {
        RunScenarioToFiles(groom, {Path("g.json"), ""});
      },
      "output", ".npz");
  const ScenarioRunReport strands = RunScenarioToFiles(groom, {Path("g.npz"), ""});
  EXPECT_EQ(strands.kind, ScenarioKind::kGroom);
  EXPECT_LT(strands.strands.max_length_error, 1e-12);

  const AnyScenario bad = ReadScenarioText(R"({"curve": {"points": [[0, 0]]}, "leader": {}})");
  ASSERT_FALSE(bad.valid());
  EXPECT_THROW(RunScenarioToFiles(bad, {Path("b.npz"), ""}), InputError);
  EXPECT_FALSE(std::filesystem::exists(Path("b.npz")));
}

}  // namespace flexkin
