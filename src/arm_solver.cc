// The fixed-base step of a hyper-redundant arm (include/flexkin/arm.h, docs/robots.md).
//
// One evaluation ("sweep") translates the arm by u, moves the end effector in a straight line to
// the target and lets every link follow by the closed-form tractrix step, from the end effector
// down to the base, putting each link back into its joint's limits as soon as it is placed. The
// base then sits at B(u); the step solves F(u) = B(u) - base = 0. Near u = 0, F(u) ~ u + g
// (target - EE - u), where g is the base's reply to a move of the end effector; g's Jacobian has
// norm < 1 wherever the motion dies out along the arm, so F's Jacobian is well conditioned except
// at the edge of the workspace (an arm stretched straight, pulled along itself, translates). Newton
// therefore converges quadratically in a few sweeps, independent of the number of links, while
// the fixed-point iteration u <- u - F(u) (the predecessors' scheme) contracts only by the norm of
// g's Jacobian per sweep, which approaches 1 for long arms and near the edge.
#include <Eigen/Dense>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "arm_internal.h"
#include "arm_revolute.h"
#include "flexkin/arm.h"
#include "flexkin/error.h"
#include "link_rules.h"

namespace flexkin {
namespace {

using Vec = Eigen::VectorXd;

// The sweep of one step and its workspace.
class Sweeper {
 public:
  Sweeper(const ArmModel& model, const Points& start, const Vec& target, int substeps)
      : model_(model), start_(start), target_(target), substeps_(substeps),
        n_(model.num_links()), dim_(model.dim) {
    base_direction_ = model.base_direction.normalized();
  }

  // Sweeps the start translated by u; returns F(u) = base after the sweep - model.base, leaves
  // the points in points().
  Vec Evaluate(const Vec& u) {
    ++sweeps_;
    points_ = start_;
    points_.rowwise() += u.transpose();
    Run(&points_);
    return points_.row(0).transpose() - model_.base;
  }
  // One sweep of the given points in place (the fixed-point baseline translates them itself).
  Vec SweepInPlace(Points* points) {
    ++sweeps_;
    Run(points);
    return points->row(0).transpose() - model_.base;
  }
  const Points& points() const { return points_; }
  bool limited() const { return limited_; }
  int sweeps() const { return sweeps_; }

 private:
  void Run(Points* p) {
    limited_ = false;
    const Vec from = p->row(n_).transpose();
    double head_old[3], tail_old[3];
    for (int s = 1; s <= substeps_; ++s) {
      for (int k = 0; k < dim_; ++k) head_old[k] = (*p)(n_, k);
      const Vec head = s == substeps_ ? target_ : Vec(from + (target_ - from) * (double(s) / substeps_));
      p->row(n_) = head.transpose();
      for (int j = n_; j >= 1; --j) {
        const double length = model_.link_lengths[j - 1];
        double* tail = p->row(j - 1).data();
        for (int k = 0; k < dim_; ++k) tail_old[k] = tail[k];
        const double* head_new = p->row(j).data();
        if (dim_ == 2) {
          internal::TractrixStep<2>(head_old, head_new, tail, length, 1.0 / length);
        } else {
          internal::TractrixStep<3>(head_old, head_new, tail, length, 1.0 / length);
        }
        if (model_.has_limits()) Limit(p, j);
        for (int k = 0; k < dim_; ++k) head_old[k] = tail_old[k];
      }
    }
  }

  // Puts link j (points j-1, j) back into the limits of joint j (against link j+1) and, for the
  // base link, of joint 0 (against the base direction), turning it about point j.
  void Limit(Points* p, int j) {
    const double length = model_.link_lengths[j - 1];
    double d[3], ref[3];
    for (int k = 0; k < dim_; ++k) d[k] = ((*p)(j, k) - (*p)(j - 1, k)) / length;
    bool changed = false;
    if (j < n_) {
      const double next_length = model_.link_lengths[j];
      for (int k = 0; k < dim_; ++k) ref[k] = ((*p)(j + 1, k) - (*p)(j, k)) / next_length;
      // Joint j turns link j into link j+1: seen from link j+1 the angle is reversed.
      changed |= dim_ == 2 ? arm_internal::ClampDirection(2, ref, -model_.joint_max[j],
                                                          -model_.joint_min[j], d)
                           : arm_internal::ClampDirection(3, ref, 0.0, model_.max_bend[j], d);
    }
    if (j == 1) {
      changed |= dim_ == 2 ? arm_internal::ClampDirection(2, base_direction_.data(),
                                                          model_.joint_min[0], model_.joint_max[0], d)
                           : arm_internal::ClampDirection(3, base_direction_.data(), 0.0,
                                                          model_.max_bend[0], d);
    }
    if (!changed) return;
    limited_ = true;
    for (int k = 0; k < dim_; ++k) (*p)(j - 1, k) = (*p)(j, k) - length * d[k];
  }

  const ArmModel& model_;
  const Points& start_;
  const Vec target_;
  const int substeps_, n_, dim_;
  Vec base_direction_;
  Points points_;
  bool limited_ = false;
  int sweeps_ = 0;
};

// Where a solver ended: the best sweep it found.
struct SolveResult {
  Points points;
  double residual = 0.0;
  int iterations = 0;
  bool converged = false;
  bool limited = false;
};

// A unit vector perpendicular to `v` (any if v is zero): the side to which a stuck solve is kicked.
Vec Perpendicular(const Vec& v) {
  const int dim = static_cast<int>(v.size());
  Vec dir = v.squaredNorm() > 0.0 ? Vec(v.normalized()) : Vec(Vec::Unit(dim, 0));
  if (dim == 2) return Eigen::Vector2d(-dir[1], dir[0]);
  return Eigen::Vector3d(dir[0], dir[1], dir[2]).unitOrthogonal();
}

// Sweeper: Sweeper, or arm_internal::RevoluteSweeper for revolute joints about given axes.
template <typename AnySweeper>
SolveResult SolveNewton(AnySweeper* sweeper, const ArmModel& model, const Vec& move,
                        const ArmOptions& options, double tol, double scale) {
  const int dim = model.dim;
  Vec u = Vec::Zero(dim);
  Vec f = sweeper->Evaluate(u);
  SolveResult best{sweeper->points(), f.norm(), 0, f.norm() <= tol, sweeper->limited()};
  auto remember = [&](const Vec& fv) {
    if (fv.norm() < best.residual) {
      best.points = sweeper->points();
      best.residual = fv.norm();
      best.limited = sweeper->limited();
    }
  };
  Eigen::MatrixXd jac(dim, dim);
  auto fresh_jacobian = [&]() {
    const double h = 1e-7 * scale;
    for (int k = 0; k < dim; ++k) {
      Vec uk = u;
      uk[k] += h;
      jac.col(k) = (sweeper->Evaluate(uk) - f) / h;
    }
  };
  bool keep_jacobian = false;  // the Broyden-updated Jacobian is doing well: no refresh
  int kicks = 0;
  for (int it = 0; it < options.max_iterations && !best.converged; ++it) {
    best.iterations = it + 1;
    const bool fresh = !keep_jacobian;
    if (fresh) fresh_jacobian();
    // Newton step; where the Jacobian is (nearly) singular, a Levenberg-Marquardt step instead.
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(jac);
    Vec step;
    if (lu.rcond() > 1e-10) {
      step = -lu.solve(f);
    } else {
      const double mu = 1e-6 * std::max(jac.squaredNorm(), 1e-300);
      step = -(jac.transpose() * jac + mu * Eigen::MatrixXd::Identity(dim, dim))
                  .ldlt()
                  .solve(jac.transpose() * f);
    }
    if (!step.allFinite()) step.setZero();
    // Backtracking: the full step, then halves, until the residual drops enough.
    bool accepted = false;
    Vec f_new;
    double alpha = 1.0;
    for (int half = 0; half < 12 && step.squaredNorm() > 0.0; ++half, alpha *= 0.5) {
      f_new = sweeper->Evaluate(u + alpha * step);
      if (f_new.allFinite() && f_new.norm() <= (1.0 - 1e-4 * alpha) * f.norm()) {
        accepted = true;
        break;
      }
    }
    if (accepted) {
      // Broyden's update keeps the Jacobian current at one sweep per iteration while the
      // residual at least halves; otherwise the next iteration makes a fresh one.
      const Vec s = alpha * step;
      jac += (f_new - f - jac * s) * s.transpose() / s.squaredNorm();
      keep_jacobian = f_new.norm() <= 0.5 * f.norm();
      u += s;
      f = f_new;
      remember(f);
      best.converged = f.norm() <= tol;
      continue;
    }
    keep_jacobian = false;
    if (!fresh) continue;  // an outdated Broyden Jacobian: retry with a fresh one
    // Stuck with a fresh Jacobian: a symmetric singular configuration (an arm stretched straight
    // and pushed along itself). Kick the translation sideways and start over from there.
    if (kicks == 3) break;
    u += std::pow(10.0, kicks - 3) * scale * Perpendicular(move);
    ++kicks;
    f = sweeper->Evaluate(u);
    remember(f);
    best.converged = f.norm() <= tol;
  }
  return best;
}

SolveResult SolveFixedPoint(Sweeper* sweeper, const ArmModel& model, const Points& start,
                            const ArmOptions& options, double tol) {
  SolveResult result;
  result.points = start;
  Vec f = sweeper->SweepInPlace(&result.points);
  result.iterations = 1;
  while (f.allFinite() && f.norm() > tol &&
         result.iterations < options.max_fixed_point_iterations) {
    result.points.rowwise() -= f.transpose();  // the base back where it is bolted
    f = sweeper->SweepInPlace(&result.points);
    ++result.iterations;
  }
  result.residual = f.norm();
  result.converged = result.residual <= tol;
  result.limited = sweeper->limited();
  (void)model;
  return result;
}

// The fixed-point baseline for revolute joints about axes: u <- u + F(u), F being the rebuilt
// end effector's miss, which is about minus the base residual of the other arms.
SolveResult SolveFixedPointRevolute(arm_internal::RevoluteSweeper* sweeper, const ArmOptions& options,
                                    double tol) {
  SolveResult result;
  Vec u = Vec::Zero(3);
  Vec f = sweeper->Evaluate(u);
  result.iterations = 1;
  while (f.allFinite() && f.norm() > tol && result.iterations < options.max_fixed_point_iterations) {
    u += f;
    f = sweeper->Evaluate(u);
    ++result.iterations;
  }
  result.points = sweeper->points();
  result.residual = f.norm();
  result.converged = result.residual <= tol;
  result.limited = sweeper->limited();
  return result;
}

void CheckState(const ArmModel& model, const ArmState& state, const Vec& target) {
  const int n = model.num_links();
  if (state.points.rows() != n + 1 || state.points.cols() != model.dim) {
    throw InputError("state.points", "shape " + std::to_string(state.points.rows()) + " by " +
                                         std::to_string(state.points.cols()) +
                                         " is not valid; expected " + std::to_string(n + 1) +
                                         " by " + std::to_string(model.dim));
  }
  if (!state.points.allFinite()) throw InputError("state.points", "a value is not finite");
  if (target.size() != model.dim) {
    throw InputError("target", "has " + std::to_string(target.size()) + " values; expected " +
                                   std::to_string(model.dim));
  }
  for (int k = 0; k < target.size(); ++k) {
    if (!std::isfinite(target[k])) {
      throw InputError("target[" + std::to_string(k) + "]",
                       "value " + FormatNumber(target[k]) + " is not a finite number");
    }
  }
}

}  // namespace

const char* FixedBaseMethodName(FixedBaseMethod method) {
  return method == FixedBaseMethod::kNewton ? "newton" : "fixed_point";
}

FixedBaseMethod ParseFixedBaseMethod(std::string_view name, const std::string& field) {
  if (name == "newton") return FixedBaseMethod::kNewton;
  if (name == "fixed_point") return FixedBaseMethod::kFixedPoint;
  throw InputError(field, "value \"" + std::string(name) +
                              "\" is not a fixed-base method; expected \"newton\" or \"fixed_point\"");
}

std::string ArmOptions::Validate() const {
  if (!(tolerance > 0.0 && tolerance < 1.0)) {
    return "tolerance: value " + FormatNumber(tolerance) + " is not valid; expected 0 < tolerance < 1";
  }
  if (max_iterations < 1) return "max_iterations: value " + std::to_string(max_iterations) + " is not >= 1";
  if (max_fixed_point_iterations < 1) {
    return "max_fixed_point_iterations: value " + std::to_string(max_fixed_point_iterations) +
           " is not >= 1";
  }
  if (substeps < 1) return "substeps: value " + std::to_string(substeps) + " is not >= 1";
  if (!(edge_margin >= 0.0 && edge_margin < 0.5)) {
    return "edge_margin: value " + FormatNumber(edge_margin) + " is not valid; expected 0 <= edge_margin < 0.5";
  }
  return "";
}

ArmStepReport ArmStep(const ArmModel& model, const ArmState& state,
                      const Eigen::Ref<const Eigen::VectorXd>& target_in, const ArmOptions& options) {
  arm_internal::CheckModel(model);
  const std::string why = options.Validate();
  if (!why.empty()) throw InputError("options." + why.substr(0, why.find(':')), why.substr(why.find(':') + 2));
  const Vec target = target_in;
  CheckState(model, state, target);

  const int n = model.num_links();
  const double scale = model.link_lengths.mean();
  const double tol = options.tolerance * scale;
  ArmStepReport report;
  Points points;
  const Vec to_target = target - model.base;
  // The solver's result into the report (`sweeps` read after the solve).
  auto take = [&](const SolveResult& solved, int sweeps) {
    points = solved.points;
    report.base_error = solved.residual;
    report.iterations = solved.iterations;
    report.converged = solved.converged;
    report.limited = solved.limited;
    report.sweeps = sweeps;
  };
  if (to_target.norm() >= model.reach() * (1.0 - options.edge_margin)) {
    // Out of reach (or on its edge, where the Jacobian is singular): stretched toward the target.
    report.stretched = true;
    points.resize(n + 1, model.dim);
    const Vec dir = to_target.normalized();
    points.row(0) = model.base.transpose();
    for (int j = 0; j < n; ++j) points.row(j + 1) = points.row(j) + model.link_lengths[j] * dir.transpose();
    report.converged = true;
  } else if (model.has_axes()) {
    if (state.angles.angle.size() != n || !state.angles.angle.allFinite()) {
      throw InputError("state.angles", "has " + std::to_string(state.angles.angle.size()) +
                                           " finite values or fewer; expected " + std::to_string(n));
    }
    arm_internal::RevoluteSweeper sweeper(model, state, target, options.substeps);
    const SolveResult solved =
        options.method == FixedBaseMethod::kNewton
            ? SolveNewton(&sweeper, model, target - state.points.row(n).transpose(), options, tol,
                          scale)
            : SolveFixedPointRevolute(&sweeper, options, tol);
    take(solved, sweeper.sweeps());
  } else {
    Sweeper sweeper(model, state.points, target, options.substeps);
    const SolveResult solved =
        options.method == FixedBaseMethod::kNewton
            ? SolveNewton(&sweeper, model, target - state.points.row(n).transpose(), options, tol,
                          scale)
            : SolveFixedPoint(&sweeper, model, state.points, options, tol);
    take(solved, sweeper.sweeps());
  }
  // Re-anchor: rebuild the points from the joint angles at the fixed base; this also puts any
  // joint the sweep could not keep within its limits (the base link between two limits) there.
  report.state.angles = JointAnglesFromPoints(model, points);
  report.limited |= arm_internal::ClampToLimits(model, &report.state.angles);
  report.state.points = ForwardKinematics(model, report.state.angles);
  report.ee_error = (report.state.points.row(n).transpose() - target).norm();
  report.reached = report.converged && report.ee_error <= 2.0 * tol + 1e-13 * model.reach();
  return report;
}

std::string ArmStepReport::BriefReport() const {
  char line[256];
  std::snprintf(line, sizeof(line),
                "%s: end-effector error %.3g, base residual %.3g, %d iterations, %d sweeps%s%s",
                reached ? "reached" : "NOT reached", ee_error, base_error, iterations, sweeps,
                stretched ? ", stretched toward an out-of-reach target" : "",
                limited ? ", joint limits active" : "");
  return line;
}

ArmTrajectory TrackPath(const ArmModel& model, const Points& path, const ArmOptions& options) {
  arm_internal::CheckModel(model);
  if (path.rows() < 1 || path.cols() != model.dim) {
    throw InputError("path", "shape " + std::to_string(path.rows()) + " by " +
                                 std::to_string(path.cols()) + " is not valid; expected m >= 1 by " +
                                 std::to_string(model.dim));
  }
  const auto begin = std::chrono::steady_clock::now();
  ArmTrajectory trajectory;
  trajectory.steps.reserve(path.rows());
  ArmState state = InitialState(model);
  for (int i = 0; i < path.rows(); ++i) {
    ArmStepReport step;
    try {
      step = ArmStep(model, state, path.row(i).transpose(), options);
    } catch (const InputError& e) {
      if (e.field().rfind("target", 0) != 0) throw;
      throw InputError("path[" + std::to_string(i) + "]" + e.field().substr(6),
                       std::string(e.what()).substr(e.field().size() + 2));
    }
    state = step.state;
    trajectory.max_ee_error = std::max(trajectory.max_ee_error, step.ee_error);
    trajectory.max_base_error = std::max(trajectory.max_base_error, step.base_error);
    trajectory.unreached += step.reached ? 0 : 1;
    trajectory.max_iterations = std::max(trajectory.max_iterations, step.iterations);
    trajectory.total_sweeps += step.sweeps;
    trajectory.steps.push_back(std::move(step));
  }
  trajectory.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return trajectory;
}

std::string ArmTrajectory::BriefReport() const {
  char line[256];
  std::snprintf(line, sizeof(line),
                "%zu steps, %d not reached, max end-effector error %.3g, max base residual %.3g, "
                "max %d iterations, %lld sweeps, %.3g s",
                steps.size(), unreached, max_ee_error, max_base_error, max_iterations, total_sweeps,
                seconds);
  return line;
}

}  // namespace flexkin
