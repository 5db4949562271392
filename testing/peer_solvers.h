#pragma once
// General-purpose optimizers run on the very problem OverallStep solves
// (include/flexkin/overall.h), for the tests and the benchmark: NLopt's SLSQP (dense SQP with a
// BFGS Hessian, the closest open relative of MATLAB fmincon's "sqp", which the paper used) and
// IPOPT (sparse interior point with the exact Hessian and MUMPS). Same unknowns (x_1..x_n), same
// objective (OverallObjective), same constraints |x_i - x_{i-1}| = L_i, same starting point (the
// sequential tractrix step), so that a difference in the result is a difference between the
// solvers.
//
// Not part of the installed library: Debian's libnlopt-dev and coinor-libipopt-dev are needed
// only to build the tests and the benchmarks.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/overall.h"

namespace flexkin::peers {

struct PeerOptions {
  ObjectiveWeights weights;
  // Both: a point is feasible when every |(|D_i|^2 - L_i^2)| / (2 L_i^2) is below this (the
  // measure of OverallReport::constraint_violation). SLSQP only counts feasible points as
  // candidates for its answer. Typical: 1e-12.
  double constraint_tolerance = 1e-12;
  // SLSQP: stop when one iteration changes every coordinate by less than this relative amount.
  // Typical: 1e-14.
  double xtol_rel = 1e-14;
  // SLSQP: ... or the objective by less than this relative amount. Typical: 1e-16.
  double ftol_rel = 1e-16;
  // SLSQP: objective evaluations (each with its gradient) at most. Typical: 20000.
  int max_evaluations = 20000;
  // IPOPT: tolerance on its scaled KKT error ("tol"). Typical: 1e-12.
  double ipopt_tolerance = 1e-12;
  // IPOPT: iterations at most ("max_iter"). Typical: 3000.
  int max_iterations = 3000;
  // IPOPT: true, the exact Hessian of the Lagrangian (banded, from OverallObjective's Hessian);
  // false, its limited-memory quasi-Newton approximation.
  bool exact_hessian = true;
  // IPOPT: Mehrotra's predictor-corrector ("mehrotra_algorithm yes"), IPOPT's documented faster
  // mode for convex problems; off by default (these problems are not convex).
  bool ipopt_mehrotra = false;
  // Both: time limit in seconds (SLSQP: wall clock; IPOPT: CPU time); 0 for none.
  double max_seconds = 0.0;

  // Every problem (empty if valid), each naming its member.
  Problems Validate() const;
};

// What a peer did. The solver's own verdict is kept as it is: a peer that stops early is
// reported (converged = false, status says why), never thrown.
struct PeerReport {
  std::string solver;      // "slsqp" or "ipopt"
  bool converged = false;  // the solver's own success code (see `status`)
  std::string status;      // the solver's own status name, e.g. "XTOL_REACHED", "Solve_Succeeded"
  int status_code = 0;     // nlopt_result or Ipopt::ApplicationReturnStatus
  Points points;           // (n+1) by dim, the configuration returned; row 0 is `head`
  double objective = 0.0;  // OverallObjective at `points`
  // The solver's own objective at its answer: `objective` for SolveWithSlsqp and SolveWithIpopt;
  // for SolveL2WithIpopt (l2_peer.h) its epigraph's sum of w_j t_j plus the smooth terms, which
  // is >= `objective` (t_j >= |x_j - a_j|) and shows how tightly the cones close.
  double solver_objective = 0.0;
  double constraint_violation = 0.0;  // largest |(|D_i|^2 - L_i^2)| / (2 L_i^2) at `points`
  int iterations = -1;  // IPOPT's iterations; -1 for SLSQP (NLopt does not report them)
  int evaluations = 0;  // objective evaluations
  // Wall time of the solver's own work: nlopt_optimize, or IPOPT's OptimizeTNLP (its first solve)
  // and ReOptimizeTNLP (later ones). Not in it: the starting point (the tractrix step, flexkin's
  // work given to the peer), the checks of the input, and the solver's set-up (SlsqpPeer,
  // IpoptPeer, made once).
  double seconds = 0.0;

  std::string BriefReport() const;
};

// A peer set up as its users set it up: once for a chain's links and dimension, then reused for
// every step. SlsqpPeer holds NLopt's object with its n equality constraints and stopping rules;
// IpoptPeer holds an IpoptApplication, initialized once, and its problem object, which later
// solves hand to ReOptimizeTNLP (same sizes and sparsity, IPOPT's documented way to solve a
// sequence of problems). Solve() is one step from `old_points` (the chain's shape given at
// construction) to `head`, from the same start as OverallStep (the sequential tractrix step).
class SlsqpPeer {
 public:
  SlsqpPeer(const Eigen::VectorXd& lengths, int dim, const PeerOptions& options);
  ~SlsqpPeer();
  SlsqpPeer(const SlsqpPeer&) = delete;
  SlsqpPeer& operator=(const SlsqpPeer&) = delete;
  PeerReport Solve(const Eigen::Ref<const Eigen::VectorXd>& head, const Points& old_points);

 private:
  struct State;
  Eigen::VectorXd lengths_;
  PeerOptions options_;
  std::unique_ptr<State> state_;
};

class IpoptPeer {
 public:
  IpoptPeer(const Eigen::VectorXd& lengths, int dim, const PeerOptions& options);
  ~IpoptPeer();
  IpoptPeer(const IpoptPeer&) = delete;
  IpoptPeer& operator=(const IpoptPeer&) = delete;
  PeerReport Solve(const Eigen::Ref<const Eigen::VectorXd>& head, const Points& old_points);

 private:
  struct State;
  Eigen::VectorXd lengths_;
  PeerOptions options_;
  std::unique_ptr<State> state_;
};

// One step, as OverallStep(lengths, head, {weights}, &old_points) but by SLSQP (NLopt's
// NLOPT_LD_SLSQP: dense, memory and time grow as the square and the cube of n): a SlsqpPeer made
// for this one solve. Throws InputError on invalid input, as OverallStep does.
PeerReport SolveWithSlsqp(const Eigen::VectorXd& lengths,
                          const Eigen::Ref<const Eigen::VectorXd>& head, const PeerOptions& options,
                          const Points& old_points);

// The same by IPOPT (sparse: banded Hessian and Jacobian, MUMPS), an IpoptPeer made for this one
// solve. Prints nothing.
PeerReport SolveWithIpopt(const Eigen::VectorXd& lengths,
                          const Eigen::Ref<const Eigen::VectorXd>& head, const PeerOptions& options,
                          const Points& old_points);

// The Hessian of OverallObjective in block-band form, assembled from OverallObjective's own dense
// Hessian on overlapping windows of the chain, so that it costs O(n) instead of O(n^2). Every
// term of the objective couples points at most `band` apart (1 without the joint-angle term, 2
// with it). What IPOPT's exact Hessian is made of.
struct BandedHessian {
  int n = 0;     // points 1..n
  int dim = 0;   // 2 or 3
  int band = 0;  // blocks (j, k) with 0 <= j - k <= band are stored
  // Block (j, j - t), dim by dim row-major, at ((j - 1) * (band + 1) + t) * dim * dim.
  std::vector<double> blocks;

  // Entry (row coordinate r of point j, column coordinate c of point j - t).
  double at(int j, int t, int r, int c) const {
    return blocks[static_cast<size_t>(((j - 1) * (band + 1) + t) * dim * dim + r * dim + c)];
  }
  Eigen::MatrixXd ToDense() const;  // n dim square, symmetric, for tests
};

// Band needed by `weights` (see BandedHessian).
int HessianBand(const ObjectiveWeights& weights, int dim);

// Fills `hessian` (resized) with the Hessian of OverallObjective(weights, lengths, old_points,
// new_points) with respect to x_1..x_n.
void ObjectiveHessianBands(const ObjectiveWeights& weights, const Eigen::VectorXd& lengths,
                           const Points& old_points, const Points& new_points,
                           BandedHessian* hessian);

}  // namespace flexkin::peers
