// The fixed-base step solved in joint space (src/arm/joint_space.h, docs/robots.md).
//
// Why revolute joints about given axes are solved here and not by the tractrix sweep: with such
// joints the sweep's frames, carried down from the end effector, need not meet the base's, and
// rebuilding the arm from the base turns every joint to absorb the mismatch. Measured on the
// 16-link pitch/yaw snake of tests/arm_test.cc (60 targets), Newton on the sweep's translation
// left 34 steps unreached, and even finishing its angles with a joint-space correction (all
// reached) moved each joint 3.6 (end effector) to 0.9 (base) rad in total, against 0.55 to 0.10
// rad here; as a proposal from a single sweep the motion did not even die out (2.4 / 2.9 / 2.0
// rad, end effector / middle / base).
//
// Why planar and spherical arms fall back to it: with limits saturated near the end effector the
// sweep's base residual may have no root although the target is reachable (the bending it needs
// is near the base, where the tractrix motion has died out).
//
// The step: at q with miss r = FK(q) - target and position Jacobian J (column k: joint k's world
// axis cross (end effector - joint k)), the step dq = W^-1 J' (J W^-1 J')^-1 (-r) is the smallest
// in (dq)' W (dq) that cancels r to first order. From the previous pose the first such step is
// the weighted minimum-norm motion; the next ones only remove what curvature leaves (Gauss-Newton
// converges quadratically: 4 to 5 iterations to 1e-10 of a link on the tests).
#include "arm/joint_space.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "arm/internal.h"
#include "arm/revolute.h"

namespace flexkin::arm_internal {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// lambda = (A + ridge)^-1 rhs. A tiny ridge keeps the solve finite where the free joints cannot
// move the end effector along some direction (an arm stretched straight, most joints held; with
// pointing, the roll about the tool axis, which no residual asks for); the Levenberg-Marquardt
// damping is relative to A's trace as well. Only a's lower triangle is read, and `a` is
// overwritten. The ridged matrix is positive definite: its Cholesky factor (T by T, unrolled) is
// what solves it; where rounding leaves a pivot that is not positive, LDLT' with pivoting does.
template <int T>
Eigen::Matrix<double, T, 1> SolveNormal(Eigen::Matrix<double, T, T>* a_io,
                                        const Eigen::Matrix<double, T, 1>& rhs, double damping) {
  Eigen::Matrix<double, T, T>& a = *a_io;
  const double ridge = (1e-14 + damping) * a.trace() + 1e-300;
  a.diagonal().array() += ridge;
  Eigen::Matrix<double, T, T> l;    // lower triangle: A = L L'
  Eigen::Matrix<double, T, 1> inv;  // 1 / L's diagonal (one division a column)
  for (int j = 0; j < T; ++j) {
    double d = a(j, j);
    for (int k = 0; k < j; ++k) d -= l(j, k) * l(j, k);
    if (!(d > 0.0)) return a.template selfadjointView<Eigen::Lower>().ldlt().solve(rhs);
    l(j, j) = std::sqrt(d);
    inv[j] = 1.0 / l(j, j);
    for (int i = j + 1; i < T; ++i) {
      double e = a(i, j);
      for (int k = 0; k < j; ++k) e -= l(i, k) * l(j, k);
      l(i, j) = e * inv[j];
    }
  }
  Eigen::Matrix<double, T, 1> x;
  for (int i = 0; i < T; ++i) {  // L y = rhs
    double e = rhs[i];
    for (int k = 0; k < i; ++k) e -= l(i, k) * x[k];
    x[i] = e * inv[i];
  }
  for (int i = T - 1; i >= 0; --i) {  // L' x = y
    double e = x[i];
    for (int k = i + 1; k < T; ++k) e -= l(k, i) * x[k];
    x[i] = e * inv[i];
  }
  return x;
}

// What a solve aims at: the end effector's position and, with pointing, the direction the tool
// axis should take (a unit vector; for look_at, recomputed from the end effector as it moves).
struct Goal {
  Vec3 position;
  const ArmOptions::Pointing* pointing = nullptr;  // null: position only
  Vec3 direction = Vec3::UnitX();                  // unit; pointing along it (not look_at)
  bool look_at = false;
  Vec3 point = Vec3::Zero();  // with look_at
  Vec3 Direction(const Vec3& end) const { return AimedDirection(look_at, point, direction, end); }
};

// Joints about or along given axes (planar arms embedded with every axis z). The state is the
// joint values q. T = 3: the end effector's position; T = 6: its position and, scaled by
// `angle_scale` (length per rad), the rotation that would turn the tool axis onto its goal.
// Prismatic joints are solved in q / scale (scale the mean link length), so that every column of
// the Jacobian is a length and the weights stay dimensionless (InverseJointWeights).
template <int T>
class RevoluteArm {
 public:
  using Task = Eigen::Matrix<double, T, 1>;

  // `ws`: the storage, sized here; where it holds the pose of the start (the last solve's end),
  // that pose is taken instead of computing the forward kinematics.
  RevoluteArm(const ArmModel& model, const AxisKinematics& kinematics, const Eigen::VectorXd& start,
              const Eigen::VectorXd& winv, double scale, JointSpacePlan::Workspace* ws,
              const Vec3& tool_axis = Vec3::UnitX(), double angle_scale = 0.0)
      : model_(model),
        kinematics_(kinematics),
        n_(model.num_links()),
        limits_(model.joint_min.size() == n_),
        winv_(winv),
        scale_(scale),
        angle_scale_(angle_scale),
        q_(ws->q),
        dq_(ws->dq),
        trial_(ws->trial),
        free_step_(ws->free_step),
        points_(ws->points),
        trial_points_(ws->trial_points),
        axes_(ws->axes),
        trial_axes_(ws->trial_axes),
        frame_(ws->frame),
        trial_frame_(ws->trial_frame),
        jac_(Sized(ws, n_), T, n_),
        wjac_(ws->weighted.data(), T, n_),
        held_(ws->held) {
    const Eigen::Vector4d& t = model.tip_rotation;
    tool_axis_ = Eigen::Quaterniond(t[0], t[1], t[2], t[3]) * tool_axis;
    for (int k = 0; k < n_; ++k) trial_[k] = std::clamp(start[k], lo(k), hi(k));
    if (ws->valid && q_.size() == n_ && q_ == trial_) {
      initial_passes_ = 0;
    } else {
      q_.swap(trial_);
      trial_.resize(n_);
      kinematics_.Forward(q_, &points_, &axes_, &frame_);
      ws->valid = true;
    }
  }
  // Passes over the links that the constructor made: 1, or 0 where it started from the last
  // solve's end.
  int initial_passes() const { return initial_passes_; }
  Vec3 end() const { return points_.row(n_).transpose(); }
  const Points& points() const { return points_; }
  const Eigen::VectorXd& angles() const { return q_; }
  bool limited() const {
    for (int k = 0; k < n_ && limits_; ++k) {
      if (q_[k] <= lo(k) || q_[k] >= hi(k)) return true;
    }
    return false;
  }
  // The tool axis in the world.
  Vec3 axis() const { return frame_ * tool_axis_; }
  Task Miss(const Goal& goal) const { return MissAt(points_, frame_, goal); }
  Task TrialMiss(const Goal& goal) const { return MissAt(trial_points_, trial_frame_, goal); }
  // Whether the miss is within the tolerances (position; angle in rad).
  bool Within(const Task& r, double tol, double angle_tol) const {
    if constexpr (T == 3) {
      (void)angle_tol;
      return r.norm() <= tol;
    } else {
      return r.template head<3>().norm() <= tol &&
             r.template tail<3>().norm() <= angle_tol * angle_scale_;
    }
  }
  double AngleMiss(const Task& r) const {
    if constexpr (T == 3) {
      (void)r;
      return 0.0;
    } else {
      return r.template tail<3>().norm() / angle_scale_;
    }
  }

  // The step for the miss r. The active set: a joint that the step would carry past a limit is
  // moved onto that limit and held there, and the rest of the step re-solved for what it leaves
  // of the miss (each round holds at least one more joint: at most n rounds).
  bool Propose(const Task& r, double damping, const Goal& goal) {
    const Vec3 ee = end();
    Vec3 a_w = Vec3::Zero();
    double look = 0.0;  // looking at a point: 1 / its distance (the goal turns as the end moves)
    if constexpr (T == 6) {
      a_w = axis();
      if (goal.look_at && (goal.point - ee).norm() > 0.0) look = 1.0 / (goal.point - ee).norm();
    }
    for (int k = 0; k < n_; ++k) {
      const Vec3 axis = axes_.row(k).transpose();
      if (model_.prismatic(k)) {
        jac_.col(k).template head<3>() = axis * scale_;
        if constexpr (T == 6) jac_.col(k).template tail<3>().setZero();
      } else {
        jac_.col(k).template head<3>() = axis.cross(ee - Vec3(points_.row(k).transpose()));
        // The tool axis turns with w x a_w: only w across a_w counts.
        if constexpr (T == 6) {
          jac_.col(k).template tail<3>() = angle_scale_ * (axis - axis.dot(a_w) * a_w);
        }
      }
      // Looking at a point, the goal direction t = (point - end) / |point - end| turns as the
      // end effector moves: d(a x t) = a x dt, dt = -(I - t t') d(end) / |point - end|.
      if constexpr (T == 6) {
        if (look > 0.0) {
          const Vec3 move = jac_.col(k).template head<3>();
          jac_.col(k).template tail<3>() += angle_scale_ * look * a_w.cross(move);
        }
      }
    }
    std::fill(held_.begin(), held_.end(), 0);
    dq_.setZero();
    // W^-1 J' by rows (a held joint's column is zeroed): the normal matrix J W^-1 J' is then
    // T(T+1)/2 dot products of rows, contiguous in memory.
    for (int i = 0; i < T; ++i) wjac_.row(i) = jac_.row(i).cwiseProduct(winv_.transpose());
    for (int round = 0; round <= n_; ++round) {
      Eigen::Matrix<double, T, T> a;
      for (int i = 0; i < T; ++i) {
        for (int j = 0; j <= i; ++j) a(i, j) = wjac_.row(i).dot(jac_.row(j));  // lower triangle
      }
      Task rhs = -r;
      for (int k = 0; k < n_ && round > 0; ++k) {
        if (held_[k]) rhs -= jac_.col(k) * dq_[k];
      }
      const Task lambda = SolveNormal<T>(&a, rhs, damping);
      free_step_.noalias() = wjac_.transpose() * lambda;  // W^-1 J' lambda (0 for held joints)
      bool more = false;
      for (int k = 0; k < n_; ++k) {
        if (held_[k]) continue;
        dq_[k] = free_step_[k];
        const double unit = unit_of(k);
        const double to = std::clamp(q_[k] + unit * dq_[k], lo(k), hi(k));
        if (to != q_[k] + unit * dq_[k]) {
          dq_[k] = (to - q_[k]) / unit;
          held_[k] = 1;
          wjac_.col(k).setZero();
          more = true;
        }
      }
      if (!more) break;
    }
    return dq_.allFinite();
  }
  // The arm at q + alpha dq (the clamp only guards against rounding: the limits are an interval).
  void Try(double alpha) {
    for (int k = 0; k < n_; ++k) {
      trial_[k] = std::clamp(q_[k] + alpha * (unit_of(k) * dq_[k]), lo(k), hi(k));
    }
    kinematics_.Forward(trial_, &trial_points_, &trial_axes_, &trial_frame_);
  }
  void Accept() {
    q_.swap(trial_);
    points_.swap(trial_points_);
    axes_.swap(trial_axes_);
    frame_ = trial_frame_;
  }

 private:
  double lo(int k) const { return limits_ ? model_.joint_min[k] : -INFINITY; }
  double hi(int k) const { return limits_ ? model_.joint_max[k] : INFINITY; }
  // The joint value per unit of the solved variable: 1 (rad), or the scale for a prismatic joint.
  double unit_of(int k) const { return model_.prismatic(k) ? scale_ : 1.0; }
  Task MissAt(const Points& points, const Mat3& frame, const Goal& goal) const {
    const Vec3 end = points.row(n_).transpose();
    Task r;
    r.template head<3>() = end - goal.position;
    if constexpr (T == 6) {
      const Vec3 a_w = frame * tool_axis_;
      r.template tail<3>() = -angle_scale_ * RotationVector(a_w, goal.Direction(end));
    }
    return r;
  }

  const ArmModel& model_;
  const AxisKinematics& kinematics_;
  const int n_;
  const bool limits_;
  const Eigen::VectorXd& winv_;
  const double scale_, angle_scale_;
  Vec3 tool_axis_;  // in the last link's frame
  // The workspace's storage (JointSpacePlan::Workspace).
  Eigen::VectorXd &q_, &dq_, &trial_, &free_step_;
  Points &points_, &trial_points_;
  Eigen::MatrixXd &axes_, &trial_axes_;
  Mat3 &frame_, &trial_frame_;
  // The Jacobian (T by n; row k of J' per joint) and W^-1 J', stored by rows.
  using Rows = Eigen::Map<Eigen::Matrix<double, T, Eigen::Dynamic, Eigen::RowMajor>>;
  Rows jac_, wjac_;
  std::vector<char>& held_;
  int initial_passes_ = 1;

  // Sizes the workspace's vectors for n joints; the Jacobian's storage (T by n).
  static double* Sized(JointSpacePlan::Workspace* ws, int n) {
    ws->dq.resize(n);
    ws->trial.resize(n);
    ws->free_step.resize(n);
    ws->held.resize(n);
    ws->jacobian.resize(T, n);
    ws->weighted.resize(T, n);
    return ws->jacobian.data();
  }
};

// exp of a rotation vector.
Eigen::Quaterniond Exp(const Vec3& w) {
  const double angle = w.norm();
  if (!(angle > 0.0)) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, w / angle));
}

// Spherical joints. The state is the links' unit directions d_1..d_n (d_0 the base direction);
// joint j's step is a rotation vector w_j turning links j+1..n about point j, so the end effector
// moves by w_j x (end effector - point j) to first order. Applied from the end effector down,
// link k turns by exp(w_0) ... exp(w_{k-1}), and joint j's bend, the angle between d_j and d_{j+1},
// becomes the angle between d_j and exp(w_j) d_{j+1}: each joint's limit involves its own w_j only.
class SphericalArm {
 public:
  SphericalArm(const ArmModel& model, const Points& start, const Eigen::VectorXd& winv)
      : model_(model),
        n_(model.num_links()),
        limits_(model.max_bend.size() == n_),
        winv_(winv),
        dirs_(n_ + 1),
        trial_dirs_(n_ + 1),
        omega_(n_),
        lever_(n_),
        held_(n_) {
    dirs_[0] = model.base_direction.head<3>().normalized();
    trial_dirs_[0] = dirs_[0];
    for (int k = 1; k <= n_; ++k) {
      dirs_[k] = (start.row(k) - start.row(k - 1)).transpose().normalized();
      if (limits_)
        ClampDirection(3, dirs_[k - 1].data(), 0.0, model.max_bend[k - 1], dirs_[k].data());
    }
    points_.resize(n_ + 1, 3);
    points_.row(0) = model.base.transpose();
    for (int k = 1; k <= n_; ++k) {
      points_.row(k) = points_.row(k - 1) + model.link_lengths[k - 1] * dirs_[k].transpose();
    }
    trial_points_ = points_;
  }
  using Task = Vec3;
  Vec3 end() const { return points_.row(n_).transpose(); }
  const Points& points() const { return points_; }
  int initial_passes() const { return 1; }  // the constructor's pass over the links
  Task Miss(const Goal& goal) const { return end() - goal.position; }
  Task TrialMiss(const Goal& goal) const {
    return trial_points_.row(n_).transpose() - goal.position;
  }
  bool Within(const Task& r, double tol, double) const { return r.norm() <= tol; }
  double AngleMiss(const Task&) const { return 0.0; }
  bool limited() const {
    for (int j = 0; j < n_ && limits_; ++j) {
      if (std::acos(std::clamp(dirs_[j].dot(dirs_[j + 1]), -1.0, 1.0)) >=
          model_.max_bend[j] - 1e-12) {
        return true;
      }
    }
    return false;
  }

  // The step for the miss r, with the same active set as RevoluteArm's: a joint that the step
  // would carry out of its cone is turned onto the cone's nearest direction and held.
  bool Propose(const Vec3& r, double damping, const Goal&) {
    const Vec3 ee = end();
    for (int j = 0; j < n_; ++j) lever_[j] = ee - points_.row(j).transpose();
    std::fill(held_.begin(), held_.end(), 0);
    for (int round = 0; round <= n_; ++round) {
      Mat3 a = Mat3::Zero();
      Vec3 rhs = -r;
      for (int j = 0; j < n_; ++j) {
        const Vec3& l = lever_[j];
        if (held_[j]) {
          rhs -= omega_[j].cross(l);
        } else {  // J_j J_j' for J_j w = w x l
          a.noalias() += winv_[j] * (l.squaredNorm() * Mat3::Identity() - l * l.transpose());
        }
      }
      const Vec3 lambda = SolveNormal<3>(&a, rhs, damping);
      bool more = false;
      for (int j = 0; j < n_; ++j) {
        if (held_[j]) continue;
        omega_[j] = winv_[j] * lever_[j].cross(lambda);
        if (!limits_) continue;
        Vec3 to = Exp(omega_[j]) * dirs_[j + 1];
        if (ClampDirection(3, dirs_[j].data(), 0.0, model_.max_bend[j], to.data())) {
          omega_[j] = RotationVector(dirs_[j + 1], to);
          held_[j] = 1;
          more = true;
        }
      }
      if (!more) break;
    }
    for (const Vec3& w : omega_) {
      if (!w.allFinite()) return false;
    }
    return true;
  }
  // The arm after alpha times the step, every joint put back into its cone (on a curved step a
  // free joint may leave it between alpha = 0 and 1).
  void Try(double alpha) {
    Eigen::Quaterniond turn = Eigen::Quaterniond::Identity();
    for (int j = 0; j < n_; ++j) {
      Eigen::Quaterniond step = Exp(alpha * omega_[j]);
      if (limits_) {
        const Vec3 to = step * dirs_[j + 1];
        Vec3 in = to;
        if (ClampDirection(3, dirs_[j].data(), 0.0, model_.max_bend[j], in.data())) {
          step = Eigen::Quaterniond::FromTwoVectors(to, in) * step;
        }
      }
      turn = (turn * step).normalized();
      trial_dirs_[j + 1] = (turn * dirs_[j + 1]).normalized();
      trial_points_.row(j + 1) =
          trial_points_.row(j) + model_.link_lengths[j] * trial_dirs_[j + 1].transpose();
    }
  }
  void Accept() {
    dirs_.swap(trial_dirs_);
    points_.swap(trial_points_);
    trial_points_.row(0) = points_.row(0);
    trial_dirs_[0] = dirs_[0];
  }

 private:
  const ArmModel& model_;
  const int n_;
  const bool limits_;
  const Eigen::VectorXd& winv_;
  std::vector<Vec3> dirs_, trial_dirs_, omega_, lever_;
  Points points_, trial_points_;
  std::vector<char> held_;
};

// Gauss-Newton with line search, damping and intermediate goals, on either arm. `angle_tol`:
// the pointing tolerance (rad), with pointing.
template <class Arm>
JointSpaceSolve Drive(Arm* arm, double scale, const Goal& target, double tol, double angle_tol,
                      int max_iterations) {
  using Task = typename Arm::Task;
  JointSpaceSolve out;
  out.passes = arm->initial_passes();  // the arm's first forward kinematics
  Task r;
  // Gauss-Newton toward `goal` until the miss is within `goal_tol` (or no descent is left).
  auto solve_to = [&](const Goal& goal, double goal_tol, double goal_angle_tol, int max_it) {
    r = arm->Miss(goal);
    double damping = 0.0;
    for (int it = 0; it < max_it && !arm->Within(r, goal_tol, goal_angle_tol); ++it) {
      ++out.iterations;
      if (!arm->Propose(r, damping, goal)) break;
      // Backtracking on the miss (every trial is within the limits).
      bool improved = false;
      double taken = 0.0;  // the step length accepted
      for (double alpha = 1.0; alpha > 1e-9 && !improved; alpha *= 0.5) {
        arm->Try(alpha);
        const Task r_trial = arm->TrialMiss(goal);
        ++out.passes;
        if (r_trial.allFinite() && r_trial.norm() <= (1.0 - 1e-4 * alpha) * r.norm()) {
          arm->Accept();
          r = r_trial;
          improved = true;
          taken = alpha;
        }
      }
      // Levenberg-Marquardt damping: raised where the full step did not do (a poor
      // linearisation, far from the goal), dropped again after full steps, so the last
      // iterations are pure Gauss-Newton and converge quadratically.
      if (improved && taken == 1.0) {
        damping = damping < 1e-8 ? 0.0 : damping * 0.25;
      } else if (damping < 1e3) {
        damping = std::max(damping * 4.0, 1e-4);
        continue;
      }
      if (!improved) break;  // no descent left: the nearest configuration the free joints give
    }
  };
  // A far target is approached through intermediate ones on the straight line from the end
  // effector, at most kLeg mean link lengths apart: one solve across a large move linearises
  // badly and stalls more often (single jumps of the 64-link snake to 200 random reachable
  // targets: 135 unreached without legs, 80 with), while each short leg converges in a few
  // iterations, its motion again carried by the joints near the end effector, as the tractrix
  // step moves a chain whose end is dragged along a line. The legs need not be reached exactly
  // (kLegTol); the target must. With pointing, the tool axis is turned toward its goal along the
  // great circle in the same legs, at most kLegAngle rad apart.
  constexpr double kLeg = 0.5, kLegTol = 1e-3, kLegAngle = 0.5;
  constexpr int kLegIterations = 20;
  const Vec3 from = arm->end();
  int legs = static_cast<int>(std::ceil((target.position - from).norm() / (kLeg * scale)));
  Vec3 turn = Vec3::Zero();  // the tool axis' rotation to its goal, with pointing
  Vec3 axis_from = Vec3::UnitX();
  if constexpr (Arm::Task::RowsAtCompileTime == 6) {
    axis_from = arm->axis();
    turn = RotationVector(axis_from, target.Direction(target.position));
    legs = std::max(legs, static_cast<int>(std::ceil(turn.norm() / kLegAngle)));
  }
  for (int leg = 1; leg < legs; ++leg) {
    const double t = double(leg) / legs;
    Goal goal = target;
    goal.position = from + (target.position - from) * t;
    if constexpr (Arm::Task::RowsAtCompileTime == 6) {
      goal.look_at = false;
      goal.direction =
          Eigen::AngleAxisd(t * turn.norm(),
                            turn.norm() > 0.0 ? Vec3(turn.normalized()) : Vec3::UnitX()) *
          axis_from;
    }
    solve_to(goal, kLegTol * scale, kLegAngle, kLegIterations);
  }
  solve_to(target, tol, angle_tol, max_iterations);
  out.residual = r.template head<3>().norm();
  out.angle_residual = arm->AngleMiss(r);
  out.converged = arm->Within(r, tol, angle_tol);
  out.limited = arm->limited();
  out.points = arm->points();
  return out;
}

// A planar arm as a spatial one with every joint axis z (angles and limits carry over).
ArmModel Embedded(const ArmModel& planar) {
  const int n = planar.num_links();
  ArmModel model;
  model.dim = 3;
  model.link_lengths = planar.link_lengths;
  model.base = Vec3(planar.base[0], planar.base[1], 0.0);
  model.base_direction = Vec3(planar.base_direction[0], planar.base_direction[1], 0.0);
  model.joint_min = planar.joint_min;
  model.joint_max = planar.joint_max;
  model.joint_axes = Eigen::MatrixXd(n, 3);
  model.joint_axes.rowwise() = Eigen::RowVector3d::UnitZ();
  return model;
}

}  // namespace

Vec3 RotationVector(const Vec3& from, const Vec3& to) {
  const Vec3 axis = from.cross(to);
  const double s = axis.norm(), c = from.dot(to);
  if (!(s > 0.0)) return c >= 0.0 ? Vec3::Zero() : Vec3(from.unitOrthogonal() * M_PI);
  return axis * (std::atan2(s, c) / s);
}

Vec3 AimedDirection(bool look_at, const Vec3& point, const Vec3& direction, const Vec3& end) {
  if (!look_at) return direction;
  const Vec3 d = point - end;
  return d.squaredNorm() > 0.0 ? Vec3(d.normalized()) : direction;
}

Eigen::VectorXd InverseJointWeights(const ArmModel& model) {
  const int n = model.num_links();
  const double scale = model.link_lengths.mean();
  Eigen::VectorXd winv(n);
  double along = 0.0;
  for (int k = n - 1; k >= 0; --k) {
    along += model.link_lengths[k];
    winv[k] = 1.0 / ((along / scale) * (along / scale));
  }
  // Joints at the end effector itself (a tip on its joint: d = 0) turn the tool frame only; they
  // are weighted as the nearest joint with a lever.
  double nearest = 0.0;  // the shortest positive distance along the chain to the end effector
  along = 0.0;
  for (int k = n - 1; k >= 0 && !(nearest > 0.0); --k) nearest = along += model.link_lengths[k];
  for (int k = 0; k < n; ++k) {
    if (!std::isfinite(winv[k])) winv[k] = 1.0 / ((nearest / scale) * (nearest / scale));
  }
  // A prismatic joint is solved in q / scale with the column axis x scale: weight 1 lets it move
  // the end effector as much per unit of the weighted norm as any revolute joint does.
  for (int k = 0; k < n; ++k) {
    if (model.prismatic(k)) winv[k] = 1.0;
  }
  return winv;
}

namespace {

// The goal of a step: the target and, with pointing, the tool axis' goal.
Goal MakeGoal(const Eigen::VectorXd& target, const ArmOptions::Pointing& pointing) {
  Goal goal;
  goal.position = Vec3::Zero();
  goal.position.head(target.size()) = target;
  if (pointing.enabled) {
    goal.pointing = &pointing;
    goal.look_at = pointing.look_at;
    goal.point = pointing.point;
    goal.direction = pointing.direction.normalized();
  }
  return goal;
}

// One solve from `previous` with the weights `winv`.
JointSpaceSolve Attempt(const JointSpacePlan& plan, const ArmState& previous,
                        const Eigen::VectorXd& target, double tol, int max_iterations,
                        const Eigen::VectorXd& winv, const ArmOptions::Pointing& pointing) {
  const ArmModel& model = plan.model();
  const double scale = model.link_lengths.mean();
  const Goal goal = MakeGoal(target, pointing);
  JointSpaceSolve out;
  if (model.has_axes() && pointing.enabled) {
    RevoluteArm<6> arm(model, plan.kinematics(), previous.angles.angle, winv, scale,
                       &plan.workspace(), pointing.axis.normalized(), pointing.weight * scale);
    out = Drive(&arm, scale, goal, tol, pointing.angle_tolerance, max_iterations);
    out.angles = arm.angles();
  } else if (model.has_axes()) {
    RevoluteArm<3> arm(model, plan.kinematics(), previous.angles.angle, winv, scale,
                       &plan.workspace());
    out = Drive(&arm, scale, goal, tol, 0.0, max_iterations);
    out.angles = arm.angles();
  } else if (model.dim == 2) {
    const ArmModel embedded = Embedded(model);
    const AxisKinematics kinematics(embedded);
    JointSpacePlan::Workspace ws;
    RevoluteArm<3> arm(embedded, kinematics, AnglesUnchecked(model, previous.points).angle, winv,
                       scale, &ws);
    out = Drive(&arm, scale, goal, tol, 0.0, max_iterations);
    out.points = Points(out.points.leftCols(2));
  } else {
    SphericalArm arm(model, previous.points, winv);
    out = Drive(&arm, scale, goal, tol, 0.0, max_iterations);
  }
  out.merit = std::hypot(out.residual,
                         pointing.enabled ? out.angle_residual * pointing.weight * scale : 0.0);
  return out;
}

}  // namespace

JointSpacePlan::JointSpacePlan(const ArmModel& model)
    : model_(model), winv_(InverseJointWeights(model)) {
  if (model.has_axes()) kinematics_.emplace(model);
}

JointSpaceSolve SolveJointSpace(const JointSpacePlan& plan, const ArmState& previous,
                                const Eigen::VectorXd& target, double tol, int max_iterations,
                                int restarts, const ArmOptions::Pointing& pointing) {
  const ArmModel& model = plan.model();
  const Eigen::VectorXd& winv = plan.inverse_weights();
  JointSpaceSolve best = Attempt(plan, previous, target, tol, max_iterations, winv, pointing);
  if (best.converged) return best;  // the usual case: nothing below is needed
  auto consider = [&](JointSpaceSolve next) {
    next.iterations += best.iterations;
    next.passes += best.passes;
    next.restarts = best.restarts + 1;
    if (next.converged || next.merit < best.merit) {
      best = std::move(next);
    } else {
      best.iterations = next.iterations;
      best.passes = next.passes;
      best.restarts = next.restarts;
    }
  };
  // Restarts, in order: from the same pose with weights that spread the motion more evenly along
  // the arm (w_k ~ d_k, then uniform: the joints near the end effector saturate less), then from
  // poses drawn at random within the limits around the last one, a quarter, a half, then the
  // whole of each joint's range away (a fixed seed: the same input gives the same result).
  // Measured (single jumps to 200 random reachable targets for each of 4, 8, 16, 64 links, snake,
  // planar and spherical arms with limits +-0.6 rad, targets from angles within +-0.6 and +-0.3
  // rad): 113 of 4800 missed without restarts, none with; the random starts that succeeded did
  // so with the half or whole range.
  const int n = model.num_links();
  const bool spherical = model.joint() == ArmJoint::kSpherical;
  const JointAngles from =
      model.has_axes() ? previous.angles : AnglesUnchecked(model, previous.points);
  std::mt19937 rng(20261122);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int k = 0; k < restarts && !best.converged; ++k) {
    if (k < 2) {
      const double power = k == 0 ? 0.5 : 0.0;
      consider(
          Attempt(plan, previous, target, tol, max_iterations, winv.array().pow(power), pointing));
      continue;
    }
    const double amplitude = k == 2 ? 0.25 : k == 3 ? 0.5 : 1.0;
    ArmState start;
    start.angles = from;
    for (int j = 0; j < n; ++j) {
      double& q = start.angles.angle[j];
      // The joint's range: the limits, or the whole circle (a bend within [0, pi]); without a
      // finite limit, half a turn (a mean link length for a prismatic joint) either side.
      const double half = model.prismatic(j) ? model.link_lengths.mean() : M_PI;
      double lo = spherical ? 0.0 : -M_PI, hi = M_PI;
      if (model.has_axes()) lo = q - half, hi = q + half;
      if (model.joint_min.size() == n) {
        lo = std::isfinite(model.joint_min[j]) ? model.joint_min[j] : q - half;
        hi = std::isfinite(model.joint_max[j]) ? model.joint_max[j] : q + half;
      }
      if (model.max_bend.size() == n) hi = model.max_bend[j];
      q = std::clamp(q + amplitude * 0.5 * (hi - lo) * unit(rng), lo, hi);
      if (spherical) start.angles.azimuth[j] += amplitude * M_PI * unit(rng);
    }
    start.points = ForwardUnchecked(model, start.angles);
    consider(Attempt(plan, start, target, tol, max_iterations, winv, pointing));
  }
  return best;
}

}  // namespace flexkin::arm_internal
