#pragma once

#include <string>
#include <string_view>

#include <Eigen/Core>

#include "flexkin/chain.h"

namespace flexkin {

// How each link's trailing end follows its leading end.
enum class Method {
  kTractrix,         // "tractrix": closed-form tractrix step, velocity along the link (paper Sec. 2-3)
  kFollowTheLeader,  // "ftl": nearest point on the sphere around the new leading end (FABRIK, hair)
  // "overall": all points at once, each step minimizing a metric under the length constraints
  // (paper Sec. 3 and 4; overall.h). Not a link rule: used by Run and OverallStep, not Stepper.
  kOverall,
};

// The one vocabulary for method names, shared by the CLI, files and messages.
const char* MethodName(Method method);
// Parses "tractrix", "ftl" or "overall"; throws InputError naming `field` and listing them.
Method ParseMethod(std::string_view name, const std::string& field = "method");
// Convergence order of the multi-step method to the continuous motion (2 for tractrix, 1 for ftl;
// 0 for overall, whose order is not established).
int MethodOrder(Method method);

// Data precomputed once per chain and reused by every move (the reciprocal link lengths).
struct Stepper {
  Method method = Method::kTractrix;
  int dim = 0;
  Eigen::VectorXd lengths;      // n
  Eigen::VectorXd inv_lengths;  // n, 1 / lengths
};

// Throws InputError if `chain` is not valid (see ValidateChain) or `method` is not a link rule.
Stepper MakeStepper(Method method, const Chain& chain);

// Sequential propagation. The leading end moves in a straight line from its current position to
// `target` in `substeps` equal sub-steps; after each sub-step every link, from the leading end
// down, applies the stepper's rule with its leading end moving along the straight segment between
// its old and new positions. `points` is (n+1) by dim and is updated in place.
// Throws InputError on a target of the wrong size or with non-finite values, or substeps < 1.
void MoveLeader(const Stepper& stepper, const Eigen::Ref<const Eigen::VectorXd>& target,
                int substeps, Points* points);

// Convenience for one-off calls: makes a stepper for `chain` and moves it.
void MoveLeader(Method method, const Eigen::Ref<const Eigen::VectorXd>& target, int substeps,
                Chain* chain);

}  // namespace flexkin
