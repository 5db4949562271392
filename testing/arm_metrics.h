#pragma once
// Measures for comparing joint trajectories of a fixed-base arm (include/flexkin/arm.h) from
// different solvers (flexkin's TrackPath, KDL's pseudo-inverse in kdl_peer.h): how much each
// joint moves along a path, and where along the arm the motion is.

#include <Eigen/Core>
#include <vector>

#include "flexkin/arm.h"

namespace flexkin::peers {

// How far joint j turns from `from` to `to` (rad). Planar: |to - from| wrapped into [0, pi].
// Spatial: the angle of the relative rotation between the two joint rotations
// (JointQuaternions), in [0, pi].
Eigen::VectorXd JointMotionStep(const ArmModel& model, const JointAngles& from,
                                const JointAngles& to);

// Each joint's total motion along a trajectory (rad): the sum over the steps of
// JointMotionStep, starting from `start` (usually model.initial). n values, base joint first.
Eigen::VectorXd TotalJointMotion(const ArmModel& model, const JointAngles& start,
                                 const std::vector<JointAngles>& steps);

// The joint angles of every step of a flexkin trajectory, in order.
std::vector<JointAngles> AnglesOf(const ArmTrajectory& trajectory);

}  // namespace flexkin::peers
