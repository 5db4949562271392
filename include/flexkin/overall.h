#pragma once
// Whole-curve ("overall") optimization of one step (paper Sec. 3 and 4): the leading end is moved
// to a prescribed position and all other points move at once, to the configuration that
// minimizes a metric of the motion subject to every link keeping its length.

#include <Eigen/Core>
#include <memory>
#include <string>

#include "flexkin/chain.h"
#include "flexkin/error.h"
#include "flexkin/vocabulary.h"

namespace flexkin {
namespace internal {
struct OverallBuffers;
}  // namespace internal

// The terms of the step metric (the members of ObjectiveWeights below).
enum class ObjectiveTerm { kL2, kL2Weighted, kSquared, kSquaredWeighted, kRotation, kJointAngle };

template <>
struct Vocabulary<ObjectiveTerm> {
  static constexpr const char* kKind = "objective term";
  static constexpr NamedValue<ObjectiveTerm> kEntries[] = {
      {ObjectiveTerm::kL2, "l2", "sum of the distances the points move (the paper's L2 metric)"},
      {ObjectiveTerm::kL2Weighted, "l2_weighted", "the same weighted by arc length (eq. 6)"},
      {ObjectiveTerm::kSquared, "squared", "sum of the squared distances the points move"},
      {ObjectiveTerm::kSquaredWeighted, "squared_weighted",
       "the same weighted by arc length (the squared form of eq. 6)"},
      {ObjectiveTerm::kRotation, "rotation",
       "body rotation: sum over links of |D_i - D_i_old|^2 / L_i (Sec. 4.1)"},
      {ObjectiveTerm::kJointAngle, "joint_angle",
       "joint-angle change, planar chains only: sum of L_mean (psi_i - psi_i_old)^2 (Sec. 4.2)"},
  };
};

// The metric of one step, from the old configuration a_0..a_n to the new one x_0..x_n, as a
// weighted sum of these terms. Link vectors: D_i = x_i - x_{i-1}, D_i^old = a_i - a_{i-1}.
struct ObjectiveWeights {
  // Sum over points j = 1..n of |x_j - a_j|^2: the smooth form of the paper's L2 metric.
  // Typical: 1 (a "rope").
  double squared = 1.0;
  // Sum over points of (arc-length weight w_j) |x_j - a_j|^2, w_j = (L_j + L_{j+1}) / 2 and
  // L_n / 2 at the trailing end: the squared form of eq. (6).
  double squared_weighted = 0.0;
  // Body rotation (Sec. 4.1): sum over links of |D_i - D_i^old|^2 / L_i = sum of
  // L_i |e_i - e_i^old|^2 = sum of 2 L_i (1 - cos theta_i), theta_i the rotation of link i.
  // Alone, its minimizer is a pure translation (Fig. 8).
  double rotation = 0.0;
  // Joint-angle change (Sec. 4.2, planar chains only): sum over the inner joints i = 1..n-1 of
  // L_mean (psi_i - psi_i^old)^2, psi_i the signed angle from link i to link i+1 and
  // L_mean = (L_i + L_{i+1}) / 2. Alone it leaves the chain rigid (Fig. 9); it does not fix
  // the chain's overall rotation, so combine it with another term.
  double joint_angle = 0.0;

  // The paper's L2 metric: sum over points j = 1..n of |x_j - a_j|, the distance each point
  // moves. Not differentiable where a point stays still, and its minimizer is sparse: points
  // that need not move stay exactly still (OverallReport::moving_points). Like Coulomb
  // friction, each point resists with a force of at most its weight, so a pull moves as few
  // points as it must. Typical: 1. Not combined with joint_angle (an InputError).
  double l2 = 0.0;
  // The same, point j weighted by its arc length (L_j + L_{j+1}) / 2 (L_n / 2 at the trailing
  // end): the discrete form of eq. (6).
  double l2_weighted = 0.0;

  // The weight of `term` (one of the members above).
  double& operator[](ObjectiveTerm term);
  double operator[](ObjectiveTerm term) const;

  // Every problem (empty if valid: every weight finite and >= 0, at least one > 0, no L2 term
  // with the joint-angle term), each naming its member ("l2").
  Problems Validate() const;
};

// Options of the overall solver (an SQP/Newton method on the KKT system, whose linear algebra is
// banded: the cost per iteration is linear in the number of points).
struct OverallOptions {
  ObjectiveWeights weights;
  // Stop when every |(|x_i - x_{i-1}|^2 - L_i^2)| / (2 L_i^2) is below this. Typical: 1e-12
  // (points far from the origin cannot be stored closer than about 1e-16 |x| / L).
  double constraint_tolerance = 1e-12;
  // ... and the first-order optimality is below this: the largest component of the Lagrangian's
  // gradient divided by the largest component of the objective's gradient (at the solution or
  // at the start, whichever is larger); 0 when the Lagrangian's gradient is at the rounding
  // level of the positions. Typical: 1e-12.
  double optimality_tolerance = 1e-12;
  // Newton iterations at most. Typical: 50.
  int max_iterations = 50;

  // Every problem (empty if valid), each naming its member ("max_iterations", "weights.l2").
  Problems Validate() const;
};

enum class OverallStatus {
  kConverged,      // both tolerances met
  kMaxIterations,  // max_iterations reached first
  kStalled,        // the line search could not make progress
  kFailed,         // a linear system was singular or a value not finite
};
const char* OverallStatusName(OverallStatus status);  // "converged", "max_iterations", ...

// What the solver did. Never a silent failure: anything but kConverged is reported as such.
struct OverallReport {
  OverallStatus status = OverallStatus::kFailed;
  int iterations = 0;
  double objective = 0.0;             // metric of the step at the returned configuration
  double constraint_violation = 0.0;  // largest |(|D_i|^2 - L_i^2)| / (2 L_i^2)
  double optimality = 0.0;            // as in OverallOptions::optimality_tolerance
  // How the returned local minimizer was reached: the head advances in sub-steps of at most half
  // the shortest link, each solved by Newton's method from the tractrix step of the previous
  // solution ("continuation in k head sub-steps from the old configuration"), or, for a short
  // move, directly from the tractrix step ("sequential tractrix step"). It is the minimizer
  // continuously connected to the old configuration.
  std::string start;
  // Points 1..moving_points moved; the others stayed exactly where they were. n for the smooth
  // metrics; usually fewer with an L2 term (its sparse minimizer).
  int moving_points = 0;

  bool converged() const { return status == OverallStatus::kConverged; }
  std::string BriefReport() const;
};

// Everything the overall solver stores while it works (the banded KKT matrix and its factors,
// gradients, multipliers, trial configurations, the L2 metric's friction bounds ...), kept from
// one step to the next by a caller that makes many: sized for the chain on first use (for the
// largest problem it poses), then reused, so that a step allocates nothing once the workspace is
// warm. (The LU fallback's storage, rarely needed, is sized when first needed.) Opaque; one per
// thread; a chain of another size or dimension simply resizes it. Costs O(n) memory.
class OverallWorkspace {
 public:
  OverallWorkspace();
  ~OverallWorkspace();
  OverallWorkspace(OverallWorkspace&&) noexcept;
  OverallWorkspace& operator=(OverallWorkspace&&) noexcept;

  internal::OverallBuffers& buffers() { return *buffers_; }  // the solver's own

 private:
  std::unique_ptr<internal::OverallBuffers> buffers_;
};

// One step: moves point 0 of `chain->points` (the old configuration, (n+1) by dim) to `head` and
// the other points to the minimizer of `options.weights` subject to |x_i - x_{i-1}| = L_i
// (`chain->lengths`, unchanged). `chain->points` is updated in place (to the best configuration
// found, even when not converged: check the report). `workspace`: the buffers to reuse (see
// OverallWorkspace); without one, a temporary one is made. Throws InputError on invalid input
// (the chain, whose field is named "points"; the head's size and values; the options; the
// joint-angle term in 3D).
OverallReport OverallStep(const Eigen::Ref<const Eigen::VectorXd>& head,
                          const OverallOptions& options, Chain* chain,
                          OverallWorkspace* workspace = nullptr);

// The value, gradient (n dim) and, if `hessian` is not null, the Hessian (n dim square, dense:
// for tests and small problems) of the step metric as a function of x_1..x_n (point 0 fixed at
// `new_points.row(0)`). Exposed so that tests and other solvers evaluate the very same function.
// It does not validate its input (OverallStep does): the shapes must match, and the joint-angle
// term is ignored for 3D chains. At a point that has not moved, the L2 term contributes the
// subgradient 0 and no Hessian.
double OverallObjective(const ObjectiveWeights& weights, const Eigen::VectorXd& lengths,
                        const Points& old_points, const Points& new_points,
                        Eigen::VectorXd* gradient = nullptr, Eigen::MatrixXd* hessian = nullptr);

}  // namespace flexkin
