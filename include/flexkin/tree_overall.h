#pragma once
// The overall method on trees with several targets (docs/trees.md, "The overall method"): the
// exact minimizer of the paper's smooth metrics under the length constraints, every target and
// fixed point held exactly, by Newton's method on the KKT system, whose linear algebra is
// eliminated along the tree (leaves first), so that an iteration costs time linear in the links.
//
//   minimize   sum_i w_i |p_i - a_i|^2 + rotation * sum_links |D_l - D_l^old|^2 / L_l
//   subject to |D_l| = L_l for every link, p_t = target_t, p_f = a_f,
//
// a_i the points before the step, w_i = squared + squared_weighted * (half the lengths of the
// links at point i), D_l a link's vector. A path whose only target is point 0 poses the chain's
// overall step (OverallStep with the same weights): the same minimizer.

#include "flexkin/overall.h"
#include "flexkin/tree.h"

namespace flexkin {

struct TreeOverallOptions {
  // squared, squared_weighted and rotation; the L2 and joint-angle terms are refused.
  ObjectiveWeights weights;
  // Stop when every |(|D_l|^2 - L_l^2)| / (2 L_l^2) is at most this and Newton's step moves no
  // point by more than it times the longest link.
  double tolerance = 1e-13;
  int max_iterations = 50;
};

struct TreeOverallReport {
  bool converged = false;
  int iterations = 0;  // Newton's, over all sub-steps
  int substeps = 0;    // of the continuation (the targets advance at most half the shortest link
                       // a sub-step)
  double objective = 0.0;     // the metric at the returned points
  double length_error = 0.0;  // the largest |(|D_l|^2 - L_l^2)| / (2 L_l^2)
  ReachReport start;          // the passes that gave Newton's start
};

// Moves `points` (the reacher's tree, each link at its length) so that target k's point is at row
// k of `positions` and the fixed points stay, by the least motion in the metric (the anchors'
// own motion is given, so not counted). The targets advance in sub-steps of at most half the
// shortest link, each solved by Newton from the reacher's passes (ReachTargets with its options)
// from the last solution: the minimizer returned is the one continuously connected to the points
// before the step, as the chain's overall step's. Where the passes do not reach the targets (out
// of reach) or Newton does not converge in max_iterations, `points` is left as the passes leave
// it for the whole move and the report says so. Throws InputError as ReachTargets does, on weights
// that ObjectiveWeights::Validate refuses or that have an L2 or joint-angle term ("weights.l2"), or
// on a tolerance or max_iterations out of range, or on a reacher with pointing goals
// ("targets[k]": the overall step takes position targets only); a refused call changes nothing.
TreeOverallReport StepTreeOverall(const TreeReacher& reacher, const Points& positions,
                                  const TreeOverallOptions& options, Points* points);

// Completes passes that stalled short of reachable targets (docs/trees.md, "Finishing stalled
// passes"): `passes` is ReachTargets's report for `positions`, `points` where it left them. Where
// it did not reach them, but came within 0.05 of the longest link, the least correction of the
// points (the squared metric: the smallest sum of squared displacements from where the passes
// left them) that holds every target and fixed point exactly and keeps every length, by
// StepTreeOverall's Newton's method in one step. Returns the report with reached, finished and the
// residual (the targets' largest distance after the correction, of the longest link) where Newton
// converged; otherwise `passes`, `points` unchanged (a target out of reach). A reacher with
// pointing goals is returned unchanged: the correction takes position targets only. Throws
// InputError as ReachTargets does on positions or points of the wrong shape.
ReachReport FinishTreeReach(const TreeReacher& reacher, const Points& positions,
                            const ReachReport& passes, Points* points);

}  // namespace flexkin
