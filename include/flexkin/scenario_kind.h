#pragma once
// The kinds of scenario file, and the one place they are told apart (src/io/scenario_kind.cc).
// The front door that reads any of them is flexkin/any_scenario.h.

#include <string>

#include "flexkin/vocabulary.h"

namespace flexkin {

// The kinds of scenario file.
enum class ScenarioKind {
  kChain,  // "chain": a curve and a motion of its leading end
  kGroom,  // "groom": strands on a moving body
  kRobot,  // "robot": a fixed-base arm and a path of its end effector
  kTree,   // "tree": a branching body, some of its points driven (docs/trees.md)
};

template <>
struct Vocabulary<ScenarioKind> {
  static constexpr const char* kKind = "scenario kind";
  static constexpr NamedValue<ScenarioKind> kEntries[] = {
      {ScenarioKind::kChain, "chain",
       "a curve and a motion of its leading end (docs/scenario-format.md)"},
      {ScenarioKind::kGroom, "groom",
       "strands grown on (or given on) a moving body (docs/groom-format.md)"},
      {ScenarioKind::kRobot, "robot",
       "a fixed-base arm and a path of its end effector (docs/robot-format.md)"},
      {ScenarioKind::kTree, "tree",
       "a branching body, some of its points driven along paths (docs/trees.md)"},
  };
};

// The kind of a scenario from its JSON text: a robot has "format": "flexkin-robot", or "arm" or
// "urdf" and neither "curve" nor "leader"; a tree has "format": "flexkin-tree", or "tree"; a groom
// has "groom" or "strands"; anything else (text that is not JSON included) is read as a chain
// scenario.
ScenarioKind ScenarioKindOfText(const std::string& json_text);

}  // namespace flexkin
