#pragma once
// The scenario parser's internals (src/scenario*.cc): the Parser that collects every problem of a
// scenario document while building the Scenario, and the helpers its messages share.

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "flexkin/curves.h"
#include "flexkin/error.h"
#include "flexkin/scenario.h"
#include "flexkin/vocabulary.h"

namespace flexkin::scenario_internal {

using json = nlohmann::json;

// Upper bound of "substeps", "record/every" and "accuracy/max_substeps": far beyond any useful
// value, small enough for an int.
constexpr int64_t kMaxCount = int64_t{1} << 30;

// Numbers accepted for a floating-point field.
enum class Range { kAny, kPositive, kNonNegative };

inline const char* Expected(Range range) {
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
inline std::string ShowJson(const json& v) {
  std::string text = v.dump(-1, ' ', false, json::error_handler_t::replace);
  if (text.size() > 60) text = text.substr(0, 56) + " ...";
  return text;
}

inline std::string JsonTypeName(const json& v) {
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
inline std::string EscapePointerToken(const std::string& key) {
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

// "center[1]" -> "/center/1": C++ field names of the curve definitions to JSON pointers.
inline std::string FieldToPointer(const std::string& field) { return MemberPathToPointer(field); }

// The library's (flexkin/vocabulary.h).
using flexkin::EditDistance;

// Collects every problem of a scenario document while building the Scenario. Each Parse* method
// returns nullopt (or false) when its part is unusable, so later checks that depend on it (the
// leader's dimension depends on the curve) are skipped rather than reported twice.
class Parser {
 public:
  Scenario Parse(const json& root);
  Problems problems;

 private:
  void Add(const std::string& pointer, std::string message) {
    problems.emplace_back(pointer, std::move(message));
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
    const Problems curve_problems = CurveProblems(def);
    for (Problem p : curve_problems) {
      p.field = ptr + FieldToPointer(p.field);
      problems.push_back(std::move(p));
    }
    if (!curve_problems.empty()) return std::nullopt;
    return make(def);
  }
  static const json* Find(const json& obj, const char* key) {
    const auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }
};

}  // namespace flexkin::scenario_internal
