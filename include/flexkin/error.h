#pragma once

#include <stdexcept>
#include <string>

namespace flexkin {

// Bad user input: a malformed chain, option or scenario. The message names the offending field,
// its value and what would be valid, e.g.
//   "points[3]: link 3 has zero length (points 2 and 3 coincide); links must have positive length".
class InputError : public std::invalid_argument {
 public:
  InputError(std::string field, const std::string& reason)
      : std::invalid_argument(field.empty() ? reason : field + ": " + reason),
        field_(std::move(field)) {}

  // Where the problem is: a C++ argument name or a JSON pointer into a scenario ("/leader/steps").
  const std::string& field() const { return field_; }

 private:
  std::string field_;
};

// A number for an error message: the shortest of 15 or 17 significant digits that reads back
// as exactly `x` ("0.1", not "0.10000000000000001"); "nan", "inf" and "-inf" as such.
std::string FormatNumber(double x);

}  // namespace flexkin
