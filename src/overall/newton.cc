#include "overall/newton.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "overall/banded_lu.h"
#include "overall/objective.h"

namespace flexkin::internal {
namespace {

// A vector of a point's coordinates (2 or 3) without heap allocation: the loops over links below
// run in every Newton iteration.
using PointVector = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, 3, 1>;

// The follow-the-leader projection from the (fixed) head down: exact lengths in one pass.
// (Plain loops on the row-major storage: this runs for every trial point of the line search.)
void RetractFollowTheLeader(const Eigen::VectorXd& lengths, Points* x) {
  const int dim = static_cast<int>(x->cols());
  double* p = x->data();
  for (Eigen::Index i = 1; i < x->rows(); ++i) {
    double* point = p + i * dim;
    const double* previous = point - dim;
    double sq = 0.0;
    for (int k = 0; k < dim; ++k) sq += (point[k] - previous[k]) * (point[k] - previous[k]);
    const double norm = std::sqrt(sq);
    if (!(norm > 0.0)) continue;
    const double f = lengths[i - 1] / norm;
    for (int k = 0; k < dim; ++k) point[k] = previous[k] + f * (point[k] - previous[k]);
  }
}

// Solves (J J^T) y = rhs in place, J the constraint Jacobian of links 1..m (rows of `e`: D_i / L_i)
// with points 1..moving free: row i of J is +e_i at x_i (i <= moving) and -e_i at x_{i-1}
// (i >= 2), so J J^T is tridiagonal (symmetric positive definite while J has full rank). False
// when a pivot is not positive or the last one is below `tiny` times the largest.
bool SolveChainNormalEquations(const Eigen::MatrixXd& e, int moving, double tiny,
                               Eigen::VectorXd* rhs) {
  const int m = static_cast<int>(e.rows());
  Eigen::VectorXd diag(m), off(m);
  Eigen::VectorXd& y = *rhs;
  for (int i = 1; i <= m; ++i) {
    diag[i - 1] = e.row(i - 1).squaredNorm() * ((i <= moving ? 1.0 : 0.0) + (i >= 2 ? 1.0 : 0.0));
    off[i - 1] = i < m ? -e.row(i - 1).dot(e.row(i)) : 0.0;  // (i, i+1), shared point x_i
  }
  for (int i = 1; i < m; ++i) {
    if (!(diag[i - 1] > 0.0)) return false;
    const double f = off[i - 1] / diag[i - 1];
    diag[i] -= f * off[i - 1];
    y[i] -= f * y[i - 1];
  }
  if (!(diag[m - 1] > tiny * diag.cwiseAbs().maxCoeff())) return false;
  y[m - 1] /= diag[m - 1];
  for (int i = m - 2; i >= 0; --i) y[i] = (y[i] - off[i] * y[i + 1]) / diag[i];
  return y.allFinite();
}

// Least-change projection of points 1..moving onto the chain of links 1..moving+1 between the
// head and the fixed point moving+1: Gauss-Newton steps x -= J^T (J J^T)^-1 c(x) with
// c_i = (|D_i|^2 - L_i^2) / (2 L_i). J J^T is tridiagonal, so each step is linear.
bool RetractBetweenEnds(const Eigen::VectorXd& lengths, int moving, Points* x) {
  const int m = moving + 1;  // constraints
  const int dim = static_cast<int>(x->cols());
  Eigen::MatrixXd e(m, dim);  // rows: D_i / L_i
  Eigen::VectorXd c(m), y(m);
  double last_violation = std::numeric_limits<double>::infinity();
  for (int iteration = 0; iteration < 30; ++iteration) {
    double violation = 0.0;
    for (int i = 1; i <= m; ++i) {
      const double l = lengths[i - 1];
      e.row(i - 1) = (x->row(i) - x->row(i - 1)) / l;
      c[i - 1] = 0.5 * l * (e.row(i - 1).squaredNorm() - 1.0);
      violation = std::fmax(violation, std::fabs(c[i - 1]) / l);
    }
    if (!std::isfinite(violation)) return false;
    // Done at the rounding level, or when Gauss-Newton stops gaining (rounding reached).
    if (violation <= 4.0 * std::numeric_limits<double>::epsilon() ||
        (violation <= 1e-14 && violation >= 0.5 * last_violation)) {
      return true;
    }
    if (iteration > 0 && violation > 0.9 * last_violation && violation > 1e-8) return false;
    last_violation = violation;
    y = c;
    if (!SolveChainNormalEquations(e, moving, 1e-14, &y)) return false;
    // x -= J^T y.
    for (int i = 1; i <= m; ++i) {
      if (i <= moving) x->row(i) -= y[i - 1] * e.row(i - 1);
      if (i >= 2) x->row(i - 1) += y[i - 1] * e.row(i - 1);
    }
  }
  return false;
}

}  // namespace

double ConstraintViolation(const Eigen::VectorXd& lengths, const Points& x) {
  double worst = 0.0;
  for (Eigen::Index i = 1; i < x.rows(); ++i) {
    const double l = lengths[i - 1];
    const double c = ((x.row(i) - x.row(i - 1)).squaredNorm() - l * l) / (2.0 * l * l);
    worst = std::fmax(worst, std::fabs(c));
  }
  return worst;
}

bool Retract(const Eigen::VectorXd& lengths, int moving, Points* x) {
  if (moving == lengths.size()) {
    RetractFollowTheLeader(lengths, x);
    return true;
  }
  return RetractBetweenEnds(lengths, moving, x);
}

OverallReport NewtonSolve(const Eigen::VectorXd& lengths, const Points& old_points,
                          const OverallOptions& options, int moving, Points* start,
                          Eigen::VectorXd* multipliers, double smoothing,
                          bool* strict_minimizer) {
  const int n = static_cast<int>(lengths.size());
  const int k = moving;
  const int nc = k < n ? k + 1 : n;  // constraints: links 1..k, and link k+1 to the fixed point
  const int dim = static_cast<int>(start->cols());
  OverallReport report;
  report.moving_points = k;
  Points x = *start;

  // Unknowns interleaved point by point, [x_1, lambda_1, ..., x_k, lambda_k (, lambda_k+1)], so
  // that the KKT matrix is banded (constraint i couples x_{i-1} and x_i; the objective couples
  // neighbours).
  const int block = dim + 1;
  const int size = k * block + (nc - k);
  Sink sink;
  sink.dim = dim;
  sink.offset.assign(n + 1, -1);
  for (int j = 1; j <= k; ++j) sink.offset[j] = (j - 1) * block;
  auto multiplier_row = [&](int i) { return i <= k ? (i - 1) * block + dim : k * block; };
  const int last = std::min(n, k + 1);  // the objective's terms beyond are 0

  Eigen::VectorXd g(size), lambda = Eigen::VectorXd::Zero(nc), rhs(size);
  auto evaluate = [&](const Points& p, BandMatrix* hessian, Eigen::VectorXd* grad) {
    sink.gradient = grad;
    sink.band = hessian;
    sink.form = nullptr;
    if (grad != nullptr) grad->setZero(size);
    return Evaluate(options.weights, lengths, old_points, p, sink, last, smoothing);
  };
  auto constraints = [&](const Points& p, Eigen::VectorXd* out) {
    Eigen::VectorXd& c = *out;
    for (int i = 1; i <= nc; ++i) {
      c[i - 1] = ((p.row(i) - p.row(i - 1)).squaredNorm() - lengths[i - 1] * lengths[i - 1]) /
                 (2.0 * lengths[i - 1]);
    }
  };
  // Gradient of the Lagrangian g + J^T lambda (x rows only), into `out` (no allocation: this
  // runs three times per iteration).
  auto lagrangian_gradient_into = [&](const Points& p, const Eigen::VectorXd& grad,
                                      const Eigen::VectorXd& lam, Eigen::VectorXd* out) {
    Eigen::VectorXd& result = *out;
    result = grad;
    double* r = result.data();
    const double* points = p.data();
    for (int i = 1; i <= nc; ++i) {
      const double f = lam[i - 1] / lengths[i - 1];
      const double* a = points + (i - 1) * dim;
      for (int c = 0; c < dim; ++c) {
        const double force = f * (a[dim + c] - a[c]);  // lambda_i e_i
        if (i <= k) r[sink.offset[i] + c] += force;
        if (i > 1) r[sink.offset[i - 1] + c] -= force;
      }
    }
    for (int i = 1; i <= nc; ++i) r[multiplier_row(i)] = 0.0;
  };
  // First-order optimality: the Lagrangian's gradient relative to the objective's gradient (now
  // or at the start, whichever is larger). Where the metric is 0 at the solution (a still head,
  // or a pure translation under the rotation metric) that ratio means nothing; a gradient at the
  // rounding level of the positions counts as 0 instead: positions are known to about
  // eps max(|x|, L), and a point's gradient moves by its curvature times that, so the level of
  // point j's components is 64 eps max(|x|, L) kappa_j, with kappa_j the sum of the weights plus
  // the constraints' curvature |lambda_j| / L_j + |lambda_j+1| / L_j+1 plus, under the L2
  // metric, w_j / sqrt(r_j^2 + mu^2) (r_j = |x_j - a_j|, mu the smoothing): large where a point
  // moves by little, whose direction of motion is then known only to eps |x| / r_j.
  const ObjectiveWeights& w = options.weights;
  const double weight_sum = w.squared + w.squared_weighted * lengths.maxCoeff() +
                            (w.rotation + w.l2 + w.l2_weighted * lengths.maxCoeff()) /
                                lengths.minCoeff() +
                            w.joint_angle;
  double start_gradient = 0.0;
  const bool l2 = w.l2 > 0.0 || w.l2_weighted > 0.0;
  const Eigen::VectorXd inverse_length = lengths.cwiseInverse();
  const double max_inverse_length = inverse_length.maxCoeff();
  auto optimality = [&](const Points& p, const Eigen::VectorXd& grad, const Eigen::VectorXd& lag) {
    const double residual = lag.cwiseAbs().maxCoeff();
    const double extent = std::fmax(p.cwiseAbs().maxCoeff(), lengths.maxCoeff());
    const double level = 64.0 * std::numeric_limits<double>::epsilon() * extent;
    // Without an L2 term every kappa_j is at most weight_sum + 2 max|lambda| / L_min: above that
    // level, no point is at its rounding level (the usual case, decided without the loop).
    bool rounding = l2 || residual <= level * (weight_sum + 2.0 * lambda.cwiseAbs().maxCoeff() *
                                                                 max_inverse_length);
    for (int j = 1; j <= k && rounding; ++j) {
      double kappa = weight_sum + std::fabs(lambda[j - 1]) * inverse_length[j - 1] +
                     (j < nc ? std::fabs(lambda[j]) * inverse_length[j] : 0.0);
      if (l2) {
        const double r = (p.row(j) - old_points.row(j)).norm();
        kappa += L2Weight(w, lengths, j) / std::sqrt(r * r + smoothing * smoothing);
      }
      for (int q = 0; q < dim; ++q) rounding &= std::fabs(lag[sink.offset[j] + q]) <= level * kappa;
    }
    if (rounding) return 0.0;
    const double scale = std::fmax(std::fmax(grad.cwiseAbs().maxCoeff(), start_gradient),
                                   std::numeric_limits<double>::min());
    return residual / scale;
  };

  // Half-bandwidth of the KKT matrix in the interleaved order: x_j reaches x_{j+1} (2 dim) and
  // lambda_j reaches x_{j-1} (2 dim + 1); the joint-angle term reaches x_{j+2} (3 dim + 1).
  const int band = options.weights.joint_angle > 0.0 ? 3 * dim + 1 : 2 * dim + 1;
  // The KKT matrix is assembled into the LDL^T's storage and factored there; the LU fallback's
  // general storage and factors are made when first needed.
  BandedLdlt ldlt(size, std::min(band, size - 1));
  std::optional<BandMatrix> kkt_general;
  std::optional<BandedLu> lu;
  bool factorized = false;  // the last attempt's matrix was not singular
  double regularization = 0.0;
  double value = evaluate(x, nullptr, &g);
  start_gradient = g.cwiseAbs().maxCoeff();
  Eigen::VectorXd c(nc);
  constraints(x, &c);
  // Starting multipliers: the least-squares ones, J J^T lambda = -J g (J J^T is tridiagonal),
  // so that the first Newton step already sees the constraints' curvature.
  {
    Eigen::MatrixXd e(nc, dim);
    Eigen::VectorXd y(nc);
    for (int i = 1; i <= nc; ++i) {
      e.row(i - 1) = (x.row(i) - x.row(i - 1)) / lengths[i - 1];
      // -(J g)_i = -(e_i . g_i - e_i . g_{i-1})
      double jg = 0.0;
      for (int q = 0; q < dim; ++q) {
        if (i <= k) jg += e(i - 1, q) * g[sink.offset[i] + q];
        if (i >= 2) jg -= e(i - 1, q) * g[sink.offset[i - 1] + q];
      }
      y[i - 1] = -jg;
    }
    if (SolveChainNormalEquations(e, k, 1e-12, &y)) lambda = y;
  }

  // H = hess f + sum lam_i hess c_i at (p, lam), into the sink's Hessian target.
  auto hessian_terms = [&](const Points& p, const Eigen::VectorXd& lam) {
    sink.gradient = nullptr;
    Evaluate(options.weights, lengths, old_points, p, sink, last, smoothing);
    for (int i = 1; i <= nc; ++i) {
      const double s = lam[i - 1] / lengths[i - 1];
      sink.Identity(i, i, s);
      if (i > 1) {
        sink.Identity(i - 1, i - 1, s);
        sink.Identity(i, i - 1, -s);
        sink.Identity(i - 1, i, -s);
      }
    }
  };
  // v' H v at (p, lam), v indexed like the unknowns (its multiplier rows ignored).
  auto curvature_along = [&](const Points& p, const Eigen::VectorXd& lam,
                             const Eigen::VectorXd& v) {
    double form = 0.0;
    sink.band = nullptr;
    sink.form = &form;
    sink.form_vector = v.data();
    hessian_terms(p, lam);
    sink.form = nullptr;
    return form;
  };
  // The KKT matrix [H + delta I, J^T; J, 0] at (p, lam), into `kkt`. The terms that are
  // multiples of the identity per pair of neighbouring points are summed by point first (see
  // Sink) and written in one pass.
  std::vector<double> identity_diagonal(n + 1), identity_below(n + 1);
  auto assemble = [&](const Points& p, const Eigen::VectorXd& lam, double delta, BandMatrix* kkt) {
    kkt->SetZero();
    std::fill(identity_diagonal.begin(), identity_diagonal.end(), 0.0);
    std::fill(identity_below.begin(), identity_below.end(), 0.0);
    sink.band = kkt;
    sink.form = nullptr;
    sink.identity_diagonal = identity_diagonal.data();
    sink.identity_below = identity_below.data();
    hessian_terms(p, lam);
    sink.identity_diagonal = nullptr;
    sink.identity_below = nullptr;
    for (int j = 1; j <= k; ++j) {
      const int row = sink.offset[j];
      const double diagonal = identity_diagonal[j] + delta;
      for (int q = 0; q < dim; ++q) kkt->Add(row + q, row + q, diagonal);
      if (j == 1) continue;  // point 0 is fixed
      const int column = sink.offset[j - 1];
      const double below = identity_below[j];
      for (int q = 0; q < dim; ++q) {
        kkt->Add(row + q, column + q, below);
        kkt->Add(column + q, row + q, below);
      }
    }
    for (int i = 1; i <= nc; ++i) {
      const PointVector e = (p.row(i) - p.row(i - 1)).transpose() / lengths[i - 1];
      for (int q = 0; q < dim; ++q) {
        if (i <= k) {
          kkt->Add(multiplier_row(i), sink.offset[i] + q, e[q]);
          kkt->Add(sink.offset[i] + q, multiplier_row(i), e[q]);
        }
        if (i > 1) {
          kkt->Add(multiplier_row(i), sink.offset[i - 1] + q, -e[q]);
          kkt->Add(sink.offset[i - 1] + q, multiplier_row(i), -e[q]);
        }
      }
    }
  };
  // The iteration's work vectors, allocated once.
  Eigen::VectorXd lag(size), lag_trial(size), lag_new(size), sol(size), lambda_new(nc),
      dx_only(size), g_trial(size);
  Points dx = Points::Zero(n + 1, dim), trial(n + 1, dim);
  bool lag_current = false;  // `lag` already holds the gradient at (x, lambda)
  for (report.iterations = 0;; ++report.iterations) {
    if (!lag_current) lagrangian_gradient_into(x, g, lambda, &lag);
    lag_current = false;
    report.objective = value;
    report.constraint_violation = ConstraintViolation(lengths, x);
    report.optimality = optimality(x, g, lag);
    if (!std::isfinite(report.objective) || !std::isfinite(report.optimality)) {
      report.status = OverallStatus::kFailed;
      break;
    }
    if (report.iterations > 0 && report.constraint_violation <= options.constraint_tolerance &&
        report.optimality <= options.optimality_tolerance) {
      report.status = OverallStatus::kConverged;
      break;
    }
    if (report.iterations >= options.max_iterations) {
      report.status = OverallStatus::kMaxIterations;
      break;
    }

    // Regularization delta I on the Hessian block, carried over (decayed) from the last
    // iteration; `regularize` raises it: to `first` if there was none, else 11 times.
    auto regularize = [&](double first) {
      regularization += regularization == 0.0 ? first : 10.0 * regularization;
    };

    // Newton step for (x, lambda_new): [H + delta I, J^T; J, 0] [dx; lambda_new] = -[g; c].
    bool stepped = false;
    for (int attempt = 0; attempt < 12 && !stepped; ++attempt) {
      assemble(x, lambda, regularization, &ldlt.matrix());
      for (int j = 1; j <= k; ++j) {
        for (int q = 0; q < dim; ++q) rhs[sink.offset[j] + q] = -g[sink.offset[j] + q];
      }
      for (int i = 1; i <= nc; ++i) rhs[multiplier_row(i)] = -c[i - 1];
      // First LDL^T without pivoting (a quarter of the LU's work), kept if no pivot is tiny and
      // its factors did not grow (so that its backward error is at the rounding level);
      // otherwise the LU with partial pivoting.
      bool inertia_ok = false;
      if (ldlt.Factorize(1e-10)) {
        ldlt.SolveInto(rhs, &sol);
        // As many negative pivots as constraints: H + delta I is positive definite on the
        // constraints' tangent space (the KKT matrix's inertia, by Sylvester's law), so the
        // step minimizes the local quadratic model there.
        inertia_ok = ldlt.negative() == nc;
      } else {
        if (!kkt_general) {
          kkt_general.emplace(size, ldlt.matrix().band());
          lu.emplace(*kkt_general);
        }
        assemble(x, lambda, regularization, &*kkt_general);
        factorized = lu->Factorize(*kkt_general);
        if (!factorized) {
          regularize(1e-10 * std::fmax(1.0, g.cwiseAbs().maxCoeff()));  // singular
          continue;
        }
        sol = lu->Solve(rhs);
      }
      factorized = true;
      if (!sol.allFinite()) break;
      for (int j = 1; j <= k; ++j) {
        for (int q = 0; q < dim; ++q) dx(j, q) = sol[sink.offset[j] + q];
      }
      for (int i = 1; i <= nc; ++i) lambda_new[i - 1] = sol[multiplier_row(i)];
      // Without that inertia (an LU gives none), a curvature test: the step must see positive
      // curvature of the regularized Lagrangian, dx' (H + delta I) dx >= 1e-8 |dx|^2 (scaled);
      // else more regularization. Otherwise Newton heads for a saddle or maximum on non-convex
      // terms.
      if (!inertia_ok) {
        // dx' (H + delta I) dx, evaluated term by term (not -g' dx + c' lambda_new, which the
        // system implies: near the solution that cancels catastrophically).
        dx_only.setZero();
        for (int j = 1; j <= k; ++j) {
          for (int q = 0; q < dim; ++q) dx_only[sink.offset[j] + q] = dx(j, q);
        }
        const double curvature =
            curvature_along(x, lambda, dx_only) + regularization * dx.squaredNorm();
        const double floor = 1e-8 * std::fmax(1.0, weight_sum) * dx.squaredNorm();
        if (curvature < floor && dx.squaredNorm() > 0.0) {
          regularize(1e-4 * std::fmax(1.0, weight_sum));
          continue;
        }
      }

      // Line search on the metric itself, every trial put back on the constraint manifold by
      // the retraction. Iterates stay feasible, so no merit function is needed and full Newton
      // steps are never rejected near the solution for leaving the manifold (no Maratos effect).
      // (Swaps: the trial buffers take the old iterate, to be overwritten by the next trial.)
      auto accept = [&](double v_trial) {
        x.swap(trial);
        value = v_trial;
        g.swap(g_trial);
        constraints(x, &c);
        lambda = lambda_new;
        stepped = true;
      };
      auto try_point = [&](double alpha) {
        trial = x + alpha * dx;
        if (!Retract(lengths, k, &trial)) return std::numeric_limits<double>::infinity();
        return evaluate(trial, nullptr, &g_trial);
      };
      // First the full Newton step: near the solution the metric changes by less than rounding,
      // so it is judged by the Lagrangian's gradient, which it must halve, without raising the
      // metric beyond rounding (Newton's method is drawn to saddles and maxima as well; the
      // iterates are feasible, so this cannot lead away from the constraints).
      // (Rounding of the metric: of its value, and of the positions, which the retraction
      // recomputes, times the gradient.)
      const double allowance =
          64.0 * std::numeric_limits<double>::epsilon() *
          (std::fabs(value) +
           g.cwiseAbs().sum() * std::fmax(x.cwiseAbs().maxCoeff(), lengths.maxCoeff()));
      {
        const double v_trial = try_point(1.0);
        // (The second test accepts a step that only corrects the multipliers: with as many
        // constraints as unknowns the configuration is already determined.)
        if (std::isfinite(v_trial) && v_trial <= value + allowance) {
          lagrangian_gradient_into(trial, g_trial, lambda_new, &lag_trial);
          lagrangian_gradient_into(x, g, lambda_new, &lag_new);
          if (lag_trial.cwiseAbs().maxCoeff() < 0.5 * lag_new.cwiseAbs().maxCoeff() ||
              optimality(trial, g_trial, lag_trial) <= options.optimality_tolerance) {
            accept(v_trial);
            lag.swap(lag_trial);  // the next iteration's (x, lambda)
            lag_current = true;
            break;
          }
        }
      }
      // Otherwise Armijo backtracking on the metric, from a descent direction only.
      double slope = 0.0;
      for (int j = 1; j <= k; ++j) {
        slope += g.segment(sink.offset[j], dim).dot(dx.row(j).transpose());
      }
      if (slope < 0.0) {
        for (double alpha = 1.0; alpha > 1e-12 && !stepped; alpha *= 0.5) {
          const double v_trial = try_point(alpha);
          if (std::isfinite(v_trial) && v_trial <= value + 1e-4 * alpha * slope + allowance) {
            accept(v_trial);
          }
        }
      }
      // No acceptable step: more regularization, then try again.
      if (!stepped) regularize(1e-8 * std::fmax(1.0, g.cwiseAbs().maxCoeff()));
    }
    if (!stepped) {
      report.objective = value;
      report.constraint_violation = ConstraintViolation(lengths, x);
      lagrangian_gradient_into(x, g, lambda, &lag);
      report.optimality = optimality(x, g, lag);
      const bool done = report.constraint_violation <= options.constraint_tolerance &&
                        report.optimality <= options.optimality_tolerance;
      report.status = done              ? OverallStatus::kConverged
                      : factorized      ? OverallStatus::kStalled
                                        : OverallStatus::kFailed;
      break;
    }
    regularization *= 0.1;
    if (regularization < 1e-14) regularization = 0.0;
  }
  // A strict local minimizer (second-order sufficient conditions) has a KKT matrix with exactly
  // as many negative eigenvalues as constraints and none zero.
  if (strict_minimizer != nullptr) {
    *strict_minimizer = false;
    if (report.converged()) {
      assemble(x, lambda, 0.0, &ldlt.matrix());
      *strict_minimizer = ldlt.Factorize(1e-12) && ldlt.negative() == nc;
    }
  }
  *start = x;
  *multipliers = lambda;
  return report;
}

}  // namespace flexkin::internal
