#pragma once
// A fixed-base arm among colliders (docs/robots.md, "Colliders"): the colliders grown for the
// sweep's contact steps, the clearance of an arm's link capsules, and the refusals of a start or a
// target inside a collider.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "flexkin/arm.h"
#include "flexkin/colliders.h"

namespace flexkin::arm_internal {

// What a link may end a step inside a collider (relative to its length) before the step counts
// as `collided`: the 1e-12 of a link.
constexpr double kArmContactSlack = 1e-12;

// The time a step (or a leg of one) spans, in leader steps, for keyframed colliders
// (Collider::motion; docs/colliders.md, "Moving colliders"): TrackPath's step toward path row i
// spans [i, i + 1], so the state after it (frame i + 1) is at time i + 1; sub-step j of m of a
// sweep is at start + (end - start) j / m (i + j / m for a whole step, as in chain runs).
struct StepWindow {
  double start = 0.0, end = 1.0;
  // Sub-step j (1-based) of m.
  double Substep(int j, int m) const {
    return j == m ? end : start + (end - start) * (double(j) / double(m));
  }
  // Leg `leg` (1-based) of `legs` equal legs; the last ends where this window does.
  StepWindow Leg(int leg, int legs) const { return {Substep(leg - 1, legs), Substep(leg, legs)}; }
};

// `colliders` where their motions have them at `time` (ColliderAt): `colliders` themselves where
// none moves, otherwise *storage, filled.
const std::vector<Collider>& CollidersNow(const std::vector<Collider>& colliders, double time,
                                          std::vector<Collider>* storage);

// The colliders as the sweep's contact step sees them: each grown by the arm's largest link
// radius (exact for a uniform arm, conservative for thinner links) and by a skin (SweepSkin).
std::vector<Collider> SweepColliders(const ArmModel& model, const ArmOptions& options);

// The skin: max(2 x options.tolerance, 1e-8) x mean link length. It absorbs the re-anchoring,
// which shifts the swept points by the base residual when it rebuilds the arm from the fixed
// base: a link the sweep laid on a grown surface stays outside after it, for residuals up to the
// skin (in 3D the contact step is a search whose answer is exact to ~1e-9 of a link across the
// surface, so Newton may stall at such residuals: docs/robots.md).
double SweepSkin(const ArmModel& model, const ArmOptions& options);

// The least clearance of the arm's link capsules (link k: radius link_radii[k-1] about points
// k-1, k; base first) from `colliders`: absolute (length unit) in the return value, and the least
// clearance relative to its link's length in *relative; the link (1-based) and the collider of
// the least relative one in *link and *collider (may be null).
double ArmClearance(const ArmModel& model, const Points& points,
                    const std::vector<Collider>& colliders, double* relative, int* link = nullptr,
                    int* collider = nullptr);

// Throws InputError (field `field`) naming the link, the collider (by index) and the depth if a
// link capsule of `points` lies inside a collider, where its motion has it at `time`, beyond
// kArmContactSlack of its length.
void CheckArmOutside(const ArmModel& model, const Points& points,
                     const std::vector<Collider>& colliders, const std::string& field,
                     double time = 0.0);

// Throws InputError (field `field`) if `target` lies inside a collider grown by the end
// effector's link radius and the sweep's skin (the end effector could not be put there).
// Keyframed colliders are not checked: one that comes onto a target blocks the steps where it
// is there (ArmStepReport::blocked).
void CheckTargetOutside(const ArmModel& model, const ArmOptions& options,
                        const Eigen::VectorXd& target, const std::string& field);

}  // namespace flexkin::arm_internal
