// The scenario parser's readers of single values: each reports its problem by JSON pointer.

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "flexkin/curves.h"
#include "flexkin/error.h"
#include "flexkin/leader.h"
#include "flexkin/propagate.h"
#include "io/scenario_parser.h"

namespace flexkin::scenario_internal {

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
    std::string message = "unknown key \"" + key + "\"; valid keys here are " + QuotedList(allowed);
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
  const std::string expected = "one of " + QuotedList(choices);
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

}  // namespace flexkin::scenario_internal
