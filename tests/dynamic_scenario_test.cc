// Dynamic chains in chain scenario files (docs/scenario-format.md "dynamics", docs/dynamics.md):
// every member read, every mistake named by its JSON pointer with nothing written, a run through
// the front door (RunScenarioToFiles) equal bit for bit to SimulateChain called directly, and the
// command line end to end (run, validate, render, the overrides).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "flexkin/any_scenario.h"
#include "flexkin/dynamics.h"
#include "flexkin/error.h"
#include "flexkin/render.h"
#include "flexkin/result_io.h"
#include "flexkin/scenario.h"
#include "io/json_file.h"
#include "io/scenario_json.h"
#include "test_util.h"

namespace flexkin {
namespace {

using json = nlohmann::json;
using test_util::CliResult;
using test_util::RunCli;

const std::string kCli = FLEXKIN_CLI;

std::string Example(const std::string& name) {
  return std::string(FLEXKIN_SOURCE_DIR) + "/examples/" + name;
}

// A 3-link rope, horizontal, its first point fixed for 30 frames, with `dynamics`.
json Rope(const json& dynamics) {
  json doc = json::parse(R"({
    "name": "rope",
    "curve": {"shape": "line", "links": 3, "link_length": 0.5},
    "leader": {"pull": [0, 0], "steps": 30}})");
  doc["dynamics"] = dynamics;
  return doc;
}

std::set<std::string> Fields(const Problems& problems) {
  std::set<std::string> fields;
  for (const Problem& p : problems) fields.insert(p.field);
  return fields;
}

std::string AllText(const Problems& problems) {
  std::string text;
  for (const Problem& p : problems) text += p.Text() + "\n";
  return text;
}

TEST(DynamicScenarioTest, ReadsEveryMember) {
  const Scenario s = ParseScenario(Rope(json::parse(R"({
      "projection": "shake", "gravity": [0.5, -9.81], "damping": 0.25, "wind": [3, 0.5],
      "frame_rate": 30, "substeps": 8, "mass": [1, 2, 3], "dftl_damping": 0.5})")));
  ASSERT_TRUE(s.dynamics.has_value());
  const DynamicOptions& d = *s.dynamics;
  EXPECT_EQ(d.projection, Projection::kShake);
  EXPECT_EQ(d.gravity, Eigen::Vector2d(0.5, -9.81));
  EXPECT_EQ(d.damping, 0.25);
  EXPECT_EQ(d.wind, Eigen::Vector2d(3, 0.5));
  EXPECT_TRUE(d.wind_keys.empty());
  EXPECT_EQ(d.frame_rate, 30.0);
  EXPECT_EQ(d.substeps, 8);
  EXPECT_EQ(d.masses, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(d.dftl_damping, 0.5);
  EXPECT_TRUE(d.colliders.empty());
  // The leader's steps are the first point's path, one row per frame.
  EXPECT_EQ(s.leader_steps.rows(), 30);
  EXPECT_EQ(s.leader_steps, Points::Zero(30, 2));

  const Scenario keyed = ParseScenario(Rope(json::parse(R"({
      "gravity": [0, -9.81], "damping": 1, "mass": "uniform",
      "wind_keys": [{"time": 0, "velocity": [0, 0]}, {"time": 0.5, "velocity": [4, 1]}]})")));
  const DynamicOptions& k = *keyed.dynamics;
  ASSERT_EQ(k.wind_keys.size(), 2u);
  EXPECT_EQ(k.wind_keys[1].time, 0.5);
  EXPECT_EQ(k.wind_keys[1].velocity, Eigen::Vector2d(4, 1));
  EXPECT_EQ(k.wind.size(), 0);
  EXPECT_FALSE(k.mass_by_length);
  EXPECT_EQ(k.masses.size(), 0);

  // Defaults: those of DynamicOptions.
  const Scenario plain = ParseScenario(Rope(json::parse(R"({"gravity": [0, -1]})")));
  const DynamicOptions defaults;
  const DynamicOptions& p = *plain.dynamics;
  EXPECT_EQ(p.projection, defaults.projection);
  EXPECT_EQ(p.damping, defaults.damping);
  EXPECT_EQ(p.frame_rate, defaults.frame_rate);
  EXPECT_EQ(p.substeps, defaults.substeps);
  EXPECT_EQ(p.mass_by_length, defaults.mass_by_length);
  EXPECT_EQ(p.dftl_damping, defaults.dftl_damping);
  EXPECT_EQ(p.wind.size(), 0);
  for (const auto& entry : Vocabulary<Projection>::kEntries) {
    json doc = Rope({{"gravity", {0, -1}}, {"projection", entry.name}});
    EXPECT_EQ(ParseScenario(doc).dynamics->projection, entry.value) << entry.name;
  }
  // A kinematic scenario has none.
  EXPECT_FALSE(LoadScenarioFile(Example("fig06_parabola_multi_step.json")).dynamics.has_value());
}

// Every mistake, each named by its JSON pointer, all of them listed.
TEST(DynamicScenarioTest, EveryMistakeIsNamedByItsPointer) {
  struct Case {
    json dynamics;
    std::string pointer;
    std::string says;
  };
  const std::vector<Case> cases = {
      {5, "/dynamics", "an object"},
      {{{"gravity", {0, -9.81}}, {"projection", "overal"}},
       "/dynamics/projection",
       "did you mean \"overall\"?"},
      {{{"gravity", {0, -9.81}}, {"projection", 3}}, "/dynamics/projection", "a string"},
      {{{"damping", 1}}, "/dynamics/gravity", "missing"},
      {{{"gravity", {0, -9.81, 0}}}, "/dynamics/gravity", "2 numbers"},
      {{{"gravity", {0, "down"}}}, "/dynamics/gravity/1", "\"down\""},
      {{{"gravity", {0, -9.81}}, {"gravty", 1}}, "/dynamics/gravty", "did you mean \"gravity\"?"},
      {{{"gravity", {0, -9.81}}, {"damping", -1}}, "/dynamics/damping", ">= 0"},
      {{{"gravity", {0, -9.81}}, {"wind", {1}}}, "/dynamics/wind", "2 numbers"},
      {{{"gravity", {0, -9.81}},
        {"wind", {1, 0}},
        {"wind_keys", {{{"time", 0}, {"velocity", {1, 0}}}}}},
       "/dynamics/wind_keys",
       "with \"wind\""},
      {{{"gravity", {0, -9.81}}, {"wind_keys", json::array()}},
       "/dynamics/wind_keys",
       "at least 1"},
      {{{"gravity", {0, -9.81}},
        {"wind_keys", {{{"time", 0}, {"velocity", {1, 0}}}, {{"time", 0}, {"velocity", {2, 0}}}}}},
       "/dynamics/wind_keys/1/time",
       "after the previous key's"},
      {{{"gravity", {0, -9.81}}, {"wind_keys", {{{"time", 0}, {"velocity", {1}}}}}},
       "/dynamics/wind_keys/0/velocity",
       "2 numbers"},
      {{{"gravity", {0, -9.81}}, {"wind_keys", {{{"tim", 0}, {"velocity", {1, 0}}}}}},
       "/dynamics/wind_keys/0/time",
       "missing"},
      {{{"gravity", {0, -9.81}}, {"wind_keys", {3}}}, "/dynamics/wind_keys/0", "an object"},
      {{{"gravity", {0, -9.81}}, {"frame_rate", 0}}, "/dynamics/frame_rate", "> 0"},
      {{{"gravity", {0, -9.81}}, {"substeps", 0}}, "/dynamics/substeps", ">= 1"},
      {{{"gravity", {0, -9.81}}, {"substeps", 2.5}}, "/dynamics/substeps", "integer"},
      {{{"gravity", {0, -9.81}}, {"mass", "heavy"}}, "/dynamics/mass", "\"by_length\""},
      {{{"gravity", {0, -9.81}}, {"mass", true}}, "/dynamics/mass", "\"by_length\""},
      {{{"gravity", {0, -9.81}}, {"mass", {1, 2}}}, "/dynamics/mass", "expected 3"},
      {{{"gravity", {0, -9.81}}, {"mass", {1, -2, 1}}}, "/dynamics/mass/1", "> 0"},
      {{{"gravity", {0, -9.81}}, {"dftl_damping", 1.5}}, "/dynamics/dftl_damping", "[0, 1]"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.dynamics.dump());
    const Problems problems = ValidateScenario(Rope(c.dynamics));
    ASSERT_EQ(Fields(problems).count(c.pointer), 1u) << AllText(problems);
    for (const Problem& p : problems) {
      if (p.field == c.pointer) EXPECT_NE(p.Text().find(c.says), std::string::npos) << p.Text();
    }
    // The front door lists the same.
    EXPECT_EQ(AllText(ReadScenarioText(Rope(c.dynamics).dump()).problems), AllText(problems));
  }
  // Several at once, all listed.
  const Problems several = ValidateScenario(Rope(json::parse(R"({
      "projection": "fast", "gravity": [0], "frame_rate": -1, "mass": [1]})")));
  EXPECT_EQ(Fields(several), (std::set<std::string>{"/dynamics/projection", "/dynamics/gravity",
                                                    "/dynamics/frame_rate", "/dynamics/mass"}))
      << AllText(several);
}

// What a dynamic chain cannot take is refused by name, not ignored.
TEST(DynamicScenarioTest, OptionsItCannotTakeAreRefusedByName) {
  const json dynamics = {{"gravity", {0, -9.81}}};
  struct Case {
    const char* key;
    json value;
    std::string pointer;
  };
  const std::vector<Case> cases = {
      {"/method", "overall", "/method"},
      {"/method", "ftl", "/method"},
      {"/leader/substeps", 4, "/leader/substeps"},
      {"/accuracy", {{"tolerance", 1e-6}}, "/accuracy/tolerance"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.key);
    json doc = Rope(dynamics);
    doc[json::json_pointer(c.key)] = c.value;
    const Problems problems = ValidateScenario(doc);
    EXPECT_EQ(Fields(problems), std::set<std::string>{c.pointer}) << AllText(problems);
    EXPECT_NE(AllText(problems).find("\"dynamics\""), std::string::npos) << AllText(problems);
  }
  // "method": "tractrix" (the default) and "leader/substeps": 1 are accepted.
  json doc = Rope(dynamics);
  doc["method"] = "tractrix";
  doc["leader"]["substeps"] = 1;
  EXPECT_TRUE(ValidateScenario(doc).empty());
}

// The keys the parser accepts in "dynamics" are the schema's (docs/schema/scenario.schema.json),
// and its projections are the library's.
TEST(DynamicScenarioTest, SchemaListsTheKeysAndProjections) {
  const json schema =
      ReadJsonFile(std::string(FLEXKIN_SOURCE_DIR) + "/docs/schema/scenario.schema.json");
  const json& d = schema["properties"]["dynamics"];
  std::set<std::string> keys;
  for (const auto& item : d["properties"].items()) keys.insert(item.key());
  json doc = Rope({{"gravity", {0, -9.81}}, {"zzz_unknown", 1}});
  std::set<std::string> accepted;
  for (const Problem& p : ValidateScenario(doc)) {
    ASSERT_EQ(p.field, "/dynamics/zzz_unknown");
    accepted = test_util::KeysOfUnknownKeyMessage(p.message);
  }
  EXPECT_EQ(accepted, keys);
  EXPECT_EQ(d["properties"]["projection"]["enum"].get<std::vector<std::string>>(),
            NamesOf<Projection>());
  const json result =
      ReadJsonFile(std::string(FLEXKIN_SOURCE_DIR) + "/docs/schema/result.schema.json");
  EXPECT_EQ(result["properties"]["dynamics"]["properties"]["projection"]["enum"]
                .get<std::vector<std::string>>(),
            NamesOf<Projection>());
}

TEST(DynamicScenarioTest, SummaryNamesTheDynamics) {
  const AnyScenario s = ReadScenarioFile(Example("rope_fall.json"));
  ASSERT_TRUE(s.valid()) << AllText(s.problems);
  EXPECT_EQ(s.Summary(),
            "2D, 40 links (total length 1), dynamic: 180 frames at 60 fps (3 s), projection "
            "overall, 4 sub-steps, gravity [0, -9.81], damping 0.1 /s, masses by length");
}

class DynamicRunTest : public test_util::TempDirTest {};

// The front door's run is SimulateChain's, bit for bit, in both formats and the CSV, for every
// projection; the energy comes with it.
TEST_F(DynamicRunTest, FrontDoorEqualsSimulateChainBitForBit) {
  for (const auto& entry : Vocabulary<Projection>::kEntries) {
    SCOPED_TRACE(entry.name);
    json doc = Rope({{"gravity", {0, -9.81}},
                     {"projection", entry.name},
                     {"damping", 0.5},
                     {"wind", {1, 0}},
                     {"substeps", 3}});
    doc["leader"] = {{"path", {{0.01, 0}, {0.02, 0.01}, {0.03, 0}, {0.03, 0}, {0.02, -0.01}}}};
    doc["record"] = {{"every", 2}};
    const AnyScenario any = ReadScenarioText(doc.dump());
    ASSERT_TRUE(any.valid()) << AllText(any.problems);
    const Scenario& s = *any.chain;
    const DynamicResult direct = SimulateChain(s.chain, s.leader_steps, *s.dynamics);
    for (const char* name : {"r.json", "r.npz"}) {
      const ScenarioRunReport report = RunScenarioToFiles(any, {Path(name), Path("r.csv")});
      EXPECT_TRUE(report.chain.dynamics.enabled);
      EXPECT_EQ(report.chain.recorded_frames, 4);  // frames 0, 2, 4 and 5
      const ResultFile file = ReadResultFile(Path(name));
      const RunResult& r = file.result;
      EXPECT_EQ(file.scenario_name, "rope");
      EXPECT_EQ(r.num_steps, 5);
      ASSERT_EQ(r.frames.size(), 4);
      const std::vector<int64_t> steps = {0, 2, 4, 5};
      for (size_t f = 0; f < steps.size(); ++f) {
        EXPECT_EQ(r.frames[f].step, steps[f]);
        EXPECT_EQ(Points(r.frames[f].points), direct.frames[static_cast<size_t>(steps[f])]);
        EXPECT_EQ(r.frames[f].link_angles.size(), 0);
      }
      ASSERT_TRUE(r.dynamics.enabled);
      EXPECT_EQ(r.dynamics.projection, entry.name);
      EXPECT_EQ(r.dynamics.frame_rate, 60.0);
      EXPECT_EQ(r.dynamics.substeps, 3);
      EXPECT_EQ(r.dynamics.failures, direct.failures);
      EXPECT_EQ(r.dynamics.energy, direct.energy);
      EXPECT_EQ(r.accuracy.substeps, 3);
      EXPECT_EQ(r.metrics.max_relative_length_error, direct.max_relative_length_error);
      EXPECT_EQ(r.metrics.l2_per_step.size(), 5);
      EXPECT_EQ(r.metrics.path_length[0],
                (direct.frames[1].row(0) - direct.frames[0].row(0)).norm() +
                    (direct.frames[2].row(0) - direct.frames[1].row(0)).norm() +
                    (direct.frames[3].row(0) - direct.frames[2].row(0)).norm() +
                    (direct.frames[4].row(0) - direct.frames[3].row(0)).norm() +
                    (direct.frames[5].row(0) - direct.frames[4].row(0)).norm());
      // Written back, the same file (the reader keeps "dynamics").
      WriteResultFile(file, Path("again.json"), ResultFileFormat::kJson);
      EXPECT_EQ(ReadResultFile(Path("again.json")).result.dynamics.energy, direct.energy);
    }
    const std::string csv = test_util::ReadFile(Path("r.csv"));
    EXPECT_EQ(csv.rfind("step,point,x,y\n0,0,", 0), 0u) << csv.substr(0, 40);
    // RunChainScenario with arrays gives the same frames.
    FrameRecorder recorder;
    const RunResult arrays = RunChainScenario(s, {}, &recorder);
    ASSERT_EQ(recorder.frames.size(), 4);
    EXPECT_EQ(Points(recorder.frames[3].points), direct.frames[5]);
    EXPECT_EQ(arrays.dynamics.energy, direct.energy);
  }
}

// Options changed after reading (Python, C++) are checked by the run, nothing written.
TEST_F(DynamicRunTest, RunRefusesWhatTheParserRefusesAndWritesNothing) {
  AnyScenario any = ReadScenarioText(Rope({{"gravity", {0, -9.81}}}).dump());
  ASSERT_TRUE(any.valid());
  const std::vector<std::pair<std::function<void(RunOptions*)>, std::string>> changes = {
      {[](RunOptions* o) { o->method = Method::kOverall; }, "/method"},
      {[](RunOptions* o) { o->substeps = 2; }, "/leader/substeps"},
      {[](RunOptions* o) { o->tolerance = 1e-6; }, "/accuracy/tolerance"},
      {[](RunOptions* o) { o->record_every = 0; }, "/record/every"},
  };
  for (const auto& [change, pointer] : changes) {
    AnyScenario changed = any;
    change(&changed.chain->options);
    try {
      RunScenarioToFiles(changed, {Path("r.json"), Path("r.csv")});
      ADD_FAILURE() << pointer << ": no InputError";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), pointer) << e.what();
    }
    EXPECT_TRUE(Files().empty());
  }
  // An invalid scenario: its first problem, nothing written.
  const AnyScenario bad = ReadScenarioText(Rope({{"gravity", {0}}}).dump());
  ASSERT_FALSE(bad.valid());
  try {
    RunScenarioToFiles(bad, {Path("r.json"), ""});
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "/dynamics/gravity");
  }
  EXPECT_TRUE(Files().empty());
}

// The scenario's colliders reach SimulateChain: a rope falls onto a floor (a half-space) and a
// ball, and no point goes through them; the run equals SimulateChain with those colliders. A mesh
// collider is refused by name.
TEST_F(DynamicRunTest, CollidersAreTaken) {
  json doc = Rope({{"gravity", {0, -9.81}}, {"substeps", 4}});
  doc["leader"]["steps"] = 90;
  doc["colliders"] = json::parse(R"([
      {"shape": "half_space", "point": [0, -0.6], "normal": [0, 1]},
      {"shape": "sphere", "center": [0.9, -0.35], "radius": 0.1}])");
  const AnyScenario any = ReadScenarioText(doc.dump());
  ASSERT_TRUE(any.valid()) << AllText(any.problems);
  const Scenario& s = *any.chain;
  const RunResult r = RunScenarioToFiles(any, {Path("r.json"), ""}).chain;
  EXPECT_EQ(r.contacts.num_colliders, 2);
  DynamicOptions options = *s.dynamics;
  options.colliders = s.options.colliders;
  const DynamicResult direct = SimulateChain(s.chain, s.leader_steps, options);
  const ResultFile file = ReadResultFile(Path("r.json"));
  ASSERT_EQ(file.colliders.size(), 2u);
  ASSERT_EQ(file.result.frames.size(), 91);
  double lowest = 0.0;
  for (int64_t f = 0; f <= 90; ++f) {
    const Points points = file.result.frames[f].points;
    EXPECT_EQ(points, direct.frames[static_cast<size_t>(f)]);
    lowest = std::min(lowest, points.col(1).minCoeff());
    for (Eigen::Index j = 0; j < points.rows(); ++j) {
      EXPECT_GT((points.row(j) - Eigen::RowVector2d(0.9, -0.35)).norm(), 0.1 - 1e-9) << f;
    }
  }
  EXPECT_GT(lowest, -0.6 - 1e-9);
  EXPECT_LT(lowest, -0.59);  // it reached the floor
  // The contact counts, in the report and the file: the overall projection (the default) solved
  // its contact sub-steps with the contacts.
  ASSERT_EQ(options.projection, Projection::kOverall);
  EXPECT_GT(direct.contact_solves, 0);
  for (const DynamicRunReport* d : {&r.dynamics, &file.result.dynamics}) {
    EXPECT_EQ(d->contact_substeps, direct.contact_substeps);
    EXPECT_EQ(d->contact_solves, direct.contact_solves);
    EXPECT_EQ(d->contact_solve_failures, direct.contact_solve_failures);
  }
  EXPECT_NE(
      r.BriefReport().find(std::to_string(direct.contact_substeps) + " contact sub-steps (" +
                           std::to_string(direct.contact_solves) + " solved with the contacts"),
      std::string::npos)
      << r.BriefReport();

  std::ofstream(Path("tet.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                 << "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  doc["colliders"] = {{{"shape", "mesh"}, {"file", Path("tet.obj")}, {"position", {5, 5, 5}}}};
  doc["curve"]["direction"] = {1, 0, 0};
  doc["leader"]["pull"] = {0, 0, 0};
  doc["dynamics"]["gravity"] = {0, 0, -9.81};
  const Problems problems = ValidateScenario(doc);
  EXPECT_EQ(Fields(problems).count("/colliders/0"), 1u) << AllText(problems);
}

// The shipped example: the rope falls (its energy drops, the tip goes down by about the rope's
// length) and keeps its lengths.
TEST_F(DynamicRunTest, RopeFallExampleFalls) {
  const AnyScenario any = ReadScenarioFile(Example("rope_fall.json"));
  ASSERT_TRUE(any.valid()) << AllText(any.problems);
  const RunResult r = RunScenarioToFiles(any, {Path("rope.npz"), ""}).chain;
  EXPECT_EQ(r.num_steps, 180);
  EXPECT_EQ(r.dynamics.energy.size(), 181);
  EXPECT_EQ(r.dynamics.failures, 0);
  EXPECT_LT(r.metrics.max_relative_length_error, 1e-9);
  EXPECT_LT(r.dynamics.energy[180], r.dynamics.energy[0] - 1.0);  // fell: m g L / 2 = 4.9
  const ResultFile file = ReadResultFile(Path("rope.npz"));
  ASSERT_EQ(file.result.frames.size(), 181);
  const Points last = file.result.frames[180].points;
  EXPECT_EQ(last.row(0), Eigen::RowVector2d(0, 0));
  EXPECT_LT(last(40, 1), -0.5);
}

// The energy plot (docs/rendering.md, "Plots"): drawn for a dynamic run; a kinematic one is refused
// naming the plot, nothing written.
TEST_F(DynamicRunTest, EnergyPlotIsForDynamicRuns) {
  const AnyScenario any = ReadScenarioFile(Example("rope_fall.json"));
  ASSERT_TRUE(any.valid()) << AllText(any.problems);
  RunScenarioToFiles(any, {Path("rope.npz"), ""});
  ResultFile file = ReadResultFile(Path("rope.npz"));
  WritePlot(file, PlotKind::kEnergy, PlotOptions(), Path("energy.svg"));
  EXPECT_GT(std::filesystem::file_size(Path("energy.svg")), 1000u);
  file.result.dynamics = DynamicRunReport();
  try {
    WritePlot(file, PlotKind::kEnergy, PlotOptions(), Path("kinematic.svg"));
    ADD_FAILURE() << "a kinematic run's energy plot was drawn";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "plot");
    EXPECT_NE(std::string(e.what()).find("dynamic runs"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(Path("kinematic.svg")));
}

class DynamicCliTest : public test_util::TempDirTest {
 protected:
  CliResult Cli(const std::string& args) { return RunCli(kCli, dir_, args); }
};

TEST_F(DynamicCliTest, RunValidateRenderAndOverrides) {
  ASSERT_FALSE(kCli.empty());
  const std::string example = "'" + Example("rope_fall.json") + "'";
  CliResult v = Cli("validate " + example);
  ASSERT_EQ(v.exit_code, 0) << v.err;
  EXPECT_NE(v.out.find("ok: 2D, 40 links (total length 1), dynamic: 180 frames at 60 fps"),
            std::string::npos)
      << v.out;
  EXPECT_NE(v.out.find("output: 181 frames"), std::string::npos) << v.out;

  CliResult r = Cli("run " + example + " -o rope.json --csv rope.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("dynamic, projection overall: 40 links, 180 frames at 60 fps x 4 sub-steps"),
            std::string::npos)
      << r.out;
  // The command line's file is the library's, bit for bit.
  const AnyScenario any = ReadScenarioFile(Example("rope_fall.json"));
  const DynamicResult direct =
      SimulateChain(any.chain->chain, any.chain->leader_steps, *any.chain->dynamics);
  const ResultFile file = ReadResultFile(Path("rope.json"));
  ASSERT_EQ(file.result.frames.size(), 181);
  for (int64_t f = 0; f <= 180; f += 30) {
    EXPECT_EQ(Points(file.result.frames[f].points), direct.frames[static_cast<size_t>(f)]);
  }
  EXPECT_EQ(file.result.dynamics.energy, direct.energy);

  // flexkin render draws it unchanged.
  CliResult render = Cli("render rope.json -o out --formats png,html --quiet");
  ASSERT_EQ(render.exit_code, 0) << render.err;
  EXPECT_TRUE(std::filesystem::exists(Path("out")));
  EXPECT_FALSE(std::filesystem::is_empty(Path("out")));
  // Its plots include the energy.
  render = Cli("render rope.json -o plots --formats plots --quiet");
  ASSERT_EQ(render.exit_code, 0) << render.err;
  EXPECT_TRUE(std::filesystem::exists(Path("plots/rope_energy.svg")));
  EXPECT_TRUE(std::filesystem::exists(Path("plots/rope_energy.png")));

  // --projection and --substeps set the dynamics; --record-every records fewer frames.
  r = Cli("run " + example +
          " -o shake.npz --projection shake --substeps 8 --record-every 60 --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const ResultFile shake = ReadResultFile(Path("shake.npz"));
  EXPECT_EQ(shake.result.dynamics.projection, "shake");
  EXPECT_EQ(shake.result.dynamics.substeps, 8);
  EXPECT_EQ(shake.result.frames.size(), 4);
  DynamicOptions options = *any.chain->dynamics;
  options.projection = Projection::kShake;
  options.substeps = 8;
  const DynamicResult shaken = SimulateChain(any.chain->chain, any.chain->leader_steps, options);
  EXPECT_EQ(Points(shake.result.frames[3].points), shaken.frames[180]);

  // What a dynamic chain cannot take is refused by name, nothing written.
  for (const std::string& option :
       {std::string("--method overall"), std::string("--tolerance 1e-6"),
        std::string("--max-substeps 8")}) {
    SCOPED_TRACE(option);
    r = Cli("run " + example + " -o no.json " + option);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_NE(r.err.find(option.substr(0, option.find(' '))), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(Path("no.json")));
  }
  r = Cli("run " + example + " -o no.json --projection shak");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--projection"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("did you mean \"shake\"?"), std::string::npos) << r.err;
  r = Cli("run " + example + " -o no.json --substeps 0");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--substeps"), std::string::npos) << r.err;
  r = Cli("run '" + Example("fig06_parabola_multi_step.json") + "' -o no.json --projection shake");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--projection"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(Path("no.json")));

  // A bad scenario: named by file and pointer, nothing written.
  json doc = ReadJsonFile(Example("rope_fall.json"));
  doc["dynamics"]["wind_keys"] = {{{"time", 1}, {"velocity", {1, 0}}},
                                  {{"time", 0.5}, {"velocity", {1, 0}}}};
  std::ofstream(Path("bad.json")) << doc.dump();
  v = Cli("validate bad.json");
  EXPECT_EQ(v.exit_code, 1);
  EXPECT_NE(v.out.find("bad.json: /dynamics/wind_keys/1/time"), std::string::npos) << v.out;
  r = Cli("run bad.json -o no.json");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("/dynamics/wind_keys/1/time"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(Path("no.json")));
}

}  // namespace
}  // namespace flexkin
