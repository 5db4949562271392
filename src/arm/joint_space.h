#pragma once
// The fixed-base step solved in joint space (src/arm/joint_space.cc, docs/robots.md "Revolute
// joints about given axes" and "Joint limits"): Gauss-Newton on the end effector's position whose
// every step is the smallest joint motion in a weighted norm that favours the joints near the end
// effector, with the joint limits as an active set.
//
// Method "newton" uses it for revolute joints about given axes (always), and for planar and
// spherical arms where the tractrix sweep's Newton does not reach a target: with joint limits
// saturated near the end effector the sweep's base residual may have no root, though the target
// is reachable.

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "arm/revolute.h"
#include "flexkin/arm.h"

namespace flexkin::arm_internal {

// W^-1 of the weighted norm (dq)' W (dq): entry k is 1 / (d_k / mean link length)^2, d_k the
// distance along the chain from joint k to the end effector. A joint's lever on the end effector
// grows about as d_k, so its share of a step, w_k^-1 (J' lambda)_k, falls off about as 1 / d_k.
Eigen::VectorXd InverseJointWeights(const ArmModel& model);

// The rotation vector of the smallest rotation taking unit `from` to unit `to`.
Eigen::Vector3d RotationVector(const Eigen::Vector3d& from, const Eigen::Vector3d& to);

// Where pointing aims the tool axis with the end effector at `end`: the unit `direction`, or,
// with `look_at`, toward `point` (`direction` where the end is on that point).
Eigen::Vector3d AimedDirection(bool look_at, const Eigen::Vector3d& point,
                               const Eigen::Vector3d& direction, const Eigen::Vector3d& end);

// What the joint-space solve needs of a model, prepared once for many steps (TrackPath prepares
// it for all of its steps, ArmStep for its one): the weights and, for arms with joint axes, the
// forward kinematics. Holds a reference to the model, which must outlive it.
class JointSpacePlan {
 public:
  explicit JointSpacePlan(const ArmModel& model);
  const ArmModel& model() const { return model_; }
  const Eigen::VectorXd& inverse_weights() const { return winv_; }
  const AxisKinematics& kinematics() const { return *kinematics_; }  // arms with joint axes only

  // The storage of the solves of arms with joint axes, kept from one to the next so that a step
  // allocates nothing; q, points, axes and frame are where the last solve ended (valid), so the
  // next step, starting there, need not compute its forward kinematics again. A plan is used by
  // one thread.
  struct Workspace {
    Eigen::VectorXd q, dq, trial, free_step;
    Points points, trial_points;
    Eigen::MatrixXd axes, trial_axes, jacobian, weighted;
    Eigen::Matrix3d frame, trial_frame;
    std::vector<char> held;
    bool valid = false;
  };
  Workspace& workspace() const { return workspace_; }

 private:
  const ArmModel& model_;
  Eigen::VectorXd winv_;
  std::optional<AxisKinematics> kinematics_;
  mutable Workspace workspace_;
};

struct JointSpaceSolve {
  Points points;                // the arm at the end (n+1 by dim, base first), within the limits
  Eigen::VectorXd angles;       // with joint axes: the joint values of `points`
  double residual = 0.0;        // |end effector - target| (length)
  double angle_residual = 0.0;  // with pointing: the tool axis' angle from its goal (rad)
  double merit = 0.0;           // the residual with the weighted angle (what restarts compare)
  int iterations = 0;           // Gauss-Newton iterations
  int passes = 0;               // forward-kinematics passes over the links (cost ~ passes * n)
  bool converged = false;       // residual <= tol
  bool limited = false;         // a joint ended at one of its limits
  int restarts = 0;             // solves after the first (see SolveJointSpace)
};

// From the arm at `previous` (its angles for revolute joints about axes, otherwise its points;
// with the model's lengths and within its limits) to the end effector at `target`: every
// Gauss-Newton step is the smallest in (dq)' W (dq) that cancels the miss to first order; a
// backtracking line search on the miss, with Levenberg-Marquardt damping where full steps fail; far
// targets through intermediate goals half a link apart. Each iteration is O(n). Never leaves the
// limits; where the target cannot be reached from here it ends at the nearest configuration found
// (no descent left, or max_iterations). The joints:
//   revolute about given axes (model.has_axes()): dq the joint angles; a joint the step would
//     carry past a limit is moved onto it and held, and the rest re-solved (the active set);
//   planar: the same with every axis z;
//   spherical: dq_j a rotation vector (3 components) turning links j+1..n about point j; the
//     bend limit is a cone about link j, and a joint the step would carry out of its cone is
//     turned onto the cone's nearest direction and held.
// Gauss-Newton is local: where it stalls short of the target (held joints blocking the way), up
// to `restarts` more solves (ArmOptions::restarts): with weights that spread the motion more
// evenly, then from random poses around the last one. The first that converges is taken,
// otherwise the nearest end found.
// With pointing.enabled (arms with joint axes), the tool axis is turned to its goal as well
// (ArmOptions::Pointing), and converged means both are within their tolerances.
JointSpaceSolve SolveJointSpace(const JointSpacePlan& plan, const ArmState& previous,
                                const Eigen::VectorXd& target, double tol, int max_iterations,
                                int restarts, const ArmOptions::Pointing& pointing);

}  // namespace flexkin::arm_internal
