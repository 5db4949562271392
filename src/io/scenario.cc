#include "flexkin/scenario.h"

#include <algorithm>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/result_io.h"
#include "io/scenario_parser.h"

namespace flexkin {
namespace scenario_internal {

Scenario Parser::Parse(const json& root) {
  Scenario s;
  if (!ExpectObject(root, "", "an object with \"curve\" and \"leader\"")) return s;
  CheckKeys(root, "",
            {"$schema", "name", "description", "curve", "leader", "method", "objective", "solver",
             "record", "accuracy"});
  for (const char* key : {"$schema", "name", "description"}) {
    if (const json* v = Find(root, key)) {
      if (const auto text = String(*v, std::string("/") + key)) {
        if (key == std::string("name")) s.name = *text;
        if (key == std::string("description")) s.description = *text;
      }
    }
  }
  std::optional<Chain> chain;
  if (const json* c =
          Required(root, "", "curve", "an object: {\"points\": [...]} or {\"shape\": ...}")) {
    chain = ParseCurve(*c, "/curve");
  }
  ParseOptions(root, &s.options);
  const bool max_substeps_given = root.contains("accuracy") && root["accuracy"].is_object() &&
                                  root["accuracy"].contains("max_substeps");
  std::optional<Points> steps;
  if (const json* l = Required(root, "", "leader",
                               "an object: {\"path\": [...]} or {\"pull\": [...], \"steps\": n}")) {
    steps = ParseLeader(*l, "/leader", chain ? &*chain : nullptr, &s.options);
  }
  // A large "substeps" raises the default cap rather than contradicting it.
  if (!max_substeps_given)
    s.options.max_substeps = std::max(s.options.max_substeps, s.options.substeps);
  if (!problems.empty()) return s;
  if (const std::string why = s.options.Validate(); !why.empty()) {
    const std::string field = why.substr(0, why.find(':'));
    const std::string pointer = field == "substeps"                      ? "/leader/substeps"
                                : field == "record_every"                ? "/record/every"
                                : field == "tolerance"                   ? "/accuracy/tolerance"
                                : field.rfind("overall.weights.", 0) == 0
                                    ? "/objective/" + field.substr(16)
                                : field == "overall.weights"             ? "/objective"
                                : field.rfind("overall.", 0) == 0        ? "/solver"
                                                                         : "/accuracy/max_substeps";
    Add(pointer, why.substr(why.find(':') + 2));
    return s;
  }
  s.chain = std::move(*chain);
  s.leader_steps = std::move(*steps);
  return s;
}

}  // namespace scenario_internal

using scenario_internal::Parser;

Scenario ParseScenario(const nlohmann::json& json) {
  Parser parser;
  Scenario scenario = parser.Parse(json);
  if (!parser.problems.empty()) {
    throw InputError(parser.problems.front().pointer, parser.problems.front().message);
  }
  return scenario;
}

std::vector<ScenarioProblem> ValidateScenario(const nlohmann::json& json) {
  Parser parser;
  parser.Parse(json);
  return std::move(parser.problems);
}

Scenario LoadScenarioFile(const std::string& path) { return ParseScenario(ReadJsonFile(path)); }

std::string ScenarioSummary(const Scenario& scenario) {
  const Chain& c = scenario.chain;
  const RunOptions& o = scenario.options;
  char total[40];
  std::snprintf(total, sizeof total, "%.6g", c.lengths.sum());
  std::string out = std::to_string(c.dim()) + "D, " + std::to_string(c.num_links()) +
                    (c.num_links() == 1 ? " link" : " links") + " (total length " + total + "), " +
                    std::to_string(scenario.leader_steps.rows()) +
                    (scenario.leader_steps.rows() == 1 ? " leader step" : " leader steps") +
                    ", method " + MethodName(o.method) + ", " + std::to_string(o.substeps) +
                    (o.substeps == 1 ? " sub-step" : " sub-steps");
  if (o.tolerance > 0.0) {
    char tol[40];
    std::snprintf(tol, sizeof tol, "%.3g", o.tolerance);
    out += std::string(" (automatic up to ") + std::to_string(o.max_substeps) + ", tolerance " +
           tol + ")";
  }
  if (o.record_every != 1) out += ", recording every " + std::to_string(o.record_every);
  return out;
}

}  // namespace flexkin
