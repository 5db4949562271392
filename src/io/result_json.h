#pragma once
// Result documents already parsed as JSON: for the tests, which change documents value by value,
// and for the .npz reader, whose result.json holds the summary. Everything else takes text or
// paths (flexkin/result_io.h).

#include <nlohmann/json.hpp>

#include "flexkin/result_io.h"

namespace flexkin {

// ResultFromText (flexkin/result_io.h) of a parsed document.
ResultFile ResultFromJson(const nlohmann::json& json);

// The arrays that an .npz result holds as members rather than in its result.json.
struct ResultArrays {
  Eigen::VectorXd lengths, path_length, l2_per_step, l2_weighted_per_step;
};
// Everything of a result document but its frames, checked as ResultFromJson does (InputError with
// the JSON pointer); with `arrays`, the link lengths and the metrics' arrays are taken from them
// (unchecked: the caller checks their sizes) instead of the document.
void ReadResultSummary(const nlohmann::json& json, const ResultArrays* arrays, ResultFile* file);

// An .npz result file (src/io/result_npz.cc); ReadResultFile's second format.
ResultFile ReadNpzResult(const std::string& path);

}  // namespace flexkin
