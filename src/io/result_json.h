#pragma once
// Result documents already parsed as JSON: for the tests, which change documents value by value.
// Everything else takes text or paths (flexkin/result_io.h).

#include <nlohmann/json.hpp>

#include "flexkin/result_io.h"

namespace flexkin {

// ResultFromText (flexkin/result_io.h) of a parsed document.
ResultFile ResultFromJson(const nlohmann::json& json);

}  // namespace flexkin
