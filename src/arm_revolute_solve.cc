// The step of method "newton" for spatial arms with revolute joints about given axes
// (src/arm_revolute.h, docs/robots.md "Revolute joints about given axes").
//
// Why not the tractrix sweep: with such joints the sweep's frames, carried down from the end
// effector, need not meet the base's, and rebuilding the arm from the base turns every joint to
// absorb the mismatch. Measured on the 16-link pitch/yaw snake of tests/arm_test.cc (60 targets),
// Newton on the sweep's translation left 34 steps unreached, and even finishing its angles with a
// joint-space correction (all reached) moved each joint 3.6 (end effector) to 0.9 (base) rad in
// total, against 0.55 to 0.10 rad here; as a proposal from a single sweep the motion did not
// even die out (2.4 / 2.9 / 2.0 rad, end effector / middle / base).
//
// The step: at q with miss r = FK(q) - target and position Jacobian J (3 by n, column k the
// world axis a_k x (end effector - joint k)), the step dq = W^-1 J' (J W^-1 J')^-1 (-r) is the
// smallest in (dq)' W (dq) that cancels r to first order. From the previous angles the first such
// step is the weighted minimum-norm motion; the next ones only remove what curvature leaves
// (Gauss-Newton converges quadratically: 4 to 5 iterations to 1e-10 of a link on the tests). A
// joint's lever on the end effector grows about linearly with its distance d_k from it, so with
// w_k ~ d_k^2 its share of the motion, w_k^-1 (J' lambda)_k, falls off about as 1 / d_k.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

#include "arm_revolute.h"

namespace flexkin::arm_internal {
RevoluteSolve SolveRevolute(const ArmModel& model, const Eigen::VectorXd& previous,
                            const Eigen::VectorXd& target, double tol, int max_iterations) {
  const int n = model.num_links();
  const bool limits = model.joint_min.size() == n;
  auto lo = [&](int k) { return limits ? model.joint_min[k] : -INFINITY; };
  auto hi = [&](int k) { return limits ? model.joint_max[k] : INFINITY; };
  // W^-1: 1 / (distance along the chain from joint k to the end effector, in mean link lengths)^2.
  const double scale = model.link_lengths.mean();
  Eigen::VectorXd winv(n);
  double along = 0.0;
  for (int k = n - 1; k >= 0; --k) {
    along += model.link_lengths[k];
    winv[k] = 1.0 / ((along / scale) * (along / scale));
  }

  RevoluteSolve out;
  Eigen::VectorXd q(n), dq(n), trial(n);
  for (int k = 0; k < n; ++k) q[k] = std::clamp(previous[k], lo(k), hi(k));
  Points points, trial_points;
  Eigen::MatrixXd axes, trial_axes;
  points = RevoluteForward(model, q, &axes);
  ++out.passes;
  // Gauss-Newton toward `goal` until the miss is at most `goal_tol` (or no descent is left).
  Eigen::Vector3d r;
  Eigen::Matrix<double, 3, Eigen::Dynamic> jac(3, n);
  std::vector<char> held(n);
  auto solve_to = [&](const Eigen::Vector3d& goal, double goal_tol, int max_it) {
    r = points.row(n).transpose() - goal;
    double damping = 0.0;
    for (int it = 0; it < max_it && r.norm() > goal_tol; ++it) {
      ++out.iterations;
      const Eigen::Vector3d ee = points.row(n).transpose();
      for (int k = 0; k < n; ++k) {
        const Eigen::Vector3d axis = axes.row(k).transpose(), lever = ee - points.row(k).transpose();
        jac.col(k) = axis.cross(lever);
      }
      // The active set: a joint that the step would carry past a limit is moved onto that limit
      // and held there, and the rest of the step re-solved for what it leaves of the miss (each
      // round holds at least one more joint: at most n rounds).
      std::fill(held.begin(), held.end(), 0);
      dq.setZero();
      for (int round = 0; round <= n; ++round) {
        Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
        Eigen::Vector3d rhs = -r;
        for (int k = 0; k < n; ++k) {
          if (held[k]) {
            rhs -= jac.col(k) * dq[k];
          } else {
            a.noalias() += winv[k] * jac.col(k) * jac.col(k).transpose();
          }
        }
        // A tiny ridge keeps the solve finite where the free joints cannot move the end effector
        // along some direction (an arm stretched straight, most joints held).
        a.diagonal().array() += (1e-14 + damping) * a.trace() + 1e-300;
        const Eigen::Vector3d lambda = a.ldlt().solve(rhs);
        bool more = false;
        for (int k = 0; k < n; ++k) {
          if (held[k]) continue;
          dq[k] = winv[k] * jac.col(k).dot(lambda);
          const double to = std::clamp(q[k] + dq[k], lo(k), hi(k));
          if (to != q[k] + dq[k]) {
            dq[k] = to - q[k];
            held[k] = 1;
            more = true;
          }
        }
        if (!more) break;
      }
      if (!dq.allFinite()) break;
      // Backtracking on the miss (every trial is within the limits, which are an interval; the
      // clamp only guards against rounding).
      bool improved = false;
      double taken = 0.0;  // the step length accepted
      for (double alpha = 1.0; alpha > 1e-9 && !improved; alpha *= 0.5) {
        for (int k = 0; k < n; ++k) trial[k] = std::clamp(q[k] + alpha * dq[k], lo(k), hi(k));
        trial_points = RevoluteForward(model, trial, &trial_axes);
        ++out.passes;
        const Eigen::Vector3d r_trial = trial_points.row(n).transpose() - goal;
        if (r_trial.allFinite() && r_trial.norm() <= (1.0 - 1e-4 * alpha) * r.norm()) {
          q = trial;
          points.swap(trial_points);
          axes.swap(trial_axes);
          r = r_trial;
          improved = true;
          taken = alpha;
        }
      }
      // Levenberg-Marquardt damping (relative to the trace of J W^-1 J'): raised where the full
      // step did not do (a poor linearisation, far from the goal), dropped again after full
      // steps, so the last iterations are pure Gauss-Newton and converge quadratically.
      if (improved && taken == 1.0) {
        damping = damping < 1e-8 ? 0.0 : damping * 0.25;
      } else if (damping < 1e3) {
        damping = std::max(damping * 4.0, 1e-4);
        continue;
      }
      if (!improved) break;  // no descent left: the nearest configuration the free joints give
    }
  };
  // A far target is approached through intermediate ones on the straight line from the end
  // effector, at most kLeg mean link lengths apart: one solve across a large move linearises
  // badly and stalls more often (single jumps of the 64-link snake to 200 random reachable
  // targets: 135 unreached without legs, 80 with), while each short leg converges in a few
  // iterations, its motion again carried by the joints near the end effector, as the tractrix
  // step moves a chain whose end is dragged along a line. The legs need not be reached exactly
  // (kLegTol); the target must.
  constexpr double kLeg = 0.5, kLegTol = 1e-3;
  constexpr int kLegIterations = 20;
  const Eigen::Vector3d from = points.row(n).transpose();
  const int legs = static_cast<int>(std::ceil((target - from).norm() / (kLeg * scale)));
  for (int leg = 1; leg < legs; ++leg) {
    solve_to(from + (target - from) * (double(leg) / legs), kLegTol * scale, kLegIterations);
  }
  solve_to(target, tol, max_iterations);
  out.residual = r.norm();
  out.converged = out.residual <= tol;
  for (int k = 0; k < n && limits; ++k) out.limited |= q[k] <= lo(k) || q[k] >= hi(k);
  out.angle = q;
  out.points = points;
  return out;
}

}  // namespace flexkin::arm_internal
