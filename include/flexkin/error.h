#pragma once
// Bad user input, and the one way flexkin says what is wrong with it.
//
// Every check of an input (options, chains, leader paths, scenario files, robot files, result
// files) reports Problems. A Problem names where (`field`), what was given (`value`) and what
// would be valid (`expected`). C++ inputs name fields by their member paths ("substeps",
// "overall.weights.l2", "points[3]"); files by JSON pointers ("/leader/substeps"). Front ends map
// an option's member path to their own location once (io/option_locations: the scenario key, the
// command-line flag).

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace flexkin {

struct Problem {
  Problem() = default;
  Problem(std::string field, std::string message, std::string value = "", std::string expected = "")
      : field(std::move(field)),
        message(std::move(message)),
        value(std::move(value)),
        expected(std::move(expected)) {}
  // The usual shape: "value <value> is not valid; expected <expected>".
  static Problem Invalid(std::string field, std::string value, std::string expected);

  // Where: a member path ("overall.weights.l2", "points[3]") or a JSON pointer ("/leader/steps");
  // "" for the input as a whole.
  std::string field;
  // What is wrong and what would be valid, without the field, e.g.
  //   "0 is not valid; must be >= 1"
  //   "link 3 has zero length (points 2 and 3 coincide); links must have positive length".
  std::string message;
  // The offending value as text ("0", "nan", "\"tractrx\""); "" where the problem is not one value
  // (a missing key, two values that contradict each other).
  std::string value;
  // What would be valid ("an integer >= 1"); "" where the message says it in other words.
  std::string expected;

  // "field: message", or the message alone when there is no field.
  std::string Text() const;
};

using Problems = std::vector<Problem>;

// Bad user input: a malformed chain, option or file. what() is Problem::Text(), e.g.
//   "points[3]: link 3 has zero length (points 2 and 3 coincide); links must have positive length".
class InputError : public std::invalid_argument {
 public:
  explicit InputError(Problem problem);
  InputError(std::string field, std::string message);

  // Where the problem is: a C++ member path or a JSON pointer into a file ("/leader/steps").
  const std::string& field() const { return problem_.field; }
  // The message without the field.
  const std::string& message() const { return problem_.message; }
  const Problem& problem() const { return problem_; }

 private:
  Problem problem_;
};

// Throws InputError for the first of `problems`; nothing if there are none.
void ThrowIfAny(const Problems& problems);

// Appends `nested` to `*out` with "prefix." before each field ("weights" + "l2" ->
// "weights.l2"; a field that starts with "[" is joined without the dot).
void AppendNested(const std::string& prefix, const Problems& nested, Problems* out);

// A member path as a JSON pointer into the file that holds the members under the same names:
// "frames[3].points[2][1]" -> "/frames/3/points/2/1", "metrics.l2_total" -> "/metrics/l2_total".
std::string MemberPathToPointer(const std::string& path);

// A number for an error message: the shortest of 15 or 17 significant digits that reads back
// as exactly `x` ("0.1", not "0.10000000000000001"); "nan", "inf" and "-inf" as such.
std::string FormatNumber(double x);

}  // namespace flexkin
