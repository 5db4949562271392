#pragma once
// Orocos KDL on a URDF chain, read by Debian's kdl_parser (libkdl-parser-dev) from the same URDF
// text that flexkin's ArmFromUrdf reads (include/flexkin/urdf.h): the reference for flexkin's
// URDF reader (forward kinematics of every joint and of the tool frame) and the peer of the URDF
// benchmark (bench/urdf_kdl_benchmark.cc). For the tests and the benchmark only; not part of the
// installed library. (testing/kdl_peer.h is the other KDL peer: a KDL chain built from an
// ArmModel, not from a URDF.)
//
// The chain is kdl_parser's tree.getChain(base_link, tip_link): one segment per URDF joint on the
// way (fixed joints included, as KDL::Joint::None), base first, and a last fixed segment
// "flexkin_tool_point" carrying UrdfChain::tip_offset, so that the chain's tip frame is the
// end effector with the tip link's rotation. KDL's joint array lists the movable joints in chain
// order: the same order and values as flexkin's JointAngles::angle of ArmFromUrdf (rad, or m for
// prismatic joints).
//
// Tracking: each path point is one call of the position IK, started from the previous step's
// joints (warm start). Two solvers, each with a position-only and a position+pointing form:
//   kNewtonPinv: ChainIkSolverPos_NR + ChainIkSolverVel_pinv. NR's target is a full 6D frame and
//     its stopping test is on every twist component, so
//       position only: the target frame has the orientation the tip had before the step (hold
//         the orientation: 3 task constraints more than flexkin's, which a redundant arm meets);
//       position+pointing: the target frame is the one flexkin reached at that step (its end
//         effector's position is the path point to the tolerance, and its rotation is
//         ToolPoseAt's), given as `target_rotations`. flexkin's pointing fixes 2 rotational
//         degrees of freedom (the tool axis' direction), KDL then fixes all 3: flexkin's roll
//         about the axis is given to KDL, which makes KDL's task the easier one to converge.
//   kLma: ChainIkSolverPos_LMA with task-space weights (1, 1, 1, 0, 0, 0) for position only
//     (exactly flexkin's task), and (1, 1, 1, w, w, w) for position+pointing, with the same target
//     frames as NR and w = KdlUrdfOptions::rotation_weight (length per rad: flexkin's
//     pointing.weight x the mean link length, so that both weigh an angular miss alike).
// Neither solver has joint limits: KDL may leave them (the report counts the steps that do).
// KDL resolves rotations only to about 1e-6 rad: its frame difference (Rotation::GetRot) reads a
// rotation whose matrix is within KDL::epsilon (1e-6) of symmetric as the identity, so neither
// NR's stopping test nor LMA's error sees a smaller angle, and both report success with up to
// ~1e-6 rad left to the target rotation (angle_error below; set angle_tolerance accordingly).

#include <Eigen/Core>
#include <kdl/chain.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/tree.hpp>
#include <string>
#include <vector>

#include "flexkin/arm.h"
#include "flexkin/chain.h"

namespace flexkin::peers {

// A URDF chain in KDL (see above).
struct KdlUrdfChain {
  KDL::Chain chain;
  // Per movable joint (KDL's joint order): the index of its segment in `chain`, and its URDF name.
  std::vector<int> joint_segments;
  std::vector<std::string> joint_names;
  int num_joints() const { return static_cast<int>(joint_segments.size()); }
};

// kdl_parser's chain of the URDF text from base_link ("" = the URDF's root link) to tip_link,
// plus the fixed segment to tip_offset (a point of the tip link's frame). Throws
// std::runtime_error if kdl_parser cannot read the text or there is no such chain.
KdlUrdfChain KdlChainFromUrdf(const std::string& urdf_text, const std::string& base_link,
                              const std::string& tip_link,
                              const Eigen::Vector3d& tip_offset = Eigen::Vector3d::Zero());

// flexkin's joint angles (JointAngles::angle) as KDL's joint array, and back.
KDL::JntArray KdlJointArray(const Eigen::VectorXd& angle);
Eigen::VectorXd AnglesOfJointArray(const KDL::JntArray& q);

// KDL's forward kinematics (ChainFkSolverPos_recursive, each segment's frame) at `q`, in the
// frame of the chain's base link.
struct KdlUrdfPose {
  // (n+1) by 3, base first: row j the origin of movable joint j (the joint frame's origin before
  // its own motion: for a prismatic joint, where it slides from), row n the end effector.
  Points points;
  Eigen::Matrix3d tip_rotation = Eigen::Matrix3d::Identity();  // the tip link's rotation
};
KdlUrdfPose KdlUrdfForward(const KdlUrdfChain& chain, const KDL::JntArray& q);

enum class KdlUrdfSolver { kNewtonPinv, kLma };
const char* KdlUrdfSolverName(KdlUrdfSolver solver);  // "kdl_nr_pinv", "kdl_lma"

struct KdlUrdfOptions {
  // Stop when the end effector is within this distance (length unit, e.g. 1e-10 x the mean link
  // length, as flexkin's ArmOptions::tolerance means). NR: every twist component below it
  // (rotations in rad); LMA: KDL's eps (the weighted error's norm).
  double tolerance = 1e-11;
  // Position+pointing: the largest angle (rad) between the tip rotation reached and the target
  // rotation for the step to count as reached (KDL's resolution is about 1e-6 rad, see above).
  double angle_tolerance = 1e-6;
  // LMA with target rotations: the task-space weight of the three rotation components (length
  // per rad).
  double rotation_weight = 0.1;
  int max_iterations = 500;       // per step (KDL's defaults: NR 100, LMA 500)
  double pinv_eps = 1e-5;         // ChainIkSolverVel_pinv: singular values below it count as 0
  double lma_eps_joints = 1e-15;  // ChainIkSolverPos_LMA: stop when the joint increment is below
};

struct KdlUrdfStep {
  Eigen::VectorXd angles;  // KDL's joints after the step (flexkin's JointAngles::angle)
  Eigen::Vector3d end_effector = Eigen::Vector3d::Zero();
  Eigen::Matrix3d tip_rotation = Eigen::Matrix3d::Identity();
  double ee_error = 0.0;     // |end effector - target| (length unit)
  double angle_error = 0.0;  // with target rotations: the angle to the target rotation (rad)
  int iterations = 0;        // NR: FK evaluations - 1; LMA: lastNrOfIter
  double seconds = 0.0;      // wall time of the solver's CartToJnt
  int status = 0;            // the solver's return code (>= 0: KDL counts it as a solution)
  std::string status_name;   // KDL's strError of `status`
  // status >= 0, finite joints, ee_error <= 2 x tolerance, and with target rotations
  // angle_error <= angle_tolerance.
  bool reached = false;
};

struct KdlUrdfTrajectory {
  std::vector<KdlUrdfStep> steps;  // one per path row
  double max_ee_error = 0.0, max_angle_error = 0.0;
  int unreached = 0;
  int max_iterations = 0;
  double mean_iterations = 0.0;
  double seconds = 0.0;  // sum of the steps' solver times
};

// Tracks `path` (m by 3, in the base link's frame) from `start` (n joint values), one
// warm-started IK per row. `target_rotations`: empty for position only; otherwise one tip
// rotation per row (position+pointing, see above). Throws std::invalid_argument on sizes that do
// not match.
KdlUrdfTrajectory TrackUrdfPathWithKdl(const KdlUrdfChain& chain, const Eigen::VectorXd& start,
                                       const Points& path, KdlUrdfSolver solver,
                                       const KdlUrdfOptions& options,
                                       const std::vector<Eigen::Matrix3d>& target_rotations = {});

// Robot trees (flexkin/robot_tree.h): kdl_parser's tree of the whole URDF text (a segment per
// link, named by the link; each segment's joint named by the URDF joint to it), and its forward
// kinematics by KDL's TreeFkSolverPos_recursive. Throws std::runtime_error if kdl_parser cannot
// read the text.
struct KdlUrdfTree {
  KDL::Tree tree;
  std::vector<std::string> joint_names;  // indexed by KDL's joint numbers (q_nr)
  int num_joints() const { return static_cast<int>(joint_names.size()); }
};
KdlUrdfTree KdlTreeFromUrdf(const std::string& urdf_text);
// KDL's joint array of angles given by name (joints not named stay 0).
KDL::JntArray KdlTreeJoints(const KdlUrdfTree& tree, const std::vector<std::string>& names,
                            const Eigen::VectorXd& angles);
// Link `link`'s frame in the root's frame at `q`: its rotation and origin.
struct KdlLinkPose {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
};
KdlLinkPose KdlTreeLinkPose(const KdlUrdfTree& tree, const KDL::JntArray& q,
                            const std::string& link);
// The link whose segment's joint is the URDF joint `joint` ("" if none).
std::string KdlTreeChildLink(const KdlUrdfTree& tree, const std::string& joint);

}  // namespace flexkin::peers
