#pragma once
// Physics with known answers for the dynamic chains' checks (tests/dynamics_test.cc) and plots
// (examples/dynamics_plots.cc): the exact pendulum's elliptic integral, a measured period, and
// the discrete hanging chain's linearized modes.

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/dynamics.h"

namespace flexkin::testing_physics {

constexpr double kG = 9.81;

// K(k) by the arithmetic-geometric mean: pi / (2 AGM(1, sqrt(1 - k^2))).
inline double EllipticK(double k) {
  double a = 1.0, b = std::sqrt(1.0 - k * k);
  for (int i = 0; i < 40; ++i) {
    const double m = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = m;
  }
  return M_PI / (2.0 * a);
}

// The mean time between successive upward zero crossings of `x` (sampled every dt), linearly
// interpolated; 0 if fewer than two.
inline double Period(const std::vector<double>& x, double dt) {
  std::vector<double> crossings;
  for (size_t i = 1; i < x.size(); ++i) {
    if (x[i - 1] < 0.0 && x[i] >= 0.0) {
      crossings.push_back(dt * ((i - 1) + x[i - 1] / (x[i - 1] - x[i])));
    }
  }
  if (crossings.size() < 2) return 0.0;
  return (crossings.back() - crossings.front()) / (crossings.size() - 1);
}

// The discrete hanging chain's linearized modes: n links of length L / n, masses by length (the
// last point half), tension in link i g times the mass below it. Small sideways motion u:
// M u'' = -K u, K tridiagonal. Returns the angular frequencies, ascending, and the modes (columns).
inline Eigen::VectorXd DiscreteModes(int n, double length, Eigen::MatrixXd* modes) {
  const double l = length / n;
  Eigen::VectorXd m = Eigen::VectorXd::Constant(n, l);
  m[n - 1] = 0.5 * l;
  Eigen::VectorXd tension(n + 1);  // tension[i]: link i (1..n), tension[n + 1 - 1] ...
  tension.setZero();
  for (int i = n; i >= 1; --i) tension[i - 1] = kG * m.tail(n - i + 1).sum();
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(n, n);
  for (int j = 1; j <= n; ++j) {
    // Link j (above point j) and link j + 1 (below).
    k(j - 1, j - 1) += tension[j - 1] / l;
    if (j >= 2) k(j - 1, j - 2) -= tension[j - 1] / l;
    if (j < n) {
      k(j - 1, j - 1) += tension[j] / l;
      k(j - 1, j) -= tension[j] / l;
    }
  }
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(k, Eigen::MatrixXd(m.asDiagonal()));
  *modes = eig.eigenvectors();
  return eig.eigenvalues().cwiseSqrt();
}

// The chain of n links of total length `length` released from the shape of mode `k` (0-based) of
// its linearized motion, 0.01 of the length at its widest: each link turned by the mode's slope,
// so the lengths are exact.
inline Chain ChainInMode(int n, double length, const Eigen::MatrixXd& modes, int k) {
  Eigen::VectorXd mode = modes.col(k);
  mode *= 0.01 * length / mode.cwiseAbs().maxCoeff();
  Points p = Points::Zero(n + 1, 2);
  for (int j = 1; j <= n; ++j) {
    const double du = mode[j - 1] - (j >= 2 ? mode[j - 2] : 0.0);
    const double angle = std::asin(du / (length / n));
    p(j, 0) = p(j - 1, 0) + (length / n) * std::sin(angle);
    p(j, 1) = p(j - 1, 1) - (length / n) * std::cos(angle);
  }
  return MakeChain(p);
}

// A rope of `links` equal links and length 1 lying along x from the origin (released from
// horizontal).
inline Chain Horizontal(int links) {
  Points p = Points::Zero(links + 1, 2);
  for (int j = 0; j <= links; ++j) p(j, 0) = static_cast<double>(j) / links;
  return MakeChain(p);
}

// The angular frequency at which point `point` of a run at 60 frames per second swings sideways
// (along x): 2 pi over the mean period of its x.
inline double SwingOmega(const DynamicResult& r, int point) {
  std::vector<double> x;
  for (const Points& f : r.frames) x.push_back(f(point, 0));
  return 2.0 * M_PI / Period(x, 1.0 / 60.0);
}

// A 2D dynamic chain's options: the projection, gravity -kG along y, `substeps` per frame.
inline DynamicOptions Options(Projection projection, int substeps) {
  DynamicOptions o;
  o.projection = projection;
  o.gravity = Eigen::Vector2d(0.0, -kG);
  o.substeps = substeps;
  return o;
}

}  // namespace flexkin::testing_physics
