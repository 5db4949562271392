#pragma once
// Newton's method on the KKT conditions of one overall step, with the points after a given index
// held fixed (the L2 metric's still tail), and the retractions that keep its iterates feasible.

#include <Eigen/Core>

#include "flexkin/overall.h"

namespace flexkin::internal {

// Largest |(|x_i - x_{i-1}|^2 - L_i^2)| / (2 L_i^2) over the links.
double ConstraintViolation(const Eigen::VectorXd& lengths, const Points& x);

// Puts `*x` back on the constraints with point 0 and points moving+1..n where they are. With
// moving = n, the follow-the-leader sweep from the head (exact in one pass); otherwise the
// least-change (Gauss-Newton) projection of points 1..moving onto the chain between the head and
// the fixed point moving+1, linear in `moving` per iteration. False if that projection does not
// reach the constraints to rounding (no such chain, or the chain is stretched straight).
bool Retract(const Eigen::VectorXd& lengths, int moving, Points* x);

// Solves the step with points 1..moving free (1 <= moving <= n) and the others fixed where they
// are in `*x`, from the feasible configuration `*x` (point 0 the prescribed head). `*x` becomes
// the result and `*multipliers` the Lagrange multipliers of the constraints on links
// 1..min(moving + 1, n) (of (|D_i|^2 - L_i^2) / (2 L_i)). The report's `start` is left empty.
// `smoothing` > 0 solves the L2 term smoothed (see Evaluate) instead. If `strict_minimizer` is
// not null, it tells whether the result is a strict local minimizer, from the inertia of the KKT
// matrix there (false also when that cannot be decided).
OverallReport NewtonSolve(const Eigen::VectorXd& lengths, const Points& old_points,
                          const OverallOptions& options, int moving, Points* x,
                          Eigen::VectorXd* multipliers, double smoothing = 0.0,
                          bool* strict_minimizer = nullptr);

}  // namespace flexkin::internal
