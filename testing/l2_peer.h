#pragma once
// The paper's L2 metric (ObjectiveWeights::l2 and l2_weighted: sum of w_j |x_j - a_j|, a sum of
// norms, not differentiable where a point stays still) solved by IPOPT on its standard smooth
// epigraph (second-order-cone) form, as an independent check of OverallStep's exact sparse
// minimizer:
//   unknowns   x_1..x_n (n dim) and t_1..t_n (one per point), t_j >= 0;
//   minimize   sum_j w_j t_j + S(x), S the smooth terms (OverallObjective with the L2 weights
//              zeroed; its Hessian from ObjectiveHessianBands);
//   subject to (|x_i - x_{i-1}|^2 - L_i^2) / (2 L_i) = 0 (the links, as in SolveWithIpopt) and
//              t_j^2 - |x_j - a_j|^2 >= 0 (with t_j >= 0: t_j >= |x_j - a_j|).
// At the minimum t_j = |x_j - a_j|, so both problems have the same minimizers and values. The
// Hessian of the Lagrangian is exact: the cone constraint j contributes 2 at (t_j, t_j) and -2 I
// at (x_j, x_j), times its multiplier.
// At a point that stays still (x_j = a_j, t_j = 0) the cone constraint's gradient vanishes: the
// constraints are degenerate there (no constraint qualification holds), the cone's multiplier
// grows like 1 / mu as IPOPT's barrier parameter mu goes to 0, and IPOPT may converge slowly or
// stop short. Its own verdict is kept in the report (converged only on Solve_Succeeded).

#include <Eigen/Core>

#include "flexkin/chain.h"
#include "peer_solvers.h"

namespace flexkin::peers {

// What SolveL2WithIpopt starts from, and how strictly it stops.
struct EpigraphOptions {
  // x_0..x_n, (n+1) by dim (row 0 is ignored: point 0 is pinned at the head); empty: the
  // sequential tractrix step of the whole move, as SolveWithIpopt starts.
  Points start;
  // t_j starts at |x_j - a_j| + margin * L_j, strictly inside its cone (a point that the start
  // leaves still starts at t_j = margin * L_j > 0). Typical: 1e-2. Must be > 0 and finite.
  double margin = 1e-2;
  // IPOPT's s_max (>= 1): its stopping test divides the dual infeasibility by the mean multiplier
  // over this. The cone multipliers of still points grow without bound, so with the default, 100,
  // IPOPT reports convergence with relative objective errors up to about 1e-5; 1e20 makes the
  // test absolute (answers exact to rounding) but IPOPT converges much less often.
  double error_scaling_limit = 100.0;
};

// One step, as OverallStep(lengths, head, {options.weights}, &old_points) with an L2 term, but by
// IPOPT on the epigraph form above (sparse: banded Jacobian and Hessian, MUMPS). PeerReport's
// `objective` is OverallObjective (the true metric) at the returned points, `solver_objective`
// the epigraph's. IPOPT's options (mu_strategy adaptive, ...) are explained in l2_peer.cc. Throws
// InputError on invalid input, as OverallStep does, when the weights have no L2 term (field
// "options.weights") and on invalid `epigraph` fields. Prints nothing.
PeerReport SolveL2WithIpopt(const Eigen::VectorXd& lengths,
                            const Eigen::Ref<const Eigen::VectorXd>& head,
                            const PeerOptions& options, const Points& old_points,
                            const EpigraphOptions& epigraph = EpigraphOptions());

}  // namespace flexkin::peers
