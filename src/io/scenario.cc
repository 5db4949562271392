#include "flexkin/scenario.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "io/json_file.h"
#include "io/scenario_json.h"
#include "io/scenario_kinds.h"
#include "io/scenario_parser.h"

namespace flexkin {
namespace scenario_internal {

Scenario Parser::Parse(const json& root) {
  Scenario s;
  if (!ExpectObject(root, "", "an object with \"curve\" and \"leader\"")) return s;
  CheckKeys(root, "",
            {"$schema", "name", "description", "curve", "leader", "method", "objective", "solver",
             "record", "accuracy", "colliders", "link_radius", "dynamics"});
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
  if (const json* c = Find(root, "colliders"); c != nullptr && chain) {
    ParseColliders(*c, "/colliders", chain->dim(), &s.options.colliders);
  }
  Optional(
      root, "", "link_radius",
      [&](const json& x, const std::string& p) { return Number(x, p, Range::kNonNegative); },
      &s.options.link_radius);
  const bool max_substeps_given = root.contains("accuracy") && root["accuracy"].is_object() &&
                                  root["accuracy"].contains("max_substeps");
  std::optional<Points> steps;
  if (const json* l = Required(root, "", "leader",
                               "an object: {\"path\": [...]} or {\"pull\": [...], \"steps\": n}")) {
    steps = ParseLeader(*l, "/leader", chain ? &*chain : nullptr, &s.options);
  }
  std::optional<DynamicOptions> dynamics;
  if (const json* d = Find(root, "dynamics")) {
    dynamics = ParseDynamics(*d, "/dynamics", chain ? &*chain : nullptr);
  }
  // A large "substeps" raises the default cap rather than contradicting it.
  if (!max_substeps_given)
    s.options.max_substeps = std::max(s.options.max_substeps, s.options.substeps);
  if (!problems.empty()) return s;
  if (const Problems option_problems = s.options.Validate(); !option_problems.empty()) {
    for (const Problem& p : option_problems) problems.push_back(InScenarioFile(p));
    return s;
  }
  s.chain = std::move(*chain);
  s.leader_steps = std::move(*steps);
  s.dynamics = std::move(dynamics);
  for (Problem& p : DynamicScenarioProblems(s)) problems.push_back(std::move(p));
  return s;
}

}  // namespace scenario_internal

using scenario_internal::Parser;

const std::vector<OptionLocation>& RunOptionLocations() {
  static const std::vector<OptionLocation> locations = {
      {"method", "/method", "--method"},
      {"substeps", "/leader/substeps", "--substeps"},
      {"record_every", "/record/every", "--record-every"},
      {"link_angles", "/record/link_angles", "--no-link-angles"},
      {"tolerance", "/accuracy/tolerance", "--tolerance"},
      {"max_substeps", "/accuracy/max_substeps", "--max-substeps"},
      {"colliders", "/colliders", ""},
      {"link_radius", "/link_radius", ""},
      {"overall.weights.", "/objective", ""},
      {"overall.weights", "/objective", ""},
      {"overall.", "/solver", ""},
  };
  return locations;
}

const OptionLocation* FindOptionLocation(const std::string& field) {
  for (const OptionLocation& l : RunOptionLocations()) {
    const std::string f = l.field;
    if (field == f || (f.back() == '.' && field.rfind(f, 0) == 0)) return &l;
  }
  return nullptr;
}

Problem InScenarioFile(Problem problem) {
  if (const OptionLocation* l = FindOptionLocation(problem.field)) {
    const std::string f = l->field;
    std::string pointer = l->pointer;
    if (f.back() == '.') {
      for (char c : problem.field.substr(f.size())) pointer += c == '.' ? '/' : c;
      pointer.insert(std::string(l->pointer).size(), "/");
    }
    problem.field = pointer;
  }
  return problem;
}

namespace internal {
Scenario ReadChainScenario(const nlohmann::json& root, Problems* problems,
                           const std::string& directory) {
  scenario_internal::Parser parser;
  parser.directory = directory;
  Scenario scenario = parser.Parse(root);
  for (Problem& p : parser.problems) problems->push_back(std::move(p));
  return scenario;
}
}  // namespace internal

Scenario ParseScenario(const nlohmann::json& json) {
  Parser parser;
  Scenario scenario = parser.Parse(json);
  ThrowIfAny(parser.problems);
  return scenario;
}

Problems ValidateScenario(const nlohmann::json& json) {
  Parser parser;
  parser.Parse(json);
  return std::move(parser.problems);
}

Scenario ParseScenarioText(const std::string& json_text) {
  return ParseScenario(ParseJsonText(json_text));
}

Problems ValidateScenarioText(const std::string& json_text) {
  nlohmann::json json;
  try {
    json = ParseJsonText(json_text);
  } catch (const InputError& e) {
    return {e.problem()};
  }
  return ValidateScenario(json);
}

Scenario LoadScenarioFile(const std::string& path) { return ParseScenario(ReadJsonFile(path)); }

Problems ValidateScenarioFile(const std::string& path) {
  return ValidateScenarioText(ReadTextFile(path));
}

std::string ScenarioSummary(const Scenario& scenario) {
  const Chain& c = scenario.chain;
  const RunOptions& o = scenario.options;
  char total[40];
  std::snprintf(total, sizeof total, "%.6g", c.lengths.sum());
  std::string out = std::to_string(c.dim()) + "D, " + std::to_string(c.num_links()) +
                    (c.num_links() == 1 ? " link" : " links") + " (total length " + total + "), ";
  if (scenario.dynamics) {
    const DynamicOptions& d = *scenario.dynamics;
    const auto number = [](const char* fmt, double x) {
      char text[40];
      std::snprintf(text, sizeof text, fmt, x);
      return std::string(text);
    };
    const auto vector = [&number](const Eigen::VectorXd& v) {
      std::string text = "[";
      for (Eigen::Index k = 0; k < v.size(); ++k) text += (k ? ", " : "") + number("%.6g", v[k]);
      return text + "]";
    };
    const Eigen::Index frames = scenario.leader_steps.rows();
    out += "dynamic: " + std::to_string(frames) + (frames == 1 ? " frame" : " frames") + " at " +
           number("%.6g", d.frame_rate) + " fps (" +
           number("%.6g", static_cast<double>(frames) / d.frame_rate) + " s), projection " +
           ProjectionName(d.projection) + ", " + std::to_string(d.substeps) +
           (d.substeps == 1 ? " sub-step" : " sub-steps") + ", gravity " + vector(d.gravity);
    if (d.damping > 0.0) out += ", damping " + number("%.6g", d.damping) + " /s";
    if (!d.wind_keys.empty()) {
      out += ", wind in " + std::to_string(d.wind_keys.size()) + " keys";
    } else if (d.wind.size() > 0) {
      out += ", wind " + vector(d.wind);
    }
    out += d.masses.size() > 0 ? ", masses given"
           : d.mass_by_length  ? ", masses by length"
                               : ", uniform masses";
    if (o.record_every != 1) out += ", recording every " + std::to_string(o.record_every);
    return out;
  }
  out += std::to_string(scenario.leader_steps.rows()) +
         (scenario.leader_steps.rows() == 1 ? " leader step" : " leader steps") + ", method " +
         MethodName(o.method) + ", " + std::to_string(o.substeps) +
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
