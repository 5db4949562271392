#pragma once
// Orocos KDL (Debian's liborocos-kdl-dev) on flexkin's fixed-base arms (include/flexkin/arm.h):
// the Jacobian pseudo-inverse that robotics users would otherwise pick, for the comparison of
// docs/robots.md ("Against the Jacobian pseudo-inverse"). For the tests, the benchmark and the
// example only; not part of the installed library.
//
// The KDL chain of an ArmModel, base first:
//   segment 0: no joint; the frame of the base (translation to model.base, then the rotation
//     taking the world x axis to model.base_direction, as flexkin's base frame).
//   Planar (revolute joints): per link one segment, a joint about z then the translation of the
//     link length along x. KDL joint j = flexkin angle[j].
//   Spatial (spherical joints): per link a universal joint, two revolute joints about z then y,
//     the second with the translation along x: two degrees of freedom per link, as flexkin's
//     twist-free joint (bend and azimuth) has, so that KDL solves the same kinematic model (no
//     twist joint, which would move no point and only enlarge KDL's Jacobian). The two point a
//     link the same way; KdlJoints reads the KDL joints from flexkin's points.
//
// Tracking: each path point is one call of the position IK, started from the previous step's
// joints (warm start, as a controller would), with the solvers made once for the path. Only the
// call (CartToJnt) is timed (KdlStepReport::seconds); the goal's orientation and the points and
// angles read back from the answer are computed outside it. Two solvers:
//   kNewtonPinv: ChainIkSolverPos_NR with ChainIkSolverVel_pinv and ChainFkSolverPos_recursive.
//     NR's stopping test is on the full 6D twist, so a target needs an orientation: it gets the
//     end effector's orientation before the step (hold the orientation). This is the only
//     position-only-like use of NR; it adds 1 (planar) or 3 (spatial) task constraints, which a
//     hyper-redundant arm can always satisfy.
//   kLma: ChainIkSolverPos_LMA with the task-space weights (1, 1, 1, 0, 0, 0): position only,
//     exactly flexkin's task.
// Neither solver has joint limits; models with limits are rejected.

#include <Eigen/Core>
#include <kdl/chain.hpp>
#include <kdl/jntarray.hpp>
#include <string>
#include <vector>

#include "flexkin/arm.h"

namespace flexkin::peers {

enum class KdlSolver { kNewtonPinv, kLma };
const char* KdlSolverName(KdlSolver solver);  // "kdl_nr_pinv", "kdl_lma"

struct KdlOptions {
  // Stop when the end-effector error is below tolerance x the mean link length (the same measure
  // as ArmOptions::tolerance). NR: every twist component below it (rotation in rad, also scaled
  // by the mean link length); LMA: KDL's eps = the same length (its header
  // speaks of the squared error E; the measured errors stay below the tolerance, as a test on the
  // norm would give; the peer checks ee_error itself). Typical 1e-10.
  double tolerance = 1e-10;
  // Iterations per step at most (NR default 100, LMA default 500 in KDL). Typical 500.
  int max_iterations = 500;
  // ChainIkSolverVel_pinv: singular values below this are treated as zero (KDL's default 1e-5).
  double pinv_eps = 1e-5;
  // ChainIkSolverPos_LMA: stop when the joint increments are below this (KDL's default 1e-15).
  double lma_eps_joints = 1e-15;
  // Every problem (empty if valid), each naming its member.
  Problems Validate() const;
};

// Joints per link in the KDL chain: 1 (planar) or 2 (spatial).
int KdlJointsPerLink(const ArmModel& model);
// The KDL chain of `model` (see above). Throws InputError on an invalid model or joint limits.
KDL::Chain KdlChain(const ArmModel& model);
// flexkin's joint angles as KDL joints (planar: the angle; spatial: the universal joint's two
// angles that point each link as flexkin's angles do).
KDL::JntArray KdlJoints(const ArmModel& model, const JointAngles& angles);
// The (n+1) by dim points (base first) of `chain` at `q`, by KDL's ChainFkSolverPos_recursive.
Points KdlPoints(const ArmModel& model, const KDL::Chain& chain, const KDL::JntArray& q);

struct KdlStepReport {
  JointAngles angles;       // flexkin's convention, read from `points` (JointAnglesFromPoints)
  Points points;            // (n+1) by dim, KDL's FK of `q`
  KDL::JntArray q;          // KDL's joints
  double ee_error = 0.0;    // |end effector - target| (length unit)
  int iterations = 0;       // NR: FK evaluations - 1; LMA: lastNrOfIter
  double seconds = 0.0;     // wall time of the solver's CartToJnt
  int status = 0;           // the solver's return code (>= 0: KDL counts it as a solution)
  std::string status_name;  // KDL's strError of `status`
  bool reached = false;     // status >= 0 and ee_error <= 2 x tolerance x mean link length
};

struct KdlTrajectory {
  std::vector<KdlStepReport> steps;  // one per path row
  double max_ee_error = 0.0;
  int unreached = 0;
  double max_iterations = 0, mean_iterations = 0;
  double seconds = 0.0;  // sum of the steps' solver times
};

// Tracks `path` (m by dim) from the model's initial angles, one warm-started IK per row.
// Throws InputError on invalid input.
KdlTrajectory TrackPathWithKdl(const ArmModel& model, const Points& path, KdlSolver solver,
                               const KdlOptions& options);

}  // namespace flexkin::peers
