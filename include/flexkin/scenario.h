#pragma once

#include <optional>
#include <string>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/dynamics.h"
#include "flexkin/run.h"

namespace flexkin {

// A scenario file (JSON, docs/scenario-format.md, docs/schema/scenario.schema.json): an initial
// curve, a motion of its leading end, and the options of the run.
struct Scenario {
  std::string name;         // "name", "" if absent
  std::string description;  // "description", "" if absent
  // From "curve". For a generated shape every link length is exactly "link_length"; for a point
  // list they are the distances between the points (MakeChain).
  Chain chain;
  Points leader_steps;  // m by dim, m >= 1: the targets from "leader", not including the start
  RunOptions options;   // "method", "leader/substeps", "record/every", "accuracy/..."
  // "dynamics" (docs/scenario-format.md, docs/dynamics.md): a dynamic chain, its first point
  // driven along `leader_steps`, one row per frame (SimulateChain's root_path), the others moved
  // by inertia, gravity and the air. Its colliders are `options.colliders` (times in frames, as
  // leader steps), its frames recorded as `options.record_every` says. nullopt: a kinematic run.
  std::optional<DynamicOptions> dynamics;
};

// What a scenario with "dynamics" cannot take, each named by the JSON pointer of the scenario
// file where it is set ("/method", "/leader/substeps", "/accuracy/tolerance", "/colliders/0"):
// a method other than "tractrix", sub-steps of the leader (the frame's are
// "dynamics/substeps"), accuracy control and mesh colliders. Empty for a kinematic scenario. The
// parser and the run (RunChainScenario) check it; options changed after parsing (the command line,
// Python) are checked by the run.
Problems DynamicScenarioProblems(const Scenario& scenario);

// Checks the JSON text of a scenario and builds the scenario. Throws InputError whose field() is
// the JSON pointer of the first problem and whose what() is "pointer: message", e.g.
//   "/leader/steps: value 0 is not valid; expected an integer >= 1";
// for text that is not JSON, the field is empty and the message "line L, column C: invalid JSON:
// <reason>" (a number too large for a double is named by its pointer).
Scenario ParseScenarioText(const std::string& json_text);

// Every problem found in the JSON text of a scenario (unknown keys, wrong types, values out of
// range, inconsistent dimensions, curves that cannot be generated, ...), in the order checked
// (the keys of an object alphabetically); empty if and only if ParseScenarioText would succeed.
// Each problem's field is the JSON pointer of the offending value ("/leader/steps"; "" for the
// whole document). Text that is not JSON is one problem, the one ParseScenarioText throws.
Problems ValidateScenarioText(const std::string& json_text);

// The same for the file at `path`. Messages do not repeat the path; callers add it. Throw
// std::system_error if the file cannot be read.
Scenario LoadScenarioFile(const std::string& path);
Problems ValidateScenarioFile(const std::string& path);

// Colliders from the JSON text of an array in the form of a scenario's "colliders"
// (docs/scenario-format.md), in `dim` dimensions (0: the length of the first collider's "center",
// "from", "point" or "position", 3 for none); a mesh's relative "file" is read from the working
// directory. Throws InputError naming the first problem by JSON pointer ("/colliders/1/radius").
std::vector<Collider> ParseCollidersText(const std::string& json_text, int dim = 0);
// The JSON text of `colliders` in that form, in `dim` dimensions (io's writer; every collider
// must be one the form can say in `dim`: InputError otherwise).
std::string CollidersText(const std::vector<Collider>& colliders, int dim);

// Where a RunOptions member is set: in a scenario file and on the command line. The one map from
// the fields of RunOptions::Validate's problems to the places a user wrote them.
struct OptionLocation {
  const char* field;    // the member ("substeps"); ending in '.', every member below it
  const char* pointer;  // the scenario file's JSON pointer ("/leader/substeps"); for a prefix, the
                        // members below it are appended as keys ("overall.weights.l2" ->
                        // "/objective/l2")
  const char* flag;     // the `flexkin run` option ("--substeps"); "" if there is none
};
const std::vector<OptionLocation>& RunOptionLocations();
// The entry whose field is `field` or a prefix of it; null if none.
const OptionLocation* FindOptionLocation(const std::string& field);
// A problem of RunOptions::Validate with its field as the scenario file's JSON pointer.
Problem InScenarioFile(Problem problem);

// One line: "2D, 20 links (total length 5), 5 leader steps, method tractrix, 1 sub-step"; with
// "dynamics": "2D, 40 links (total length 1), dynamic: 180 frames at 60 fps (3 s), projection
// overall, 4 sub-steps, gravity [0, -9.81], masses by length".
std::string ScenarioSummary(const Scenario& scenario);

}  // namespace flexkin
