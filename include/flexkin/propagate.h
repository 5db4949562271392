#pragma once

#include <Eigen/Core>
#include <string>
#include <string_view>

#include "flexkin/chain.h"
#include "flexkin/vocabulary.h"

namespace flexkin {

// How each link's trailing end follows its leading end.
enum class Method {
  kTractrix,  // "tractrix": closed-form tractrix step, velocity along the link (paper Sec. 2-3)
  kFollowTheLeader,  // "ftl": nearest point on the sphere around the new leading end (FABRIK, hair)
  // "min_rotation": sequential minimum body rotation (Sec. 4.1): each link translates, so the
  // whole chain does.
  kMinRotation,
  // "min_joint_angle": sequential minimum joint-angle change (Sec. 4.2): the first link moves by
  // the tractrix step, every later link keeps its angle to the one before: the chain behind the
  // first link moves rigidly with it.
  kMinJointAngle,
  // "overall": all points at once, each step minimizing a metric under the length constraints
  // (paper Sec. 3 and 4; overall.h). Not a link rule: used by Run and OverallStep, not Stepper.
  kOverall,
  // "follow_path": every point is placed on the head's path (the initial points reversed, then
  // the targets), behind the one before it at its link's length (run/follow_path.cc,
  // docs/colliders.md "Follow the path"). Not a link rule: used by Run only.
  kFollowPath,
};

// The method names, defined once (flexkin/vocabulary.h).
template <>
struct Vocabulary<Method> {
  static constexpr const char* kKind = "method";
  static constexpr NamedValue<Method> kEntries[] = {
      {Method::kTractrix, "tractrix",
       "closed-form tractrix step, each point's velocity along its link (sequential)"},
      {Method::kFollowTheLeader, "ftl",
       "follow-the-leader: nearest point on the sphere around the new leading end"},
      {Method::kMinRotation, "min_rotation",
       "sequential minimum body rotation: each link translates (Sec. 4.1)"},
      {Method::kMinJointAngle, "min_joint_angle",
       "sequential minimum joint-angle change: the chain behind the first link moves rigidly "
       "(Sec. 4.2)"},
      {Method::kOverall, "overall",
       "all points at once, minimizing the objective under the length constraints (Sec. 3, 4)"},
      {Method::kFollowPath, "follow_path",
       "every joint on the head's path: each point where the path meets the sphere of its link "
       "around the point before"},
  };
};

inline const char* MethodName(Method method) { return NameOf(method); }
// Throws InputError naming `field` and listing the names.
inline Method ParseMethod(std::string_view name, const std::string& field = "method") {
  return ParseName<Method>(name, field);
}
// Convergence order of the multi-step method to the continuous motion (2 for tractrix, 1 for ftl;
// 0 where it is not established: accuracy control is then not offered).
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
