#pragma once
// The groom scenario reader from a parsed JSON document, for the front door
// (src/scenario/any_scenario.cc): the scenario with its strands grown, and every problem appended
// to `problems` (valid if and only if none was added).

#include <nlohmann/json.hpp>

#include "flexkin/error.h"
#include "flexkin/groom.h"

namespace flexkin::internal {

// A mesh collider's relative "file" is taken from `directory` ("" : the working directory).
GroomScenario ReadGroomScenario(const nlohmann::json& root, Problems* problems,
                                const std::string& directory = "");

}  // namespace flexkin::internal
