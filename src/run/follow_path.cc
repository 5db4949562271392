// The follow_path method: every point of the chain on the head's path (the chain's initial points
// reversed, then the leader targets), each behind the one before it where the path meets the
// sphere of its link's length around it (a quadratic per segment). And PathDeviation, which
// measures any run's frames against that path.
#include "run/follow_path.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "flexkin/error.h"
#include "world/contact.h"

namespace flexkin {
namespace internal {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Distance from x to the segment [a, b] (a point where a == b).
double SegmentDistance(const double* x, const double* a, const double* b, int dim) {
  double dd = 0.0, wd = 0.0;
  for (int k = 0; k < dim; ++k) {
    const double d = b[k] - a[k];
    dd += d * d;
    wd += (x[k] - a[k]) * d;
  }
  const double t = dd > 0.0 ? std::clamp(wd / dd, 0.0, 1.0) : 0.0;
  double q = 0.0;
  for (int k = 0; k < dim; ++k) {
    const double e = x[k] - (a[k] + t * (b[k] - a[k]));
    q += e * e;
  }
  return std::sqrt(q);
}

double PointDistance(const double* x, const double* a, int dim) {
  double q = 0.0;
  for (int k = 0; k < dim; ++k) q += (x[k] - a[k]) * (x[k] - a[k]);
  return std::sqrt(q);
}

Eigen::Vector3d At3(const double* p, int dim) {
  return Eigen::Vector3d(p[0], p[1], dim == 3 ? p[2] : 0.0);
}

// The tip error of `points` with the head at arc length `s_head` of `path`, vertices 0..last.
double TipError(const ArcPolyline& path, Eigen::Index last, double s_head, double body_length,
                const Points& points) {
  const int dim = static_cast<int>(points.cols());
  double where[3];
  path.PointAt(s_head - body_length, last, where);
  return PointDistance(points.row(points.rows() - 1).data(), where, dim);
}

}  // namespace

ArcPolyline::ArcPolyline(Points v) : vertices(std::move(v)), arc(vertices.rows()) {
  const int dim = static_cast<int>(vertices.cols());
  arc[0] = 0.0;
  for (Eigen::Index k = 1; k < vertices.rows(); ++k) {
    arc[k] = arc[k - 1] + PointDistance(vertices.row(k).data(), vertices.row(k - 1).data(), dim);
  }
}

double ArcPolyline::Distance(const double* x, Eigen::Index last, double bound) const {
  const int dim = static_cast<int>(vertices.cols());
  double best = std::fmin(bound, PointDistance(x, vertices.row(last).data(), dim));
  Eigen::Index v = last;  // the segment [v-1, v] is next
  while (v >= 1) {
    best = std::fmin(best,
                     SegmentDistance(x, vertices.row(v - 1).data(), vertices.row(v).data(), dim));
    if (v == 1) break;
    // Every point y of the path with arc length s <= arc[v-1] is at least
    // |x - v_{v-1}| - (arc[v-1] - s) from x: the segments wholly above arc[v-1] - (d - best)
    // cannot beat `best`.
    const double d = PointDistance(x, vertices.row(v - 1).data(), dim);
    const double below = arc[v - 1] - (d - best);
    if (d <= best || below >= arc[v - 2]) {
      --v;
      continue;
    }
    // The last vertex u with arc[u] < below: the segment [u, u+1] is the next that may be nearer.
    const auto first_not_below = std::lower_bound(arc.data(), arc.data() + v - 1, below);
    const Eigen::Index u = (first_not_below - arc.data()) - 1;
    if (u < 0) break;
    v = u + 1;
  }
  return best;
}

void ArcPolyline::PointAt(double s, Eigen::Index last, double* out) const {
  const int dim = static_cast<int>(vertices.cols());
  if (!(s > 0.0)) {
    for (int k = 0; k < dim; ++k) out[k] = vertices(0, k);
    return;
  }
  if (s >= arc[last]) {
    for (int k = 0; k < dim; ++k) out[k] = vertices(last, k);
    return;
  }
  // The segment [u, u+1] with arc[u] <= s < arc[u+1] (not of zero length: arc increases there).
  const Eigen::Index u = (std::upper_bound(arc.data(), arc.data() + last + 1, s) - arc.data()) - 1;
  const double t = (s - arc[u]) / (arc[u + 1] - arc[u]);
  for (int k = 0; k < dim; ++k) {
    out[k] = vertices(u, k) + t * (vertices(u + 1, k) - vertices(u, k));
  }
}

FollowPathMover::FollowPathMover(const Chain& chain, const Points& leader_steps,
                                 const std::vector<Collider>& colliders)
    : path_(HeadPath(chain, leader_steps)),
      lengths_(chain.lengths),
      body_length_(chain.lengths.sum()),
      n_(chain.lengths.size()),
      colliders_(colliders),
      segments_(chain.lengths.size() + 1),
      step_clearance_(kInf),
      relative_clearance_(kInf) {}

void FollowPathMover::Step(const Eigen::VectorXd& head, int64_t step, Points* points) {
  const int dim = static_cast<int>(points->cols());
  double* pts = points->data();
  for (int k = 0; k < dim; ++k) pts[k] = head[k];
  // Walk back along the path from point i-1, which lies on the segment [j, j+1], toward vertex j:
  // a is where this segment's part of the walk starts (point i-1 itself, then vertex j+1 ... as
  // the walk goes on), and the first point a + u (v_j - a), u in [0, 1], at distance L_i from
  // point i-1 is the larger root of |a - x + u d|^2 = L_i^2 (|a - x| <= L_i on the walk).
  Eigen::Index j = n_ + step - 1;
  segments_[0] = j;
  for (Eigen::Index i = 1; i <= n_; ++i) {
    const double* x = pts + (i - 1) * dim;
    const double length = lengths_[i - 1];
    double a[3];
    for (int k = 0; k < dim; ++k) a[k] = x[k];
    for (;;) {
      const double* vj = path_.vertices.row(j).data();
      double d[3], dd = 0.0, b = 0.0, c = -length * length;
      for (int k = 0; k < dim; ++k) {
        d[k] = vj[k] - a[k];
        const double w = a[k] - x[k];
        dd += d[k] * d[k];
        b += w * d[k];
        c += w * w;
      }
      if (dd > 0.0) {
        const double root = std::sqrt(std::fmax(b * b - dd * c, 0.0));
        // The larger root, without cancellation.
        double u = b > 0.0 ? -c / (b + root) : (root - b) / dd;
        if (u <= 1.0) {
          u = std::fmax(u, 0.0);
          double* p = pts + i * dim;
          for (int k = 0; k < dim; ++k) p[k] = a[k] + u * d[k];
          segments_[i] = j;
          break;
        }
      }
      for (int k = 0; k < dim; ++k) a[k] = vj[k];
      if (--j < 0) {
        const int64_t s = step - 1;
        throw InputError(
            "leader_steps[" + std::to_string(s) + "]",
            "method \"follow_path\": at leader step " + std::to_string(step) +
                " the head's path is too short for the body: no point of it lies " +
                FormatNumber(length) + " (link " + std::to_string(i) + ") behind point " +
                std::to_string(i - 1) +
                "; the path (the chain's initial points reversed, then the targets) must reach "
                "at least as far behind the head as the links' chords need");
      }
    }
  }
  if (colliders_.empty()) return;
  for (Eigen::Index i = 1; i <= n_; ++i) {
    const double clearance =
        SegmentClearance(colliders_, At3(pts + (i - 1) * dim, dim), At3(pts + i * dim, dim));
    step_clearance_ = std::fmin(step_clearance_, clearance);
    relative_clearance_ = std::fmin(relative_clearance_, clearance / lengths_[i - 1]);
  }
}

void FollowPathMover::EndStep(int64_t step, const Points& points, RunResult* result) {
  PathReport& r = result->path;
  const Eigen::Index s = step - 1, last = n_ + step;
  r.clearance[s] = step_clearance_;
  if (step_clearance_ < r.least_clearance) {
    r.least_clearance = step_clearance_;
    r.least_clearance_step = step;
  }
  step_clearance_ = kInf;
  result->contacts.least_clearance = relative_clearance_;
  r.tip_error[s] = TipError(path_, last, path_.arc[last], body_length_, points);
  double worst = 0.0;
  for (Eigen::Index i = 0; i <= n_; ++i) {
    // Seeded with the distance to the segment the point was placed on: the search then skips
    // all but a few segments (the result is the same, the exact distance to the path).
    const double* x = points.row(i).data();
    const Eigen::Index j = segments_[i];
    const double seed = SegmentDistance(x, path_.vertices.row(j).data(),
                                        path_.vertices.row(std::min(j + 1, last)).data(),
                                        static_cast<int>(points.cols()));
    worst = std::fmax(worst, path_.Distance(x, last, seed));
  }
  r.deviation[s] = worst;
  r.max_tip_error = std::fmax(r.max_tip_error, r.tip_error[s]);
  r.max_deviation = std::fmax(r.max_deviation, worst);
}

}  // namespace internal

Points HeadPath(const Chain& chain, const Points& leader_steps) {
  const Eigen::Index n1 = chain.points.rows(), m = leader_steps.rows();
  Points path(n1 + m, chain.points.cols());
  path.topRows(n1) = chain.points.colwise().reverse();
  if (m > 0) path.bottomRows(m) = leader_steps;
  return path;
}

PathComparison PathDeviation(const Chain& chain, const Points& leader_steps, const Frames& frames) {
  ValidateChain(chain);
  if (leader_steps.rows() > 0 && leader_steps.cols() != chain.dim()) {
    throw InputError("leader_steps", "targets have " + std::to_string(leader_steps.cols()) +
                                         " coordinates; the chain is " +
                                         std::to_string(chain.dim()) + "D");
  }
  if (!frames.empty() &&
      (frames.num_points() != chain.points.rows() || frames.dim() != chain.dim())) {
    throw InputError("frames", "have " + std::to_string(frames.num_points()) + " points of " +
                                   std::to_string(frames.dim()) + "D; the chain has " +
                                   std::to_string(chain.points.rows()) + " of " +
                                   std::to_string(chain.dim()) + "D");
  }
  const internal::ArcPolyline path(HeadPath(chain, leader_steps));
  const Eigen::Index n = chain.lengths.size();
  const double body_length = chain.lengths.sum();
  PathComparison out;
  out.deviation.resize(static_cast<Eigen::Index>(frames.size()), n + 1);
  out.tip_error.resize(static_cast<Eigen::Index>(frames.size()));
  for (size_t f = 0; f < frames.size(); ++f) {
    const Frame frame = frames[f];
    if (frame.step < 0 || frame.step > leader_steps.rows()) {
      throw InputError("frames[" + std::to_string(f) + "]",
                       "is at leader step " + std::to_string(frame.step) + "; the run has " +
                           std::to_string(leader_steps.rows()) + " leader steps");
    }
    const Eigen::Index last = n + frame.step;
    const Points points = frame.points;
    const auto row = static_cast<Eigen::Index>(f);
    for (Eigen::Index i = 0; i <= n; ++i) {
      out.deviation(row, i) = path.Distance(points.row(i).data(), last);
    }
    out.tip_error[row] = internal::TipError(path, last, path.arc[last], body_length, points);
  }
  return out;
}

}  // namespace flexkin
