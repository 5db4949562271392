#include "flexkin/overall.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "banded_lu.h"
#include "flexkin/error.h"
#include "flexkin/propagate.h"
#include "overall_objective.h"

namespace flexkin {
namespace {

using internal::BandedLu;
using internal::Evaluate;
using internal::Sink;
using internal::Triplets;

// Puts every point back at its link's length from the point before it, from the (fixed) head
// down: the follow-the-leader projection, a retraction onto the set of feasible configurations.
void Retract(const Eigen::VectorXd& lengths, Points* x) {
  for (Eigen::Index i = 1; i < x->rows(); ++i) {
    const Eigen::VectorXd d = (x->row(i) - x->row(i - 1)).transpose();
    const double norm = d.norm();
    if (norm > 0.0) x->row(i) = x->row(i - 1) + (lengths[i - 1] / norm) * d.transpose();
  }
}

// Largest |(|D_i|^2 - L_i^2)| / (2 L_i^2).
double ConstraintViolation(const Eigen::VectorXd& lengths, const Points& x) {
  double worst = 0.0;
  for (Eigen::Index i = 1; i < x.rows(); ++i) {
    const double l = lengths[i - 1];
    const double c = ((x.row(i) - x.row(i - 1)).squaredNorm() - l * l) / (2.0 * l * l);
    worst = std::fmax(worst, std::fabs(c));
  }
  return worst;
}

void ValidateInput(const Eigen::VectorXd& lengths, const Eigen::Ref<const Eigen::VectorXd>& head,
                   const OverallOptions& options, const Points& points) {
  Chain chain{points, lengths};
  ValidateChain(chain, "points");
  if (head.size() != points.cols()) {
    throw InputError("head", "has " + std::to_string(head.size()) + " coordinates; the chain is " +
                                 std::to_string(points.cols()) + "D");
  }
  for (Eigen::Index k = 0; k < head.size(); ++k) {
    if (!std::isfinite(head[k])) {
      throw InputError("head[" + std::to_string(k) + "]",
                       "value " + FormatNumber(head[k]) + " is not a finite number");
    }
  }
  if (const std::string why = options.Validate(); !why.empty()) {
    const auto colon = why.find(':');
    throw InputError(why.substr(0, colon), why.substr(colon + 2));
  }
  if (options.weights.joint_angle > 0.0 && points.cols() != 2) {
    throw InputError("weights.joint_angle",
                     "the joint-angle term is defined for planar (2D) chains only; this chain is "
                     "3D: set it to 0");
  }
}

}  // namespace

std::string OverallOptions::Validate() const {
  if (const std::string why = weights.Validate(); !why.empty()) return why;
  if (!(constraint_tolerance > 0.0) || !std::isfinite(constraint_tolerance)) {
    return "constraint_tolerance: " + FormatNumber(constraint_tolerance) +
           " is not valid; must be a finite number > 0 (typical 1e-14)";
  }
  if (!(optimality_tolerance > 0.0) || !std::isfinite(optimality_tolerance)) {
    return "optimality_tolerance: " + FormatNumber(optimality_tolerance) +
           " is not valid; must be a finite number > 0 (typical 1e-10)";
  }
  if (max_iterations < 1) {
    return "max_iterations: " + std::to_string(max_iterations) + " is not valid; must be >= 1";
  }
  return "";
}

const char* OverallStatusName(OverallStatus status) {
  switch (status) {
    case OverallStatus::kConverged:
      return "converged";
    case OverallStatus::kMaxIterations:
      return "max_iterations";
    case OverallStatus::kStalled:
      return "stalled";
    case OverallStatus::kFailed:
      return "failed";
  }
  return "unknown";
}

std::string OverallReport::BriefReport() const {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "%s after %d iterations: objective %.12g, constraint violation %.2g, optimality "
                "%.2g (start: %s)",
                OverallStatusName(status), iterations, objective, constraint_violation, optimality,
                start.c_str());
  return buf;
}

namespace {

// Newton's method on the KKT conditions from the feasible configuration `*start` (whose point 0
// is the prescribed head), for the metric measured from `old_points`. `*start` becomes the result.
OverallReport NewtonSolve(const Eigen::VectorXd& lengths, const Points& old_points,
                          const OverallOptions& options, Points* start) {
  const int n = static_cast<int>(lengths.size());
  const int dim = static_cast<int>(start->cols());
  OverallReport report;
  Points x = *start;

  // Unknowns interleaved point by point, [x_1, lambda_1, x_2, lambda_2, ...], so that the KKT
  // matrix is banded (constraint i couples x_{i-1} and x_i; the objective couples neighbours).
  const int block = dim + 1;
  const int size = n * block;
  Sink sink;
  sink.dim = dim;
  sink.offset.resize(n + 1);
  for (int j = 1; j <= n; ++j) sink.offset[j] = (j - 1) * block;
  auto multiplier_row = [&](int i) { return (i - 1) * block + dim; };

  // Objective gradient g (in the interleaved layout, multiplier rows 0), constraints
  // c_i = (|D_i|^2 - L_i^2) / (2 L_i), and the KKT matrix.
  Eigen::VectorXd g(size), lambda = Eigen::VectorXd::Zero(n), rhs(size);
  auto evaluate = [&](const Points& p, Triplets* hessian, Eigen::VectorXd* grad) {
    sink.gradient = grad;
    sink.hessian = hessian;
    if (grad != nullptr) grad->setZero(size);
    return Evaluate(options.weights, lengths, old_points, p, sink);
  };
  auto constraints = [&](const Points& p) {
    Eigen::VectorXd c(n);
    for (int i = 1; i <= n; ++i) {
      c[i - 1] = ((p.row(i) - p.row(i - 1)).squaredNorm() - lengths[i - 1] * lengths[i - 1]) /
                 (2.0 * lengths[i - 1]);
    }
    return c;
  };
  // Gradient of the Lagrangian g + J^T lambda (x rows only).
  auto lagrangian_gradient = [&](const Points& p, const Eigen::VectorXd& grad,
                                 const Eigen::VectorXd& lam) {
    Eigen::VectorXd r = grad;
    for (int i = 1; i <= n; ++i) {
      const Eigen::VectorXd e = (p.row(i) - p.row(i - 1)).transpose() / lengths[i - 1];
      for (int k = 0; k < dim; ++k) {
        r[sink.offset[i] + k] += lam[i - 1] * e[k];
        if (i > 1) r[sink.offset[i - 1] + k] -= lam[i - 1] * e[k];
      }
    }
    for (int i = 1; i <= n; ++i) r[multiplier_row(i)] = 0.0;
    return r;
  };
  // First-order optimality: the Lagrangian's gradient relative to the objective's gradient (now
  // or at the start, whichever is larger). Where the metric is 0 at the solution (a still head,
  // or a pure translation under the rotation metric) that ratio means nothing; a gradient at the
  // rounding level of the positions, 64 eps (sum of weights) max(|x|, L), counts as 0 instead.
  const ObjectiveWeights& w = options.weights;
  const double weight_sum = w.squared + w.squared_weighted * lengths.maxCoeff() +
                            w.rotation / lengths.minCoeff() + w.joint_angle;
  double start_gradient = 0.0;
  auto optimality = [&](const Points& p, const Eigen::VectorXd& grad, const Eigen::VectorXd& lag) {
    const double residual = lag.cwiseAbs().maxCoeff();
    const double extent = std::fmax(p.cwiseAbs().maxCoeff(), lengths.maxCoeff());
    if (residual <= 64.0 * std::numeric_limits<double>::epsilon() * weight_sum * extent) {
      return 0.0;
    }
    const double scale = std::fmax(std::fmax(grad.cwiseAbs().maxCoeff(), start_gradient),
                                   std::numeric_limits<double>::min());
    return residual / scale;
  };

  // Half-bandwidth of the KKT matrix in the interleaved order: x_j reaches x_{j+1} (2 dim) and
  // lambda_j reaches x_{j-1} (2 dim + 1); the joint-angle term reaches x_{j+2} (3 dim + 1).
  const int band = options.weights.joint_angle > 0.0 ? 3 * dim + 1 : 2 * dim + 1;
  BandedLu lu(size, std::min(band, size - 1));
  double regularization = 0.0;
  double value = evaluate(x, nullptr, &g);
  start_gradient = g.cwiseAbs().maxCoeff();
  Eigen::VectorXd c = constraints(x);

  for (report.iterations = 0;; ++report.iterations) {
    const Eigen::VectorXd lag = lagrangian_gradient(x, g, lambda);
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

    // KKT matrix: [H + delta I, J^T; J, 0] with H = hess f + sum lambda_i hess c_i.
    Triplets t;
    evaluate(x, &t, nullptr);
    for (int i = 1; i <= n; ++i) {
      const double s = lambda[i - 1] / lengths[i - 1];
      sink.Identity(i, i, s);
      if (i > 1) {
        sink.Identity(i - 1, i - 1, s);
        sink.Identity(i, i - 1, -s);
        sink.Identity(i - 1, i, -s);
      }
      const Eigen::VectorXd e = (x.row(i) - x.row(i - 1)).transpose() / lengths[i - 1];
      for (int k = 0; k < dim; ++k) {
        t.emplace_back(multiplier_row(i), sink.offset[i] + k, e[k]);
        t.emplace_back(sink.offset[i] + k, multiplier_row(i), e[k]);
        if (i > 1) {
          t.emplace_back(multiplier_row(i), sink.offset[i - 1] + k, -e[k]);
          t.emplace_back(sink.offset[i - 1] + k, multiplier_row(i), -e[k]);
        }
      }
    }
    // Regularization delta I on the Hessian block, carried over (decayed) from the last
    // iteration; `regularize` adds more: `first` if there was none, else 10 times as much.
    auto add_to_diagonal = [&](double amount) {
      for (int j = 1; j <= n; ++j) {
        for (int k = 0; k < dim; ++k)
          t.emplace_back(sink.offset[j] + k, sink.offset[j] + k, amount);
      }
    };
    auto regularize = [&](double first) {
      const double bump = regularization == 0.0 ? first : 10.0 * regularization;
      add_to_diagonal(bump);
      regularization += bump;
    };
    add_to_diagonal(regularization);

    // Newton step for (x, lambda_new): [H J^T; J 0] [dx; lambda_new] = -[g; c].
    bool stepped = false;
    for (int attempt = 0; attempt < 12 && !stepped; ++attempt) {
      lu.Factorize(t);
      if (!lu.factorized()) {
        regularize(1e-10 * std::fmax(1.0, g.cwiseAbs().maxCoeff()));  // singular
        continue;
      }
      for (int j = 1; j <= n; ++j) {
        for (int k = 0; k < dim; ++k) rhs[sink.offset[j] + k] = -g[sink.offset[j] + k];
        rhs[multiplier_row(j)] = -c[j - 1];
      }
      const Eigen::VectorXd sol = lu.Solve(rhs);
      if (!sol.allFinite()) break;
      Eigen::VectorXd lambda_new(n);
      Points dx(n + 1, dim);
      dx.row(0).setZero();
      for (int j = 1; j <= n; ++j) {
        for (int k = 0; k < dim; ++k) dx(j, k) = sol[sink.offset[j] + k];
        lambda_new[j - 1] = sol[multiplier_row(j)];
      }
      // Curvature test (an LU gives no inertia): the step must see positive curvature of
      // the regularized Lagrangian, dx' (H + delta I) dx >= 1e-8 |dx|^2 (scaled); else more
      // regularization. Otherwise Newton heads for a saddle or maximum on non-convex terms.
      {
        Eigen::VectorXd dx_only = Eigen::VectorXd::Zero(size);
        for (int j = 1; j <= n; ++j) {
          for (int k = 0; k < dim; ++k) dx_only[sink.offset[j] + k] = dx(j, k);
        }
        // (H + delta I) dx, from the triplets of the Hessian block.
        Eigen::VectorXd k_dx = Eigen::VectorXd::Zero(size);
        for (const auto& e : t) {
          if (e.row() % block != dim && e.col() % block != dim) {
            k_dx[e.row()] += e.value() * dx_only[e.col()];
          }
        }
        double curvature = 0.0;
        for (int j = 1; j <= n; ++j) {
          for (int k = 0; k < dim; ++k) curvature += dx(j, k) * k_dx[sink.offset[j] + k];
        }
        const double floor = 1e-8 * std::fmax(1.0, weight_sum) * dx.squaredNorm();
        if (curvature < floor && dx.squaredNorm() > 0.0) {
          regularize(1e-4 * std::fmax(1.0, weight_sum));
          continue;
        }
      }

      // Line search on the metric itself, every trial put back on the constraint manifold by
      // a follow-the-leader sweep from the fixed head (a retraction: exact lengths in O(n)).
      // Iterates stay feasible, so no merit function is needed and full Newton steps are never
      // rejected near the solution for leaving the manifold (no Maratos effect).
      auto accept = [&](Points&& trial, double v_trial, Eigen::VectorXd&& g_trial) {
        x = std::move(trial);
        value = v_trial;
        g = std::move(g_trial);
        c = constraints(x);
        lambda = lambda_new;
        stepped = true;
      };
      // First the full Newton step: near the solution the metric changes by less than rounding,
      // so it is judged by the Lagrangian's gradient, which it must halve, without raising the
      // metric beyond rounding (Newton's method is drawn to saddles and maxima as well; the
      // iterates are feasible, so this cannot lead away from the constraints).
      const double allowance = 64.0 * std::numeric_limits<double>::epsilon() * std::fabs(value);
      {
        Points trial = x + dx;
        Retract(lengths, &trial);
        Eigen::VectorXd g_trial(size);
        const double v_trial = evaluate(trial, nullptr, &g_trial);
        if (std::isfinite(v_trial) && v_trial <= value + allowance &&
            lagrangian_gradient(trial, g_trial, lambda_new).cwiseAbs().maxCoeff() <
                0.5 * lagrangian_gradient(x, g, lambda_new).cwiseAbs().maxCoeff()) {
          accept(std::move(trial), v_trial, std::move(g_trial));
          break;
        }
      }
      // Otherwise Armijo backtracking on the metric, from a descent direction only.
      double slope = 0.0;
      for (int j = 1; j <= n; ++j) {
        slope += g.segment(sink.offset[j], dim).dot(dx.row(j).transpose());
      }
      if (slope < 0.0) {
        for (double alpha = 1.0; alpha > 1e-12 && !stepped; alpha *= 0.5) {
          Points trial = x + alpha * dx;
          Retract(lengths, &trial);
          Eigen::VectorXd g_trial(size);
          const double v_trial = evaluate(trial, nullptr, &g_trial);
          if (std::isfinite(v_trial) && v_trial <= value + 1e-4 * alpha * slope + allowance) {
            accept(std::move(trial), v_trial, std::move(g_trial));
          }
        }
      }
      // No acceptable step: more regularization, then try again.
      if (!stepped) regularize(1e-8 * std::fmax(1.0, g.cwiseAbs().maxCoeff()));
    }
    if (!stepped) {
      report.objective = value;
      report.constraint_violation = ConstraintViolation(lengths, x);
      report.optimality = optimality(x, g, lagrangian_gradient(x, g, lambda));
      const bool done = report.constraint_violation <= options.constraint_tolerance &&
                        report.optimality <= options.optimality_tolerance;
      report.status = done              ? OverallStatus::kConverged
                      : lu.factorized() ? OverallStatus::kStalled
                                        : OverallStatus::kFailed;
      break;
    }
    regularization *= 0.1;
    if (regularization < 1e-14) regularization = 0.0;
  }
  *start = x;
  return report;
}

}  // namespace

OverallReport OverallStep(const Eigen::VectorXd& lengths,
                          const Eigen::Ref<const Eigen::VectorXd>& head,
                          const OverallOptions& options, Points* points) {
  ValidateInput(lengths, head, options, *points);
  const Points old_points = *points;
  // Continuation: the head advances to its target in sub-steps no longer than half the shortest
  // link; each sub-problem (the same metric, measured from the old configuration, with the head
  // part of the way) starts from the tractrix step of the previous solution and is solved by
  // Newton's method. At the old head position the old configuration is the global minimizer, so
  // this follows the minimizer continuously connected to it, rather than whichever stationary
  // point (possibly a saddle) a single Newton run from far away would reach.
  const Eigen::VectorXd from = old_points.row(0).transpose();
  const double distance = (head - from).norm();
  const int sub_steps =
      std::max(1, static_cast<int>(std::ceil(distance / (0.5 * lengths.minCoeff()))));
  OverallReport report;
  int iterations = 0;
  Chain chain{old_points, lengths};
  for (int s = 1; s <= sub_steps; ++s) {
    const Eigen::VectorXd target =
        s == sub_steps
            ? Eigen::VectorXd(head)
            : Eigen::VectorXd(from + (static_cast<double>(s) / sub_steps) * (head - from));
    MoveLeader(Method::kTractrix, target, 1, &chain);
    report = NewtonSolve(lengths, old_points, options, &chain.points);
    iterations += report.iterations;
    if (!report.converged()) break;
  }
  report.iterations = iterations;
  report.start = sub_steps == 1 ? "sequential tractrix step"
                                : "continuation in " + std::to_string(sub_steps) +
                                      " head sub-steps from the old configuration";
  *points = chain.points;
  return report;
}

}  // namespace flexkin
