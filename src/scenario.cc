#include "flexkin/scenario.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "flexkin/curves.h"
#include "flexkin/error.h"
#include "flexkin/leader.h"
#include "flexkin/propagate.h"
#include "flexkin/result_io.h"

namespace flexkin {
namespace {

using json = nlohmann::json;

// Upper bound of "substeps", "record/every" and "accuracy/max_substeps": far beyond any useful
// value, small enough for an int.
constexpr int64_t kMaxCount = int64_t{1} << 30;

// Numbers accepted for a floating-point field.
enum class Range { kAny, kPositive, kNonNegative };

const char* Expected(Range range) {
  switch (range) {
    case Range::kPositive:
      return "a finite number > 0";
    case Range::kNonNegative:
      return "a finite number >= 0";
    case Range::kAny:
      break;
  }
  return "a finite number";
}

// A JSON value as it would appear in the file, shortened for a one-line message.
std::string ShowJson(const json& v) {
  std::string text = v.dump(-1, ' ', false, json::error_handler_t::replace);
  if (text.size() > 60) text = text.substr(0, 56) + " ...";
  return text;
}

std::string JsonTypeName(const json& v) {
  switch (v.type()) {
    case json::value_t::object:
      return "an object";
    case json::value_t::array:
      return "an array";
    case json::value_t::string:
      return "a string";
    case json::value_t::boolean:
      return "a boolean";
    case json::value_t::null:
      return "null";
    default:
      return "a number";
  }
}

// A key as one reference token of a JSON pointer (RFC 6901): "~" -> "~0", "/" -> "~1".
std::string EscapePointerToken(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~') {
      out += "~0";
    } else if (c == '/') {
      out += "~1";
    } else {
      out += c;
    }
  }
  return out;
}

// The part of an InputError's message after "field: ".
std::string Reason(const InputError& e) {
  const std::string what = e.what();
  return e.field().empty() ? what : what.substr(e.field().size() + 2);
}

// "center[1]" -> "/center/1": C++ field names of the curve definitions to JSON pointers.
std::string FieldToPointer(const std::string& field) {
  std::string out = "/";
  for (char c : field) {
    if (c == '[') {
      out += '/';
    } else if (c != ']') {
      out += c;
    }
  }
  return out;
}

// Levenshtein distance, to suggest the intended key for a typo.
size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1] ? 1 : 0)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::string Quoted(const std::vector<std::string>& names) {
  std::string out;
  for (size_t i = 0; i < names.size(); ++i) {
    out += (i == 0 ? "\"" : (i + 1 == names.size() ? "\" or \"" : "\", \"")) + names[i];
  }
  return out + "\"";
}

// Collects every problem of a scenario document while building the Scenario. Each Parse* method
// returns nullopt (or false) when its part is unusable, so later checks that depend on it (the
// leader's dimension depends on the curve) are skipped rather than reported twice.
class Parser {
 public:
  Scenario Parse(const json& root);
  std::vector<ScenarioProblem> problems;

 private:
  void Add(const std::string& pointer, std::string message) {
    problems.push_back({pointer, std::move(message)});
  }
  void TypeProblem(const json& v, const std::string& ptr, const std::string& expected) {
    Add(ptr,
        "value " + ShowJson(v) + " (" + JsonTypeName(v) + ") is not valid; expected " + expected);
  }
  bool ExpectObject(const json& v, const std::string& ptr, const std::string& expected);
  void CheckKeys(const json& obj, const std::string& ptr, const std::vector<std::string>& allowed);
  const json* Required(const json& obj, const std::string& ptr, const char* key,
                       const std::string& expected);
  std::optional<double> Number(const json& v, const std::string& ptr, Range range);
  std::optional<int64_t> Integer(const json& v, const std::string& ptr, int64_t min, int64_t max);
  std::optional<std::string> String(const json& v, const std::string& ptr);
  std::optional<std::string> Choice(const json& v, const std::string& ptr,
                                    const std::vector<std::string>& choices);
  std::optional<Eigen::VectorXd> Vector(const json& v, const std::string& ptr, int dim);
  std::optional<Points> PointList(const json& v, const std::string& ptr, int dim, int min_rows);
  std::optional<Chain> ParseCurve(const json& v, const std::string& ptr);
  std::optional<Chain> ParseShape(const json& v, const std::string& ptr);
  std::optional<Points> ParseLeader(const json& v, const std::string& ptr, const Chain* chain,
                                    RunOptions* options);
  void ParseOptions(const json& root, RunOptions* options);

  // Reads obj[key] with `get` into *out if it is there (and valid); Require also reports a
  // missing key.
  template <typename T, typename Get>
  void Optional(const json& obj, const std::string& ptr, const char* key, Get get, T* out) {
    if (const json* v = Find(obj, key)) {
      if (auto value = get(*v, ptr + "/" + key)) *out = *value;
    }
  }
  template <typename T, typename Get>
  void Require(const json& obj, const std::string& ptr, const char* key,
               const std::string& expected, Get get, T* out) {
    if (Required(obj, ptr, key, expected) != nullptr) Optional(obj, ptr, key, get, out);
  }
  // Lets the curve module check and build a shape whose values were all read. Its own checks
  // (radius vs. link length, a zero direction) only run then, so that a default standing in for
  // a bad value is never blamed.
  template <typename Def>
  std::optional<Points> Generate(Def def, int links, double link_length, Points (*make)(const Def&),
                                 const std::string& ptr, size_t problems_before) {
    if (problems.size() != problems_before) return std::nullopt;
    def.links = links;
    def.link_length = link_length;
    const std::vector<InputError> curve_problems = CurveProblems(def);
    for (const InputError& e : curve_problems) Add(ptr + FieldToPointer(e.field()), Reason(e));
    if (!curve_problems.empty()) return std::nullopt;
    return make(def);
  }
  static const json* Find(const json& obj, const char* key) {
    const auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }
};

bool Parser::ExpectObject(const json& v, const std::string& ptr, const std::string& expected) {
  if (v.is_object()) return true;
  TypeProblem(v, ptr, expected);
  return false;
}

void Parser::CheckKeys(const json& obj, const std::string& ptr,
                       const std::vector<std::string>& allowed) {
  for (const auto& item : obj.items()) {
    const std::string& key = item.key();
    if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
    std::string message = "unknown key \"" + key + "\"; valid keys here are " + Quoted(allowed);
    for (const std::string& name : allowed) {
      if (EditDistance(key, name) <= 2) {
        message += " (did you mean \"" + name + "\"?)";
        break;
      }
    }
    Add(ptr + "/" + EscapePointerToken(key), message);
  }
}

const json* Parser::Required(const json& obj, const std::string& ptr, const char* key,
                             const std::string& expected) {
  if (const json* v = Find(obj, key)) return v;
  Add(ptr + "/" + key, "is missing; expected " + expected);
  return nullptr;
}

std::optional<double> Parser::Number(const json& v, const std::string& ptr, Range range) {
  if (!v.is_number()) {
    TypeProblem(v, ptr, Expected(range));
    return std::nullopt;
  }
  const double x = v.get<double>();
  const bool ok = std::isfinite(x) &&
                  (range == Range::kAny || x > 0.0 || (range == Range::kNonNegative && x == 0.0));
  if (!ok) {
    Add(ptr, "value " + ShowJson(v) + " is not valid; expected " + Expected(range));
    return std::nullopt;
  }
  return x;
}

std::optional<int64_t> Parser::Integer(const json& v, const std::string& ptr, int64_t min,
                                       int64_t max) {
  const std::string expected =
      "an integer from " + std::to_string(min) + " to " + std::to_string(max);
  if (!v.is_number()) {
    TypeProblem(v, ptr, expected);
    return std::nullopt;
  }
  // 5.0 is accepted as 5, as JSON Schema's "integer" does.
  const double x = v.get<double>();
  if (!(x == std::floor(x)) || x < static_cast<double>(min) || x > static_cast<double>(max)) {
    Add(ptr, "value " + ShowJson(v) + " is not valid; expected " +
                 (x < static_cast<double>(min) && x == std::floor(x)
                      ? "an integer >= " + std::to_string(min)
                      : expected));
    return std::nullopt;
  }
  return static_cast<int64_t>(x);
}

std::optional<std::string> Parser::String(const json& v, const std::string& ptr) {
  if (v.is_string()) return v.get<std::string>();
  TypeProblem(v, ptr, "a string");
  return std::nullopt;
}

std::optional<std::string> Parser::Choice(const json& v, const std::string& ptr,
                                          const std::vector<std::string>& choices) {
  const std::string expected = "one of " + Quoted(choices);
  if (!v.is_string()) {
    TypeProblem(v, ptr, expected);
    return std::nullopt;
  }
  const std::string s = v.get<std::string>();
  if (std::find(choices.begin(), choices.end(), s) != choices.end()) return s;
  Add(ptr, "value " + ShowJson(v) + " is not valid; expected " + expected);
  return std::nullopt;
}

// An array of `dim` finite numbers; dim 0 accepts 2 or 3.
std::optional<Eigen::VectorXd> Parser::Vector(const json& v, const std::string& ptr, int dim) {
  const std::string expected = dim == 0
                                   ? std::string("an array of 2 or 3 numbers")
                                   : "an array of " + std::to_string(dim) +
                                         " numbers (the curve is " + std::to_string(dim) + "D)";
  if (!v.is_array()) {
    TypeProblem(v, ptr, expected);
    return std::nullopt;
  }
  const bool size_ok = dim == 0 ? (v.size() == 2 || v.size() == 3) : v.size() == size_t(dim);
  if (!size_ok) {
    Add(ptr, "value " + ShowJson(v) + " has " + std::to_string(v.size()) +
                 " coordinates; expected " + expected);
    return std::nullopt;
  }
  Eigen::VectorXd out(v.size());
  bool ok = true;
  for (size_t k = 0; k < v.size(); ++k) {
    const auto x = Number(v[k], ptr + "/" + std::to_string(k), Range::kAny);
    if (x) out[k] = *x;
    ok = ok && x.has_value();
  }
  return ok ? std::optional<Eigen::VectorXd>(out) : std::nullopt;
}

// An array of at least `min_rows` points, all of dimension `dim` (0: that of the first point).
std::optional<Points> Parser::PointList(const json& v, const std::string& ptr, int dim,
                                        int min_rows) {
  const std::string expected = "an array of at least " + std::to_string(min_rows) +
                               (min_rows == 1 ? " point" : " points") + " [x, y] or [x, y, z]";
  if (!v.is_array()) {
    TypeProblem(v, ptr, expected);
    return std::nullopt;
  }
  if (v.size() < size_t(min_rows)) {
    Add(ptr, "has " + std::to_string(v.size()) + (v.size() == 1 ? " point" : " points") +
                 "; expected " + expected);
    return std::nullopt;
  }
  if (v.size() > size_t(kMaxLeaderSteps)) {
    Add(ptr, "has " + std::to_string(v.size()) + " points; expected at most " +
                 std::to_string(kMaxLeaderSteps));
    return std::nullopt;
  }
  bool ok = true;
  Points points;
  for (size_t i = 0; i < v.size(); ++i) {
    const auto p = Vector(v[i], ptr + "/" + std::to_string(i), dim);
    if (!p) {
      ok = false;
      continue;
    }
    if (dim == 0) dim = static_cast<int>(p->size());
    if (points.size() == 0) points.resize(v.size(), dim);
    points.row(i) = p->transpose();
  }
  return ok ? std::optional<Points>(points) : std::nullopt;
}

std::optional<Chain> Parser::ParseCurve(const json& v, const std::string& ptr) {
  const std::string expected =
      "an object: {\"points\": [[x, y], ...]} or {\"shape\": \"line\"|\"parabola\"|\"arc\"|"
      "\"helix\", ...}";
  if (!ExpectObject(v, ptr, expected)) return std::nullopt;
  const bool has_points = v.contains("points"), has_shape = v.contains("shape");
  if (has_points == has_shape) {
    Add(ptr, std::string(has_points ? "has both \"points\" and \"shape\""
                                    : "has neither \"points\" nor \"shape\"") +
                 "; expected " + expected);
    return std::nullopt;
  }
  if (has_shape) return ParseShape(v, ptr);
  CheckKeys(v, ptr, {"points"});
  const auto points = PointList(v["points"], ptr + "/points", 0, 2);
  if (!points) return std::nullopt;
  bool ok = true;
  for (Eigen::Index i = 1; i < points->rows(); ++i) {
    if (points->row(i) == points->row(i - 1)) {
      Add(ptr + "/points/" + std::to_string(i),
          "value " + ShowJson(v["points"][i]) + " equals point " + std::to_string(i - 1) +
              ", so link " + std::to_string(i) +
              " would have zero length; consecutive points must differ");
      ok = false;
    }
  }
  if (!ok) return std::nullopt;
  try {
    return MakeChain(*points);
  } catch (const InputError& e) {  // e.g. a link too long to represent
    Add(ptr + "/points", e.what());
    return std::nullopt;
  }
}

std::optional<Chain> Parser::ParseShape(const json& v, const std::string& ptr) {
  const std::vector<std::string> shapes = {"line", "parabola", "arc", "helix"};
  const auto shape = Choice(v["shape"], ptr + "/shape", shapes);
  if (!shape) return std::nullopt;
  std::vector<std::string> keys = {"shape", "links", "link_length"};
  if (*shape == "line") keys.insert(keys.end(), {"start", "direction"});
  if (*shape == "parabola") keys.insert(keys.end(), {"a", "side"});
  if (*shape == "arc") keys.insert(keys.end(), {"radius", "center", "start_angle", "turn"});
  if (*shape == "helix") {
    keys.insert(keys.end(), {"radius", "pitch", "center", "start_angle", "turn"});
  }
  CheckKeys(v, ptr, keys);

  const size_t before = problems.size();
  const auto integer_links = [this](const json& x, const std::string& p) {
    const auto n = Integer(x, p, 1, kMaxGeneratedLinks);
    return n ? std::optional<int>(static_cast<int>(*n)) : std::nullopt;
  };
  const auto positive = [this](const json& x, const std::string& p) {
    return Number(x, p, Range::kPositive);
  };
  const auto any = [this](const json& x, const std::string& p) {
    return Number(x, p, Range::kAny);
  };
  const auto vector_of = [this](int dim) {
    return [this, dim](const json& x, const std::string& p) { return Vector(x, p, dim); };
  };
  const auto clockwise = [this](const json& x, const std::string& p) {
    const auto turn = Choice(x, p, {"ccw", "cw"});
    return turn ? std::optional<bool>(*turn == "cw") : std::nullopt;
  };
  const auto side = [this](const json& x, const std::string& p) {
    const auto name = Choice(x, p, {"+x", "-x"});
    return name ? std::optional<int>(*name == "+x" ? 1 : -1) : std::nullopt;
  };
  int links = 1;
  double link_length = 1.0;
  Require(v, ptr, "links", "an integer >= 1 (the number of links)", integer_links, &links);
  Require(v, ptr, "link_length", "a finite number > 0 (the length of every link)", positive,
          &link_length);

  std::optional<Points> points;
  if (*shape == "line") {
    LineDef def;
    Optional(v, ptr, "start", vector_of(0), &def.start);
    // "direction" must match a valid "start"; without one it sets the dimension itself.
    const bool has_start = v.contains("start") && problems.size() == before;
    const int dim = has_start ? static_cast<int>(def.start.size()) : 0;
    def.direction = Eigen::VectorXd::Unit(has_start ? dim : 2, 0);
    Optional(v, ptr, "direction", vector_of(dim), &def.direction);
    if (!v.contains("start")) def.start = Eigen::VectorXd::Zero(def.direction.size());
    points = Generate(def, links, link_length, MakeLine, ptr, before);
  } else if (*shape == "parabola") {
    ParabolaDef def;
    Require(v, ptr, "a", "a finite number (y = a x^2)", any, &def.a);
    Optional(v, ptr, "side", side, &def.side);
    points = Generate(def, links, link_length, MakeParabola, ptr, before);
  } else if (*shape == "arc") {
    ArcDef def;
    Require(v, ptr, "radius", "a finite number > 0", positive, &def.radius);
    Optional(v, ptr, "center", vector_of(2), &def.center);
    Optional(v, ptr, "start_angle", any, &def.start_angle);
    Optional(v, ptr, "turn", clockwise, &def.clockwise);
    points = Generate(def, links, link_length, MakeArc, ptr, before);
  } else {
    HelixDef def;
    Require(v, ptr, "radius", "a finite number > 0", positive, &def.radius);
    Require(v, ptr, "pitch", "a finite number (rise along z per turn)", any, &def.pitch);
    Optional(v, ptr, "center", vector_of(3), &def.center);
    Optional(v, ptr, "start_angle", any, &def.start_angle);
    Optional(v, ptr, "turn", clockwise, &def.clockwise);
    points = Generate(def, links, link_length, MakeHelix, ptr, before);
  }
  if (!points) return std::nullopt;
  try {
    return MakeEqualLinkChain(*points, link_length);
  } catch (const InputError& e) {
    Add(ptr, e.what());
    return std::nullopt;
  }
}

std::optional<Points> Parser::ParseLeader(const json& v, const std::string& ptr, const Chain* chain,
                                          RunOptions* options) {
  const std::string expected =
      "an object: {\"path\": [[x, y], ...]}, {\"path\": [...], \"max_step\": s} or "
      "{\"pull\": [dx, dy], \"steps\": n}";
  if (!ExpectObject(v, ptr, expected)) return std::nullopt;
  CheckKeys(v, ptr, {"path", "pull", "steps", "max_step", "substeps"});
  if (const json* s = Find(v, "substeps")) {
    if (const auto n = Integer(*s, ptr + "/substeps", 1, kMaxCount)) {
      options->substeps = static_cast<int>(*n);
    }
  }
  const bool has_path = v.contains("path"), has_pull = v.contains("pull");
  if (has_path == has_pull) {
    Add(ptr, std::string(has_path ? "has both \"path\" and \"pull\""
                                  : "has neither \"path\" nor \"pull\"") +
                 "; expected " + expected);
    return std::nullopt;
  }
  const int dim = chain != nullptr ? chain->dim() : 0;
  const size_t before = problems.size();
  Points steps;
  if (has_pull) {
    if (v.contains("max_step")) {
      Add(ptr + "/max_step", "is only valid with \"path\"; use \"steps\" to split a \"pull\"");
    }
    int64_t count = 1;
    if (const json* s = Find(v, "steps")) {
      if (const auto n = Integer(*s, ptr + "/steps", 1, kMaxLeaderSteps)) count = *n;
    }
    const auto pull = Vector(v["pull"], ptr + "/pull", dim);
    if (problems.size() != before || chain == nullptr) return std::nullopt;
    steps = SplitPull(chain->points.row(0).transpose(), *pull, count);
  } else {
    if (v.contains("steps")) {
      Add(ptr + "/steps", "is only valid with \"pull\"; use \"max_step\" to resample a \"path\"");
    }
    std::optional<double> max_step;
    if (const json* s = Find(v, "max_step")) {
      max_step = Number(*s, ptr + "/max_step", Range::kPositive);
    }
    const auto path = PointList(v["path"], ptr + "/path", dim, 1);
    if (problems.size() != before || chain == nullptr) return std::nullopt;
    if (!max_step) return path;
    try {
      steps = ResamplePath(chain->points.row(0).transpose(), *path, *max_step);
    } catch (const InputError& e) {  // too many steps
      Add(ptr + FieldToPointer(e.field()), Reason(e));
      return std::nullopt;
    }
    if (steps.rows() == 0) {
      Add(ptr + "/path", "every target equals the start " +
                             ShowJson(json(std::vector<double>(
                                 chain->points.row(0).data(), chain->points.row(0).data() + dim))) +
                             ", so there is no leader step; expected a path that moves");
      return std::nullopt;
    }
  }
  return steps;
}

void Parser::ParseOptions(const json& root, RunOptions* options) {
  if (const json* m = Find(root, "method")) {
    if (const auto name = String(*m, "/method")) {
      try {
        options->method = ParseMethod(*name, "/method");
      } catch (const InputError& e) {
        Add(e.field(), "value " + ShowJson(*m) + " is not valid; expected " + MethodNames());
      }
    }
  }
  // The overall method's metric and solver.
  for (const char* key : {"objective", "solver"}) {
    if (Find(root, key) != nullptr && options->method != Method::kOverall) {
      Add(std::string("/") + key, std::string("is used only with \"method\": \"overall\"; ") +
                                      "remove it or set the method to \"overall\"");
    }
  }
  if (const json* o = Find(root, "objective")) {
    if (ExpectObject(*o, "/objective",
                     "an object of term weights, e.g. {\"squared\": 1, \"rotation\": 0.5}")) {
      ObjectiveWeights& w = options->overall.weights;
      const std::pair<const char*, double*> terms[] = {
          {"l2", &w.l2},
          {"l2_weighted", &w.l2_weighted},
          {"squared", &w.squared},
          {"squared_weighted", &w.squared_weighted},
          {"rotation", &w.rotation},
          {"joint_angle", &w.joint_angle}};
      std::vector<std::string> names;
      for (const auto& [name, weight] : terms) names.push_back(name);
      CheckKeys(*o, "/objective", names);
      // Only the terms listed count: {"rotation": 1} is the rotation metric alone.
      for (const auto& [name, weight] : terms) {
        *weight = 0.0;
        Optional(
            *o, "/objective", name,
            [&](const json& v, const std::string& p) { return Number(v, p, Range::kNonNegative); },
            weight);
      }
    }
  }
  if (const json* v = Find(root, "solver")) {
    if (ExpectObject(*v, "/solver",
                     "an object {\"max_iterations\": n, \"constraint_tolerance\": t, "
                     "\"optimality_tolerance\": t}")) {
      CheckKeys(*v, "/solver", {"max_iterations", "constraint_tolerance", "optimality_tolerance"});
      OverallOptions& o = options->overall;
      Optional(
          *v, "/solver", "constraint_tolerance",
          [&](const json& x, const std::string& p) { return Number(x, p, Range::kPositive); },
          &o.constraint_tolerance);
      Optional(
          *v, "/solver", "optimality_tolerance",
          [&](const json& x, const std::string& p) { return Number(x, p, Range::kPositive); },
          &o.optimality_tolerance);
      if (const json* m = Find(*v, "max_iterations")) {
        if (const auto n = Integer(*m, "/solver/max_iterations", 1, 1000000)) {
          o.max_iterations = static_cast<int>(*n);
        }
      }
    }
  }
  if (const json* r = Find(root, "record")) {
    if (ExpectObject(*r, "/record", "an object {\"every\": n}")) {
      CheckKeys(*r, "/record", {"every"});
      if (const json* e = Find(*r, "every")) {
        if (const auto n = Integer(*e, "/record/every", 1, kMaxCount)) {
          options->record_every = static_cast<int>(*n);
        }
      }
    }
  }
  if (const json* a = Find(root, "accuracy")) {
    if (ExpectObject(*a, "/accuracy", "an object {\"tolerance\": t, \"max_substeps\": n}")) {
      CheckKeys(*a, "/accuracy", {"tolerance", "max_substeps"});
      if (const json* t = Find(*a, "tolerance")) {
        if (const auto x = Number(*t, "/accuracy/tolerance", Range::kNonNegative)) {
          options->tolerance = *x;
        }
      }
      if (const json* m = Find(*a, "max_substeps")) {
        if (const auto n = Integer(*m, "/accuracy/max_substeps", 1, kMaxCount)) {
          options->max_substeps = static_cast<int>(*n);
        }
      }
    }
  }
}

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

}  // namespace

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
