#include "flexkin/overall.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/propagate.h"
#include "overall/newton.h"
#include "overall/objective.h"

namespace flexkin {
namespace {


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

// The L2 metric's still points as Coulomb friction. A point j that has not moved satisfies the
// optimality condition 0 in s_j + w_j B + lambda_j e_j - lambda_{j+1} e_{j+1} (s_j the smooth
// terms' gradient, w_j its L2 weight, B the unit ball, e_i the unit link vectors, lambda the
// multipliers of (|D_i|^2 - L_i^2) / (2 L_i)) when the pull of its links is at most w_j. A still
// tail k+1..n can hold the pull on point k+1 if multipliers of its links exist that meet this
// at every still point. The values of lambda_j that points j..n can hold form an interval
// [lo_j, hi_j], found here from the trailing end up, once per step.
struct TailFriction {
  std::vector<double> lo, hi;  // indexed by link j = 2..n, and j = n+1: [0, 0]
  Points e;                    // unit link vectors of the old configuration; row i-1: link i
  std::vector<double> w;       // L2 weight of each point, indexed by j = 1..n
};

// max over mu in [a, b] with |mu| s <= w of mu c + sqrt(w^2 - mu^2 s^2): the largest multiplier
// of a link at angle (c = cos, s = sin) to the next one, whose multiplier lies in [a, b], that a
// point of weight w holds.
double Reach(double c, double s, double w, double a, double b) {
  double low = a, high = b;
  if (s > 0.0) {
    low = std::fmax(low, -w / s);
    high = std::fmin(high, w / s);
  }
  // The concave function's maximizer c w / s, clamped (s = 0: the end c points to).
  const double best = s > 0.0 ? c * w / s : (c > 0.0 ? high : low);
  const double mu = std::clamp(best, low, high);
  return mu * c + std::sqrt(std::fmax(0.0, w * w - mu * mu * s * s));
}

TailFriction MakeTailFriction(const ObjectiveWeights& weights, const Eigen::VectorXd& lengths,
                              const Points& old_points) {
  const int n = static_cast<int>(lengths.size());
  const int dim = static_cast<int>(old_points.cols());
  TailFriction f;
  f.lo.assign(n + 2, 0.0);
  f.hi.assign(n + 2, 0.0);
  f.w.assign(n + 1, 0.0);
  f.e.resize(n, dim);
  for (int i = 1; i <= n; ++i) {
    f.e.row(i - 1) = (old_points.row(i) - old_points.row(i - 1)).normalized();
    f.w[i] = internal::L2Weight(weights, lengths, i);
  }
  for (int j = n; j >= 2; --j) {
    if (j == n) {
      f.lo[j] = -f.w[n];
      f.hi[j] = f.w[n];
      continue;
    }
    const Eigen::VectorXd u = f.e.row(j - 1).transpose(), v = f.e.row(j).transpose();
    const double c = u.dot(v);
    const double s = dim == 2 ? std::fabs(u[0] * v[1] - u[1] * v[0])
                              : Eigen::Vector3d(u[0], u[1], u[2])
                                    .cross(Eigen::Vector3d(v[0], v[1], v[2]))
                                    .norm();
    f.hi[j] = Reach(c, s, f.w[j], f.lo[j + 1], f.hi[j + 1]);
    f.lo[j] = -Reach(c, s, f.w[j], -f.hi[j + 1], -f.lo[j + 1]);
  }
  return f;
}

// The part of `force` on the still point j (pulled by link j) that the still tail after it
// cannot hold: zero if it holds it (to a relative 1e-9 of w_j).
Eigen::VectorXd UnheldForce(const TailFriction& f, int j, const Eigen::VectorXd& force) {
  const int n = static_cast<int>(f.w.size()) - 1;
  Eigen::VectorXd rest = force;
  if (j < n) {
    const Eigen::VectorXd e = f.e.row(j).transpose();  // link j+1
    rest -= std::clamp(force.dot(e), f.lo[j + 1], f.hi[j + 1]) * e;
  }
  if (rest.norm() <= f.w[j] * (1.0 + 1e-9)) return Eigen::VectorXd::Zero(force.size());
  return rest;
}

// Releases the still points that the pull `force` on point k+1 sets moving: point k+1, and the
// points after it down to the first whose tail holds the tension passed on along the chain (an
// estimate: the active-set loop corrects it either way). They start a little way (1e-3 of a
// link) against the `unheld` part of the pull, the block dragged after point k+1 by follow-the-leader steps, so that
// Newton's method does not start in the kinks of the L2 term. Returns the new k.
int Release(const TailFriction& f, const Eigen::VectorXd& lengths, const Points& old_points, int k,
            const Eigen::VectorXd& force, const Eigen::VectorXd& unheld, Points* x) {
  const int n = static_cast<int>(lengths.size());
  int m = k + 1;
  Eigen::VectorXd pull = force;
  while (m < n) {
    const Eigen::VectorXd e = f.e.row(m).transpose();  // link m+1
    const double tension = pull.dot(e);
    if (tension >= f.lo[m + 1] && tension <= f.hi[m + 1]) break;  // the tail after m holds it
    pull = tension * e;
    ++m;
  }
  x->row(k + 1) = old_points.row(k + 1) - (1e-3 * lengths[k] / unheld.norm()) * unheld.transpose();
  for (int j = k + 2; j <= m; ++j) {
    const Eigen::RowVectorXd d = old_points.row(j) - x->row(j - 1);
    x->row(j) = x->row(j - 1) + (lengths[j - 1] / d.norm()) * d;
  }
  return m;
}

// One (sub-)step of a metric with an L2 term: Newton's method on points 1..k, the others held
// still, with k (`*moving`, carried from the last sub-step) raised while the still points cannot
// hold the pull, and lowered where a moving point comes to rest. `*x` is the solution of the
// last sub-step on entry, of this one on return.
OverallReport SolveActiveSet(const Eigen::VectorXd& lengths, const Points& old_points,
                             const OverallOptions& options, const TailFriction& friction,
                             const Eigen::VectorXd& head, int* moving, Points* x) {
  const int n = static_cast<int>(lengths.size());
  const int dim = static_cast<int>(old_points.cols());
  int k = std::max(*moving, 1);
  Points current = *x;
  std::vector<char> rested(n + 1, 0);
  OverallReport report;
  int iterations = 0;
  bool released = false;
  for (int round = 0;; ++round) {
    if (round > 2 * n + 8) {  // the active set cycles
      report.status = OverallStatus::kStalled;
      break;
    }
    Points trial = current;
    trial.row(0) = head.transpose();
    trial.bottomRows(n - k) = old_points.bottomRows(n - k);
    if (!internal::Retract(lengths, k, &trial)) {
      // No chain of points 1..k reaches from the head to the still point k+1.
      ++k;
      continue;
    }
    Eigen::VectorXd lambda;
    // After a release the new points sit in the L2 term's kinks: the way out goes through the
    // smoothed problem (mu = 1e-2, 1e-4, 1e-6 of the shortest link), then the exact one.
    if (released) {
      for (const double mu : {1e-2, 1e-4, 1e-6}) {
        report = internal::NewtonSolve(lengths, old_points, options, k, &trial, &lambda,
                                       mu * lengths.minCoeff());
        iterations += report.iterations;
      }
    }
    report = internal::NewtonSolve(lengths, old_points, options, k, &trial, &lambda);
    iterations += report.iterations;
    released = false;
    current = trial;
    // A moving point (nearly) back where it was: at the minimizer it, and every point after it,
    // may be still. (Newton's method converges slowly into the L2 metric's kink, so a failed
    // solve is looked at with a looser threshold.) The friction check below confirms it.
    const double near = report.converged() ? 1e-12 : 1e-5;
    int rest = 0;
    for (int j = 2; j <= k && rest == 0; ++j) {
      if (!rested[j] && (trial.row(j) - old_points.row(j)).norm() <= near * lengths[j - 1]) rest = j;
    }
    if (rest > 0) {
      rested[rest] = 1;
      k = rest - 1;
      continue;
    }
    if (!report.converged()) {
      if (k == n) break;
      ++k;
      continue;
    }
    if (k == n) break;
    // The pull on the first still point: its smooth terms' gradient plus link k+1's multiplier.
    internal::Sink sink;
    sink.dim = dim;
    sink.offset.assign(n + 1, -1);
    for (int j = 1; j <= k + 1; ++j) sink.offset[j] = (j - 1) * dim;
    Eigen::VectorXd gradient = Eigen::VectorXd::Zero((k + 1) * dim);
    sink.gradient = &gradient;
    internal::Evaluate(options.weights, lengths, old_points, trial, sink, std::min(n, k + 2));
    const Eigen::VectorXd e =
        (trial.row(k + 1) - trial.row(k)).transpose() / lengths[k];
    const Eigen::VectorXd force = gradient.tail(dim) + lambda[k] * e;
    const Eigen::VectorXd unheld = UnheldForce(friction, k + 1, force);
    if (unheld.squaredNorm() == 0.0) break;
    k = Release(friction, lengths, old_points, k, force, unheld, &current);
    released = true;
  }
  report.moving_points = k;
  report.iterations = iterations;
  *moving = k;
  *x = current;
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
  const bool l2 = options.weights.l2 > 0.0 || options.weights.l2_weighted > 0.0;
  const int n = static_cast<int>(lengths.size());
  if (l2 && distance == 0.0) {  // nothing moves: the minimizer is the old configuration
    OverallReport report;
    report.status = OverallStatus::kConverged;
    report.start = "the old configuration (the head did not move)";
    return report;
  }
  // With an L2 term, the sub-problems are solved on an active set: the points after the last
  // moving one held still (their friction bound checked), from the last sub-step's solution.
  const TailFriction friction =
      l2 ? MakeTailFriction(options.weights, lengths, old_points) : TailFriction{};
  int moving = l2 ? 0 : n;
  OverallReport report;
  int iterations = 0;
  Chain chain{old_points, lengths};
  // Without an L2 term, first one Newton run from the sequential tractrix step of the whole move:
  // kept if it converges to a strict local minimizer (the inertia of the KKT matrix says so),
  // which is the usual case and several times cheaper than the continuation below.
  if (!l2 && sub_steps > 1) {
    Chain direct{old_points, lengths};
    MoveLeader(Method::kTractrix, head, 1, &direct);
    Eigen::VectorXd multipliers;
    bool strict = false;
    report = internal::NewtonSolve(lengths, old_points, options, n, &direct.points, &multipliers,
                                   0.0, &strict);
    iterations = report.iterations;
    if (report.converged() && strict) {
      report.start = "sequential tractrix step (a strict local minimizer: KKT inertia checked)";
      *points = direct.points;
      return report;
    }
  }
  for (int s = 1; s <= sub_steps; ++s) {
    const Eigen::VectorXd target =
        s == sub_steps
            ? Eigen::VectorXd(head)
            : Eigen::VectorXd(from + (static_cast<double>(s) / sub_steps) * (head - from));
    if (l2) {
      report = SolveActiveSet(lengths, old_points, options, friction, target, &moving,
                              &chain.points);
    } else {
      MoveLeader(Method::kTractrix, target, 1, &chain);
      Eigen::VectorXd multipliers;
      report = internal::NewtonSolve(lengths, old_points, options, n, &chain.points, &multipliers);
    }
    iterations += report.iterations;
    if (!report.converged()) break;
  }
  report.iterations = iterations;
  const std::string from_where = l2 ? "the last sub-step's solution" : "its tractrix step";
  report.start = sub_steps == 1
                     ? (l2 ? "the old configuration, on an active set of moving points"
                           : "sequential tractrix step")
                     : "continuation in " + std::to_string(sub_steps) +
                           " head sub-steps from the old configuration, each from " + from_where;
  *points = chain.points;
  return report;
}

}  // namespace flexkin
