#pragma once
// The overall step with colliders (docs/colliders.md, "The overall method"): the least motion
// under a smooth metric that keeps every link's length and keeps every point and every link
// outside every collider. Where the step without colliders ends clear, it is that step (bit for
// bit); otherwise the head advances in sub-steps, and each sub-problem, started from the
// sequential contact step, is solved by Newton's method on its KKT conditions with the contacts
// chosen by a primal-dual active set.

#include <Eigen/Core>
#include <vector>

#include "flexkin/colliders.h"
#include "flexkin/overall.h"
#include "overall/active_set.h"
#include "sequential/sweep.h"

namespace flexkin::internal {

// What OverallContactStep keeps from step to step: the contacts' multipliers (a warm start for
// the next step's active set) and its buffers.
struct OverallContactState {
  std::vector<double> point_multipliers;  // (n + 1) by colliders: point j against collider k
  std::vector<double> link_multipliers;   // (n + 1) by colliders: link i against collider k
  Eigen::VectorXd lambda;                 // n: the length constraints' multipliers
  Points start;                           // a sub-step's sequential contact step
  Points previous_solution;               // the last sub-step's solution (retry start)
  Points free;                            // the step without colliders
  // With an L2 term: the still tail's friction (and its buffers), the normal of the collider
  // each old point lies on, and the active set's iterates.
  ActiveSetBuffers active_set;
  std::vector<Eigen::Vector3d> normals;
  Points current, trial, guess;
};

// One overall step of the chain (`lengths`, `*points`) with the head moving to `head`, for
// options and colliders the caller has checked (RunOptions::Validate: a smooth metric; the chain
// starts outside the colliders). `*report` tells how it was solved; `*stats` gains the
// links in contact and the least clearance. Where a sub-problem's Newton iteration does not
// converge, that sub-step keeps its sequential contact step (outside every collider) and the
// report says so. Throws InputError where the colliders leave a link no room.
void OverallContactStep(const Eigen::VectorXd& lengths, const Eigen::VectorXd& head,
                        const OverallOptions& options, const std::vector<Collider>& colliders,
                        Points* points, OverallWorkspace* workspace, OverallContactState* state,
                        OverallReport* report, ContactStats* stats);

// The least-constraint projection with colliders (dynamics, docs/dynamics.md): of the positions
// that keep every link's length and every point and link outside every collider, the one nearest
// `predicted` in the mass-weighted distance sum_j m_j |x_j - p_j|^2 (`mass`: n + 1 entries, [0]
// unused; point 0 held at predicted's row 0), solved as OverallContactStep's sub-problem from `*x`
// (the lengths kept; the projection without colliders, whose points or links inside a collider
// join the solve as contacts, or a start outside every collider). Returns true where it converged
// with every link clear (exact clearances); else `*x` is left as it was. `*iterations` (if set):
// the Newton iterations taken.
bool LeastConstraintContact(const Eigen::VectorXd& lengths, const Eigen::VectorXd& mass,
                            const Points& predicted, const std::vector<Collider>& colliders,
                            OverallContactState* state, Points* x, int* iterations = nullptr);

}  // namespace flexkin::internal
