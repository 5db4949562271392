#pragma once
// The one way flexkin reads values out of a JSON document (scenario files, robot scenario files):
// a JsonReader collects every problem, each named by its JSON pointer, in one set of message
// shapes ("value 0 is not valid; expected an integer >= 1", "value "3" (a string) is not valid;
// expected ...", "missing; expected ...", "unknown key ...; did you mean ...?"), and accepts one
// set of number forms (5.0 where an integer is expected, as JSON Schema's "integer" does).
// Private to the library, its tests and its front ends.

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/colliders.h"
#include "flexkin/dynamics.h"
#include "flexkin/error.h"

namespace flexkin::json_internal {

using json = nlohmann::json;

// Numbers accepted for a floating-point field.
enum class Range { kAny, kPositive, kNonNegative };

// "a finite number", "a finite number > 0", "a finite number >= 0".
const char* Expected(Range range);

// A JSON value as it would appear in the file, shortened for a one-line message.
std::string ShowJson(const json& v);

// "an object", "an array", "a string", "a boolean", "null" or "a number".
std::string JsonTypeName(const json& v);

// A key as one reference token of a JSON pointer (RFC 6901): "~" -> "~0", "/" -> "~1".
std::string EscapePointerToken(const std::string& key);

// Reads values of a JSON document, adding a Problem (field: the JSON pointer) for each one that
// is not valid. Each reader returns nullopt when its value is unusable, so that checks depending
// on it can be skipped rather than report the same mistake twice.
class JsonReader {
 public:
  Problems problems;

 protected:
  void Add(const std::string& pointer, std::string message, std::string value = "",
           std::string expected = "") {
    problems.emplace_back(pointer, std::move(message), std::move(value), std::move(expected));
  }
  // "value <v> (<type>) is not valid; expected <expected>": a value of the wrong JSON type.
  void TypeProblem(const json& v, const std::string& ptr, const std::string& expected);
  // "value <v> is not valid; expected <expected>": the right type, a value out of range.
  void ValueProblem(const json& v, const std::string& ptr, const std::string& expected);

  bool ExpectObject(const json& v, const std::string& ptr, const std::string& expected);
  // Reports every key of `obj` outside `allowed`, suggesting the nearest one for a typo.
  void CheckKeys(const json& obj, const std::string& ptr, const std::vector<std::string>& allowed);
  // obj[key], or null after reporting "missing; expected <expected>".
  const json* Required(const json& obj, const std::string& ptr, const char* key,
                       const std::string& expected);
  std::optional<double> Number(const json& v, const std::string& ptr, Range range);
  // An integer in [min, max]; 5.0 counts as 5, 5.5 is refused.
  std::optional<int64_t> Integer(const json& v, const std::string& ptr, int64_t min, int64_t max);
  std::optional<std::string> String(const json& v, const std::string& ptr);
  std::optional<std::string> Choice(const json& v, const std::string& ptr,
                                    const std::vector<std::string>& choices);
  // An array of `dim` finite numbers (a point or a direction); dim 0 accepts 2 or 3.
  std::optional<Eigen::VectorXd> Vector(const json& v, const std::string& ptr, int dim);
  // An array of at least `min_rows` (at most `max_rows`) points, all of dimension `dim` (0: that
  // of the first point).
  std::optional<Points> PointList(const json& v, const std::string& ptr, int dim, int min_rows,
                                  int64_t max_rows);
  // An array of at least `min_size` numbers in `range`.
  std::optional<Eigen::VectorXd> NumberList(const json& v, const std::string& ptr, int min_size,
                                            Range range);
  // One number per item of `size` items (`what`: "joint"): an array of `size` numbers in
  // `range`, or one number for all of them. size 0: the count is not known (an array of any
  // length is read as it is).
  std::optional<Eigen::VectorXd> NumberPerItem(const json& v, const std::string& ptr, int size,
                                               Range range, const char* what);

  // The "interpolation" ("smooth" by default, or "linear") and "keyframes" of a keyframed rigid
  // motion (a groom's "motion", a chain scenario's collider's "motion"; docs/groom-format.md
  // "motion"): at least 1 and at most `max_keyframes` keyframes {"time": t, "translation": [..],
  // "rotation": {..}} (3D) or {"time": t, "translation": [x, y], "angle_deg": a} (2D), times
  // strictly increasing, in `time_unit` ("seconds"). dim 0: the dimension is not known yet. The
  // caller checks `motion`'s keys. Null where a problem was added.
  std::optional<std::pair<std::vector<BodyKeyframe>, KeyframeInterpolation>> ReadKeyframes(
      const json& motion, const std::string& ptr, int dim, const char* time_unit,
      int64_t max_keyframes);

  // "dynamics" (io/dynamics_json.cc; docs/scenario-format.md and docs/groom-format.md): the
  // options of a dynamic chain of `num_links` links (0: not known), or, `strands`, of dynamic
  // strands, which take no "frame_rate" or "substeps" (a groom's are its motion's fps and its
  // "substeps"), no per-point masses and no "shake". dim 0: the dimension is not known (read,
  // checked as far as it goes, nothing returned). Null where a problem was added.
  std::optional<DynamicOptions> ReadDynamics(const json& v, const std::string& ptr, int dim,
                                             int num_links, bool strands);

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
  static const json* Find(const json& obj, const char* key) {
    const auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }

  std::optional<BodyKeyframe> ReadKeyframe(const json& v, const std::string& ptr, int dim,
                                           const char* time_unit);
  // {"axis": [x, y, z], "angle_deg": a} or {"quaternion": [w, x, y, z]} (normalized).
  std::optional<Eigen::Quaterniond> ReadRotation(const json& r, const std::string& ptr);

  // What a Vector's dimension belongs to, for its message: "an array of 2 numbers (the curve is
  // 2D)".
  std::string dimension_of_ = "the curve";
};

}  // namespace flexkin::json_internal
