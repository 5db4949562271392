// NewtonSolver's iteration: measure, stop or take one Newton step (a solve of the regularized KKT
// system, then a line search along it), until both tolerances are met.

#include "overall/newton.h"

#include <algorithm>
#include <cmath>

namespace flexkin::internal {
namespace {

// Half-bandwidth of the KKT matrix in the interleaved order: x_j reaches x_{j+1} (2 dim) and
// lambda_j reaches x_{j-1} (2 dim + 1); the joint-angle term reaches x_{j+2} (3 dim + 1).
int KktBand(const ObjectiveWeights& weights, int dim) {
  return weights.joint_angle > 0.0 ? 3 * dim + 1 : 2 * dim + 1;
}

}  // namespace

void NewtonBuffers::Reserve(int n, int dim, const ObjectiveWeights& weights) {
  const Eigen::Index unknowns = static_cast<Eigen::Index>(n) * (dim + 1);
  for (Eigen::VectorXd* v : {&gradient, &trial_gradient, &rhs, &solution, &lagrangian,
                             &trial_lagrangian, &new_lagrangian, &step_only}) {
    internal::Reserve(v, unknowns);
  }
  for (Eigen::VectorXd* v : {&multipliers, &new_multipliers, &constraints, &inverse_lengths}) {
    internal::Reserve(v, n);
  }
  for (Points* p : {&x, &step, &trial}) p->resize(n + 1, dim);
  sink.offset.reserve(n + 1);
  identity_diagonal.reserve(n + 1);
  identity_below.reserve(n + 1);
  ldlt.Reserve(static_cast<int>(unknowns), KktBand(weights, dim));
  chain_system.Reserve(n, dim);
  // (The LU fallback's storage is sized when it is first needed: it is rarely.)
}

NewtonSolver::NewtonSolver(const Eigen::VectorXd& lengths, const Points& old_points,
                           const OverallOptions& options, int moving, double smoothing,
                           NewtonBuffers* buffers)
    : lengths_(lengths),
      old_points_(old_points),
      options_(options),
      n_(static_cast<int>(lengths.size())),
      k_(moving),
      nc_(moving < n_ ? moving + 1 : n_),  // links 1..k, and link k+1 to the fixed point
      dim_(static_cast<int>(old_points.cols())),
      block_(dim_ + 1),
      size_(k_ * block_ + (nc_ - k_)),
      last_(std::min(n_, k_ + 1)),  // the objective's terms beyond are 0
      smoothing_(smoothing),
      l2_(options.weights.l2 > 0.0 || options.weights.l2_weighted > 0.0),
      weight_sum_(WeightSum(options.weights, lengths)),
      constant_metric_hessian_(!l2_ && !(options.weights.joint_angle > 0.0)),
      buffers_(*buffers),
      sink_(buffers->sink),
      x_(buffers->x),
      dx_(buffers->step),
      trial_(buffers->trial),
      g_(Leading(&buffers->gradient, size_)),
      g_trial_(Leading(&buffers->trial_gradient, size_)),
      rhs_(Leading(&buffers->rhs, size_)),
      sol_(Leading(&buffers->solution, size_)),
      lag_(Leading(&buffers->lagrangian, size_)),
      lag_trial_(Leading(&buffers->trial_lagrangian, size_)),
      lag_new_(Leading(&buffers->new_lagrangian, size_)),
      dx_only_(Leading(&buffers->step_only, size_)),
      lambda_(Leading(&buffers->multipliers, nc_)),
      lambda_new_(Leading(&buffers->new_multipliers, nc_)),
      c_(Leading(&buffers->constraints, nc_)),
      inverse_length_(Leading(&buffers->inverse_lengths, n_)) {
  sink_.dim = dim_;
  sink_.gradient = nullptr;
  sink_.band = nullptr;
  sink_.form = nullptr;
  sink_.form_vector = nullptr;
  sink_.hessian = nullptr;
  sink_.identity_diagonal = nullptr;
  sink_.identity_below = nullptr;
  sink_.offset.assign(n_ + 1, -1);
  for (int j = 1; j <= k_; ++j) sink_.offset[j] = (j - 1) * block_;
  buffers_.identity_diagonal.assign(n_ + 1, 0.0);
  buffers_.identity_below.assign(n_ + 1, 0.0);
  inverse_length_ = lengths.cwiseInverse();
  max_inverse_length_ = inverse_length_.maxCoeff();
  lambda_.setZero();
  dx_.setZero(n_ + 1, dim_);
  trial_.resize(n_ + 1, dim_);
  // The KKT matrix is assembled into the LDL^T's storage and factored there; the LU fallback's
  // general storage and factors are shaped when first needed.
  buffers_.ldlt.Resize(size_, std::min(KktBand(options.weights, dim_), size_ - 1));
}

OverallReport NewtonSolver::Solve(Points* x) {
  x_ = *x;
  value_ = EvaluateMetric(x_, &g_);
  start_gradient_ = g_.cwiseAbs().maxCoeff();
  EvaluateConstraints(x_);
  StartingMultipliers();
  OverallReport report;
  report.moving_points = k_;
  for (report.iterations = 0;; ++report.iterations) {
    if (!lag_current_) LagrangianGradient(x_, g_, lambda_, &lag_);
    lag_current_ = false;
    Measure(&report);
    if (!std::isfinite(report.objective) || !std::isfinite(report.optimality)) {
      report.status = OverallStatus::kFailed;
      break;
    }
    if (report.iterations > 0 && report.constraint_violation <= options_.constraint_tolerance &&
        report.optimality <= options_.optimality_tolerance) {
      report.status = OverallStatus::kConverged;
      break;
    }
    if (report.iterations >= options_.max_iterations) {
      report.status = OverallStatus::kMaxIterations;
      break;
    }
    if (!Iterate()) {
      FinishWithoutStep(&report);
      break;
    }
    regularization_ *= 0.1;
    if (regularization_ < 1e-14) regularization_ = 0.0;
  }
  *x = x_;
  return report;
}

// A strict local minimizer (second-order sufficient conditions) has a KKT matrix with exactly as
// many negative eigenvalues as constraints and none zero. (Its own assembly and factorization:
// the last iteration's factors are of another matrix, at the iterate before and possibly
// regularized.)
bool NewtonSolver::IsStrictMinimizer(const OverallReport& report) {
  if (!report.converged()) return false;
  AssembleKkt(x_, lambda_, 0.0, &buffers_.ldlt.matrix());
  return buffers_.ldlt.Factorize(1e-12) && buffers_.ldlt.negative() == nc_;
}

// The report's measures at the iterate (lag_ the Lagrangian's gradient there).
void NewtonSolver::Measure(OverallReport* report) {
  report->objective = value_;
  report->constraint_violation = ConstraintViolation(lengths_, x_);
  report->optimality = Optimality(x_, g_, lag_);
}

// One Newton iteration: up to 12 attempts, each a Newton step at the current regularization and
// a line search along it; each failed attempt raises the regularization. False if none moved the
// iterate.
bool NewtonSolver::Iterate() {
  for (int attempt = 0; attempt < 12; ++attempt) {
    const StepOutcome outcome = ComputeNewtonStep();
    if (outcome == StepOutcome::kNotFinite) return false;
    if (outcome == StepOutcome::kRegularized) continue;
    if (LineSearch()) return true;
    // No acceptable step: more regularization, then try again.
    Regularize(1e-8 * std::fmax(1.0, g_.cwiseAbs().maxCoeff()));
  }
  return false;
}

// The Newton step (dx_, lambda_new_) from the KKT system, checked for finite values and, where
// the factorization gave no inertia, for positive curvature along it.
NewtonSolver::StepOutcome NewtonSolver::ComputeNewtonStep() {
  bool inertia_ok = false;
  if (!FactorAndSolveKkt(&inertia_ok)) {
    Regularize(1e-10 * std::fmax(1.0, g_.cwiseAbs().maxCoeff()));  // singular
    return StepOutcome::kRegularized;
  }
  factorized_ = true;
  if (!sol_.allFinite()) return StepOutcome::kNotFinite;
  const double* const solution = sol_.data();
  double* const step = dx_.data();  // row-major: point j's coordinates at j dim
  for (int j = 1; j <= k_; ++j) {
    for (int q = 0; q < dim_; ++q) step[j * dim_ + q] = solution[PointRow(j) + q];
  }
  double* const multipliers = lambda_new_.data();
  for (int i = 1; i <= nc_; ++i) multipliers[i - 1] = solution[MultiplierRow(i)];
  if (!inertia_ok && !HasPositiveCurvature()) {
    Regularize(1e-4 * std::fmax(1.0, weight_sum_));
    return StepOutcome::kRegularized;
  }
  return StepOutcome::kReady;
}

// Solves [H + delta I, J^T; J, 0] [dx; lambda_new] = -[g; c] at (x_, lambda_) into sol_: first
// by LDL^T without pivoting (a quarter of the LU's work), kept if no pivot is tiny and its factors
// did not grow (so that its backward error is at the rounding level); otherwise by the LU with
// partial pivoting. `*inertia_ok`: the LDL^T had as many negative pivots as constraints, so
// H + delta I is positive definite on the constraints' tangent space (the KKT matrix's inertia,
// by Sylvester's law) and the step minimizes the local quadratic model there. False if the
// matrix is singular.
bool NewtonSolver::FactorAndSolveKkt(bool* inertia_ok) {
  BandedLdlt& ldlt = buffers_.ldlt;
  AssembleKkt(x_, lambda_, regularization_, &ldlt.matrix());
  double* const rhs = rhs_.data();
  const double* const gradient = g_.data();
  const double* const constraints = c_.data();
  for (int j = 1; j <= k_; ++j) {
    for (int q = 0; q < dim_; ++q) rhs[PointRow(j) + q] = -gradient[PointRow(j) + q];
  }
  for (int i = 1; i <= nc_; ++i) rhs[MultiplierRow(i)] = -constraints[i - 1];
  if (ldlt.Factorize(1e-10)) {
    ldlt.SolveInto(rhs_, sol_);
    *inertia_ok = ldlt.negative() == nc_;
    return true;
  }
  if (!general_ready_) {
    // Room for the largest problem of the chain (all points free) at the first need, so that the
    // fallback allocates once per workspace.
    const int largest = n_ * block_, band = KktBand(options_.weights, dim_);
    buffers_.kkt_general.Reserve(largest, band);
    buffers_.lu.Reserve(largest, band);
    buffers_.kkt_general.Resize(size_, ldlt.matrix().band());
    buffers_.lu.Resize(buffers_.kkt_general);
    general_ready_ = true;
  }
  AssembleKkt(x_, lambda_, regularization_, &buffers_.kkt_general);
  factorized_ = buffers_.lu.Factorize(buffers_.kkt_general);
  if (!factorized_) return false;
  buffers_.lu.SolveInto(rhs_, sol_);
  return true;
}

// Without the inertia (an LU gives none), a curvature test: the step must see positive curvature
// of the regularized Lagrangian, dx' (H + delta I) dx >= 1e-8 |dx|^2 (scaled); otherwise Newton
// heads for a saddle or maximum on non-convex terms. dx' (H + delta I) dx is evaluated term by
// term (not as -g' dx + c' lambda_new, which the system implies: near the solution that cancels
// catastrophically).
bool NewtonSolver::HasPositiveCurvature() {
  dx_only_.setZero();
  for (int j = 1; j <= k_; ++j) {
    for (int q = 0; q < dim_; ++q) dx_only_[PointRow(j) + q] = dx_(j, q);
  }
  const double curvature =
      CurvatureAlong(x_, lambda_, dx_only_) + regularization_ * dx_.squaredNorm();
  const double floor = 1e-8 * std::fmax(1.0, weight_sum_) * dx_.squaredNorm();
  return !(curvature < floor && dx_.squaredNorm() > 0.0);
}

// Regularization delta I on the Hessian block, carried over (decayed) from the last iteration:
// raised to `first` if there was none, else 11 times.
void NewtonSolver::Regularize(double first) {
  regularization_ += regularization_ == 0.0 ? first : 10.0 * regularization_;
}

// No attempt moved the iterate: the report says where it stands (converged if both tolerances
// happen to be met, else stalled, or failed when the last matrix was singular).
void NewtonSolver::FinishWithoutStep(OverallReport* report) {
  LagrangianGradient(x_, g_, lambda_, &lag_);
  Measure(report);
  const bool done = report->constraint_violation <= options_.constraint_tolerance &&
                    report->optimality <= options_.optimality_tolerance;
  report->status = done          ? OverallStatus::kConverged
                   : factorized_ ? OverallStatus::kStalled
                                 : OverallStatus::kFailed;
}

}  // namespace flexkin::internal
