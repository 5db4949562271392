// The KKT system of one overall sub-problem, for NewtonSolver (newton.h): the metric and the
// constraints at a configuration, the Lagrangian's gradient, the optimality measure, the starting
// multipliers, and the KKT matrix.
//
// The unknowns are interleaved point by point, [x_1, lambda_1, ..., x_k, lambda_k (, lambda_k+1)],
// so that the KKT matrix is banded (constraint i couples x_{i-1} and x_i; the objective couples
// neighbours): PointRow(j) is the row of x_j's first coordinate, MultiplierRow(i) that of
// lambda_i.

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "overall/newton.h"

namespace flexkin::internal {

// The metric at `p` and its gradient (into `*gradient`, indexed like the unknowns).
double NewtonSolver::EvaluateMetric(const Points& p, VectorView* gradient) {
  sink_.gradient = gradient->data();
  sink_.band = nullptr;
  sink_.form = nullptr;
  gradient->setZero();
  return Evaluate(options_.weights, lengths_, old_points_, p, sink_, last_, smoothing_);
}

// c_i = (|D_i|^2 - L_i^2) / (2 L_i) at `p`, into c_. (Plain loops; |D_i|^2 summed by coordinate
// in order, as Eigen's squaredNorm of a row sums 2 or 3 entries.)
void NewtonSolver::EvaluateConstraints(const Points& p) {
  const double* const points = p.data();
  const double* const length = lengths_.data();
  double* const c = c_.data();
  for (int i = 1; i <= nc_; ++i) {
    const double* const a = points + (i - 1) * dim_;  // x_{i-1}, then x_i
    double sq = 0.0;
    for (int q = 0; q < dim_; ++q) sq += (a[dim_ + q] - a[q]) * (a[dim_ + q] - a[q]);
    const double l = length[i - 1];
    c[i - 1] = (sq - l * l) / (2.0 * l);
  }
}

// Gradient of the Lagrangian g + J^T lambda (x rows only; the multiplier rows 0), into `out`,
// point by point in one pass: point j's rows are g_j + lambda_j e_j - lambda_j+1 e_j+1, summed in
// that order (link j + 1's force is carried over to the next point). `out` may be `gradient`.
void NewtonSolver::LagrangianGradient(const Points& p, const VectorView& gradient,
                                      const VectorView& lambda, VectorView* out) const {
  assert(gradient.size() == size_ && out->size() == size_);
  const double* const g = gradient.data();
  double* const r = out->data();
  const double* const points = p.data();
  const double* const multiplier = lambda.data();
  const double* const length = lengths_.data();
  // lambda_i e_i = (lambda_i / L_i) D_i, link i's force on x_i (and minus it on x_{i-1}).
  auto force_of_link = [&](int i, double* force) {
    const double f = multiplier[i - 1] / length[i - 1];
    const double* a = points + (i - 1) * dim_;
    for (int c = 0; c < dim_; ++c) force[c] = f * (a[dim_ + c] - a[c]);
  };
  double force[3], next[3] = {0.0, 0.0, 0.0};
  force_of_link(1, force);
  for (int j = 1; j <= k_; ++j) {
    const bool pulled_back = j < nc_;  // link j + 1 is a constraint
    if (pulled_back) force_of_link(j + 1, next);
    const int row = PointRow(j);
    for (int c = 0; c < dim_; ++c) {
      double v = g[row + c] + force[c];
      if (pulled_back) v -= next[c];
      r[row + c] = v;
      force[c] = next[c];
    }
    r[MultiplierRow(j)] = 0.0;
  }
  if (nc_ > k_) r[MultiplierRow(nc_)] = 0.0;
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

// The metric's part of H at `p`: its terms that are multiples of the identity per pair of
// neighbouring points summed by point into the identity buffers (see Sink), its other blocks
// added into `kkt`. Without the L2 and joint-angle terms the metric's Hessian is made of the
// former only, and they do not depend on `p` (the squared and rotation metrics are quadratic):
// they are then summed once per solve, by the same calls in the same order, and kept.
void NewtonSolver::MetricHessianTerms(const Points& p, BandMatrix* kkt) {
  if (metric_terms_kept_) return;
  std::fill(buffers_.identity_diagonal.begin(), buffers_.identity_diagonal.end(), 0.0);
  std::fill(buffers_.identity_below.begin(), buffers_.identity_below.end(), 0.0);
  sink_.gradient = nullptr;
  sink_.band = kkt;
  sink_.form = nullptr;
  sink_.identity_diagonal = buffers_.identity_diagonal.data();
  sink_.identity_below = buffers_.identity_below.data();
  Evaluate(options_.weights, lengths_, old_points_, p, sink_, last_, smoothing_);
  sink_.identity_diagonal = nullptr;
  sink_.identity_below = nullptr;
  metric_terms_kept_ = constant_metric_hessian_;
}

// The KKT matrix [H + delta I, J^T; J, 0] at (p, lambda), into `kkt`: the metric's terms
// (MetricHessianTerms), then, in one pass over the points, the constraints' terms and J. Point
// j's identity terms are summed in the order LagrangianHessianTerms adds them (the metric's,
// then lambda_j / L_j, then lambda_j+1 / L_j+1 on the diagonal; the metric's, then
// -lambda_j / L_j below it: a + (-s) is a - s) and written once; each entry is written once, onto
// the metric's blocks, through BandMatrix::AddSymmetric (the pattern's bounds asserted here, once).
void NewtonSolver::AssembleKkt(const Points& p, const VectorView& lambda, double delta,
                               BandMatrix* kkt) {
  assert(kkt->size() == size_ && kkt->band() >= std::min(2 * dim_ + 1, size_ - 1));
  kkt->SetZero();
  MetricHessianTerms(p, kkt);
  const double* const metric_diagonal = buffers_.identity_diagonal.data();
  const double* const metric_below = buffers_.identity_below.data();
  // J's row of constraint i: +e_i at x_i (i <= k), -e_i at x_{i-1} (i >= 2).
  // (Plain loops on the storage, as in LagrangianGradient: this runs in every Newton iteration.)
  const double* const points = p.data();
  const double* const length = lengths_.data();
  const double* const multiplier = lambda.data();
  auto link = [&](int i) {
    const double* const a = points + (i - 1) * dim_;  // x_{i-1}, then x_i
    const int row = MultiplierRow(i);
    for (int q = 0; q < dim_; ++q) {
      const double e = (a[dim_ + q] - a[q]) / length[i - 1];  // e_i = D_i / L_i
      if (i <= k_) kkt->AddSymmetric(row, PointRow(i) + q, e);
      if (i > 1) kkt->AddSymmetric(row, PointRow(i - 1) + q, -e);
    }
  };
  double s = multiplier[0] / length[0];  // lambda_j / L_j, the constraints' curvature
  for (int j = 1; j <= k_; ++j) {
    const double s_next = j < nc_ ? multiplier[j] / length[j] : 0.0;
    double sum = metric_diagonal[j] + s;
    if (j < nc_) sum += s_next;
    const int row = PointRow(j);
    const double diagonal = sum + delta;
    for (int q = 0; q < dim_; ++q) kkt->AddSymmetric(row + q, row + q, diagonal);
    if (j > 1) {  // point 0 is fixed
      const int column = PointRow(j - 1);
      const double below = metric_below[j] - s;
      for (int q = 0; q < dim_; ++q) kkt->AddSymmetric(row + q, column + q, below);
    }
    link(j);
    s = s_next;
  }
  if (nc_ > k_) link(nc_);  // the link to the fixed point k + 1
}

}  // namespace flexkin::internal
