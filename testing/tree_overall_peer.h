#pragma once
// The overall step on a tree with several targets (flexkin/tree_overall.h) posed to IPOPT, as an
// independent check of StepTreeOverall's elimination along the tree: the same problem written
// from its definition, with IPOPT's own sparse linear algebra (MUMPS) and exact Hessian:
//   unknowns   the points that are neither targets nor fixed (the others are constants);
//   minimize   sum over those of w_i |p_i - a_i|^2 + rotation * sum_links |D - D_old|^2 / L;
//   subject to (|D|^2 - L^2) / (2 L) = 0 for every link with an unknown end.
// Tests and benchmarks only.

#include <vector>

#include "flexkin/tree_overall.h"

namespace flexkin::peers {

struct TreeIpoptReport {
  bool converged = false;  // IPOPT's Solve_Succeeded
  int iterations = 0;
  double objective = 0.0;
  double seconds = 0.0;
};

// Solves from `start` (the points IPOPT starts from; its anchors are ignored and set from
// `targets` (one row per point of `target_points`) and `fixed`, held where `old` has them); the
// metric is measured from `old`. `points` receives IPOPT's answer.
TreeIpoptReport SolveTreeWithIpopt(const Tree& tree, const std::vector<int>& target_points,
                                   const Points& targets, const std::vector<int>& fixed,
                                   const ObjectiveWeights& weights, const Points& old,
                                   const Points& start, double tolerance, Points* points);

}  // namespace flexkin::peers
