#pragma once
// Independent reference for the tests: the continuous motion (every trailing end's velocity
// along its link, paper Sec. 2 and eq. 11) integrated numerically with Boost.Odeint. Shares no
// code with the library, so agreement is evidence that the closed form and the propagation are
// right, not that two copies of one formula agree.

#include <Eigen/Core>
#include <array>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <vector>

#include "flexkin/chain.h"

namespace flexkin::reference {

// Tolerance of the adaptive integrator (absolute and relative, in link lengths for one link and
// in the caller's unit for a chain). Fehlberg 7(8) at 1e-13 gives about 1e-12 at the end.
constexpr double kOdeTolerance = 1e-13;

// One link of length `length`: its leading end moves at unit speed along the straight segment
// from `head_old` to `head_new`, its trailing end (at `tail` before the move) with velocity
//   dA/ds = (u . e) e,   e = (P - A) / |P - A|,
// the projection of the head's velocity u onto the link. Integrated relative to `head_old` in
// units of `length`, so that the result does not depend on the scale.
template <int Dim>
Eigen::Matrix<double, Dim, 1> ReferenceLinkStep(const Eigen::Matrix<double, Dim, 1>& head_old,
                                                const Eigen::Matrix<double, Dim, 1>& head_new,
                                                const Eigen::Matrix<double, Dim, 1>& tail,
                                                double length, double tolerance = kOdeTolerance) {
  namespace odeint = boost::numeric::odeint;
  using State = std::array<double, Dim>;
  const Eigen::Matrix<double, Dim, 1> d = head_new - head_old;
  const double p = d.norm();
  if (p == 0.0) return tail;
  const Eigen::Matrix<double, Dim, 1> u = d / p;
  State a;
  for (int k = 0; k < Dim; ++k) a[k] = (tail[k] - head_old[k]) / length;
  auto rhs = [&u](const State& x, State& dxds, double s) {
    double e[Dim];
    double norm2 = 0.0;
    for (int k = 0; k < Dim; ++k) {
      e[k] = s * u[k] - x[k];  // head minus tail; the head is at s u
      norm2 += e[k] * e[k];
    }
    double ue = 0.0;
    for (int k = 0; k < Dim; ++k) ue += u[k] * e[k];
    for (int k = 0; k < Dim; ++k) dxds[k] = ue * e[k] / norm2;
  };
  auto stepper =
      odeint::make_controlled(tolerance, tolerance, odeint::runge_kutta_fehlberg78<State>());
  const double s_end = p / length;
  odeint::integrate_adaptive(stepper, rhs, a, 0.0, s_end, std::fmin(0.01, s_end));
  Eigen::Matrix<double, Dim, 1> out;
  for (int k = 0; k < Dim; ++k) out[k] = head_old[k] + length * a[k];
  return out;
}

// A whole chain: point 0 moves at unit speed in straight lines through the rows of `targets`
// (starting from its position in `start`), and each point i >= 1 with velocity
//   dx_i/dt = (dx_{i-1}/dt . e_i) e_i,   e_i = (x_{i-1} - x_i) / |x_{i-1} - x_i|,
// which keeps every link length. Each straight piece is integrated separately, so the corner
// of the leader's path is not smeared. Returns the points at the end; if `after_each` is not
// null it receives the points after each target.
inline Points ReferenceChainMotion(const Points& start, const Points& targets,
                                   std::vector<Points>* after_each = nullptr,
                                   double tolerance = kOdeTolerance) {
  namespace odeint = boost::numeric::odeint;
  using State = std::vector<double>;
  const int dim = static_cast<int>(start.cols());
  const int num_points = static_cast<int>(start.rows());
  State x(static_cast<size_t>(num_points * dim));
  for (int i = 0; i < num_points; ++i) {
    for (int k = 0; k < dim; ++k) x[i * dim + k] = start(i, k);
  }
  for (Eigen::Index s = 0; s < targets.rows(); ++s) {
    std::vector<double> u(dim);
    double p2 = 0.0;
    for (int k = 0; k < dim; ++k) {
      u[k] = targets(s, k) - x[k];
      p2 += u[k] * u[k];
    }
    const double p = std::sqrt(p2);
    if (p > 0.0) {
      for (int k = 0; k < dim; ++k) u[k] /= p;
      auto rhs = [&](const State& y, State& dydt, double /*t*/) {
        for (int k = 0; k < dim; ++k) dydt[k] = u[k];
        for (int i = 1; i < num_points; ++i) {
          double e[3];
          double norm2 = 0.0, ve = 0.0;
          for (int k = 0; k < dim; ++k) {
            e[k] = y[(i - 1) * dim + k] - y[i * dim + k];
            norm2 += e[k] * e[k];
            ve += dydt[(i - 1) * dim + k] * e[k];
          }
          for (int k = 0; k < dim; ++k) dydt[i * dim + k] = ve * e[k] / norm2;
        }
      };
      auto stepper =
          odeint::make_controlled(tolerance, tolerance, odeint::runge_kutta_fehlberg78<State>());
      odeint::integrate_adaptive(stepper, rhs, x, 0.0, p, std::fmin(0.01, p));
      // The leading end lands on the target itself, not on its integrated approximation.
      for (int k = 0; k < dim; ++k) x[k] = targets(s, k);
    }
    if (after_each != nullptr) {
      Points now(num_points, dim);
      for (int i = 0; i < num_points; ++i) {
        for (int k = 0; k < dim; ++k) now(i, k) = x[i * dim + k];
      }
      after_each->push_back(now);
    }
  }
  Points end(num_points, dim);
  for (int i = 0; i < num_points; ++i) {
    for (int k = 0; k < dim; ++k) end(i, k) = x[i * dim + k];
  }
  return end;
}

}  // namespace flexkin::reference
