#pragma once
// What OverallWorkspace (flexkin/overall.h) holds: every buffer of one overall step, sized for
// the chain on first use and reused by every later step, so that a warmed-up workspace makes a
// step allocate nothing.

#include <Eigen/Core>

#include "flexkin/overall.h"
#include "overall/active_set.h"
#include "overall/newton.h"

namespace flexkin::internal {

struct OverallBuffers {
  Points old_points;             // (n + 1) by dim: the configuration before the step
  Points direct;                 // (n + 1) by dim: the direct attempt from the tractrix step
  Eigen::VectorXd inv_lengths;   // n: 1 / L_i, for the tractrix sweep
  Eigen::VectorXd from, target;  // dim: the head's old position, a sub-step's target
  NewtonBuffers newton;
  ActiveSetBuffers active_set;

  // Sizes everything for a chain of n links in dim dimensions under `weights` (allocates only
  // when that is more than before).
  void Reserve(int n, int dim, const ObjectiveWeights& weights);
};

}  // namespace flexkin::internal
