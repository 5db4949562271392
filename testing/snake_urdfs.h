#pragma once
// URDF texts of common hyper-redundant ("snake") arm designs and of two small arms with the joint
// kinds that issue 15 adds to the URDF reader (prismatic, multi-turn and continuous joints), for
// the tests (tests/urdf_snake_test.cc) and the benchmark (bench/urdf_kdl_benchmark.cc). Each is
// generated here, numbers written with 17 significant digits, so that flexkin's reader
// (include/flexkin/urdf.h) and KDL's kdl_parser (testing/kdl_urdf_peer.h) read the same text.
// Not part of the installed library.
//
// Every design's root link is "base_link" and its end effector's link "tip_link"; every movable
// joint has a <limit> with effort and velocity (continuous joints: velocity and effort only).
// Joint names, base first, are listed by each function's comment: they are what the tests check
// the reader's joint order against.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "flexkin/arm.h"
#include "flexkin/chain.h"

namespace flexkin::snakes {

// The length of one module of the snakes (m).
inline constexpr double kSnakeModuleLength = 0.1;

// Alternating pitch (axis y) and yaw (axis z) revolute joints "joint_0".."joint_{n-1}" (n =
// modules >= 1), limits +-1.2 rad, velocity 2 rad/s. Each module is a "housing_i" link (the
// joint's child), then a fixed joint to a "bracket_i" link half a module further with a small
// rotation of its own in the origin (so no link frame beyond the joints is aligned with the
// world), and the next joint's origin in the bracket's frame undoes that rotation: at angle 0 the
// joints lie along +x, one module apart, every joint frame aligned with the world. The tip link
// "tip_link" sits exactly on the last joint ("tip_joint", fixed, zero translation) with a
// rotation of its own (roll 0.3, pitch -0.2, yaw 0.25 rad): the tool frame of a tip on its joint.
// The end effector is the last joint's origin, so the last link has length 0.
std::string PitchYawSnakeUrdf(int modules);

// Universal-joint modules: "pitch_i" (axis y) at the module's start, then "yaw_i" (axis z) at the
// same point through the massless link "cross_i" (a zero origin), then "link_i" of one module
// length along +x; the tip link's fixed joint "tip_joint" at its end. Limits +-1.0 rad, velocity
// 2 rad/s. 2 x modules joints; link lengths alternate 0 and kSnakeModuleLength.
std::string UniversalSnakeUrdf(int modules);

// Modules of three joints at distinct points: "pitch_i" (axis y) at the module's start, "yaw_i"
// (axis z) 0.4 module further, "roll_i" (axis x, along the link: a twist joint) 0.7 module from
// the start; the next module one module from the start; "tip_joint" after the last one. Limits
// +-1.0 rad (pitch, yaw) and +-2.5 rad (roll), velocity 2 rad/s. 3 x modules joints.
std::string RollSnakeUrdf(int modules);

// A small arm with a prismatic extension: "base_yaw" (z), "shoulder" (y, 0.1 m up), "elbow" (y,
// 0.3 m along x), "extension" (prismatic along x, 0.2 m further, limits [0, 0.3] m, velocity
// 0.5 m/s), "wrist_pitch" (y, 0.1 m beyond), "wrist_roll" (x, along the link, 0.05 m beyond), then
// the fixed "tool_joint" to "tip_link" 0.03 m beyond with the tool frame pitched by pi/2 (its z
// axis along the arm). The tool point is kPrismaticToolOffset in the tip link's frame.
std::string PrismaticArmUrdf();
// The tool point of PrismaticArmUrdf's tip link (UrdfChain::tip_offset): 0.08 m along its z.
Eigen::Vector3d PrismaticToolOffset();

// An arm with multi-turn and continuous joints, all along +x at angle 0, 0.1 m apart:
// "turntable" (continuous, axis z, at the base), "shoulder" (y, +-1.2), "twist_1" (revolute,
// axis z, limits [-2 pi, 2 pi]), "elbow" (y, +-1.2), "roll" (continuous, axis x: along the link),
// "wrist" (z, limits [-2 pi, 2 pi]); "tip_joint" 0.1 m beyond. Reach 0.6 m.
std::string MultiTurnArmUrdf();

// The designs by name, for loops in the tests: "pitch_yaw", "universal", "roll", "prismatic",
// "multi_turn" (the snakes with `modules` modules; the two arms ignore it).
struct SnakeDesign {
  std::string name;
  std::string urdf;
  Eigen::Vector3d tip_offset = Eigen::Vector3d::Zero();
};
std::vector<SnakeDesign> AllSnakeDesigns(int modules);

// Bends an arm read from a URDF (joint_axes) out of its straight, singular rest pose: every joint
// whose axis is y (in its link's frame) turns by pitch_per_joint, z by yaw_per_joint, x (twist)
// by roll_per_joint; each angle is clipped into its limits, and prismatic joints go to the middle
// of theirs. Sets model->initial.
void BendInitial(ArmModel* model, double pitch_per_joint, double yaw_per_joint,
                 double roll_per_joint);

// `steps` targets on a circle of `radius` through `start` (the first target one step past it, the
// last on `start` again after `turns` turns), in the plane through `start` spanned by the unit
// vectors u (from the centre toward `start`) and v, turning from u toward v.
Points CircleThrough(const Eigen::Vector3d& start, const Eigen::Vector3d& u,
                     const Eigen::Vector3d& v, double radius, int steps, double turns = 1.0);
// `steps` targets on the straight line from `start` (excluded) to `end` (the last target).
Points LineTo(const Eigen::Vector3d& start, const Eigen::Vector3d& end, int steps);

}  // namespace flexkin::snakes
