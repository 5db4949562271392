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
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>

#include "arm/colliders.h"
#include "arm/internal.h"
#include "arm/joint_space.h"
#include "arm/joint_space_contact.h"
#include "arm/revolute.h"
#include "arm/sweep.h"
#include "flexkin/arm.h"
#include "flexkin/error.h"
#include "sequential/link_rules.h"

namespace flexkin {
namespace {

// Where the sweep with contact steps finds no root, the move is tried again in up to this many
// legs.
constexpr int kContactLegs = 8;
// Where the sweep finds no root for a far move, the move is tracked in legs of at most this many
// mean link lengths (see StepChecked).
constexpr double kLegLength = 0.5;
constexpr int kFarIterations = 20;

using Vec = arm_internal::SmallVec;
using Mat = arm_internal::SmallMat;
using arm_internal::StepWindow;
using arm_internal::Sweeper;

// Where a solver ended: the best sweep it found.
struct SolveResult {
  Points points;
  double residual = 0.0;
  int iterations = 0;
  bool converged = false;
  bool limited = false;
  ArmSolverMemory memory;  // Newton, converged: what the next step may start from
};

// A unit vector perpendicular to `v` (any if v is zero): the side to which a stuck solve is kicked.
Vec Perpendicular(const Vec& v) {
  const int dim = static_cast<int>(v.size());
  Vec dir = v.squaredNorm() > 0.0 ? Vec(v.normalized()) : Vec(Vec::Unit(dim, 0));
  if (dim == 2) return Eigen::Vector2d(-dir[1], dir[0]);
  return Eigen::Vector3d(dir[0], dir[1], dir[2]).unitOrthogonal();
}

// The remembered translations (1 to 3, usable ones) in `memory` and the path length t at which
// each was reached: t = 0 at the last step, negative before it.
int History(const ArmSolverMemory& memory, int dim, Vec* us, double* t) {
  if (!memory.Usable(dim)) return 0;
  us[0] = memory.translation;
  t[0] = 0.0;
  const Eigen::MatrixXd& earlier = memory.earlier_translations;
  const Eigen::VectorXd& lengths = memory.move_lengths;
  if (earlier.rows() != dim || earlier.cols() > 2 || lengths.size() != 1 + earlier.cols() ||
      !earlier.allFinite() || !lengths.allFinite() || !(lengths.array() > 0.0).all()) {
    return 1;
  }
  for (int i = 1; i <= earlier.cols(); ++i) {
    us[i] = earlier.col(i - 1);
    t[i] = t[i - 1] - lengths[i - 1];
  }
  return 1 + static_cast<int>(earlier.cols());
}

// The translation to start a step from: the remembered ones extrapolated along the path, by the
// polynomial in the end effector's travel through them (degree up to 2), evaluated one move
// ahead; zero without a memory. u varies smoothly along a smooth path, so the extrapolation
// leaves a residual about a tenth of the last translation's (measured on the KDL benchmark's
// path: 1e-5 to 1e-4 of a link against 1e-3 to 1e-2), and one Newton step with the curvature
// probe then usually reaches the tolerance. Far beyond the remembered span (a much longer move)
// the polynomial is not trusted: the last translation is.
Vec Predict(const ArmSolverMemory& memory, int dim, double move_length) {
  Vec us[3];
  double t[3];
  int known = History(memory, dim, us, t);
  if (known == 0) return Vec::Zero(dim);
  if (known > 1 && !(move_length <= 3.0 * -t[1])) known = 1;
  Vec u = Vec::Zero(dim);
  for (int i = 0; i < known; ++i) {
    double weight = 1.0;  // Lagrange's basis polynomial of node i at move_length
    for (int j = 0; j < known; ++j) {
      if (j != i) weight *= (move_length - t[j]) / (t[i] - t[j]);
    }
    u += weight * us[i];
  }
  return u;
}

// What this step leaves for the next: its translation `u` (reached from `start`) in front of
// the remembered ones, at most 3 in all.
ArmSolverMemory Remember(const ArmSolverMemory& memory, int dim, const Vec& u, const Vec& start,
                         double move_length) {
  ArmSolverMemory next;
  next.translation = u;
  next.prediction_error = u - start;
  Vec us[3];
  double t[3];
  int known = move_length > 0.0 ? std::min(History(memory, dim, us, t), 2) : 0;
  // The move that reached each kept translation must be known (and a length).
  for (int i = 0; i < known; ++i) {
    if (!(i < memory.move_lengths.size() && memory.move_lengths[i] > 0.0 &&
          std::isfinite(memory.move_lengths[i]))) {
      known = i;
    }
  }
  next.earlier_translations.resize(dim, known);
  next.move_lengths.resize(1 + known);
  next.move_lengths[0] = move_length;
  for (int i = 0; i < known; ++i) {
    next.earlier_translations.col(i) = us[i];
    next.move_lengths[i + 1] = memory.move_lengths[i];
  }
  return next;
}

// `memory`: the last step's (may be empty or unusable).
//
// Each iteration needs F and its Jacobian. Where the sweeper's Jacobian lanes cost about one sweep
// (cheap_jacobian(): the AVX2 lanes), every trial point is swept together with its
// finite-difference lanes, so Newton always has a fresh Jacobian and converges quadratically;
// otherwise the Jacobian is made fresh at the start and then kept current by Broyden's update.
// The start: the remembered translations extrapolated along the path (Predict).
//
// The curvature probe: Newton's step s from the start leaves about F''(s, s) / 2, which for the
// extrapolated start is still 1 to 100 times the tolerance on the benchmark's paths. Where the
// first pass has a lane to spare (spare_lane()), it also sweeps u + d, d the last step's
// prediction error (the new one points about the same way along a smooth path), which measures
// q = F(u + d) - F(u) - J d ~ F''(d, d) / 2. The first step is then corrected for the curvature
// along d: s <- s - J^-1 q (s.d / d.d)^2, one fixed-point step on F + J s + F''(s, s) / 2 = 0
// with F'' taken along d. The correction is kept only if it is at most half the step; the next
// pass measures the result as always, and the line search guards it like any step.
SolveResult SolveNewton(Sweeper* sweeper, const ArmModel& model, const Vec& move,
                        const ArmOptions& options, double tol, double scale,
                        const ArmSolverMemory& memory) {
  const int dim = model.dim;
  const double h = 1e-7 * scale;  // finite-difference step of a fresh Jacobian
  const bool every_trial_fresh = sweeper->cheap_jacobian();
  Mat jac = Mat::Zero(dim, dim);
  Vec u = Predict(memory, dim, move.norm());
  Vec probe_dir = Vec::Zero(dim), f_probe(dim);
  const Eigen::VectorXd& last_error = memory.prediction_error;
  bool probing = sweeper->spare_lane() && u.squaredNorm() > 0.0 && last_error.size() == dim &&
                 last_error.allFinite() && last_error.squaredNorm() > 0.0;
  if (probing) probe_dir = last_error;
  const Vec probe = u + probe_dir;
  Vec f = sweeper->EvaluateWithJacobian(u, h, &jac, probing ? &probe : nullptr, &f_probe);
  if (u.squaredNorm() > 0.0 && !(f.allFinite() && f.norm() <= move.norm())) {
    // The predicted translation does worse than no translation would (F(0) is the base's reply
    // to the move, smaller than the move): a stale memory, start afresh.
    u.setZero();
    probing = false;
    f = sweeper->EvaluateWithJacobian(u, h, &jac);
  }
  probing = probing && f_probe.allFinite();
  const Vec start = u;
  bool keep_jacobian = true;  // the Jacobian is fresh or a Broyden update doing well
  SolveResult best{sweeper->points(), f.norm(), 0, f.norm() <= tol, sweeper->limited(), {}};
  Vec best_u = u;
  auto remember = [&](const Vec& fv) {
    if (fv.norm() < best.residual) {
      best.points = sweeper->points();
      best.residual = fv.norm();
      best.limited = sweeper->limited();
      best_u = u;
    }
  };
  int kicks = 0;
  for (int it = 0; it < options.max_iterations && !best.converged; ++it) {
    best.iterations = it + 1;
    const bool fresh = !keep_jacobian;
    if (fresh) sweeper->Jacobian(u, f, h, &jac);
    // Newton step; where the Jacobian is (nearly) singular, a Levenberg-Marquardt step instead.
    const Eigen::FullPivLU<Mat> lu(jac);
    Vec step;
    if (lu.rcond() > 1e-10) {
      step = -lu.solve(f);
    } else {
      const double mu = 1e-6 * std::max(jac.squaredNorm(), 1e-300);
      const Mat normal = jac.transpose() * jac + mu * Mat::Identity(dim, dim);
      step = -normal.ldlt().solve(jac.transpose() * f);
    }
    if (!step.allFinite()) step.setZero();
    if (it == 0 && probing && lu.rcond() > 1e-10) {
      const Vec q = f_probe - f - jac * probe_dir;  // ~ F''(d, d) / 2
      const double w = step.dot(probe_dir) / probe_dir.squaredNorm();
      const Vec correction = lu.solve(q) * (w * w);
      if (correction.allFinite() && correction.norm() <= 0.5 * step.norm()) step -= correction;
    }
    // Backtracking: the full step, then halves, until the residual drops enough. The full step
    // comes with its Jacobian where that is cheap.
    bool accepted = false, trial_fresh = false;
    Vec f_new;
    Mat jac_new(dim, dim);
    double alpha = 1.0;
    for (int half = 0; half < 12 && step.squaredNorm() > 0.0; ++half, alpha *= 0.5) {
      const Vec trial = u + alpha * step;
      trial_fresh = every_trial_fresh && half == 0;
      f_new = trial_fresh ? sweeper->EvaluateWithJacobian(trial, h, &jac_new)
                          : sweeper->Evaluate(trial);
      if (f_new.allFinite() && f_new.norm() <= (1.0 - 1e-4 * alpha) * f.norm()) {
        accepted = true;
        break;
      }
    }
    if (accepted) {
      const Vec s = alpha * step;
      if (trial_fresh) {
        jac = jac_new;
        keep_jacobian = true;
      } else {
        // Broyden's update keeps the Jacobian current at one sweep per iteration while the
        // residual at least halves; otherwise the next iteration makes a fresh one.
        jac += (f_new - f - jac * s) * s.transpose() / s.squaredNorm();
        keep_jacobian = f_new.norm() <= 0.5 * f.norm();
      }
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
  if (best.converged) best.memory = Remember(memory, dim, best_u, start, move.norm());
  return best;
}

// Stops a fixed-point iteration that does not contract. Where the iteration converges it
// converges linearly: the slowest steps measured (512 links near the edge of the workspace, up
// to 1500 sweeps for some 30 halvings of the residual) halve it every 50 sweeps or so. Where it
// does not (revolute joints about axes, whose cone projections need not contract: on
// examples/robot_snake.urdf the residual wanders between 0.006 and 0.17 for all 100000 sweeps;
// joint limits that hold the arm off the target), max_fixed_point_iterations sweeps a step
// bought nothing but time (5.5 s for a path of 60 targets). So each window of kStallWindow
// iterations, 20 times the slowest pace measured, must halve the smallest residual so far; the
// first that does not ends the step, unconverged. A run that converges is not touched: its
// residual keeps halving.
class StallCheck {
 public:
  static constexpr int kStallWindow = 1000;
  // Whether to stop after `iterations` iterations, the last with residual `residual`.
  bool Stalled(int iterations, double residual) {
    if (iterations == 1) mark_ = residual;
    best_ = std::min(best_, residual);
    if (iterations % kStallWindow != 0) return false;
    const bool stalled = !(best_ <= 0.5 * mark_);
    mark_ = best_;
    return stalled;
  }

 private:
  double best_ = INFINITY, mark_ = INFINITY;
};

SolveResult SolveFixedPoint(Sweeper* sweeper, const Points& start, const ArmOptions& options,
                            double tol) {
  SolveResult result;
  result.points = start;
  Vec f = sweeper->SweepInPlace(&result.points);
  result.iterations = 1;
  StallCheck stall;
  while (f.allFinite() && f.norm() > tol &&
         result.iterations < options.max_fixed_point_iterations &&
         !stall.Stalled(result.iterations, f.norm())) {
    result.points.rowwise() -= f.transpose();  // the base back where it is bolted
    f = sweeper->SweepInPlace(&result.points);
    ++result.iterations;
  }
  result.residual = f.norm();
  result.converged = result.residual <= tol;
  result.limited = sweeper->limited();
  return result;
}

// The fixed-point baseline for revolute joints about axes: u <- u + F(u), F being the rebuilt
// end effector's miss, which is about minus the base residual of the other arms.
SolveResult SolveFixedPointRevolute(arm_internal::RevoluteSweeper* sweeper,
                                    const ArmOptions& options, double tol) {
  SolveResult result;
  Vec u = Vec::Zero(3);
  Vec f = sweeper->Evaluate(u);
  result.iterations = 1;
  StallCheck stall;
  while (f.allFinite() && f.norm() > tol &&
         result.iterations < options.max_fixed_point_iterations &&
         !stall.Stalled(result.iterations, f.norm())) {
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

void CheckState(const ArmModel& model, const ArmState& state, const Eigen::VectorXd& target) {
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

bool ArmSolverMemory::Usable(int dim) const {
  return translation.size() == dim && translation.allFinite();
}

Problems ArmOptions::Validate() const {
  Problems problems;
  if (!(tolerance > 0.0 && tolerance < 1.0)) {
    problems.push_back(Problem::Invalid("tolerance", FormatNumber(tolerance), "0 < tolerance < 1"));
  }
  struct Count {
    const char* name;
    int value, least;
  };
  const Count counts[] = {{"max_iterations", max_iterations, 1},
                          {"max_fixed_point_iterations", max_fixed_point_iterations, 1},
                          {"restarts", restarts, 0},
                          {"substeps", substeps, 1}};
  for (const auto& [name, value, least] : counts) {
    if (value < least) {
      problems.emplace_back(
          name, "value " + std::to_string(value) + " is not >= " + std::to_string(least),
          std::to_string(value), ">= " + std::to_string(least));
    }
  }
  if (!(edge_margin >= 0.0 && edge_margin < 0.5)) {
    problems.push_back(
        Problem::Invalid("edge_margin", FormatNumber(edge_margin), "0 <= edge_margin < 0.5"));
  }
  if (!(time_step >= 0.0 && std::isfinite(time_step))) {
    problems.push_back(Problem::Invalid("time_step", FormatNumber(time_step),
                                        "a time >= 0 (s; 0: velocity limits ignored)"));
  }
  for (size_t c = 0; c < colliders.size(); ++c) {
    const Problems bad = CheckCollider(colliders[c], "colliders[" + std::to_string(c) + "]");
    problems.insert(problems.end(), bad.begin(), bad.end());
  }
  if (pointing.enabled) {
    auto unit_vector = [&](const Eigen::Vector3d& v, const char* name) {
      if (!v.allFinite() || !(v.norm() > 0.0)) {
        problems.emplace_back(std::string("pointing.") + name,
                              "is zero or not finite; expected a non-zero direction");
      }
    };
    unit_vector(pointing.axis, "axis");
    if (pointing.look_at) {
      if (!pointing.point.allFinite()) {
        problems.emplace_back("pointing.point", "is not finite; expected a point to look at");
      }
    } else {
      unit_vector(pointing.direction, "direction");
    }
    if (!(pointing.weight > 0.0 && std::isfinite(pointing.weight))) {
      problems.push_back(Problem::Invalid("pointing.weight", FormatNumber(pointing.weight),
                                          "a finite number > 0 (mean link lengths per rad)"));
    }
    if (!(pointing.angle_tolerance > 0.0 && pointing.angle_tolerance < 1.0)) {
      problems.push_back(Problem::Invalid("pointing.angle_tolerance",
                                          FormatNumber(pointing.angle_tolerance),
                                          "0 < angle_tolerance < 1 (rad)"));
    }
  }
  return problems;
}

Problems ArmOptions::ValidateFor(const ArmModel& model) const {
  Problems problems;
  if (pointing.enabled && !model.has_axes()) {
    problems.emplace_back("pointing",
                          "needs an arm with joint axes (a URDF arm, or joint_axes); planar and "
                          "spherical arms have no tool frame");
  }
  if (method == FixedBaseMethod::kFixedPoint && model.has_axes() &&
      (pointing.enabled || !arm_internal::Sweepable(model))) {
    problems.emplace_back("method",
                          "value \"fixed_point\" is not valid for this arm: the fixed-point sweep "
                          "takes revolute joints across links of positive length with limits "
                          "within [-pi, pi] and no pointing; expected \"newton\"");
  }
  if (!colliders.empty() && model.has_axes()) {
    // Arms with joint axes keep their capsules outside in the joint-space step
    // (src/arm/joint_space_contact.h): method newton.
    if (method != FixedBaseMethod::kNewton) {
      problems.emplace_back("method",
                            "colliders with an arm with joint axes need method \"newton\" (the "
                            "joint-space step keeps the links outside); expected \"newton\"");
    }
  }
  return problems;
}

namespace {

void AddCost(const ArmStepReport& from, ArmStepReport* to);
void SetCost(const ArmStepReport& from, ArmStepReport* to);

void CheckOptions(const ArmOptions& options) {
  Problems problems;
  AppendNested("options", options.Validate(), &problems);
  ThrowIfAny(problems);
}

// The end effector's miss of the report's points, and whether the step reached the target.
void MeasureReach(const ArmModel& model, const Eigen::VectorXd& target, double tol,
                  ArmStepReport* report) {
  report->ee_error = (report->state.points.row(model.num_links()).transpose() - target).norm();
  report->reached = report->converged && report->ee_error <= 2.0 * tol + 1e-13 * model.reach();
}

// The report of a solve: the points re-anchored (rebuilt from the joint angles at the fixed
// base, which also puts any joint the sweep could not keep within its limits, the base link
// between two limits, there), the error measured on them.
ArmStepReport Report(const ArmModel& model, const Eigen::VectorXd& target, double tol,
                     const SolveResult& solved, int sweeps, int passes) {
  ArmStepReport report;
  report.base_error = solved.residual;
  report.iterations = solved.iterations;
  report.converged = solved.converged;
  report.limited = solved.limited;
  report.sweeps = sweeps;
  report.passes = passes;
  report.state.memory = solved.memory;
  report.state.angles = arm_internal::AnglesUnchecked(model, solved.points, &report.state.points);
  if (arm_internal::ClampToLimits(model, &report.state.angles)) {
    report.limited = true;
    report.state.points = arm_internal::ForwardUnchecked(model, report.state.angles);
  }
  MeasureReach(model, target, tol, &report);
  return report;
}

// The report of a joint-space solve of an arm with joint axes: the solver's joint values and
// their points, the end effector's miss as base_error. (The solve's angle residual is kept.)
ArmStepReport AxisReport(const ArmModel& model, const Eigen::VectorXd& target, double tol,
                         arm_internal::JointSpaceSolve&& solved) {
  ArmStepReport report;
  report.base_error = solved.residual;
  report.iterations = solved.iterations;
  report.converged = solved.converged;
  report.limited = solved.limited;
  report.passes = solved.passes;
  report.state.angles.angle = std::move(solved.angles);
  report.state.points = std::move(solved.points);
  MeasureReach(model, target, tol, &report);
  return report;
}

// The joint-space solve from `state` (src/arm/joint_space.h); base_error is the end effector's
// miss, sweeps 0. Arms with joint axes keep the solver's joint values (their points are its
// forward kinematics); the others read their angles from the points, as the sweep's steps do.
ArmStepReport JointSpaceStep(const arm_internal::JointSpacePlan& plan, const ArmState& state,
                             const Eigen::VectorXd& target, double tol, const ArmOptions& options) {
  const ArmModel& model = plan.model();
  arm_internal::JointSpaceSolve solved = arm_internal::SolveJointSpace(
      plan, state, target, tol, options.max_iterations, options.restarts, options.pointing);
  ArmStepReport report;
  if (model.has_axes()) {
    const double angle_residual = solved.angle_residual;
    report = AxisReport(model, target, tol, std::move(solved));
    if (options.pointing.enabled) report.pointing_error = angle_residual;
  } else {
    const SolveResult result{std::move(solved.points), solved.residual, solved.iterations,
                             solved.converged,         solved.limited,  {}};
    report = Report(model, target, tol, result, 0, solved.passes);
  }
  report.joint_space = true;
  report.restarts = solved.restarts;
  return report;
}

// The largest joint speed of the move from `from` to `to` in `time_step`, over its limit.
double VelocityRatio(const ArmModel& model, const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                     double time_step) {
  double ratio = 0.0;
  for (int j = 0; j < model.max_velocity.size(); ++j) {
    double move = to[j] - from[j];
    // Planar angles are read on the circle: the move is the shorter way round.
    if (!model.has_axes()) move = std::remainder(move, 2.0 * M_PI);
    ratio = std::max(ratio, std::abs(move) / (model.max_velocity[j] * time_step));
  }
  return ratio;
}

// The joint-space step with velocity limits (ArmOptions::time_step): where the step would move a
// joint faster than its limit, the end effector's straight move is tracked in equal legs of one
// time_step each, as many as the fastest joint needs, and more where the legs' motion is not
// even (up to kMaxVelocityRounds tries).
// The options of leg `leg` of `legs` from `state` toward `target`: with pointing, the tool axis'
// goal turned from where the axis is to the step's goal along the great circle (the last leg
// keeps the step's own goal), so that the turn is split with the move.
ArmOptions LegOptions(const ArmModel& model, const ArmState& state, const Eigen::VectorXd& target,
                      const ArmOptions& options, int leg, int legs) {
  if (!options.pointing.enabled || leg == legs) return options;
  const ArmOptions::Pointing& p = options.pointing;
  const Eigen::Vector3d from = ToolPoseAt(model, state.angles).rotation * p.axis.normalized();
  const Eigen::Vector3d to = p.look_at ? Eigen::Vector3d((p.point - target.head<3>()).normalized())
                                       : Eigen::Vector3d(p.direction.normalized());
  ArmOptions out = options;
  out.pointing.look_at = false;
  out.pointing.direction = Eigen::Quaterniond::Identity().slerp(
                               double(leg) / legs, Eigen::Quaterniond::FromTwoVectors(from, to)) *
                           from;
  return out;
}

template <class Step>
ArmStepReport VelocityLimitedStep(const ArmModel& model, const ArmState& state,
                                  const Eigen::VectorXd& target, const ArmOptions& options,
                                  const StepWindow& window, const Step& step) {
  constexpr int kMaxVelocityRounds = 8, kMaxVelocityLegs = 100000;
  ArmStepReport report = step(state, target, options, window);
  report.velocity_legs = 1;
  report.velocity_ratio =
      VelocityRatio(model, state.angles.angle, report.state.angles.angle, options.time_step);
  if (report.velocity_ratio <= 1.0) return report;
  ArmStepReport cost = report;
  const Eigen::VectorXd from = state.points.row(model.num_links()).transpose();
  int legs = static_cast<int>(std::min<double>(kMaxVelocityLegs, std::ceil(report.velocity_ratio)));
  for (int round = 0; round < kMaxVelocityRounds; ++round) {
    ArmStepReport leg_report;
    ArmState leg_state = state;
    double ratio = 0.0;
    for (int leg = 1; leg <= legs; ++leg) {
      const Eigen::VectorXd goal =
          leg == legs ? target : Eigen::VectorXd(from + (target - from) * (double(leg) / legs));
      leg_report = step(leg_state, goal, LegOptions(model, state, target, options, leg, legs),
                        window.Leg(leg, legs));
      AddCost(leg_report, &cost);
      ratio = std::max(ratio, VelocityRatio(model, leg_state.angles.angle,
                                            leg_report.state.angles.angle, options.time_step));
      leg_state = leg_report.state;
    }
    report = leg_report;
    report.velocity_legs = legs;
    report.velocity_ratio = ratio;
    if (ratio <= 1.0 || legs >= kMaxVelocityLegs) break;
    // A margin of 10%: the legs come out uneven where the motion is not linear in the move.
    legs = static_cast<int>(std::min<double>(kMaxVelocityLegs, std::ceil(legs * ratio * 1.1)));
  }
  SetCost(cost, &report);
  return report;
}

// The tractrix sweep's step (planar and spherical arms), solved by Newton or the fixed point.
// With `contact` (src/arm/colliders.h), the sweep takes the contact step where a link would enter
// a collider, keyframed ones where they are at each sub-step's time in `window`.
ArmStepReport SweepStep(const ArmModel& model, const ArmState& state, const Eigen::VectorXd& target,
                        double tol, const ArmOptions& options, const std::vector<Collider>* contact,
                        const StepWindow& window) {
  const int n = model.num_links();
  Sweeper sweeper(model, state.points, target, options.substeps, contact, window);
  const SolveResult solved =
      options.method == FixedBaseMethod::kNewton
          ? SolveNewton(&sweeper, model, target - state.points.row(n).transpose(), options, tol,
                        model.link_lengths.mean(), state.memory)
          : SolveFixedPoint(&sweeper, state.points, options, tol);
  return Report(model, target, tol, solved, sweeper.sweeps(), sweeper.passes());
}

// The cost of one attempt (iterations, sweeps, passes) added to another's, or put in its place.
void AddCost(const ArmStepReport& from, ArmStepReport* to) {
  to->iterations += from.iterations;
  to->sweeps += from.sweeps;
  to->passes += from.passes;
}
void SetCost(const ArmStepReport& from, ArmStepReport* to) {
  to->iterations = from.iterations;
  to->sweeps = from.sweeps;
  to->passes = from.passes;
}

// The move from the end effector to `target` tracked along its straight line in `legs` equal
// legs, each a sweep step with the base held, as TrackPath would track that line. Stops at the
// first leg not reached (reached = false; its error is then the leg's). Costs of all legs. Each
// leg spans its share of `window`.
ArmStepReport LegsStep(const ArmModel& model, const ArmState& state, const Eigen::VectorXd& target,
                       int legs, double tol, const ArmOptions& options,
                       const std::vector<Collider>* contact, const StepWindow& window) {
  const Eigen::VectorXd from = state.points.row(model.num_links()).transpose();
  ArmStepReport report, cost;
  ArmState leg_state = state;
  leg_state.memory = ArmSolverMemory();  // the memory is of a step of another length
  for (int leg = 1; leg <= legs; ++leg) {
    const Eigen::VectorXd goal =
        leg == legs ? target : Eigen::VectorXd(from + (target - from) * (double(leg) / legs));
    report = SweepStep(model, leg_state, goal, tol, options, contact, window.Leg(leg, legs));
    AddCost(report, &cost);
    if (!report.reached) break;
    leg_state = report.state;
  }
  report.legs = legs;
  SetCost(cost, &report);
  return report;
}

// The options that only some arms take, refused by name for the others.
void CheckOptionsForModel(const ArmModel& model, const ArmOptions& options) {
  Problems problems;
  AppendNested("options", options.ValidateFor(model), &problems);
  ThrowIfAny(problems);
}

ArmStepReport SweptStep(const arm_internal::JointSpacePlan& plan, const ArmState& state,
                        const Eigen::VectorXd& target, const ArmOptions& options,
                        const std::vector<Collider>* contact, const StepWindow& window);

// `report` (a step among `colliders`, where they are at the step's end) with its clearance
// measured; where a link is still inside a collider (no solve kept them all outside), the arm held
// where it was (`blocked`, not reached; a keyframed collider that came onto it may leave it
// inside: the clearance says by how much).
ArmStepReport KeptOutside(const ArmModel& model, const ArmState& state,
                          const Eigen::VectorXd& target, const ArmOptions& options,
                          const std::vector<Collider>& colliders, ArmStepReport report) {
  double relative = 0.0;
  report.clearance = arm_internal::ArmClearance(model, report.state.points, colliders, &relative);
  if (relative >= -arm_internal::kArmContactSlack) return report;
  ArmStepReport held = report;
  held.state = state;
  held.state.memory = ArmSolverMemory();
  held.reached = false;
  held.blocked = true;
  MeasureReach(model, target, options.tolerance * model.link_lengths.mean(), &held);
  held.reached = false;
  held.clearance = arm_internal::ArmClearance(model, state.points, colliders, &relative);
  return held;
}

// The step among colliders (planar and spherical arms): the free step where it leaves every link
// outside (then it is the step without colliders, bit for bit), else the step again with contact
// steps in the sweep. The clearance after it is measured either way, against the colliders where
// they are at the end of `window` (keyframed ones: in the sweep, at each sub-step's time).
ArmStepReport ContactStep(const arm_internal::JointSpacePlan& plan, const ArmState& state,
                          const Eigen::VectorXd& target, const ArmOptions& options,
                          const StepWindow& window) {
  const ArmModel& model = plan.model();
  double relative = 0.0;
  std::vector<Collider> posed;
  const std::vector<Collider>& colliders =
      arm_internal::CollidersNow(options.colliders, window.end, &posed);
  ArmStepReport free = SweptStep(plan, state, target, options, nullptr, window);
  free.clearance = arm_internal::ArmClearance(model, free.state.points, colliders, &relative);
  if (relative >= -arm_internal::kArmContactSlack) return free;
  const std::vector<Collider> grown = arm_internal::SweepColliders(model, options);
  ArmStepReport report = SweptStep(plan, state, target, options, &grown, window);
  AddCost(free, &report);
  // Contact makes F piecewise smooth: where Newton finds no root, the same straight move in
  // 2, 4 and 8 legs (each leg's Newton starts nearer its root).
  for (int legs = 2; !report.reached && legs <= kContactLegs; legs *= 2) {
    ArmStepReport legged =
        LegsStep(model, state, target, legs, options.tolerance * model.link_lengths.mean(), options,
                 &grown, window);
    AddCost(report, &legged);
    legged.legs = std::max(legged.legs, report.legs);
    // The legs stop at the first leg not reached, with that leg's error: measured to the target.
    MeasureReach(model, target, options.tolerance * model.link_lengths.mean(), &legged);
    const bool better = legged.reached || legged.ee_error < report.ee_error;
    if (!better) {
      SetCost(legged, &report);
      continue;
    }
    report = std::move(legged);
  }
  report.contact = true;
  return KeptOutside(model, state, target, options, colliders, std::move(report));
}

// The step among colliders of an arm with joint axes (method newton): the free joint-space step
// where it leaves every link outside (then it is that step, bit for bit), else the joint-space
// step with the capsules' clearances as constraints (src/arm/joint_space_contact.h). Keyframed
// colliders: where they are at the end of `window` (the step has no sub-steps).
ArmStepReport AxisContactStep(const arm_internal::JointSpacePlan& plan, const ArmState& state,
                              const Eigen::VectorXd& target, const ArmOptions& options,
                              const StepWindow& window) {
  const ArmModel& model = plan.model();
  const double tol = options.tolerance * model.link_lengths.mean();
  double relative = 0.0;
  std::vector<Collider> posed;
  const std::vector<Collider>& colliders =
      arm_internal::CollidersNow(options.colliders, window.end, &posed);
  ArmStepReport free = JointSpaceStep(plan, state, target, tol, options);
  free.clearance = arm_internal::ArmClearance(model, free.state.points, colliders, &relative);
  if (relative >= -arm_internal::kArmContactSlack) return free;
  arm_internal::JointSpaceSolve solved;
  arm_internal::SolveJointSpaceContact(plan, state.angles.angle, target, colliders, tol,
                                       arm_internal::kArmContactSlack, options.max_iterations,
                                       options.pointing, &solved);
  const double angle_residual = solved.angle_residual;
  ArmStepReport report = AxisReport(model, target, tol, std::move(solved));
  if (options.pointing.enabled) report.pointing_error = angle_residual;
  report.joint_space = true;
  AddCost(free, &report);
  report.contact = true;
  return KeptOutside(model, state, target, options, colliders, std::move(report));
}

// ArmStep on a checked model (prepared in `plan`), options, state and target, without velocity
// limits, over `window` (keyframed colliders).
ArmStepReport StepUnlimited(const arm_internal::JointSpacePlan& plan, const ArmState& state,
                            const Eigen::VectorXd& target, const ArmOptions& options,
                            const StepWindow& window) {
  const ArmModel& model = plan.model();
  const int n = model.num_links();
  const double scale = model.link_lengths.mean();
  const double tol = options.tolerance * scale;
  const bool newton = options.method == FixedBaseMethod::kNewton;
  if (model.has_axes()) {
    if (state.angles.angle.size() != n || !state.angles.angle.allFinite()) {
      throw InputError("state.angles", "has " + std::to_string(state.angles.angle.size()) +
                                           " finite values or fewer; expected " +
                                           std::to_string(n));
    }
    // Method newton: the weighted minimum-norm joint motion from the last angles
    // (src/arm/joint_space.cc says why not the sweep). Out of reach, it ends at the nearest
    // configuration its joints give (a straight arm is not one in general).
    if (newton && !options.colliders.empty()) {
      return AxisContactStep(plan, state, target, options, window);
    }
    if (newton) return JointSpaceStep(plan, state, target, tol, options);
    arm_internal::RevoluteSweeper sweeper(model, state, target, options.substeps);
    const SolveResult solved = SolveFixedPointRevolute(&sweeper, options, tol);
    return Report(model, target, tol, solved, sweeper.sweeps(),
                  sweeper.sweeps());  // 1 sweep a pass
  }
  if (!options.colliders.empty()) return ContactStep(plan, state, target, options, window);
  return SweptStep(plan, state, target, options, nullptr, window);
}

// The step of a planar or spherical arm (the tractrix sweep, then the legs and the joint-space
// step where it finds no root). With `contact` (the grown colliders, src/arm/colliders.h) the
// sweeps take contact steps, and a joint-space result is kept only where it keeps every link
// outside the colliders.
ArmStepReport SweptStep(const arm_internal::JointSpacePlan& plan, const ArmState& state,
                        const Eigen::VectorXd& target, const ArmOptions& options,
                        const std::vector<Collider>* contact, const StepWindow& window) {
  const ArmModel& model = plan.model();
  const int n = model.num_links();
  const double scale = model.link_lengths.mean();
  const double tol = options.tolerance * scale;
  const bool newton = options.method == FixedBaseMethod::kNewton;
  const Vec to_target = target - model.base;
  if (to_target.norm() >= model.reach() * (1.0 - options.edge_margin)) {
    // Out of reach (or on its edge, where the Jacobian is singular): stretched toward the target.
    SolveResult stretched;
    stretched.points.resize(n + 1, model.dim);
    const Vec dir = to_target.normalized();
    stretched.points.row(0) = model.base.transpose();
    for (int j = 0; j < n; ++j) {
      stretched.points.row(j + 1) =
          stretched.points.row(j) + model.link_lengths[j] * dir.transpose();
    }
    stretched.converged = true;
    ArmStepReport report = Report(model, target, tol, stretched, 0, 0);
    report.stretched = true;
    return report;
  }
  // A far move (more than one leg, below) gets fewer Newton iterations in one sweep: where
  // Newton converges it does in a few (at most 10 measured on single jumps across the
  // workspace), and the legs are the better use of the passes where it does not.
  const Vec from = state.points.row(n).transpose();
  const int legs = static_cast<int>(std::ceil((target - from).norm() / (kLegLength * scale)));
  ArmOptions first = options;
  if (legs > 1 && newton) first.max_iterations = std::min(options.max_iterations, kFarIterations);
  ArmStepReport report = SweepStep(model, state, target, tol, first, contact, window);
  if (report.reached || !newton) return report;
  // The sweep found no root. (1) A far move: the same straight line in legs.
  if (legs > 1) {
    ArmStepReport legged = LegsStep(model, state, target, legs, tol, options, contact, window);
    AddCost(report, &legged);
    if (legged.reached) return legged;
    SetCost(legged, &report);
  }
  // (2) Joint limits saturated near the end effector, where the target needs bending near the
  // base: the joint-space solve from the last state, kept if it gets nearer.
  ArmStepReport fallback = JointSpaceStep(plan, state, target, tol, options);
  AddCost(report, &fallback);
  double relative = 0.0;
  std::vector<Collider> posed;
  const bool fallback_clear =
      contact == nullptr ||
      (arm_internal::ArmClearance(model, fallback.state.points,
                                  arm_internal::CollidersNow(options.colliders, window.end, &posed),
                                  &relative),
       relative >= -arm_internal::kArmContactSlack);
  if (fallback_clear && (fallback.reached || fallback.ee_error < report.ee_error)) return fallback;
  SetCost(fallback, &report);
  return report;
}

// ArmStep on a checked model (prepared in `plan`), options, state and target, over `window`
// (keyframed colliders; velocity legs split it as they split the move).
ArmStepReport StepChecked(const arm_internal::JointSpacePlan& plan, const ArmState& state,
                          const Eigen::VectorXd& target, const ArmOptions& options,
                          const StepWindow& window) {
  const ArmModel& model = plan.model();
  if (options.time_step > 0.0 && model.max_velocity.size() == model.num_links()) {
    return VelocityLimitedStep(model, state, target, options, window,
                               [&](const ArmState& from, const Eigen::VectorXd& goal,
                                   const ArmOptions& leg_options, const StepWindow& leg_window) {
                                 return StepUnlimited(plan, from, goal, leg_options, leg_window);
                               });
  }
  return StepUnlimited(plan, state, target, options, window);
}

}  // namespace

ArmStepReport ArmStep(const ArmModel& model, const ArmState& state,
                      const Eigen::Ref<const Eigen::VectorXd>& target_in, const ArmOptions& options,
                      double time) {
  arm_internal::CheckModel(model);
  CheckOptions(options);
  CheckOptionsForModel(model, options);
  const Eigen::VectorXd target = target_in;
  CheckState(model, state, target);
  if (!std::isfinite(time)) {
    throw InputError("time", "value " + FormatNumber(time) + " is not a finite number");
  }
  arm_internal::CheckArmOutside(model, state.points, options.colliders, "state.points", time);
  arm_internal::CheckTargetOutside(model, options, target, "target");
  return StepChecked(arm_internal::JointSpacePlan(model), state, target, options,
                     StepWindow{time, time + 1.0});
}

std::string ArmStepReport::BriefReport() const {
  char line[256];
  std::snprintf(line, sizeof(line),
                "%s: end-effector error %.3g, base residual %.3g, %d iterations, %d sweeps%s%s",
                reached ? "reached" : "NOT reached", ee_error, base_error, iterations, sweeps,
                stretched ? ", stretched toward an out-of-reach target" : "",
                limited ? ", joint limits active" : "");
  std::string text = line;
  if (pointing_error > 0.0) {
    std::snprintf(line, sizeof(line), ", pointing error %.3g rad", pointing_error);
    text += line;
  }
  if (velocity_legs > 1) text += ", " + std::to_string(velocity_legs) + " legs for velocity limits";
  if (std::isfinite(clearance)) {
    std::snprintf(line, sizeof(line), ", clearance %.3g%s%s", clearance,
                  contact ? " (contact steps)" : "",
                  blocked ? ", BLOCKED: no solve kept the links outside, the arm held" : "");
    text += line;
  }
  return text;
}

ArmTrajectory TrackPath(const ArmModel& model, const Points& path, const ArmOptions& options,
                        ArmStepSink* sink) {
  arm_internal::CheckModel(model);
  if (path.rows() < 1 || path.cols() != model.dim) {
    throw InputError("path", "shape " + std::to_string(path.rows()) + " by " +
                                 std::to_string(path.cols()) +
                                 " is not valid; expected m >= 1 by " + std::to_string(model.dim));
  }
  const auto begin = std::chrono::steady_clock::now();
  ArmTrajectory trajectory;
  CheckOptions(options);
  CheckOptionsForModel(model, options);
  for (int i = 0; i < path.rows(); ++i) {  // every target before the first step
    for (int k = 0; k < path.cols(); ++k) {
      if (!std::isfinite(path(i, k))) {
        throw InputError("path[" + std::to_string(i) + "][" + std::to_string(k) + "]",
                         "value " + FormatNumber(path(i, k)) + " is not a finite number");
      }
    }
  }
  // The last step's state is the next step's start: two reports, swapped after each step.
  ArmStepReport last;
  last.state = InitialState(model);
  // Keyframed colliders where their motions have them at time 0.
  arm_internal::CheckArmOutside(model, last.state.points, options.colliders, "initial", 0.0);
  for (int i = 0; i < path.rows(); ++i) {
    arm_internal::CheckTargetOutside(model, options, path.row(i).transpose(),
                                     "path[" + std::to_string(i) + "]");
  }
  const arm_internal::JointSpacePlan plan(model);  // for every step
  for (int i = 0; i < path.rows(); ++i) {
    const Eigen::VectorXd target = path.row(i).transpose();
    // Step i spans leader step i + 1: time i to i + 1 (docs/colliders.md, "Moving colliders").
    ArmStepReport step =
        StepChecked(plan, last.state, target, options, StepWindow{double(i), double(i + 1)});
    trajectory.max_ee_error = std::max(trajectory.max_ee_error, step.ee_error);
    trajectory.max_base_error = std::max(trajectory.max_base_error, step.base_error);
    trajectory.unreached += step.reached ? 0 : 1;
    trajectory.max_pointing_error = std::max(trajectory.max_pointing_error, step.pointing_error);
    trajectory.velocity_legs += step.velocity_legs;
    trajectory.max_iterations = std::max(trajectory.max_iterations, step.iterations);
    trajectory.total_sweeps += step.sweeps;
    trajectory.total_passes += step.passes;
    trajectory.min_clearance = std::min(trajectory.min_clearance, step.clearance);
    trajectory.contact_steps += step.contact ? 1 : 0;
    trajectory.blocked_steps += step.blocked ? 1 : 0;
    ++trajectory.num_steps;
    if (sink != nullptr) sink->Add(step);
    last = std::move(step);
  }
  trajectory.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return trajectory;
}

ArmTrajectory TrackPath(const ArmModel& model, const Points& path, const ArmOptions& options) {
  ArmStepRecorder recorder;
  recorder.steps.reserve(path.rows() > 0 ? path.rows() : 0);
  ArmTrajectory trajectory = TrackPath(model, path, options, &recorder);
  trajectory.steps = std::move(recorder.steps);
  return trajectory;
}

std::string ArmTrajectory::BriefReport() const {
  char line[256];
  std::snprintf(line, sizeof(line),
                "%zu steps, %d not reached, max end-effector error %.3g, max base residual %.3g, "
                "max %d iterations, %lld sweeps, %.3g s",
                static_cast<size_t>(std::max<long long>(num_steps, steps.size())), unreached,
                max_ee_error, max_base_error, max_iterations, total_sweeps, seconds);
  std::string text = line;
  if (max_pointing_error > 0.0) {
    std::snprintf(line, sizeof(line), ", max pointing error %.3g rad", max_pointing_error);
    text += line;
  }
  if (velocity_legs > num_steps) {
    text += ", " + std::to_string(velocity_legs) + " legs to keep velocity limits";
  }
  if (std::isfinite(min_clearance)) {
    std::snprintf(line, sizeof(line), ", least clearance %.3g, %d steps with contact steps%s",
                  min_clearance, contact_steps,
                  blocked_steps > 0 ? ", BLOCKED steps (the arm held where it was): " : "");
    text += line;
    if (blocked_steps > 0) text += std::to_string(blocked_steps);
  }
  return text;
}

}  // namespace flexkin
