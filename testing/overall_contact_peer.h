#pragma once
// An independent solution of the overall step with colliders (src/overall/contact_step.h) for the
// tests: IPOPT on the same constrained minimization, written out for spheres (whose distance to a
// segment has a closed form). Minimize
//   l2 * sum_j |x_j - a_j| + squared * sum_j |x_j - a_j|^2 + rotation * sum_i |D_i - D_i^old|^2 /
//   L_i
// over points 1..n (point 0 the new head, a the old points, D_i = x_i - x_{i-1}) subject to
// |D_i|^2 = L_i^2 and, for every link and every sphere, the distance from its center to the
// segment [x_{i-1}, x_i] at least its radius. The L2 term (not differentiable where a point stays
// still) in its epigraph form: unknowns t_j >= 0 with t_j^2 - |x_j - a_j|^2 >= 0, the objective
// l2 * sum_j t_j (testing/l2_peer.h; at a still point the cone's gradient vanishes, and IPOPT
// converges there slowly or stops short).
#include <Eigen/Core>
#include <vector>

#include "contact_peer.h"

namespace flexkin::peers {

struct OverallContactProblem {
  Eigen::MatrixXd old_points;  // (n + 1) by dim (2 or 3)
  Eigen::VectorXd head;        // dim: the new head
  Eigen::VectorXd lengths;     // n
  double squared = 1.0, rotation = 0.0, l2 = 0.0;
  std::vector<SphereObstacle> spheres;  // in 3D; a 2D chain lies in z = 0
};

// The metric of `x` ((n + 1) by dim, row 0 the head), as above.
double OverallContactObjective(const OverallContactProblem& problem, const Eigen::MatrixXd& x);

// Solved by IPOPT from `start` ((n + 1) by dim) to its tolerance 1e-14 (a limited-memory
// Hessian); true if IPOPT reports success.
bool IpoptOverallContact(const OverallContactProblem& problem, const Eigen::MatrixXd& start,
                         Eigen::MatrixXd* x);

}  // namespace flexkin::peers
