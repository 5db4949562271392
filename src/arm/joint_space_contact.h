#pragma once
// The joint-space step of an arm with joint axes among colliders (docs/robots.md "Colliders",
// docs/colliders.md "Robots"): the Gauss-Newton iteration of the free joint-space step
// (src/arm/joint_space.h), each of whose steps is the smallest joint motion in the same weighted
// norm that cancels the end effector's miss to first order, with the link capsules' clearances
// from the colliders, linearized, as inequalities (and the joint limits as bounds) of that
// least-norm problem: a quadratic program solved by a primal active set.

#include <Eigen/Core>
#include <vector>

#include "arm/joint_space.h"
#include "flexkin/arm.h"
#include "flexkin/colliders.h"

namespace flexkin::arm_internal {

// From the arm at `previous` (its joint values) toward the end effector at `target` (3), in
// legs of at most half a mean link length, keeping every link capsule (radius link_radii) outside
// every collider (ungrown; a mesh's clearance linearized at its nearest sample along the link);
// with `pointing` enabled, the tool axis turned to its goal as the free step turns it (in the same
// legs, weighted alike). `out` gets the points, angles, residual, angle residual, iterations and
// whether it converged (residual <= tol, with pointing the angle within pointing.angle_tolerance,
// no capsule inside beyond `slack` of its link's length).
void SolveJointSpaceContact(const JointSpacePlan& plan, const Eigen::VectorXd& previous,
                            const Eigen::VectorXd& target, const std::vector<Collider>& colliders,
                            double tol, double slack, int max_iterations,
                            const ArmOptions::Pointing& pointing, JointSpaceSolve* out);

}  // namespace flexkin::arm_internal
