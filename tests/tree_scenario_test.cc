// Tree scenario files (flexkin/tree_scenario.h) through the front door (flexkin/any_scenario.h)
// and the command line: every problem named by its JSON pointer, the run the library's own
// calls (bit for bit), the result files whole.
#include "flexkin/tree_scenario.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "cli_process.h"
#include "flexkin/any_scenario.h"
#include "scenes/scenes.h"
#include "schema_test_util.h"
#include "test_util.h"
#include "tree_test_util.h"

namespace flexkin {
namespace {

using json = nlohmann::json;

// Two arms of two links on a shoulder (point 1) above a fixed base (point 0); 2D; the hands'
// paths of 3 frames.
json TwoHands() {
  return json::parse(R"({
    "format": "flexkin-tree",
    "name": "two hands",
    "tree": {"points": [[0, 0], [0, 1], [1, 1.2], [2, 1.1], [-1, 1.2], [-2, 1.1]],
             "parents": [-1, 0, 1, 2, 1, 4]},
    "targets": [{"point": 3, "path": [[2, 1.2], [1.9, 1.3], [1.8, 1.4]]},
                {"point": 5, "path": [[-2, 1.2], [-1.9, 1.3], [-1.8, 1.4]], "weight": 2}],
    "fixed": [0]
  })");
}

AnyScenario Read(const json& j) { return ReadScenarioText(j.dump()); }

// The first problem's "field: message".
std::string FirstProblem(const json& j) {
  const AnyScenario s = Read(j);
  EXPECT_EQ(s.kind, ScenarioKind::kTree);
  return s.problems.empty() ? "(valid)" : s.problems.front().Text();
}

TEST(TreeScenarioTest, ReadsAValidScenarioAsATree) {
  const AnyScenario s = Read(TwoHands());
  ASSERT_TRUE(s.valid()) << s.problems.front().Text();
  EXPECT_EQ(s.kind, ScenarioKind::kTree);
  ASSERT_TRUE(s.tree.has_value());
  EXPECT_EQ(s.tree->targets, (std::vector<int>{3, 5}));
  EXPECT_EQ(s.tree->weights, (std::vector<double>{1.0, 2.0}));
  EXPECT_EQ(s.tree->frames(), 3);
  EXPECT_EQ(s.Summary(),
            "tree \"two hands\": 6 points (5 links, 2D), 2 targets, 1 fixed, tractrix passes "
            "(centroid), 3 frames");
  // A file with "tree" and no "format" is a tree too.
  json j = TwoHands();
  j.erase("format");
  EXPECT_EQ(Read(j).kind, ScenarioKind::kTree);
}

// A pointing goal: "look_at" instead of "path", the point its link from its parent points at.
TEST(TreeScenarioTest, ReadsAndRunsPointingGoals) {
  json j = TwoHands();
  // A head on a neck above the shoulder (points 6 and 7), looking at a point above the hands.
  j["tree"]["points"].push_back({0, 1.4});
  j["tree"]["points"].push_back({0, 1.8});
  j["tree"]["parents"].push_back(1);
  j["tree"]["parents"].push_back(6);
  j["targets"].push_back({{"point", 7}, {"look_at", {{1, 3}, {0, 3}, {-1, 3}}}});
  const AnyScenario s = Read(j);
  ASSERT_TRUE(s.valid()) << s.problems.front().Text();
  EXPECT_EQ(s.tree->looks, (std::vector<char>{0, 0, 1}));
  EXPECT_NE(s.Summary().find("3 targets (1 pointing)"), std::string::npos) << s.Summary();
  const TreeRunResult r = RunTree(*s.tree);
  for (int f = 1; f <= 3; ++f) {
    EXPECT_TRUE(r.reached[f - 1]) << f;
    const Eigen::RowVector2d link = r.frames[f].row(7) - r.frames[f].row(6);
    const Eigen::RowVector2d look = s.tree->paths[2].row(f - 1) - r.frames[f].row(6);
    EXPECT_LT((link.normalized() - look.normalized()).norm(), 1e-9) << f;
  }
  // Problems: a path and a look_at, a pointing goal for method overall, one on the root.
  auto with = [&](const std::function<void(json&)>& change) {
    json k = j;
    change(k);
    return FirstProblem(k);
  };
  EXPECT_EQ(with([](json& k) {
              k["targets"][2]["path"] = {{0, 1}, {0, 1}, {0, 1}};
            }).rfind("/targets/2/look_at: is given with \"path\"", 0),
            0u);
  EXPECT_EQ(with([](json& k) {
              k["method"] = "overall";
            }).rfind("/targets/2/look_at: is a pointing goal; method \"overall\"", 0),
            0u);
  EXPECT_EQ(with([](json& k) {
              k["targets"][2]["point"] = 0;
              k["fixed"] = json::array();
            }).rfind("/targets/2/point: is point 0, the tree's root", 0),
            0u);
  EXPECT_EQ(with([](json& k) {
              k["targets"][2]["look_at"].erase(1);
            }).rfind("/targets/2/look_at: has 2 points; every target's path", 0),
            0u);
}

// "finish" (default true): stalled passes finished by the least correction (FinishTreeReach).
TEST(TreeScenarioTest, ReadsTheFinishOption) {
  EXPECT_TRUE(Read(TwoHands()).tree->finish);
  json j = TwoHands();
  j["finish"] = false;
  EXPECT_FALSE(Read(j).tree->finish);
  j["finish"] = 3;
  EXPECT_EQ(
      FirstProblem(j).rfind("/finish: value 3 (a number) is not valid; expected true or false", 0),
      0u)
      << FirstProblem(j);
  // Every frame of the example reaches its targets: nothing to finish.
  const TreeRunResult r = RunTree(*Read(TwoHands()).tree);
  EXPECT_EQ(r.finished, (std::vector<char>{0, 0, 0}));
  // A random tree whose passes stall (tree_reach_test): finished by default, not without.
  TreeScenario stalls;
  stalls.tree = scenes::RandomTree(40, 2, 6);
  stalls.targets = test_util::Leaves(stalls.tree, 5);
  const Points bent = test_util::Bent(stalls.tree, 0.25, 106);
  for (const int leaf : stalls.targets) stalls.paths.push_back(bent.row(leaf));
  stalls.weights.assign(5, 1.0);
  stalls.fixed = {0};
  const TreeRunResult finished = RunTree(stalls);
  EXPECT_EQ(finished.finished, (std::vector<char>{1}));
  EXPECT_EQ(finished.reached, (std::vector<char>{1}));
  EXPECT_LE(finished.residual[0], 1e-10);
  EXPECT_LE(finished.max_length_error, 1e-12);
  EXPECT_NE(finished.BriefReport().find("1 frame of stalled passes finished"), std::string::npos);
  stalls.finish = false;
  const TreeRunResult stalled = RunTree(stalls);
  EXPECT_EQ(stalled.finished, (std::vector<char>{0}));
  EXPECT_EQ(stalled.reached, (std::vector<char>{0}));
  EXPECT_GT(stalled.residual[0], 1e-5);
}

TEST(TreeScenarioTest, NamesEveryProblemByItsJsonPointer) {
  auto with = [](const std::function<void(json&)>& change) {
    json j = TwoHands();
    change(j);
    return FirstProblem(j);
  };
  // The tree: a cycle, a second root, a parent out of range, a link of length 0.
  EXPECT_EQ(with([](json& j) { j["tree"]["parents"] = {-1, 0, 3, 2, 1, 4}; }),
            "/tree/parents/2: is 3: point 2 does not lead to the root 0; its parents form the "
            "cycle 2 -> 3 -> 2");
  EXPECT_NE(with([](json& j) { j["tree"]["parents"][4] = -1; }).find("/tree/parents/4: is -1"),
            std::string::npos);
  EXPECT_NE(with([](json& j) { j["tree"]["parents"][5] = 9; }).find("/tree/parents/5: is 9"),
            std::string::npos);
  EXPECT_NE(with([](json& j) {
              j["tree"]["points"][2] = {0, 1};
            }).find("/tree/points/2: lies at distance 0 from its parent point 1"),
            std::string::npos);
  EXPECT_NE(with([](json& j) { j["tree"]["parents"].push_back(4); }).find("/tree/parents: has 7"),
            std::string::npos);
  // The targets: a point that does not exist, a point driven twice, paths of other lengths.
  EXPECT_EQ(with([](json& j) { j["targets"][1]["point"] = 6; }),
            "/targets/1/point: value 6 is not valid; expected an integer from 0 to 5");
  EXPECT_EQ(with([](json& j) { j["targets"][1]["point"] = 3; }),
            "/targets/1/point: is point 3, which targets[0] drives already; a point takes one "
            "target or is fixed");
  EXPECT_EQ(with([](json& j) { j["targets"][1]["path"].erase(2); }),
            "/targets/1/path: has 2 points; every target's path has one point per frame, 3 as "
            "/targets/0/path");
  EXPECT_NE(with([](json& j) {
              j["targets"][0]["path"][1] = {1, 2, 3};
            }).find("/targets/0/path/1"),
            std::string::npos);
  EXPECT_NE(with([](json& j) { j["targets"][1]["weight"] = 0; }).find("/targets/1/weight"),
            std::string::npos);
  EXPECT_NE(with([](json& j) { j["targets"] = json::array(); }).find("/targets"),
            std::string::npos);
  // Fixed points that conflict with a target; options that do not apply.
  EXPECT_EQ(with([](json& j) {
              j["fixed"] = {0, 5};
            }),
            "/fixed/1: is point 5, which targets[1] drives already; a point takes one target or "
            "is fixed");
  EXPECT_EQ(with([](json& j) { j["method"] = "min_rotation"; }),
            "/method: value \"min_rotation\" is not valid; expected \"tractrix\", \"ftl\" or "
            "\"overall\" (with several targets or fixed points)");
  EXPECT_NE(with([](json& j) { j["substeps"] = 4; }).find("/substeps: is an option of a tree "),
            std::string::npos);
  EXPECT_NE(with([](json& j) { j["method"] = "fabrik"; }).find("/method"), std::string::npos);
  EXPECT_NE(with([](json& j) { j["branch_rule"] = "mean"; }).find("/branch_rule"),
            std::string::npos);
  EXPECT_NE(with([](json& j) { j["tolerance"] = -1; }).find("/tolerance"), std::string::npos);
  EXPECT_NE(with([](json& j) { j["overall"] = {{"l2", 1}}; }).find("/overall"), std::string::npos);
  EXPECT_NE(with([](json& j) {
              j["overall"] = {{"squared", 0}};
            }).find("/overall: has no positive weight"),
            std::string::npos);
  EXPECT_NE(with([](json& j) { j["trees"] = 1; }).find("unknown key"), std::string::npos);
  EXPECT_NE(with([](json& j) { j["format"] = "flexkin-trees"; }).find("/format"),
            std::string::npos);
  // Every problem is listed, not only the first.
  json many = TwoHands();
  many["tolerance"] = 0;
  many["max_passes"] = 0;
  EXPECT_EQ(Read(many).problems.size(), 2u);
}

TEST(TreeScenarioTest, RunsAsTheLibrarysOwnCalls) {
  const AnyScenario s = Read(TwoHands());
  ASSERT_TRUE(s.valid());
  const TreeRunResult r = RunTree(*s.tree);
  ASSERT_EQ(r.frames.size(), 4u);
  const TreeReacher reacher = MakeTreeReacher(s.tree->tree, {3, 5}, {0}, {1.0, 2.0});
  Points points = s.tree->tree.points;
  for (int f = 0; f < 3; ++f) {
    Points goal(2, 2);
    goal.row(0) = s.tree->paths[0].row(f);
    goal.row(1) = s.tree->paths[1].row(f);
    const ReachReport report = ReachTargets(reacher, goal, &points);
    EXPECT_TRUE(r.frames[f + 1] == points);
    EXPECT_EQ(r.passes[f], report.passes);
    EXPECT_TRUE(r.reached[f]);
  }
  EXPECT_EQ(r.failures(), 0);
  EXPECT_LE(r.max_length_error, 1e-14);

  // Driven at one point with nothing fixed: MoveTreePoint with the file's method and sub-steps.
  json one = TwoHands();
  one.erase("fixed");
  one["targets"].erase(1);
  one["method"] = "min_joint_angle";
  one["substeps"] = 3;
  const AnyScenario single = Read(one);
  ASSERT_TRUE(single.valid()) << single.problems.front().Text();
  const TreeRunResult rs = RunTree(*single.tree);
  const TreeStepper stepper = MakeTreeStepper(Method::kMinJointAngle, single.tree->tree, 3);
  Points moved = single.tree->tree.points;
  for (int f = 0; f < 3; ++f) {
    MoveTreePoint(stepper, single.tree->paths[0].row(f).transpose(), 3, &moved);
    EXPECT_TRUE(rs.frames[f + 1] == moved);
  }

  // Method "overall": StepTreeOverall with the file's weights.
  json exact = TwoHands();
  exact["method"] = "overall";
  exact["overall"] = {{"squared", 1}, {"rotation", 0.5}};
  const AnyScenario o = Read(exact);
  ASSERT_TRUE(o.valid()) << o.problems.front().Text();
  const TreeRunResult ro = RunTree(*o.tree);
  TreeOverallOptions options;
  options.weights.rotation = 0.5;
  Points p = o.tree->tree.points;
  for (int f = 0; f < 3; ++f) {
    Points goal(2, 2);
    goal.row(0) = o.tree->paths[0].row(f);
    goal.row(1) = o.tree->paths[1].row(f);
    EXPECT_TRUE(StepTreeOverall(reacher, goal, options, &p).converged);
    EXPECT_TRUE(ro.frames[f + 1] == p);
    EXPECT_TRUE(ro.converged[f]);
  }
}

// The keys the reader accepts at `pointer` of `doc`.
std::set<std::string> AcceptedKeys(const json& doc, const std::string& pointer) {
  return test_util::AcceptedKeys(
      doc, pointer, [](const std::string& text) { return ReadScenarioText(text).problems; });
}
using test_util::SchemaKeys;

// docs/schema/tree.schema.json lists exactly the keys and names the reader accepts.
TEST(TreeScenarioTest, TheSchemaAndTheReaderAgree) {
  const json schema =
      json::parse(std::ifstream(std::string(FLEXKIN_SOURCE_DIR) + "/docs/schema/tree.schema.json"));
  json doc = TwoHands();
  doc["overall"] = {{"squared", 1}};
  EXPECT_EQ(AcceptedKeys(doc, ""), SchemaKeys(schema));
  EXPECT_EQ(AcceptedKeys(doc, "/tree"), SchemaKeys(schema["properties"]["tree"]));
  // A target of a tree of points or of a robot tree ("robot", docs/trees.md "Robot trees").
  const json robot = json::parse(R"({"format": "flexkin-tree", "robot": {"urdf": "r.urdf"},
      "targets": [{"link": "hand", "path": [[0, 0, 1]]}]})");
  std::set<std::string> target_keys = AcceptedKeys(doc, "/targets/0");
  for (const std::string& key : AcceptedKeys(robot, "/targets/0")) target_keys.insert(key);
  EXPECT_EQ(target_keys, SchemaKeys(schema["properties"]["targets"]["items"]));
  EXPECT_EQ(AcceptedKeys(robot, "/robot"), SchemaKeys(schema["properties"]["robot"]));
  EXPECT_EQ(AcceptedKeys(doc, "/overall"), SchemaKeys(schema["properties"]["overall"]));
  EXPECT_EQ(schema["properties"]["branch_rule"]["enum"].get<std::vector<std::string>>(),
            NamesOf<BranchRule>());
  for (const std::string method : schema["properties"]["method"]["enum"]) {
    json one = TwoHands();
    one.erase("fixed");
    one["targets"].erase(1);
    one["method"] = method;
    EXPECT_TRUE(Read(one).valid()) << method;
  }
}

class TreeResultFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("flexkin_tree_scenario_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    scenario_ = (dir_ / "two_hands.json").string();
    std::ofstream(scenario_) << TwoHands().dump();
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
  std::string scenario_;
};

TEST_F(TreeResultFileTest, WritesJsonAndNpzWholeAndRefusesOtherPaths) {
  const AnyScenario s = ReadScenarioFile(scenario_);
  ASSERT_TRUE(s.valid());
  const std::string json_path = (dir_ / "r.json").string();
  const ScenarioRunReport report = RunScenarioToFiles(s, {json_path, ""});
  const json written = json::parse(std::ifstream(json_path));
  EXPECT_EQ(written["format"], "flexkin-tree-result");
  EXPECT_EQ(written["parents"], TwoHands()["tree"]["parents"]);
  ASSERT_EQ(written["frames"].size(), 4u);
  for (size_t f = 0; f < 4; ++f) {
    for (int i = 0; i < 6; ++i) {
      for (int k = 0; k < 2; ++k) {
        EXPECT_EQ(written["frames"][f][i][k].get<double>(), report.tree.frames[f](i, k));
      }
    }
  }
  // .npz: the frames' array holds the same doubles (the header then the data, C order).
  const std::string npz_path = (dir_ / "r.npz").string();
  RunScenarioToFiles(s, {npz_path, ""});
  std::ifstream in(npz_path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const double* first = report.tree.frames[3].data();
  const std::string last_frame(reinterpret_cast<const char*>(first), sizeof(double) * 12);
  EXPECT_NE(bytes.find(last_frame), std::string::npos);
  EXPECT_NE(bytes.find("parents.npy"), std::string::npos);
  // Another extension, or a CSV: refused, nothing written.
  const std::string bad = (dir_ / "r.csv").string();
  EXPECT_THROW(RunScenarioToFiles(s, {bad, ""}), InputError);
  EXPECT_THROW(RunScenarioToFiles(s, {(dir_ / "r2.npz").string(), bad}), InputError);
  EXPECT_FALSE(std::filesystem::exists(bad));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "r2.npz"));
}

// ReadTreeResultFile gives back what WriteTreeResult wrote, in both forms, and names a damaged
// file's member or JSON pointer.
TEST_F(TreeResultFileTest, ReadsBothFormsBackExactly) {
  const AnyScenario s = ReadScenarioFile(scenario_);
  ASSERT_TRUE(s.valid());
  for (const char* name : {"r.json", "r.npz"}) {
    const std::string path = (dir_ / name).string();
    const ScenarioRunReport report = RunScenarioToFiles(s, {path, ""});
    const TreeResultFile back = ReadTreeResultFile(path);
    EXPECT_EQ(back.name, "two hands");
    EXPECT_EQ(back.dim, 2);
    EXPECT_EQ(back.parents, s.tree->tree.parents);
    EXPECT_EQ(back.targets, s.tree->targets);
    EXPECT_EQ(back.fixed, s.tree->fixed);
    EXPECT_EQ(back.method, s.tree->method);
    ASSERT_EQ(back.frames.size(), report.tree.frames.size()) << name;
    for (size_t f = 0; f < back.frames.size(); ++f) {
      EXPECT_EQ(back.frames[f], report.tree.frames[f]) << name << " frame " << f;  // bit for bit
    }
    ASSERT_EQ(back.reached.size(), back.frames.size() - 1);
    // The goals: each frame's target positions, the scenario's paths.
    ASSERT_EQ(back.goals.size(), back.frames.size() - 1) << name;
    for (size_t f = 0; f < back.goals.size(); ++f) {
      for (size_t k = 0; k < 2; ++k) {
        EXPECT_EQ(back.goals[f].row(k), s.tree->paths[k].row(f)) << name;
      }
    }
    EXPECT_EQ(back.looks, (std::vector<char>{0, 0}));
    for (size_t f = 0; f < back.reached.size(); ++f) {
      EXPECT_EQ(bool(back.reached[f]), report.tree.reached[f] && report.tree.converged[f]);
    }
  }
  // Damaged JSON results: each problem by its pointer, with the value.
  json good = json::parse(std::ifstream((dir_ / "r.json").string()));
  auto problem = [&](const std::function<void(json*)>& damage) {
    json bad = good;
    damage(&bad);
    const std::string path = (dir_ / "bad.json").string();
    std::ofstream(path) << bad.dump();
    try {
      ReadTreeResultFile(path);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("(read without a problem)");
  };
  EXPECT_EQ(problem([](json* j) { (*j)["parents"][3] = 3; }).rfind("/parents/3: ", 0), 0u);
  EXPECT_EQ(problem([](json* j) { (*j)["frames"][2][4] = {1.0}; }).rfind("/frames/2/4: ", 0), 0u);
  EXPECT_EQ(problem([](json* j) { (*j)["frames"][1].erase(5); }).rfind("/frames/1: ", 0), 0u);
  EXPECT_EQ(problem([](json* j) { (*j)["targets"][0] = 6; }).rfind("/targets/0: ", 0), 0u);
  EXPECT_EQ(problem([](json* j) { (*j)["format"] = "flexkin-result"; }).rfind("/format: ", 0), 0u);
  EXPECT_EQ(problem([](json* j) { (*j)["reached"].erase(0); }).rfind("/reached: ", 0), 0u);
  EXPECT_EQ(problem([](json* j) {
              (*j)["frames"][0][2] = (*j)["frames"][0][1];
            }).rfind("/frames/0/2: ", 0),
            0u);
  // A chain result is not a tree result.
  EXPECT_NE(problem([](json* j) { j->erase("parents"); }).find("/parents: missing"),
            std::string::npos);
}

TEST_F(TreeResultFileTest, TheCommandLineRunsAndValidatesTrees) {
  using test_util::CliProcess;
  {
    CliProcess p(test_util::kCli, dir_.string(), {"validate", scenario_});
    ASSERT_TRUE(p.Wait(60));
    EXPECT_EQ(p.exit_code(), 0) << p.err();
    EXPECT_NE(p.out().find("ok: tree \"two hands\": 6 points"), std::string::npos) << p.out();
  }
  {
    CliProcess p(test_util::kCli, dir_.string(), {"run", scenario_, "-o", "out.npz"});
    ASSERT_TRUE(p.Wait(60));
    EXPECT_EQ(p.exit_code(), 0) << p.err();
    EXPECT_TRUE(std::filesystem::exists(dir_ / "out.npz"));
    EXPECT_NE(p.out().find("4 frames; 0 not reached"), std::string::npos) << p.out();
  }
  {  // flexkin render draws a tree result (.npz or .json) in the formats of trees, and names
     // one it does not draw trees in.
    for (const char* name : {"out.npz", "out.json"}) {
      if (std::string(name) == "out.json") {
        CliProcess run(test_util::kCli, dir_.string(), {"run", scenario_, "-o", name});
        ASSERT_TRUE(run.Wait(60));
      }
      EXPECT_TRUE(IsTreeResultFile((dir_ / name).string()));
      CliProcess p(test_util::kCli, dir_.string(),
                   {"render", name, "-o", "drawn", "--formats", "svg,glb"});
      ASSERT_TRUE(p.Wait(60));
      EXPECT_EQ(p.exit_code(), 0) << p.err();
      EXPECT_TRUE(std::filesystem::exists(dir_ / "drawn" / "out.svg"));
      EXPECT_TRUE(std::filesystem::exists(dir_ / "drawn" / "out.glb"));
    }
    // Plots: a tree result's path length, link-length error and targets' misses.
    CliProcess p(test_util::kCli, dir_.string(),
                 {"render", "out.npz", "-o", "plotted", "--formats", "plots"});
    ASSERT_TRUE(p.Wait(60));
    EXPECT_EQ(p.exit_code(), 0) << p.err();
    for (const char* plot : {"path_length", "length_error", "target_miss"}) {
      for (const char* extension : {".svg", ".png"}) {
        EXPECT_TRUE(
            std::filesystem::exists(dir_ / "plotted" / ("out_" + std::string(plot) + extension)))
            << plot << extension;
      }
    }
    EXPECT_FALSE(std::filesystem::exists(dir_ / "plotted" / "out_joint_angles.svg"));  // no robot
    EXPECT_FALSE(IsTreeResultFile(scenario_));
  }
  {
    CliProcess p(test_util::kCli, dir_.string(),
                 {"run", scenario_, "-o", "out2.npz", "--substeps", "4"});
    ASSERT_TRUE(p.Wait(60));
    EXPECT_NE(p.exit_code(), 0);
    EXPECT_NE(p.err().find("--substeps: is not available for a tree scenario"), std::string::npos)
        << p.err();
    EXPECT_FALSE(std::filesystem::exists(dir_ / "out2.npz"));
  }
  {  // A bad file: its problem by JSON pointer, exit 1, nothing written.
    json bad = TwoHands();
    bad["fixed"] = {0, 3};
    std::ofstream((dir_ / "bad.json").string()) << bad.dump();
    CliProcess p(test_util::kCli, dir_.string(), {"run", "bad.json", "-o", "bad.npz"});
    ASSERT_TRUE(p.Wait(60));
    EXPECT_EQ(p.exit_code(), 1);
    EXPECT_NE(p.err().find("bad.json: /fixed/1: is point 3"), std::string::npos) << p.err();
    EXPECT_FALSE(std::filesystem::exists(dir_ / "bad.npz"));
  }
  {  // The examples run.
    for (const char* example : {"tree_two_arms.json", "tree_plant.json"}) {
      CliProcess p(test_util::kCli, dir_.string(),
                   {"run", test_util::kExamples + example, "-o", "example.npz"});
      ASSERT_TRUE(p.Wait(120));
      EXPECT_EQ(p.exit_code(), 0) << example << ": " << p.err();
    }
  }
}

}  // namespace
}  // namespace flexkin
