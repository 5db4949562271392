#pragma once
// Keeping the overall solver's iterates on the constraints: the retraction of a configuration
// onto the chain, and the chain's normal equations (J J^T) y = r, which the retraction and the
// starting multipliers solve.

#include <Eigen/Core>

#include "flexkin/chain.h"
#include "overall/buffer.h"

namespace flexkin::internal {

// Storage of the normal equations of up to m constraints (links), reused from solve to solve.
struct ChainSystem {
  Eigen::VectorXd e;          // m by dim unit link vectors D_i / L_i (column-major)
  Eigen::VectorXd c, y;       // the constraint values and the solution, m each
  Eigen::VectorXd diag, off;  // the tridiagonal J J^T and its factors, m each

  void Reserve(int m, int dim);
};

// Solves (J J^T) y = rhs in place, J the constraint Jacobian of links 1..m (rows of `e`: D_i / L_i)
// with points 1..moving free: row i of J is +e_i at x_i (i <= moving) and -e_i at x_{i-1}
// (i >= 2), so J J^T is tridiagonal (symmetric positive definite while J has full rank). False
// when a pivot is not positive or the last one is below `tiny` times the largest. The factors go
// to `system`'s diag and off.
bool SolveChainNormalEquations(const MatrixView& e, int moving, double tiny, ChainSystem* system,
                               VectorView* rhs);

// Largest |(|x_i - x_{i-1}|^2 - L_i^2)| / (2 L_i^2) over the links.
double ConstraintViolation(const Eigen::VectorXd& lengths, const Points& x);

// Puts `*x` back on the constraints with point 0 and points moving+1..n where they are. With
// moving = n, the follow-the-leader sweep from the head (exact in one pass); otherwise the
// least-change (Gauss-Newton) projection of points 1..moving onto the chain between the head and
// the fixed point moving+1, linear in `moving` per iteration, in `system`'s storage. False if that
// projection does not reach the constraints to rounding (no such chain, or the chain is
// stretched straight).
bool Retract(const Eigen::VectorXd& lengths, int moving, ChainSystem* system, Points* x);

}  // namespace flexkin::internal
