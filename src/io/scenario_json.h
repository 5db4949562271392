#pragma once
// Scenario documents already parsed as JSON: for the tests, which change documents value by
// value. Everything else takes text or paths (flexkin/scenario.h).

#include <nlohmann/json.hpp>

#include "flexkin/error.h"
#include "flexkin/scenario.h"

namespace flexkin {

// ParseScenarioText and ValidateScenarioText (flexkin/scenario.h) of a parsed document.
Scenario ParseScenario(const nlohmann::json& json);
Problems ValidateScenario(const nlohmann::json& json);

}  // namespace flexkin
