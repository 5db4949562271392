#pragma once
// Newton's method on the KKT conditions of one overall (sub-)problem: the points 1..k free (the
// others, the L2 metric's still tail, held where they are), every iterate kept on the constraints
// by the retraction (retract.h). One solver object per solve; its buffers are the caller's and
// are reused from solve to solve.
//
// The parts, one file each: kkt.cc (the unknowns' layout, the metric, the Lagrangian's gradient,
// the optimality measure, the starting multipliers, the KKT matrix), newton.cc (the iteration and
// the Newton step, a solve of the KKT system), line_search.cc (the step length).

#include <Eigen/Core>
#include <vector>

#include "flexkin/overall.h"
#include "overall/banded_lu.h"
#include "overall/buffer.h"
#include "overall/objective.h"
#include "overall/retract.h"

namespace flexkin::internal {

// Storage of NewtonSolver, sized for the largest problem of a chain (Reserve) and reused.
struct NewtonBuffers {
  // Indexed like the unknowns (at most n (dim + 1)).
  Eigen::VectorXd gradient, trial_gradient, rhs, solution, lagrangian, trial_lagrangian,
      new_lagrangian, step_only;
  // Indexed by constraint (at most n).
  Eigen::VectorXd multipliers, new_multipliers, constraints;
  Eigen::VectorXd inverse_lengths;  // 1 / L_i, n
  Points x, step, trial;            // (n + 1) by dim: the iterate, the step, a trial point
  Sink sink;                        // where the metric's derivatives go (its offsets kept)
  // n + 1: the metric's identity terms summed by point (see Sink, MetricHessianTerms).
  std::vector<double> identity_diagonal, identity_below;
  BandedLdlt ldlt;           // the KKT matrix, assembled and factored in place
  BandMatrix kkt_general;    // the LU fallback's copy of it (general layout) ...
  BandedLu lu;               // ... and its factors
  ChainSystem chain_system;  // the retraction's and the starting multipliers'

  // Sizes everything for a chain of n links in dim dimensions under `weights` (allocates only
  // when that is more than before).
  void Reserve(int n, int dim, const ObjectiveWeights& weights);
};

// Solves the step with points 1..moving free (1 <= moving <= n) and the others fixed where they
// are in `*x`, from the feasible configuration `*x` (point 0 the prescribed head). `smoothing`
// > 0 solves the L2 term smoothed (see Evaluate) instead.
class NewtonSolver {
 public:
  NewtonSolver(const Eigen::VectorXd& lengths, const Points& old_points,
               const OverallOptions& options, int moving, double smoothing, NewtonBuffers* buffers);

  // `*x` becomes the result (the best configuration found, even when not converged: see the
  // report, whose `start` is left empty).
  OverallReport Solve(Points* x);
  // After Solve: the Lagrange multipliers of the constraints on links 1..min(moving + 1, n) (of
  // (|D_i|^2 - L_i^2) / (2 L_i)).
  const VectorView& multipliers() const { return lambda_; }
  // After Solve: whether the result is a strict local minimizer, from the inertia of the KKT
  // matrix there (false also when that cannot be decided, or the solve did not converge).
  bool IsStrictMinimizer(const OverallReport& report);

 private:
  enum class StepOutcome {
    kReady,        // dx_ and lambda_new_ hold the step
    kRegularized,  // no usable step: the regularization was raised, try again
    kNotFinite,    // the solution of the KKT system is not finite: give up
  };

  // The unknowns' layout (see kkt.cc).
  int PointRow(int j) const { return sink_.offset[j]; }
  int MultiplierRow(int i) const { return i <= k_ ? (i - 1) * block_ + dim_ : k_ * block_; }

  // Values and first derivatives (kkt.cc).
  double EvaluateMetric(const Points& p, VectorView* gradient);
  void EvaluateConstraints(const Points& p);
  void LagrangianGradient(const Points& p, const VectorView& gradient, const VectorView& lambda,
                          VectorView* out) const;
  double Optimality(const Points& p, const VectorView& gradient,
                    const VectorView& lagrangian) const;
  void StartingMultipliers();

  // Second derivatives and the KKT matrix (kkt.cc).
  void LagrangianHessianTerms(const Points& p, const VectorView& lambda);
  void MetricHessianTerms(const Points& p, BandMatrix* kkt);
  double CurvatureAlong(const Points& p, const VectorView& lambda, const VectorView& v);
  void AssembleKkt(const Points& p, const VectorView& lambda, double delta, BandMatrix* kkt);

  // The iteration (newton.cc).
  void Measure(OverallReport* report);
  bool Iterate();
  StepOutcome ComputeNewtonStep();
  bool FactorAndSolveKkt(bool* inertia_ok);
  bool HasPositiveCurvature();
  void Regularize(double first);
  void FinishWithoutStep(OverallReport* report);

  // The step length (line_search.cc).
  bool LineSearch();
  bool TryFullStep(double allowance);
  bool Backtrack(double allowance);
  double TryPoint(double alpha);
  void Accept(double value);

  // The problem.
  const Eigen::VectorXd& lengths_;
  const Points& old_points_;
  const OverallOptions& options_;
  const int n_, k_, nc_, dim_, block_, size_, last_;
  const double smoothing_;
  // Constants of the optimality measure (see Optimality).
  const bool l2_;
  const double weight_sum_;
  // The metric's Hessian does not depend on the configuration (no L2 or joint-angle term): its
  // identity terms are summed once per solve (MetricHessianTerms).
  const bool constant_metric_hessian_;
  double max_inverse_length_ = 0.0;
  double start_gradient_ = 0.0;

  // The iteration's state, in the caller's buffers.
  NewtonBuffers& buffers_;
  Sink& sink_;
  Points &x_, &dx_, &trial_;
  VectorView g_, g_trial_, rhs_, sol_, lag_, lag_trial_, lag_new_, dx_only_;  // size_
  VectorView lambda_, lambda_new_, c_;                                        // nc_
  VectorView inverse_length_;                                                 // n_

  double value_ = 0.0;              // the metric at x_
  double regularization_ = 0.0;     // delta of the Hessian block H + delta I
  bool factorized_ = false;         // the last attempt's matrix was not singular
  bool lag_current_ = false;        // lag_ already holds the Lagrangian's gradient at (x_, lambda_)
  bool general_ready_ = false;      // kkt_general and lu have this problem's shape
  bool metric_terms_kept_ = false;  // the identity buffers hold this solve's metric terms
};

}  // namespace flexkin::internal
