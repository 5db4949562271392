#pragma once
// The kind of a parsed scenario document, and the readers of the kinds of this layer from a parsed
// document: what the one front door (flexkin/any_scenario.h, src/scenario/any_scenario.cc) calls
// after its one parse (the groom reader is groom/groom_reader.h). Each reader returns the scenario
// and appends every problem to `problems`; the scenario is valid if and only if none was added.

#include <nlohmann/json.hpp>
#include <string>

#include "flexkin/error.h"
#include "flexkin/robot_scenario.h"
#include "flexkin/scenario.h"
#include "flexkin/scenario_kind.h"
#include "flexkin/tree_scenario.h"

namespace flexkin::internal {

// The one place kinds are told apart (docs/scenario-format.md): a robot has "format":
// "flexkin-robot", or "arm" or "urdf" and neither "curve" nor "leader"; a tree has "format":
// "flexkin-tree", or "tree" or "robot"; a groom has "groom" or "strands"; anything else is a chain
// scenario.
ScenarioKind KindOf(const nlohmann::json& root);  // scenario_kind.cc

// A mesh collider's relative "file" is taken from `directory` ("" : the working directory).
Scenario ReadChainScenario(const nlohmann::json& root, Problems* problems,
                           const std::string& directory = "");  // scenario.cc
// Relative "urdf" paths are taken from `directory` ("" : the working directory).
RobotScenario ReadRobotScenario(const nlohmann::json& root, const RobotScenarioOptions& options,
                                const std::string& directory,
                                Problems* problems);  // robot_scenario.cc
// A robot tree's relative "urdf" path is taken from `directory` ("" : the working directory) and
// read with options.urdf_tree_loader.
TreeScenario ReadTreeScenario(const nlohmann::json& root, const RobotScenarioOptions& options,
                              const std::string& directory,
                              Problems* problems);  // tree_scenario.cc

}  // namespace flexkin::internal
