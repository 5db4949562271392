// The joint-space step of an arm with joint axes among colliders (src/arm/joint_space_contact.h).
//
// At q, with the end effector's miss r = FK(q) - target and its position Jacobian J, each step is
// the solution dq of
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
  ContactDriver(const JointSpacePlan& plan, const std::vector<Collider>& colliders, double slack)
      : model_(plan.model()),
        fk_(plan.kinematics()),
        colliders_(colliders),
        n_(plan.model().num_links()),
        scale_(plan.model().link_lengths.mean()),
        slack_(slack) {
    weight_.resize(n_);
    for (int k = 0; k < n_; ++k) {
      weight_[k] = model_.prismatic(k) ? 1.0 / (scale_ * scale_) : 1.0 / plan.inverse_weights()[k];
    }
  }

  // Drives `*q` toward `goal` until the miss is at most `tol` with every capsule outside (true),
  // or no step improves, or `iterations` run out.
  bool Drive(const Vec3& goal, double tol, int iterations, Eigen::VectorXd* q, int* used);

  double Miss(const Eigen::VectorXd& q, double* depth) {
    Forward(q);
    *depth = Depth();
    return (End() - goal_).norm();
  }
  const Points& points() const { return points_; }

 private:
  void Forward(const Eigen::VectorXd& q) { fk_.Forward(q, &points_, &axes_); }
  Vec3 At(int i) const { return points_.row(i).transpose(); }
  Vec3 End() const { return At(n_); }
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
  bool SolveQp(const Eigen::MatrixXd& jacobian, const Vec3& miss,
               const std::vector<Inequality>& inequalities, Eigen::VectorXd* dq) const;

  const ArmModel& model_;
  const AxisKinematics& fk_;
  const std::vector<Collider>& colliders_;
  const int n_;
  const double scale_, slack_;
  Eigen::VectorXd weight_;
  Vec3 goal_ = Vec3::Zero();
  Points points_;
  Eigen::MatrixXd axes_;
};

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

bool ContactDriver::SolveQp(const Eigen::MatrixXd& jacobian, const Vec3& miss,
                            const std::vector<Inequality>& inequalities,
                            Eigen::VectorXd* dq) const {
  std::vector<int> working;
  std::vector<int> left(inequalities.size(), 0);
  const double ridge = 1e-14 * weight_.maxCoeff();
  for (int round = 0; round < 4 * static_cast<int>(inequalities.size()) + 8; ++round) {
    const int m = static_cast<int>(working.size());
    const int size = n_ + 3 + m;
    Eigen::MatrixXd kkt = Eigen::MatrixXd::Zero(size, size);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(size);
    kkt.topLeftCorner(n_, n_) = weight_.asDiagonal();
    kkt.block(0, n_, n_, 3) = jacobian.transpose();
    kkt.block(n_, 0, 3, n_) = jacobian;
    rhs.segment(n_, 3) = -miss;
    for (int a = 0; a < m; ++a) {
      const Inequality& in = inequalities[working[a]];
      kkt.block(0, n_ + 3 + a, n_, 1) = -in.a.transpose();
      kkt.block(n_ + 3 + a, 0, 1, n_) = -in.a;
      rhs[n_ + 3 + a] = -in.b;
    }
    for (int r = n_; r < size; ++r) kkt(r, r) = -ridge;
    const Eigen::VectorXd solution = kkt.fullPivLu().solve(rhs);
    if (!solution.allFinite()) return false;
    *dq = solution.head(n_);
    int leave = -1;
    double most = 0.0;
    for (int a = 0; a < m; ++a) {
      if (solution[n_ + 3 + a] < most) most = solution[n_ + 3 + a], leave = a;
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

bool ContactDriver::Drive(const Vec3& goal, double tol, int iterations, Eigen::VectorXd* q,
                          int* used) {
  goal_ = goal;
  double depth = 0.0;
  double miss = Miss(*q, &depth);
  Eigen::MatrixXd jacobian(3, n_);
  std::vector<Inequality> inequalities;
  Eigen::VectorXd dq(n_), trial(n_);
  for (int it = 0; it < iterations; ++it) {
    if (miss <= tol && depth == 0.0) return true;
    ++*used;
    const Vec3 r = End() - goal_;
    for (int j = 0; j < n_; ++j) jacobian.col(j) = PointRate(n_, j);
    Inequalities(*q, &inequalities);
    if (!SolveQp(jacobian, r, inequalities, &dq)) return false;
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
      return miss <= tol && depth == 0.0;
    }
  }
  Forward(*q);
  return miss <= tol && depth == 0.0;
}

}  // namespace

void SolveJointSpaceContact(const JointSpacePlan& plan, const Eigen::VectorXd& previous,
                            const Eigen::VectorXd& target, const std::vector<Collider>& colliders,
                            double tol, double slack, int max_iterations, JointSpaceSolve* out) {
  const ArmModel& model = plan.model();
  const double scale = model.link_lengths.mean();
  ContactDriver driver(plan, colliders, slack);
  Eigen::VectorXd q = previous;
  double depth = 0.0;
  driver.Miss(q, &depth);
  const Vec3 from = driver.points().row(model.num_links()).transpose();
  Vec3 goal = Vec3::Zero();
  goal.head(target.size()) = target;
  // Legs of at most half a mean link length, as the free step's; each but the last to 1e-3 of a
  // link.
  constexpr double kLeg = 0.5, kLegTol = 1e-3;
  constexpr int kLegIterations = 20;
  const int legs = std::max(1, static_cast<int>(std::ceil((goal - from).norm() / (kLeg * scale))));
  int used = 0;
  bool converged = false;
  for (int leg = 1; leg <= legs; ++leg) {
    const bool last = leg == legs;
    const Vec3 at = last ? goal : Vec3(from + (goal - from) * (double(leg) / legs));
    converged = driver.Drive(at, last ? tol : kLegTol * scale,
                             last ? max_iterations : kLegIterations, &q, &used);
  }
  out->angles = q;
  out->residual = driver.Miss(q, &depth);
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
