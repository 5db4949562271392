// The KKT system of one overall sub-problem, for NewtonSolver (newton.h): the metric and the
// constraints at a configuration, the Lagrangian's gradient, the optimality measure, the starting
// multipliers, and the KKT matrix.
//
// The unknowns are interleaved point by point, [x_1, lambda_1, ..., x_k, lambda_k (, lambda_k+1)],
// so that the KKT matrix is banded (constraint i couples x_{i-1} and x_i; the objective couples
// neighbours): PointRow(j) is the row of x_j's first coordinate, MultiplierRow(i) that of
// lambda_i.

#include <algorithm>
#include <cmath>
#include <limits>

#include "overall/newton.h"

namespace flexkin::internal {
namespace {

// A vector of a point's coordinates (2 or 3) without heap allocation: the loops over links below
// run in every Newton iteration.
using PointVector = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, 3, 1>;

}  // namespace

// The metric at `p` and its gradient (into `*gradient`, indexed like the unknowns).
double NewtonSolver::EvaluateMetric(const Points& p, VectorView* gradient) {
  sink_.gradient = gradient->data();
  sink_.band = nullptr;
  sink_.form = nullptr;
  gradient->setZero();
  return Evaluate(options_.weights, lengths_, old_points_, p, sink_, last_, smoothing_);
}

// c_i = (|D_i|^2 - L_i^2) / (2 L_i) at `p`, into c_.
void NewtonSolver::EvaluateConstraints(const Points& p) {
  for (int i = 1; i <= nc_; ++i) {
    c_[i - 1] = ((p.row(i) - p.row(i - 1)).squaredNorm() - lengths_[i - 1] * lengths_[i - 1]) /
                (2.0 * lengths_[i - 1]);
  }
}

// Gradient of the Lagrangian g + J^T lambda (x rows only; the multiplier rows 0), into `out`.
void NewtonSolver::LagrangianGradient(const Points& p, const VectorView& gradient,
                                      const VectorView& lambda, VectorView* out) const {
  VectorView& result = *out;
  result = gradient;
  double* r = result.data();
  const double* points = p.data();
  for (int i = 1; i <= nc_; ++i) {
    const double f = lambda[i - 1] / lengths_[i - 1];
    const double* a = points + (i - 1) * dim_;
    for (int c = 0; c < dim_; ++c) {
      const double force = f * (a[dim_ + c] - a[c]);  // lambda_i e_i
      if (i <= k_) r[PointRow(i) + c] += force;
      if (i > 1) r[PointRow(i - 1) + c] -= force;
    }
  }
  for (int i = 1; i <= nc_; ++i) r[MultiplierRow(i)] = 0.0;
}

// First-order optimality: the Lagrangian's gradient relative to the objective's gradient (now
// or at the start, whichever is larger). Where the metric is 0 at the solution (a still head,
// or a pure translation under the rotation metric) that ratio means nothing; a gradient at the
// rounding level of the positions counts as 0 instead: positions are known to about
// eps max(|x|, L), and a point's gradient moves by its curvature times that, so the level of
// point j's components is 64 eps max(|x|, L) kappa_j, with kappa_j the sum of the weights plus
// the constraints' curvature |lambda_j| / L_j + |lambda_j+1| / L_j+1 plus, under the L2
// metric, w_j / sqrt(r_j^2 + mu^2) (r_j = |x_j - a_j|, mu the smoothing): large where a point
// moves by little, whose direction of motion is then known only to eps |x| / r_j.
// (The multipliers are the iterate's, lambda_, whatever `lagrangian` was computed with.)
double NewtonSolver::Optimality(const Points& p, const VectorView& gradient,
                                const VectorView& lagrangian) const {
  const double residual = lagrangian.cwiseAbs().maxCoeff();
  const double extent = std::fmax(p.cwiseAbs().maxCoeff(), lengths_.maxCoeff());
  const double level = 64.0 * std::numeric_limits<double>::epsilon() * extent;
  // Without an L2 term every kappa_j is at most weight_sum + 2 max|lambda| / L_min: above that
  // level, no point is at its rounding level (the usual case, decided without the loop).
  bool rounding = l2_ || residual <= level * (weight_sum_ + 2.0 * lambda_.cwiseAbs().maxCoeff() *
                                                                max_inverse_length_);
  for (int j = 1; j <= k_ && rounding; ++j) {
    double kappa = weight_sum_ + std::fabs(lambda_[j - 1]) * inverse_length_[j - 1] +
                   (j < nc_ ? std::fabs(lambda_[j]) * inverse_length_[j] : 0.0);
    if (l2_) {
      const double r = (p.row(j) - old_points_.row(j)).norm();
      kappa += L2Weight(options_.weights, lengths_, j) / std::sqrt(r * r + smoothing_ * smoothing_);
    }
    for (int q = 0; q < dim_; ++q)
      rounding &= std::fabs(lagrangian[PointRow(j) + q]) <= level * kappa;
  }
  if (rounding) return 0.0;
  const double scale = std::fmax(std::fmax(gradient.cwiseAbs().maxCoeff(), start_gradient_),
                                 std::numeric_limits<double>::min());
  return residual / scale;
}

// Starting multipliers: the least-squares ones, J J^T lambda = -J g (J J^T is tridiagonal), so
// that the first Newton step already sees the constraints' curvature. (lambda_ stays 0 where
// that system is singular.)
void NewtonSolver::StartingMultipliers() {
  ChainSystem& system = buffers_.chain_system;
  MatrixView e = LeadingMatrix(&system.e, nc_, dim_);
  VectorView y = Leading(&system.y, nc_);
  for (int i = 1; i <= nc_; ++i) {
    e.row(i - 1) = (x_.row(i) - x_.row(i - 1)) / lengths_[i - 1];
    // -(J g)_i = -(e_i . g_i - e_i . g_{i-1})
    double jg = 0.0;
    for (int q = 0; q < dim_; ++q) {
      if (i <= k_) jg += e(i - 1, q) * g_[PointRow(i) + q];
      if (i >= 2) jg -= e(i - 1, q) * g_[PointRow(i - 1) + q];
    }
    y[i - 1] = -jg;
  }
  if (SolveChainNormalEquations(e, k_, 1e-12, &system, &y)) lambda_ = y;
}

// H = hess f + sum lambda_i hess c_i at (p, lambda), into the sink's Hessian target.
void NewtonSolver::LagrangianHessianTerms(const Points& p, const VectorView& lambda) {
  sink_.gradient = nullptr;
  Evaluate(options_.weights, lengths_, old_points_, p, sink_, last_, smoothing_);
  for (int i = 1; i <= nc_; ++i) {
    const double s = lambda[i - 1] / lengths_[i - 1];
    sink_.Identity(i, i, s);
    if (i > 1) {
      sink_.Identity(i - 1, i - 1, s);
      sink_.Identity(i, i - 1, -s);
      sink_.Identity(i - 1, i, -s);
    }
  }
}

// v' H v at (p, lambda), v indexed like the unknowns (its multiplier rows ignored).
double NewtonSolver::CurvatureAlong(const Points& p, const VectorView& lambda,
                                    const VectorView& v) {
  double form = 0.0;
  sink_.band = nullptr;
  sink_.form = &form;
  sink_.form_vector = v.data();
  LagrangianHessianTerms(p, lambda);
  sink_.form = nullptr;
  return form;
}

// The KKT matrix [H + delta I, J^T; J, 0] at (p, lambda), into `kkt`. The terms that are
// multiples of the identity per pair of neighbouring points are summed by point first (see
// Sink) and written in one pass.
void NewtonSolver::AssembleKkt(const Points& p, const VectorView& lambda, double delta,
                               BandMatrix* kkt) {
  std::vector<double>& identity_diagonal = buffers_.identity_diagonal;
  std::vector<double>& identity_below = buffers_.identity_below;
  kkt->SetZero();
  std::fill(identity_diagonal.begin(), identity_diagonal.end(), 0.0);
  std::fill(identity_below.begin(), identity_below.end(), 0.0);
  sink_.band = kkt;
  sink_.form = nullptr;
  sink_.identity_diagonal = identity_diagonal.data();
  sink_.identity_below = identity_below.data();
  LagrangianHessianTerms(p, lambda);
  sink_.identity_diagonal = nullptr;
  sink_.identity_below = nullptr;
  for (int j = 1; j <= k_; ++j) {
    const int row = PointRow(j);
    const double diagonal = identity_diagonal[j] + delta;
    for (int q = 0; q < dim_; ++q) kkt->Add(row + q, row + q, diagonal);
    if (j == 1) continue;  // point 0 is fixed
    const int column = PointRow(j - 1);
    const double below = identity_below[j];
    for (int q = 0; q < dim_; ++q) {
      kkt->Add(row + q, column + q, below);
      kkt->Add(column + q, row + q, below);
    }
  }
  for (int i = 1; i <= nc_; ++i) {
    const PointVector e = (p.row(i) - p.row(i - 1)).transpose() / lengths_[i - 1];
    for (int q = 0; q < dim_; ++q) {
      if (i <= k_) {
        kkt->Add(MultiplierRow(i), PointRow(i) + q, e[q]);
        kkt->Add(PointRow(i) + q, MultiplierRow(i), e[q]);
      }
      if (i > 1) {
        kkt->Add(MultiplierRow(i), PointRow(i - 1) + q, -e[q]);
        kkt->Add(PointRow(i - 1) + q, MultiplierRow(i), -e[q]);
      }
    }
  }
}

}  // namespace flexkin::internal
