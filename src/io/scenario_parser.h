#pragma once
// The scenario parser's internals (src/io/scenario*.cc): the Parser that collects every problem of
// a scenario document while building the Scenario, on the value readers every file reader shares
// (src/io/json_values.h).

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "flexkin/curves.h"
#include "flexkin/dynamics.h"
#include "flexkin/error.h"
#include "flexkin/leader.h"
#include "flexkin/scenario.h"
#include "flexkin/vocabulary.h"
#include "io/json_values.h"

namespace flexkin::scenario_internal {

using json = nlohmann::json;
using json_internal::EscapePointerToken;
using json_internal::JsonTypeName;
using json_internal::Range;
using json_internal::ShowJson;

// Upper bound of "substeps", "record/every" and "accuracy/max_substeps": far beyond any useful
// value, small enough for an int.
constexpr int64_t kMaxCount = int64_t{1} << 30;

// "center[1]" -> "/center/1": C++ field names of the curve definitions to JSON pointers.
inline std::string FieldToPointer(const std::string& field) { return MemberPathToPointer(field); }

// Collects every problem of a scenario document while building the Scenario. Each Parse* method
// returns nullopt (or false) when its part is unusable, so later checks that depend on it (the
// leader's dimension depends on the curve) are skipped rather than reported twice.
class Parser : public json_internal::JsonReader {
 public:
  Scenario Parse(const json& root);
  // "colliders": an array of shapes in `dim` dimensions (scenario_colliders.cc), of a scenario
  // (`whose` "the curve") or a result file ("the result"; io/colliders_json.h).
  void ParseColliders(const json& v, const std::string& ptr, int dim,
                      std::vector<Collider>* colliders, const char* whose = "the curve");
  // Where a mesh collider's relative "file" is (the scenario file's directory; "": the working
  // directory).
  std::string directory;
  // The unit of a keyframed collider's times, for messages ("leader steps"; grooms: "seconds").
  const char* motion_time_unit = "leader steps";

 private:
  // A point list of the curve or the leader's path: at most kMaxLeaderSteps points.
  std::optional<Points> PointList(const json& v, const std::string& ptr, int dim, int min_rows) {
    return JsonReader::PointList(v, ptr, dim, min_rows, kMaxLeaderSteps);
  }
  std::optional<Chain> ParseCurve(const json& v, const std::string& ptr);
  std::optional<Chain> ParseShape(const json& v, const std::string& ptr);
  std::optional<Points> ParseLeader(const json& v, const std::string& ptr, const Chain* chain,
                                    RunOptions* options);
  void ParseOptions(const json& root, RunOptions* options);
  // "dynamics" (scenario_dynamics.cc): the options of a dynamic chain; `chain` null if the curve
  // was not valid (then its dimension is not known and the chain-dependent checks are skipped).
  std::optional<DynamicOptions> ParseDynamics(const json& v, const std::string& ptr,
                                              const Chain* chain);
  std::optional<Collider> ParseCollider(const json& v, const std::string& ptr, int dim);
  void ParseMesh(const json& v, const std::string& ptr, Collider* collider);

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
};

}  // namespace flexkin::scenario_internal
