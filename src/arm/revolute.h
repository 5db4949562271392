#pragma once

#include <optional>
// Spatial arms with revolute joints about given axes (ArmModel::joint_axes, docs/robots.md):
// kinematics and the sweep that keeps every link on the circle of directions its joint allows.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "arm/internal.h"
#include "flexkin/arm.h"
#include "flexkin/error.h"

namespace flexkin::arm_internal {

// The checks of ArmModel::Validate for joint_axes and link_directions: "" or "field: reason".
std::optional<Problem> ValidateAxes(const ArmModel& model);

// Unit direction of link k+1 (0-based k) in its own frame.
Eigen::Vector3d RestDirection(const ArmModel& model, int k);

// The angle (rad, (-pi, pi]) of the rotation about unit `axis` that takes `from` nearest to
// `to` (both in the same frame): the signed angle between their components across the axis;
// 0 where either lies along the axis.
double AngleAbout(const Eigen::Vector3d& axis, const Eigen::Vector3d& from,
                  const Eigen::Vector3d& to);

// Whether the fixed-point sweep (RevoluteSweeper) can move the arm: every joint revolute with
// limits within [-pi, pi], every link of positive length and across its joint's axis.
bool Sweepable(const ArmModel& model);

// The forward kinematics of an arm with joint axes, prepared once for its model. The links'
// rotation R is carried from the base as a matrix: joint j's axis a_j (in the frame of the zero
// pose) is R a_j in the world before the joint turns, and the joint turns R into R Rot(a_j, q_j)
// = c R + s [R a_j]x R + (1 - c) (R a_j) a_j' (Rodrigues, column by column). About a coordinate
// axis (+-x, +-y, +-z: every joint of the usual snakes, whose zero pose is straight) that is a
// plane rotation of two columns (4 products a column), and a link along a coordinate axis is a
// column of R: no normalisation, no quaternion product, no rotation of vectors.
class AxisKinematics {
 public:
  explicit AxisKinematics(const ArmModel& model);
  // The n+1 points at `angle` (n), base first (prismatic joints slide), into `points` (resized
  // to n+1 by 3); with `axes`, each joint's axis in the world (n by 3), as the Jacobian needs;
  // with `last`, the last link's rotation in the world. Allocates nothing once sized.
  void Forward(const Eigen::VectorXd& angle, Points* points, Eigen::MatrixXd* axes = nullptr,
               Eigen::Matrix3d* last = nullptr) const;
  int num_links() const { return static_cast<int>(joints_.size()); }

 private:
  struct Joint {
    int axis_index;    // 0, 1, 2: the axis is axis_sign times that coordinate axis; 3: general
    double axis_sign;  // +-1
    Eigen::Vector3d axis;
    int rest_index;        // the same for the link's rest direction times its length; -1: none
    double rest_sign;      // +-length
    Eigen::Vector3d rest;  // the rest direction times the link's length
    bool prismatic;
  };
  std::vector<Joint> joints_;
  Eigen::Vector3d base_;
};

// Forward kinematics at `angle` (n): the n+1 points, base first (prismatic joints slide).
// With `axes`, also each joint's axis in the world (n by 3), as the Jacobian needs; with
// `last_frame`, the last link's rotation in the world. (AxisKinematics, prepared for one call.)
Points RevoluteForward(const ArmModel& model, const Eigen::VectorXd& angle,
                       Eigen::MatrixXd* axes = nullptr, Eigen::Quaterniond* last_frame = nullptr);
// The angles whose forward kinematics puts every link nearest to the points' link directions
// (exactly, for points that FK produced).
Eigen::VectorXd RevoluteInverse(const ArmModel& model, const Points& points);

// The sweep of one step for these arms, now only for the fixed-point baseline (method
// "fixed_point"): method "newton" solves in joint space (src/arm/joint_space.h). Each link's frame
// is carried from the end effector down: the end-effector link turns by the smallest rotation that
// the tractrix step gives it; every other link's direction, proposed by the tractrix step, is put
// on the cone of directions that its joint with the link above allows (rotation about that joint's
// axis, angle within its limits). The joint angles so found are rebuilt into points from the fixed
// base, and F(u) is the rebuilt end effector minus the target: the same root-finding problem in dim
// = 3 unknowns as the base residual of the other arms (F ~ -(base residual) where frames agree).
class RevoluteSweeper {
 public:
  RevoluteSweeper(const ArmModel& model, const ArmState& start, const Eigen::VectorXd& target,
                  int substeps);
  // Sweeps the start translated by u; returns F(u) and leaves the rebuilt points in points().
  SmallVec Evaluate(const SmallVec& u);
  const Points& points() const { return points_; }
  bool limited() const { return limited_; }
  int sweeps() const { return sweeps_; }

 private:
  const ArmModel& model_;
  const ArmState& start_;
  const Eigen::VectorXd target_;
  const int substeps_, n_;
  std::vector<Eigen::Quaterniond> start_frames_, frames_;
  std::vector<Eigen::Vector3d> axes_, rest_;
  Eigen::VectorXd angle_;
  Points points_;
  bool limited_ = false;
  int sweeps_ = 0;
};

}  // namespace flexkin::arm_internal
