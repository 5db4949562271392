// The joint-space step of an arm with joint axes among colliders (src/arm/joint_space_contact.h).
//
// At q, with the end effector's miss r = FK(q) - target and its position Jacobian J (with
// pointing, r and J also have the free step's three rows of the tool axis' turn to its goal,
// weighted by pointing.weight mean link lengths per radian: joint_space.cc), each step is the
// solution dq of
//   minimize (1/2) dq' W dq  subject to  J dq = -r,  g_a + G_a dq >= 0,  lo <= q + dq <= hi,
// W the free step's weights (joint_space.h: W^-1 = InverseJointWeights, a prismatic joint in
// units of the mean link length), g_a the clearance of link l's capsule from collider k (the
// least signed distance of the link's axis less its radius) and G_a its gradient: by the envelope
// theorem the normal n at the nearest point p = (1 - s) x_{l-1} + s x_l dotted with dp/dq_j =
// (1 - s) dx_{l-1}/dq_j + s dx_l/dq_j, where dx_i/dq_j = axis_j x (x_i - x_j) for a revolute joint
// j < i (axis_j for a prismatic one) and 0 for j >= i. Without contacts and limits it is the free
// step's dq = W^-1 J' (J W^-1 J')^-1 (-r). The inequalities are chosen by a primal active set (a
// constraint whose multiplier pulls the wrong way leaves; the one the step would break most
// joins). Steps are backtracked on the miss plus the depth inside the colliders.

#include "arm/joint_space_contact.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "arm/revolute.h"
#include "world/contact.h"

namespace flexkin::arm_internal {
namespace {

using Vec3 = Eigen::Vector3d;

// One inequality a . dq >= b of the step's quadratic program.
struct Inequality {
  Eigen::RowVectorXd a;
  double b = 0.0;
};

class ContactDriver {
 public:
  ContactDriver(const JointSpacePlan& plan, const std::vector<Collider>& colliders, double slack,
                const ArmOptions::Pointing& pointing)
      : model_(plan.model()),
        fk_(plan.kinematics()),
        colliders_(colliders),
        n_(plan.model().num_links()),
        scale_(plan.model().link_lengths.mean()),
        slack_(slack),
        rows_(pointing.enabled ? 5 : 3),
        angle_scale_(pointing.weight * scale_),
        tool_axis_(pointing.axis.normalized()),
        point_(pointing.point) {
    weight_.resize(n_);
    for (int k = 0; k < n_; ++k) {
      weight_[k] = model_.prismatic(k) ? 1.0 / (scale_ * scale_) : 1.0 / plan.inverse_weights()[k];
    }
  }

  // Drives `*q` toward `goal` (with pointing, the tool axis toward `direction`, or toward the
  // point looked at where `look_at`) until the miss is at most `tol` and the tool axis' angle at
  // most `angle_tol`, with every capsule outside (true), or no step improves, or `iterations` run
  // out.
  bool Drive(const Vec3& goal, const Vec3& direction, bool look_at, double tol, double angle_tol,
             int iterations, Eigen::VectorXd* q, int* used);

  // The arm at q: the norm of the miss (with pointing, of the position's and the weighted turn's
  // rows together) and the capsules' depth inside the colliders.
  double Miss(const Eigen::VectorXd& q, double* depth) {
    Forward(q);
    *depth = Depth();
    return ResidualNorm();
  }
  const Points& points() const { return points_; }
  Vec3 End() const { return At(n_); }
  // The tool axis in the world, and its angle from its goal (rad).
  Vec3 ToolAxis() const { return frame_ * tool_axis_; }
  double AngleMiss() const { return RotationVector(ToolAxis(), Direction()).norm(); }
  double PositionMiss() const { return (End() - goal_).norm(); }

 private:
  void Forward(const Eigen::VectorXd& q) { fk_.Forward(q, &points_, &axes_, &frame_); }
  Vec3 At(int i) const { return points_.row(i).transpose(); }
  Vec3 Direction() const { return AimedDirection(look_at_, point_, direction_, End()); }
  // The miss: the end effector's, and with pointing the weighted turn that would bring the tool
  // axis onto its goal (as the free step's, joint_space.cc). That turn is across the tool axis:
  // its two components on `across` (two unit vectors across the tool axis), so that the rows of
  // the step's equality are independent.
  Eigen::VectorXd Residual(const Eigen::Matrix<double, 3, 2>& across) const {
    Eigen::VectorXd r(rows_);
    r.head<3>() = End() - goal_;
    if (rows_ == 5) {
      r.tail<2>() = -angle_scale_ * across.transpose() * RotationVector(ToolAxis(), Direction());
    }
    return r;
  }
  // The same norm as Residual's, without the basis.
  double ResidualNorm() const {
    const double position = (End() - goal_).squaredNorm();
    if (rows_ == 3) return std::sqrt(position);
    const double turn = angle_scale_ * RotationVector(ToolAxis(), Direction()).norm();
    return std::sqrt(position + turn * turn);
  }
  // Two unit vectors across the tool axis, and the miss' Jacobian at the current q (rows_ by n).
  Eigen::Matrix<double, 3, 2> Across() const {
    const Vec3 a = ToolAxis(), e1 = a.unitOrthogonal();
    Eigen::Matrix<double, 3, 2> across;
    across << e1, a.cross(e1);
    return across;
  }
  void Jacobian(const Eigen::Matrix<double, 3, 2>& across, Eigen::MatrixXd* jacobian) const;
  double Radius(int link) const {
    return model_.link_radii.size() > 0 ? model_.link_radii[link - 1] : 0.0;
  }
  // dx_i / dq_j.
  Vec3 PointRate(int i, int j) const {
    if (j >= i) return Vec3::Zero();
    const Vec3 axis = axes_.row(j).transpose();
    return model_.prismatic(j) ? axis : Vec3(axis.cross(At(i) - At(j)));
  }
  // The sum of the depths of the capsules inside colliders (0 when all are outside).
  double Depth() const;
  // The inequalities at the current q: contacts within reach, and the limits.
  void Inequalities(const Eigen::VectorXd& q, std::vector<Inequality>* out) const;
  // The step's quadratic program. `penalty` 0: J dq = -r as equalities; > 0: as the penalty
  // (penalty / 2) |J dq + r|^2 added to the objective instead (where the linearized equalities and
  // the constraints held active cannot all be met, the step that comes nearest).
  bool SolveQp(const Eigen::MatrixXd& jacobian, const Eigen::VectorXd& miss, double penalty,
               const std::vector<Inequality>& inequalities, Eigen::VectorXd* dq) const;

  const ArmModel& model_;
  const AxisKinematics& fk_;
  const std::vector<Collider>& colliders_;
  const int n_;
  const double scale_, slack_;
  const int rows_;  // 3, or 5 with pointing
  const double angle_scale_;
  const Vec3 tool_axis_;  // in the last link's frame
  const Vec3 point_;      // looked at (pointing.look_at)
  Eigen::VectorXd weight_;
  Vec3 goal_ = Vec3::Zero(), direction_ = Vec3::UnitX();
  bool look_at_ = false;
  Points points_;
  Eigen::MatrixXd axes_;
  Eigen::Matrix3d frame_ = Eigen::Matrix3d::Identity();
};

void ContactDriver::Jacobian(const Eigen::Matrix<double, 3, 2>& across,
                             Eigen::MatrixXd* jacobian) const {
  jacobian->resize(rows_, n_);
  for (int j = 0; j < n_; ++j) jacobian->col(j).head<3>() = PointRate(n_, j);
  if (rows_ == 3) return;
  const Vec3 a_w = ToolAxis(), to_point = point_ - End();
  // Looking at a point, the goal turns as the end effector moves (joint_space.cc, Propose).
  const double look = look_at_ && to_point.norm() > 0.0 ? 1.0 / to_point.norm() : 0.0;
  for (int j = 0; j < n_; ++j) {
    Vec3 turn = Vec3::Zero();
    if (!model_.prismatic(j)) {
      const Vec3 axis = axes_.row(j).transpose();
      turn = axis - axis.dot(a_w) * a_w;  // the tool axis turns with w x a_w
    }
    if (look > 0.0) turn += look * a_w.cross(Vec3(jacobian->col(j).head<3>()));
    jacobian->col(j).tail<2>() = angle_scale_ * across.transpose() * turn;
  }
}

double ContactDriver::Depth() const {
  double depth = 0.0;
  for (int l = 1; l <= n_; ++l) {
    for (const Collider& c : colliders_) {
      const double g = internal::SegmentClearance(c, At(l - 1), At(l)) - Radius(l);
      if (g < -slack_ * model_.link_lengths[l - 1]) depth -= g;
    }
  }
  return depth;
}

void ContactDriver::Inequalities(const Eigen::VectorXd& q, std::vector<Inequality>* out) const {
  out->clear();
  // A point shared by two links in contact at it is one constraint (else two equal rows).
  std::vector<std::pair<int, size_t>> at_points;
  for (int l = 1; l <= n_; ++l) {
    for (size_t k = 0; k < colliders_.size(); ++k) {
      const internal::SegmentContact near =
          internal::NearestOnSegment(colliders_[k], At(l - 1), At(l));
      const double g = near.clearance - Radius(l);
      if (g > scale_) continue;  // beyond a step's reach
      if (near.s == 0.0 || near.s == 1.0) {
        const int point = l - 1 + static_cast<int>(near.s);
        if (point == 0) continue;  // the base: no joint moves it
        const std::pair<int, size_t> key(point, k);
        if (std::find(at_points.begin(), at_points.end(), key) != at_points.end()) continue;
        at_points.push_back(key);
      }
      Inequality in;
      in.a = Eigen::RowVectorXd::Zero(n_);
      for (int j = 0; j < n_; ++j) {
        const Vec3 rate = (1.0 - near.s) * PointRate(l - 1, j) + near.s * PointRate(l, j);
        in.a[j] = near.normal.dot(rate);
      }
      in.b = -g;
      if (in.a.norm() > 0.0) out->push_back(in);
    }
  }
  if (model_.joint_min.size() == n_) {
    for (int j = 0; j < n_; ++j) {
      if (std::isfinite(model_.joint_min[j])) {
        Inequality lo;
        lo.a = Eigen::RowVectorXd::Unit(n_, j);
        lo.b = model_.joint_min[j] - q[j];
        out->push_back(lo);
      }
      if (std::isfinite(model_.joint_max[j])) {
        Inequality hi;
        hi.a = -Eigen::RowVectorXd::Unit(n_, j);
        hi.b = q[j] - model_.joint_max[j];
        out->push_back(hi);
      }
    }
  }
}

bool ContactDriver::SolveQp(const Eigen::MatrixXd& jacobian, const Eigen::VectorXd& miss,
                            double penalty, const std::vector<Inequality>& inequalities,
                            Eigen::VectorXd* dq) const {
  std::vector<int> working;
  std::vector<int> left(inequalities.size(), 0);
  const double ridge = 1e-14 * weight_.maxCoeff();
  const int equalities = penalty > 0.0 ? 0 : rows_;
  const int first = n_ + equalities;  // the inequalities' multipliers
  for (int round = 0; round < 4 * static_cast<int>(inequalities.size()) + 8; ++round) {
    const int m = static_cast<int>(working.size());
    const int size = first + m;
    Eigen::MatrixXd kkt = Eigen::MatrixXd::Zero(size, size);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(size);
    kkt.topLeftCorner(n_, n_) = weight_.asDiagonal();
    if (penalty > 0.0) {
      kkt.topLeftCorner(n_, n_) += penalty * jacobian.transpose() * jacobian;
      rhs.head(n_) = -penalty * (jacobian.transpose() * miss);
    } else {
      kkt.block(0, n_, n_, rows_) = jacobian.transpose();
      kkt.block(n_, 0, rows_, n_) = jacobian;
      rhs.segment(n_, rows_) = -miss;
    }
    for (int a = 0; a < m; ++a) {
      const Inequality& in = inequalities[working[a]];
      kkt.block(0, first + a, n_, 1) = -in.a.transpose();
      kkt.block(first + a, 0, 1, n_) = -in.a;
      rhs[first + a] = -in.b;
    }
    for (int r = n_; r < size; ++r) kkt(r, r) = -ridge;
    const Eigen::VectorXd solution = kkt.fullPivLu().solve(rhs);
    if (!solution.allFinite()) return false;
    *dq = solution.head(n_);
    int leave = -1;
    double most = 0.0;
    for (int a = 0; a < m; ++a) {
      if (solution[first + a] < most) most = solution[first + a], leave = a;
    }
    if (leave >= 0) {
      ++left[working[leave]];
      working.erase(working.begin() + leave);
      continue;
    }
    int join = -1;
    double worst = -1e-14 * scale_;
    for (size_t i = 0; i < inequalities.size(); ++i) {
      if (left[i] > 2 ||
          std::find(working.begin(), working.end(), static_cast<int>(i)) != working.end()) {
        continue;
      }
      const double excess = inequalities[i].a.dot(*dq) - inequalities[i].b;
      if (excess < worst) worst = excess, join = static_cast<int>(i);
    }
    if (join < 0) return true;
    working.push_back(join);
  }
  return true;
}

bool ContactDriver::Drive(const Vec3& goal, const Vec3& direction, bool look_at, double tol,
                          double angle_tol, int iterations, Eigen::VectorXd* q, int* used) {
  goal_ = goal;
  direction_ = direction;
  look_at_ = look_at;
  double depth = 0.0;
  double miss = Miss(*q, &depth);
  const auto within = [&] {
    return PositionMiss() <= tol && (rows_ == 3 || AngleMiss() <= angle_tol) && depth == 0.0;
  };
  Eigen::MatrixXd jacobian;
  std::vector<Inequality> inequalities;
  Eigen::VectorXd dq(n_), trial(n_);
  for (int it = 0; it < iterations; ++it) {
    if (within()) return true;
    ++*used;
    const Eigen::Matrix<double, 3, 2> across = Across();
    const Eigen::VectorXd r = Residual(across);
    Jacobian(across, &jacobian);
    Inequalities(*q, &inequalities);
    if (!SolveQp(jacobian, r, 0.0, inequalities, &dq)) return false;
    // Where the active constraints leave the linearized miss uncancelled (more constraints held
    // than the joints can meet with it), the step that comes nearest to cancelling it: the miss
    // as a penalty far above the weights, 1e8 per squared mean link length.
    if ((jacobian * dq + r).norm() > 1e-6 * r.norm() + 1e-14 * scale_) {
      if (!SolveQp(jacobian, r, 1e8 / (scale_ * scale_), inequalities, &dq)) return false;
    }
    // Backtracking on the miss plus the depth inside the colliders.
    const double merit = miss + depth;
    double alpha = 1.0;
    bool improved = false;
    for (int tries = 0; tries < 30; ++tries, alpha *= 0.5) {
      trial = *q + alpha * dq;
      double trial_depth = 0.0;
      const double trial_miss = Miss(trial, &trial_depth);
      if (trial_miss + trial_depth < merit * (1.0 - 1e-4 * alpha) ||
          (trial_depth == 0.0 && trial_miss <= tol)) {
        *q = trial;
        miss = trial_miss;
        depth = trial_depth;
        improved = true;
        break;
      }
    }
    if (!improved) {
      Forward(*q);
      return within();
    }
  }
  Forward(*q);
  return within();
}

}  // namespace

void SolveJointSpaceContact(const JointSpacePlan& plan, const Eigen::VectorXd& previous,
                            const Eigen::VectorXd& target, const std::vector<Collider>& colliders,
                            double tol, double slack, int max_iterations,
                            const ArmOptions::Pointing& pointing, JointSpaceSolve* out) {
  const ArmModel& model = plan.model();
  const double scale = model.link_lengths.mean();
  ContactDriver driver(plan, colliders, slack, pointing);
  Eigen::VectorXd q = previous;
  double depth = 0.0;
  driver.Miss(q, &depth);
  const Vec3 from = driver.End();
  Vec3 goal = Vec3::Zero();
  goal.head(target.size()) = target;
  // Legs of at most half a mean link length, as the free step's; each but the last to 1e-3 of a
  // link. With pointing, the tool axis turns to its goal along the great circle in the same legs,
  // at most 0.5 rad apart (the free step's legs, joint_space.cc).
  constexpr double kLeg = 0.5, kLegTol = 1e-3, kLegAngle = 0.5;
  constexpr int kLegIterations = 20;
  int legs = std::max(1, static_cast<int>(std::ceil((goal - from).norm() / (kLeg * scale))));
  const Vec3 axis_from = driver.ToolAxis();
  Vec3 turn = Vec3::Zero();
  if (pointing.enabled) {
    turn = RotationVector(axis_from, AimedDirection(pointing.look_at, pointing.point,
                                                    pointing.direction.normalized(), goal));
    legs = std::max(legs, static_cast<int>(std::ceil(turn.norm() / kLegAngle)));
  }
  int used = 0;
  bool converged = false;
  for (int leg = 1; leg <= legs; ++leg) {
    const bool last = leg == legs;
    const double t = double(leg) / legs;
    const Vec3 at = last ? goal : Vec3(from + (goal - from) * t);
    Vec3 direction = pointing.direction.normalized();
    if (!last && pointing.enabled) {
      direction = Eigen::AngleAxisd(t * turn.norm(),
                                    turn.norm() > 0.0 ? Vec3(turn.normalized()) : Vec3::UnitX()) *
                  axis_from;
    }
    converged = driver.Drive(at, direction, last && pointing.look_at, last ? tol : kLegTol * scale,
                             last ? pointing.angle_tolerance : kLegAngle,
                             last ? max_iterations : kLegIterations, &q, &used);
  }
  out->angles = q;
  driver.Miss(q, &depth);
  out->residual = driver.PositionMiss();
  out->angle_residual = pointing.enabled ? driver.AngleMiss() : 0.0;
  out->points = driver.points();
  if (model.dim == 2) out->points = Points(out->points.leftCols(2));
  out->iterations = used;
  out->passes = used;
  out->converged = converged && depth == 0.0;
  out->limited = false;
  if (model.joint_min.size() == model.num_links()) {
    for (int j = 0; j < model.num_links(); ++j) {
      out->limited |= q[j] <= model.joint_min[j] || q[j] >= model.joint_max[j];
    }
  }
}

}  // namespace flexkin::arm_internal
