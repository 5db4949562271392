#include "flexkin/error.h"

#include <cstdio>
#include <cstdlib>
#include <utility>

namespace flexkin {

Problem Problem::Invalid(std::string field, std::string value, std::string expected) {
  std::string message = "value " + value + " is not valid; expected " + expected;
  return Problem(std::move(field), std::move(message), std::move(value), std::move(expected));
}

std::string Problem::Text() const { return field.empty() ? message : field + ": " + message; }

InputError::InputError(Problem problem)
    : std::invalid_argument(problem.Text()), problem_(std::move(problem)) {}

InputError::InputError(std::string field, std::string message)
    : InputError(Problem(std::move(field), std::move(message))) {}

void ThrowIfAny(const Problems& problems) {
  if (!problems.empty()) throw InputError(problems.front());
}

void AppendNested(const std::string& prefix, const Problems& nested, Problems* out) {
  for (Problem p : nested) {
    if (!prefix.empty()) {
      p.field = p.field.empty() ? prefix : prefix + (p.field[0] == '[' ? "" : ".") + p.field;
    }
    out->push_back(std::move(p));
  }
}

std::string MemberPathToPointer(const std::string& path) {
  std::string out = "/";
  for (const char c : path) {
    if (c == '.' || c == '[') {
      if (out.back() != '/') out += '/';
    } else if (c != ']') {
      out += c;
    }
  }
  return out;
}

std::string FormatNumber(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.15g", x);
  if (std::strtod(buf, nullptr) != x) std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

}  // namespace flexkin
