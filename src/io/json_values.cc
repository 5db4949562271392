// The readers of single JSON values shared by every file reader (src/io/json_values.h): each
// reports its problem by JSON pointer.

#include "io/json_values.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/vocabulary.h"

namespace flexkin::json_internal {

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

void JsonReader::TypeProblem(const json& v, const std::string& ptr, const std::string& expected) {
  Add(ptr, "value " + ShowJson(v) + " (" + JsonTypeName(v) + ") is not valid; expected " + expected,
      ShowJson(v), expected);
}

void JsonReader::ValueProblem(const json& v, const std::string& ptr, const std::string& expected) {
  Add(ptr, "value " + ShowJson(v) + " is not valid; expected " + expected, ShowJson(v), expected);
}

bool JsonReader::ExpectObject(const json& v, const std::string& ptr, const std::string& expected) {
  if (v.is_object()) return true;
  TypeProblem(v, ptr, expected);
  return false;
}

void JsonReader::CheckKeys(const json& obj, const std::string& ptr,
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
    Add(ptr + "/" + EscapePointerToken(key), message, "\"" + key + "\"", QuotedList(allowed));
  }
}

const json* JsonReader::Required(const json& obj, const std::string& ptr, const char* key,
                                 const std::string& expected) {
  if (const json* v = Find(obj, key)) return v;
  Add(ptr + "/" + key, "missing; expected " + expected, "", expected);
  return nullptr;
}

std::optional<double> JsonReader::Number(const json& v, const std::string& ptr, Range range) {
  if (!v.is_number()) {
    TypeProblem(v, ptr, Expected(range));
    return std::nullopt;
  }
  const double x = v.get<double>();
  const bool ok = std::isfinite(x) &&
                  (range == Range::kAny || x > 0.0 || (range == Range::kNonNegative && x == 0.0));
  if (!ok) {
    ValueProblem(v, ptr, Expected(range));
    return std::nullopt;
  }
  return x;
}

std::optional<int64_t> JsonReader::Integer(const json& v, const std::string& ptr, int64_t min,
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
    ValueProblem(v, ptr,
                 x < static_cast<double>(min) && x == std::floor(x)
                     ? "an integer >= " + std::to_string(min)
                     : expected);
    return std::nullopt;
  }
  return static_cast<int64_t>(x);
}

std::optional<std::string> JsonReader::String(const json& v, const std::string& ptr) {
  if (v.is_string()) return v.get<std::string>();
  TypeProblem(v, ptr, "a string");
  return std::nullopt;
}

std::optional<std::string> JsonReader::Choice(const json& v, const std::string& ptr,
                                              const std::vector<std::string>& choices) {
  const std::string expected = "one of " + QuotedList(choices);
  if (!v.is_string()) {
    TypeProblem(v, ptr, expected);
    return std::nullopt;
  }
  const std::string s = v.get<std::string>();
  if (std::find(choices.begin(), choices.end(), s) != choices.end()) return s;
  ValueProblem(v, ptr, expected);
  return std::nullopt;
}

std::optional<Eigen::VectorXd> JsonReader::Vector(const json& v, const std::string& ptr, int dim) {
  const std::string expected = dim == 0 ? std::string("an array of 2 or 3 numbers")
                                        : "an array of " + std::to_string(dim) + " numbers (" +
                                              dimension_of_ + " is " + std::to_string(dim) + "D)";
  if (!v.is_array()) {
    TypeProblem(v, ptr, expected);
    return std::nullopt;
  }
  const bool size_ok = dim == 0 ? (v.size() == 2 || v.size() == 3) : v.size() == size_t(dim);
  if (!size_ok) {
    Add(ptr,
        "value " + ShowJson(v) + " has " + std::to_string(v.size()) + " coordinates; expected " +
            expected,
        ShowJson(v), expected);
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

std::optional<Points> JsonReader::PointList(const json& v, const std::string& ptr, int dim,
                                            int min_rows, int64_t max_rows) {
  const std::string expected = "an array of at least " + std::to_string(min_rows) +
                               (min_rows == 1 ? " point" : " points") + " [x, y] or [x, y, z]";
  if (!v.is_array()) {
    TypeProblem(v, ptr, expected);
    return std::nullopt;
  }
  if (v.size() < size_t(min_rows)) {
    Add(ptr,
        "has " + std::to_string(v.size()) + (v.size() == 1 ? " point" : " points") + "; expected " +
            expected,
        "", expected);
    return std::nullopt;
  }
  if (v.size() > size_t(max_rows)) {
    Add(ptr, "has " + std::to_string(v.size()) + " points; expected at most " +
                 std::to_string(max_rows));
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

std::optional<Eigen::VectorXd> JsonReader::NumberList(const json& v, const std::string& ptr,
                                                      int min_size, Range range) {
  const std::string expected = "an array of at least " + std::to_string(min_size) + " " +
                               (min_size == 1 ? "number" : "numbers") +
                               (range == Range::kPositive      ? " > 0"
                                : range == Range::kNonNegative ? " >= 0"
                                                               : "");
  if (!v.is_array()) {
    TypeProblem(v, ptr, expected);
    return std::nullopt;
  }
  if (v.size() < size_t(min_size)) {
    Add(ptr,
        "has " + std::to_string(v.size()) + (v.size() == 1 ? " number" : " numbers") +
            "; expected " + expected,
        ShowJson(v), expected);
    return std::nullopt;
  }
  Eigen::VectorXd out(v.size());
  bool ok = true;
  for (size_t k = 0; k < v.size(); ++k) {
    const auto x = Number(v[k], ptr + "/" + std::to_string(k), range);
    if (x) out[k] = *x;
    ok = ok && x.has_value();
  }
  return ok ? std::optional<Eigen::VectorXd>(out) : std::nullopt;
}

std::optional<Eigen::VectorXd> JsonReader::NumberPerItem(const json& v, const std::string& ptr,
                                                         int size, Range range, const char* what) {
  if (v.is_number()) {
    const auto x = Number(v, ptr, range);
    if (!x) return std::nullopt;
    return Eigen::VectorXd::Constant(std::max(size, 1), *x);
  }
  const std::string count = size > 0 ? std::to_string(size) + " " : std::string();
  const std::string expected =
      std::string(Expected(range)) + " or an array of " + count + "numbers (one per " + what + ")";
  if (!v.is_array()) {
    TypeProblem(v, ptr, expected);
    return std::nullopt;
  }
  if ((size > 0 && v.size() != size_t(size)) || v.empty()) {
    Add(ptr,
        "value " + ShowJson(v) + " has " + std::to_string(v.size()) +
            (v.size() == 1 ? " number" : " numbers") + "; expected " + expected,
        ShowJson(v), expected);
    return std::nullopt;
  }
  return NumberList(v, ptr, 1, range);
}

}  // namespace flexkin::json_internal
