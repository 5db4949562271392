#pragma once
// The overall step under a metric with an L2 term, whose minimizer is sparse: Newton's method on
// an active set of moving points 1..k, the points after k held still while their friction can
// hold the pull of the chain.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "flexkin/overall.h"
#include "overall/newton.h"
#include "overall/objective.h"

namespace flexkin::internal {

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

// Storage of the active-set method, reused from step to step. (Vectors of a point's coordinates
// are Eigen::VectorXd, sized dim once: the arithmetic is the one on such vectors.)
struct ActiveSetBuffers {
  TailFriction friction;
  Points current, trial;     // (n + 1) by dim: the last solution, a start for the next solve
  std::vector<char> rested;  // n + 1: the points found (nearly) still once, not tested again
  Sink sink;                 // the metric's gradient at the first still points
  Eigen::VectorXd gradient;  // that gradient, (k + 1) dim
  Eigen::VectorXd u, v;      // dim each: neighbouring unit link vectors
  Eigen::VectorXd link, force, rest, unheld, pull;  // dim each
  Eigen::RowVectorXd difference;                    // dim
};

// Fills `*friction` (see TailFriction) for the old configuration, using `buffers`' vectors.
// `normals` (n + 1 entries, if set; colliders, overall/contact_step.cc): the outward normal of
// the collider a still point j lies on, zero where it touches none; such a point also holds
// what the collider can push back along it, mu n with mu >= 0 (the interval found by bisection).
void MakeTailFriction(const ObjectiveWeights& weights, const Eigen::VectorXd& lengths,
                      const Points& old_points, ActiveSetBuffers* buffers,
                      const std::vector<Eigen::Vector3d>* normals = nullptr);

// The pull on the first still point k+1 at `x`: its smooth terms' gradient plus link k+1's
// multiplier times the link's direction, into buffers->force.
void PullOnFirstStillPoint(const Eigen::VectorXd& lengths, const Points& old_points,
                           const OverallOptions& options, int k, double multiplier, const Points& x,
                           ActiveSetBuffers* buffers);

// min over t in [a, b] and mu >= 0 of |v - t e - mu n| (e and n unit or zero): how far a pull v
// on a still point is from what it holds, the next link (direction e) pulling with t and a
// collider pushing along its normal n (zero: none).
double HeldDistance(const Eigen::Vector3d& v, const Eigen::Vector3d& e, const Eigen::Vector3d& n,
                    double a, double b);

// One (sub-)step of a metric with an L2 term: Newton's method on points 1..k, the others held
// still, with k (`*moving`, carried from the last sub-step) raised while the still points cannot
// hold the pull, and lowered where a moving point comes to rest. `*x` is the solution of the
// last sub-step on entry, of this one on return. Needs MakeTailFriction first.
OverallReport SolveActiveSet(const Eigen::VectorXd& lengths, const Points& old_points,
                             const OverallOptions& options, const Eigen::VectorXd& head,
                             int* moving, Points* x, ActiveSetBuffers* buffers,
                             NewtonBuffers* newton);

}  // namespace flexkin::internal
