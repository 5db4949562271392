// The scenario parser's "dynamics" (docs/scenario-format.md, "dynamics"): the options of a dynamic
// chain (flexkin/dynamics.h), and what a scenario with them cannot take.

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "flexkin/dynamics.h"
#include "flexkin/error.h"
#include "flexkin/scenario.h"
#include "flexkin/vocabulary.h"
#include "io/scenario_parser.h"

namespace flexkin {
namespace {

// Whether SimulateChain takes DynamicOptions::colliders yet. While it does not, a scenario with
// both "dynamics" and "colliders" is refused rather than run without them.
constexpr bool kDynamicCollidersTaken = true;

}  // namespace

namespace scenario_internal {

std::optional<DynamicOptions> Parser::ParseDynamics(const json& v, const std::string& ptr,
                                                    const Chain* chain) {
  // The form groom scenarios share (io/dynamics_json.cc); a chain's dimension and links, where
  // the curve was valid.
  return ReadDynamics(v, ptr, chain != nullptr ? chain->dim() : 0,
                      chain != nullptr ? chain->num_links() : 0, /*strands=*/false);
}

}  // namespace scenario_internal

Problems DynamicScenarioProblems(const Scenario& scenario) {
  Problems problems;
  if (!scenario.dynamics) return problems;
  const RunOptions& o = scenario.options;
  const std::string why = " with \"dynamics\" (a dynamic chain, docs/dynamics.md)";
  if (o.method != Method::kTractrix) {
    problems.emplace_back(
        "/method",
        std::string("is \"") + MethodName(o.method) + "\", which is not used" + why +
            ": the chain is moved by inertia and \"dynamics/projection\"; remove \"method\"",
        std::string("\"") + MethodName(o.method) + "\"", "no \"method\" (or \"tractrix\")");
  }
  if (o.substeps != 1) {
    problems.emplace_back("/leader/substeps",
                          "is " + std::to_string(o.substeps) + ", which is not used" + why +
                              ": each leader step is one frame; give the sub-steps per frame as "
                              "\"dynamics/substeps\"",
                          std::to_string(o.substeps), "none (\"dynamics/substeps\")");
  }
  if (o.tolerance > 0.0) {
    problems.emplace_back("/accuracy/tolerance",
                          "accuracy control is not available" + why +
                              "; remove \"accuracy\" and choose \"dynamics/substeps\"",
                          FormatNumber(o.tolerance), "none");
  }
  for (size_t k = 0; k < o.colliders.size(); ++k) {
    if (o.colliders[k].shape == ColliderShape::kMesh) {
      problems.emplace_back("/colliders/" + std::to_string(k),
                            "is a mesh collider, which dynamic chains do not take; expected a "
                            "sphere, capsule, cylinder, box, ellipsoid or half-space" +
                                why);
    }
  }
  if (!kDynamicCollidersTaken && !o.colliders.empty()) {
    problems.emplace_back("/colliders",
                          "are not taken by dynamic chains yet (SimulateChain does not apply "
                          "them); remove \"colliders\" or \"dynamics\"",
                          std::to_string(o.colliders.size()) + " colliders", "none");
  }
  return problems;
}

}  // namespace flexkin
