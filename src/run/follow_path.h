#pragma once
// The follow_path method (docs/colliders.md "Follow the path"): every point on the head's path,
// behind the point before it at its link's length; and the measures of how far any run's points
// are from that path.

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/colliders.h"
#include "flexkin/run.h"

namespace flexkin::internal {

// A polyline (vertices in order) with the arc length at each vertex.
struct ArcPolyline {
  explicit ArcPolyline(Points vertices);
  Points vertices;      // K by dim
  Eigen::VectorXd arc;  // K: arc[0] = 0, arc[k] = arc[k-1] + |v_k - v_{k-1}|

  // The distance of `x` (dim values) from the polyline through vertices 0..last. Exact (to
  // rounding): segments that cannot be nearer than the best so far, by the triangle inequality
  // along the arc, are skipped, so a point near the path costs a few segments, not all of them.
  // `bound`: a distance already known to be reached (e.g. that of a segment near x), which
  // lets the search skip more.
  double Distance(const double* x, Eigen::Index last,
                  double bound = std::numeric_limits<double>::infinity()) const;
  // The point at arc length `s` (clamped to [0, arc[last]]) into `out` (dim values).
  void PointAt(double s, Eigen::Index last, double* out) const;
};

// Moves a chain by the follow_path rule, sub-step by sub-step, and fills RunResult::path (and the
// contact report's least clearance) leader step by leader step.
class FollowPathMover {
 public:
  FollowPathMover(const Chain& chain, const Points& leader_steps,
                  const std::vector<Collider>& colliders);
  // Point 0 of `points` goes to `head`, on the path's segment of leader step `step` (1-based:
  // from target step-1, or the chain's start, to target step); points 1..n are placed behind it.
  // Throws InputError naming leader_steps[step-1] where the path is too short for the body.
  void Step(const Eigen::VectorXd& head, int64_t step, Points* points);
  // The report of leader step `step` (1-based), after its last sub-step.
  void EndStep(int64_t step, const Points& points, RunResult* result);

 private:
  ArcPolyline path_;
  Eigen::VectorXd lengths_;
  double body_length_;
  Eigen::Index n_;
  const std::vector<Collider>& colliders_;
  std::vector<Eigen::Index> segments_;  // the path segment [j, j+1] each point was placed on
  double step_clearance_;  // least clearance over the sub-steps of the current leader step
  double relative_clearance_;
};

}  // namespace flexkin::internal
