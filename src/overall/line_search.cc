// NewtonSolver's line search along the Newton step, on the metric itself, every trial put back
// on the constraint manifold by the retraction. Iterates stay feasible, so no merit function is
// needed and full Newton steps are never rejected near the solution for leaving the manifold (no
// Maratos effect).

#include <cmath>
#include <limits>

#include "overall/newton.h"

namespace flexkin::internal {

// The full step if it passes (TryFullStep), else Armijo backtracking. True if a step was taken.
// The allowance is the rounding of the metric: of its value, and of the positions, which the
// retraction recomputes, times the gradient.
bool NewtonSolver::LineSearch() {
  const double allowance =
      64.0 * std::numeric_limits<double>::epsilon() *
      (std::fabs(value_) +
       g_.cwiseAbs().sum() * std::fmax(x_.cwiseAbs().maxCoeff(), lengths_.maxCoeff()));
  return TryFullStep(allowance) || Backtrack(allowance);
}

// The full Newton step: near the solution the metric changes by less than rounding, so it is
// judged by the Lagrangian's gradient, which it must halve, without raising the metric beyond
// rounding (Newton's method is drawn to saddles and maxima as well; the iterates are feasible,
// so this cannot lead away from the constraints). A step that only corrects the multipliers
// passes by the optimality test (with as many constraints as unknowns the configuration is
// already determined).
bool NewtonSolver::TryFullStep(double allowance) {
  const double v_trial = TryPoint(1.0);
  if (!(std::isfinite(v_trial) && v_trial <= value_ + allowance)) return false;
  LagrangianGradient(trial_, g_trial_, lambda_new_, &lag_trial_);
  LagrangianGradient(x_, g_, lambda_new_, &lag_new_);
  if (lag_trial_.cwiseAbs().maxCoeff() < 0.5 * lag_new_.cwiseAbs().maxCoeff() ||
      Optimality(trial_, g_trial_, lag_trial_) <= options_.optimality_tolerance) {
    Accept(v_trial);
    SwapViews(&lag_, &lag_trial_);  // the next iteration's (x, lambda)
    lag_current_ = true;
    return true;
  }
  return false;
}

// Armijo backtracking on the metric, from a descent direction only.
bool NewtonSolver::Backtrack(double allowance) {
  double slope = 0.0;
  for (int j = 1; j <= k_; ++j) {
    slope += g_.segment(PointRow(j), dim_).dot(dx_.row(j).transpose());
  }
  if (!(slope < 0.0)) return false;
  for (double alpha = 1.0; alpha > 1e-12; alpha *= 0.5) {
    const double v_trial = TryPoint(alpha);
    if (std::isfinite(v_trial) && v_trial <= value_ + 1e-4 * alpha * slope + allowance) {
      Accept(v_trial);
      return true;
    }
  }
  return false;
}

// The metric at x + alpha dx put back on the constraints (into trial_, its gradient into
// g_trial_); infinity where the retraction fails.
double NewtonSolver::TryPoint(double alpha) {
  trial_ = x_ + alpha * dx_;
  if (!Retract(lengths_, k_, &buffers_.chain_system, &trial_)) {
    return std::numeric_limits<double>::infinity();
  }
  return EvaluateMetric(trial_, &g_trial_);
}

// The trial point becomes the iterate, with the step's multipliers. (Swaps: the trial buffers
// take the old iterate, to be overwritten by the next trial.)
void NewtonSolver::Accept(double value) {
  x_.swap(trial_);
  value_ = value;
  SwapViews(&g_, &g_trial_);
  EvaluateConstraints(x_);
  lambda_ = lambda_new_;
}

}  // namespace flexkin::internal
