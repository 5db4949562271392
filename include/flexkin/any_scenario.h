#pragma once
// The one front door for scenario files: every kind (a chain, docs/scenario-format.md; a groom,
// docs/groom-format.md; a robot, docs/robot-format.md) is read here, once, and told apart here.
// The command line and the Python module call this and nothing else to read a scenario, so a kind
// added to the library reaches both.
//
//   const AnyScenario s = ReadScenarioFile("tail.json", {UrdfRobotScenarioOptions()});
//   if (!s.valid()) for (const Problem& p : s.problems) ...;  // every problem, by JSON pointer
//   switch (s.kind) { case ScenarioKind::kChain: Run(s.chain->chain, ...); ... }

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "flexkin/error.h"
#include "flexkin/groom.h"
#include "flexkin/result_io.h"
#include "flexkin/robot_scenario.h"
#include "flexkin/scenario.h"
#include "flexkin/scenario_kind.h"
#include "flexkin/tree_scenario.h"

namespace flexkin {

struct ScenarioReadOptions {
  // How a robot scenario's "urdf" is read and where a relative path is taken from
  // (robot_scenario.h). The default refuses URDF robots; front ends pass
  // UrdfRobotScenarioOptions() (flexkin/urdf.h). directory "": the file's directory for
  // ReadScenarioFile, the working directory for ReadScenarioText.
  RobotScenarioOptions robot;
};

// A scenario of any kind, read and checked.
struct AnyScenario {
  ScenarioKind kind = ScenarioKind::kChain;
  // Every problem found, in the order checked, each named by its JSON pointer ("/leader/steps";
  // "" for the document, e.g. text that is not JSON). Empty if and only if the scenario of `kind`
  // below is set.
  Problems problems;
  std::optional<Scenario> chain;
  std::optional<GroomScenario> groom;
  std::optional<RobotScenario> robot;
  std::optional<TreeScenario> tree;

  bool valid() const { return problems.empty(); }
  // One line, as `flexkin validate` prints it (ScenarioSummary, GroomSummary or
  // RobotScenarioSummary); "" for an invalid scenario.
  std::string Summary() const;
  // Throws InputError for the first problem (its field the JSON pointer); does nothing if valid.
  void ThrowIfInvalid() const;
};

// Parses the text once, tells its kind, checks everything and builds the scenario where there is
// no problem. Problems of the text are listed, never thrown. Throws std::system_error for a URDF
// file a robot scenario names that cannot be read.
AnyScenario ReadScenarioText(const std::string& json_text, const ScenarioReadOptions& options = {});
// The same for the file at `path` (read once); messages do not repeat the path, callers add it.
// Throws std::system_error if the file cannot be read.
AnyScenario ReadScenarioFile(const std::string& path, const ScenarioReadOptions& options = {});

// Where a run of any kind writes: `output` (a chain's result file, .json or .npz; a groom's strand
// file, .npz; a robot's trajectory JSON) and `csv` (a chain's frames CSV, a robot's joint CSV; ""
// for none; a groom has none).
struct ScenarioOutputs {
  std::string output;
  std::string csv;
};

// What a run of any kind did: the report of its kind (the others are left at their defaults).
struct ScenarioRunReport {
  ScenarioKind kind = ScenarioKind::kChain;
  RunResult chain;          // frames not kept: they went to the files
  StrandRunReport strands;  // a groom's
  ArmTrajectory robot;      // the summary; the steps went to the files
  TreeRunResult tree;       // a tree's, its frames included
  // One line: the kind's own brief report.
  std::string BriefReport() const;
};

// A chain scenario (flexkin/scenario.h) into `files` (and `also`, if not null, e.g. arrays), as
// RunScenarioToFiles runs one and Python's run_scenario: a kinematic one by RunToFiles (Run with
// `scenario.options`), a dynamic one ("dynamics", docs/dynamics.md) by SimulateChain from the
// chain at rest, its first point on `leader_steps` (one row per frame), every frame's points
// handed on as the frames of a run (step f: frame f; the initial frame, every
// `options.record_every`-th and the last; no link angles), with RunResult::dynamics (the energy
// at every frame) and the metrics measured between frames. A dynamic run is computed whole
// before its frames are written; `options.progress` is called before and while they are.
// Throws InputError for what DynamicScenarioProblems or RunOptions::Validate finds (by the
// scenario file's JSON pointer), and what the run and the writers throw; nothing is written then.
RunResult RunChainScenario(const Scenario& scenario, const RunFiles& files,
                           FrameSink* also = nullptr);

// The one call that runs a valid scenario of any kind into its files, each streamed while the run
// goes and renamed into place only when complete (RunToFiles, RunGroomToFile, TrackToFiles): the
// command line's `flexkin run` and Python's run_scenario(output=) call it, so a kind added here
// reaches both. `progress(done, total)`, if set, is called now and then and may throw to stop the
// run. Throws InputError for an invalid scenario (its first problem), for an output the kind does
// not write ("csv" for a groom; "output" not ending in .npz for a groom), and what the run throws.
ScenarioRunReport RunScenarioToFiles(const AnyScenario& scenario, const ScenarioOutputs& outputs,
                                     const std::function<void(int64_t, int64_t)>& progress = {});

}  // namespace flexkin
