#include "overall/active_set.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "overall/retract.h"

namespace flexkin::internal {
namespace {

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

// The part of `force` on the still point j (pulled by link j) that the still tail after it
// cannot hold, into `*unheld`: zero if it holds it (to a relative 1e-9 of w_j).
void UnheldForce(const TailFriction& f, int j, const Eigen::VectorXd& force,
                 ActiveSetBuffers* buffers, Eigen::VectorXd* unheld) {
  const int n = static_cast<int>(f.w.size()) - 1;
  Eigen::VectorXd& rest = buffers->rest;
  rest = force;
  if (j < n) {
    Eigen::VectorXd& e = buffers->u;
    e = f.e.row(j).transpose();  // link j+1
    rest -= std::clamp(force.dot(e), f.lo[j + 1], f.hi[j + 1]) * e;
  }
  if (rest.norm() <= f.w[j] * (1.0 + 1e-9)) {
    unheld->setZero(force.size());
  } else {
    *unheld = rest;
  }
}

// Releases the still points that the pull `force` on point k+1 sets moving: point k+1, and the
// points after it down to the first whose tail holds the tension passed on along the chain (an
// estimate: the active-set loop corrects it either way). They start a little way (1e-3 of a
// link) against the `unheld` part of the pull, the block dragged after point k+1 by
// follow-the-leader steps, so that Newton's method does not start in the kinks of the L2 term.
// Returns the new k.
int Release(const TailFriction& f, const Eigen::VectorXd& lengths, const Points& old_points, int k,
            const Eigen::VectorXd& force, const Eigen::VectorXd& unheld, ActiveSetBuffers* buffers,
            Points* x) {
  const int n = static_cast<int>(lengths.size());
  int m = k + 1;
  Eigen::VectorXd& pull = buffers->pull;
  Eigen::VectorXd& e = buffers->u;
  pull = force;
  while (m < n) {
    e = f.e.row(m).transpose();  // link m+1
    const double tension = pull.dot(e);
    if (tension >= f.lo[m + 1] && tension <= f.hi[m + 1]) break;  // the tail after m holds it
    pull = tension * e;
    ++m;
  }
  x->row(k + 1) = old_points.row(k + 1) - (1e-3 * lengths[k] / unheld.norm()) * unheld.transpose();
  Eigen::RowVectorXd& d = buffers->difference;
  for (int j = k + 2; j <= m; ++j) {
    d = old_points.row(j) - x->row(j - 1);
    x->row(j) = x->row(j - 1) + (lengths[j - 1] / d.norm()) * d;
  }
  return m;
}

// Solves the problem with points 1..k moving from `buffers->current` with point 0 at `head`,
// into `buffers->trial`; false (nothing solved) if no chain of points 1..k reaches from the
// head to the still point k+1. After a release (`released`) the new points sit in the L2 term's
// kinks: the way out goes through the smoothed problem (mu = 1e-2, 1e-4, 1e-6 of the shortest
// link), then the exact one. `*iterations` counts the Newton iterations; `*multiplier` is link
// k+1's multiplier (k < n).
bool SolveWithMoving(const Eigen::VectorXd& lengths, const Points& old_points,
                     const OverallOptions& options, const Eigen::VectorXd& head, int k,
                     bool released, ActiveSetBuffers* buffers, NewtonBuffers* newton,
                     OverallReport* report, int* iterations, double* multiplier) {
  const int n = static_cast<int>(lengths.size());
  Points& trial = buffers->trial;
  trial = buffers->current;
  trial.row(0) = head.transpose();
  trial.bottomRows(n - k) = old_points.bottomRows(n - k);
  if (!Retract(lengths, k, &newton->chain_system, &trial)) return false;
  if (released) {
    for (const double mu : {1e-2, 1e-4, 1e-6}) {
      NewtonSolver smoothed(lengths, old_points, options, k, mu * lengths.minCoeff(), newton);
      *report = smoothed.Solve(&trial);
      *iterations += report->iterations;
    }
  }
  NewtonSolver exact(lengths, old_points, options, k, 0.0, newton);
  *report = exact.Solve(&trial);
  *iterations += report->iterations;
  *multiplier = k < n ? exact.multipliers()[k] : 0.0;
  return true;
}

}  // namespace

void PullOnFirstStillPoint(const Eigen::VectorXd& lengths, const Points& old_points,
                           const OverallOptions& options, int k, double multiplier, const Points& x,
                           ActiveSetBuffers* buffers) {
  const int n = static_cast<int>(lengths.size());
  const int dim = static_cast<int>(old_points.cols());
  Sink& sink = buffers->sink;
  sink.dim = dim;
  sink.offset.assign(n + 1, -1);
  for (int j = 1; j <= k + 1; ++j) sink.offset[j] = (j - 1) * dim;
  VectorView gradient = Leading(&buffers->gradient, (k + 1) * dim);
  gradient.setZero();
  sink.gradient = gradient.data();
  Evaluate(options.weights, lengths, old_points, x, sink, std::min(n, k + 2));
  buffers->link = (x.row(k + 1) - x.row(k)).transpose() / lengths[k];
  buffers->force = gradient.tail(dim) + multiplier * buffers->link;
}

double HeldDistance(const Eigen::Vector3d& v, const Eigen::Vector3d& e, const Eigen::Vector3d& n,
                    double a, double b) {
  const auto distance = [&](double t, double mu) { return (v - t * e - mu * n).norm(); };
  // The convex quadratic in (t, mu) over the box t in [a, b], mu >= 0: its least lies inside or
  // on a side, where it is the side's own least (the corners among them).
  double best = distance(std::clamp(v.dot(e), a, b), 0.0);
  if (n.squaredNorm() == 0.0) return best;
  for (const double t : {a, b})
    best = std::fmin(best, distance(t, std::fmax(0.0, (v - t * e).dot(n))));
  const double c = e.dot(n), det = 1.0 - c * c;
  if (e.squaredNorm() > 0.0 && det > 1e-12) {
    const double t = (v.dot(e) - c * v.dot(n)) / det;
    const double mu = (v.dot(n) - c * v.dot(e)) / det;
    if (t >= a && t <= b && mu >= 0.0) best = std::fmin(best, distance(t, mu));
  }
  return best;
}

namespace {

// The largest tension (sign +1) or the least (sign -1) of link j that a still point j of weight
// w in contact (outward normal n) holds, the next link's (direction e1) in [a, b]: the end of
// the interval of lambda with HeldDistance(lambda e, e1, n, a, b) <= w, which holds 0. By
// doubling, then bisection to the last bit; a tension it holds beyond 1e15 w (a pull straight
// into the surface) is that bound.
double HeldEnd(const Eigen::Vector3d& e, const Eigen::Vector3d& e1, const Eigen::Vector3d& n,
               double w, double a, double b, double sign) {
  const auto holds = [&](double lambda) {
    return HeldDistance(sign * lambda * e, e1, n, a, b) <= w;
  };
  double low = 0.0, high = std::fmax(w, std::numeric_limits<double>::min());
  while (holds(high)) {
    low = high;
    high *= 2.0;
    if (high > 1e15 * w) return sign * low;
  }
  for (int i = 0; i < 200 && low < high; ++i) {
    const double mid = 0.5 * (low + high);
    if (mid <= low || mid >= high) break;
    (holds(mid) ? low : high) = mid;
  }
  return sign * low;
}

}  // namespace

void MakeTailFriction(const ObjectiveWeights& weights, const Eigen::VectorXd& lengths,
                      const Points& old_points, ActiveSetBuffers* buffers,
                      const std::vector<Eigen::Vector3d>* normals) {
  const int n = static_cast<int>(lengths.size());
  const int dim = static_cast<int>(old_points.cols());
  TailFriction& f = buffers->friction;
  Eigen::VectorXd &u = buffers->u, &v = buffers->v;
  Eigen::RowVectorXd& d = buffers->difference;
  f.lo.assign(n + 2, 0.0);
  f.hi.assign(n + 2, 0.0);
  f.w.assign(n + 1, 0.0);
  f.e.resize(n, dim);
  for (int i = 1; i <= n; ++i) {
    d = old_points.row(i) - old_points.row(i - 1);
    // d.normalized(), without the temporary it returns.
    const double squared_norm = d.squaredNorm();
    if (squared_norm > 0.0) {
      f.e.row(i - 1) = d / std::sqrt(squared_norm);
    } else {
      f.e.row(i - 1) = d;
    }
    f.w[i] = L2Weight(weights, lengths, i);
  }
  const auto unit = [&](int i) {  // link i's direction as a 3-vector
    Eigen::Vector3d out = Eigen::Vector3d::Zero();
    for (int k = 0; k < dim; ++k) out[k] = f.e(i - 1, k);
    return out;
  };
  for (int j = n; j >= 2; --j) {
    if (normals != nullptr && (*normals)[j].squaredNorm() > 0.0) {
      // A still point on a collider's surface: the collider pushes it along the normal too.
      const Eigen::Vector3d e = unit(j), e1 = j < n ? unit(j + 1) : Eigen::Vector3d::Zero();
      const double a = j < n ? f.lo[j + 1] : 0.0, b = j < n ? f.hi[j + 1] : 0.0;
      f.hi[j] = HeldEnd(e, e1, (*normals)[j], f.w[j], a, b, 1.0);
      f.lo[j] = HeldEnd(e, e1, (*normals)[j], f.w[j], a, b, -1.0);
      continue;
    }
    if (j == n) {
      f.lo[j] = -f.w[n];
      f.hi[j] = f.w[n];
      continue;
    }
    u = f.e.row(j - 1).transpose();
    v = f.e.row(j).transpose();
    const double c = u.dot(v);
    const double s =
        dim == 2
            ? std::fabs(u[0] * v[1] - u[1] * v[0])
            : Eigen::Vector3d(u[0], u[1], u[2]).cross(Eigen::Vector3d(v[0], v[1], v[2])).norm();
    f.hi[j] = Reach(c, s, f.w[j], f.lo[j + 1], f.hi[j + 1]);
    f.lo[j] = -Reach(c, s, f.w[j], -f.hi[j + 1], -f.lo[j + 1]);
  }
}

OverallReport SolveActiveSet(const Eigen::VectorXd& lengths, const Points& old_points,
                             const OverallOptions& options, const Eigen::VectorXd& head,
                             int* moving, Points* x, ActiveSetBuffers* buffers,
                             NewtonBuffers* newton) {
  const int n = static_cast<int>(lengths.size());
  int k = std::max(*moving, 1);
  Points& current = buffers->current;
  const Points& trial = buffers->trial;
  current = *x;
  buffers->rested.assign(n + 1, 0);
  OverallReport report;
  int iterations = 0;
  bool released = false;
  for (int round = 0;; ++round) {
    if (round > 2 * n + 8) {  // the active set cycles
      report.status = OverallStatus::kStalled;
      break;
    }
    double multiplier = 0.0;
    if (!SolveWithMoving(lengths, old_points, options, head, k, released, buffers, newton, &report,
                         &iterations, &multiplier)) {
      ++k;
      continue;
    }
    released = false;
    current = trial;
    // A moving point (nearly) back where it was: at the minimizer it, and every point after it,
    // may be still. (Newton's method converges slowly into the L2 metric's kink, so a failed
    // solve is looked at with a looser threshold.) The friction check below confirms it.
    const double near = report.converged() ? 1e-12 : 1e-5;
    int rest = 0;
    for (int j = 2; j <= k && rest == 0; ++j) {
      if (!buffers->rested[j] &&
          (trial.row(j) - old_points.row(j)).norm() <= near * lengths[j - 1]) {
        rest = j;
      }
    }
    if (rest > 0) {
      buffers->rested[rest] = 1;
      k = rest - 1;
      continue;
    }
    if (!report.converged()) {
      if (k == n) break;
      ++k;
      continue;
    }
    if (k == n) break;
    PullOnFirstStillPoint(lengths, old_points, options, k, multiplier, trial, buffers);
    UnheldForce(buffers->friction, k + 1, buffers->force, buffers, &buffers->unheld);
    if (buffers->unheld.squaredNorm() == 0.0) break;
    k = Release(buffers->friction, lengths, old_points, k, buffers->force, buffers->unheld, buffers,
                &current);
    released = true;
  }
  report.moving_points = k;
  report.iterations = iterations;
  *moving = k;
  *x = current;
  return report;
}

}  // namespace flexkin::internal
