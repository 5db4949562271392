// The dynamic sub-step's overall projection (dynamics/least_constraint.h: Newton's method with a
// recursion along the chain) against the overall method's general Newton solver on the same
// problem (the squared metric, every point weighted by its mass; itself checked against IPOPT in
// overall_peers_test), against the first-order conditions it must meet, and in SIMD lanes
// against one lane at a time.

#include "dynamics/least_constraint.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>
#include <xsimd/xsimd.hpp>

#include "overall/newton.h"
#include "overall/retract.h"

namespace flexkin::internal {
namespace {

struct Case {
  Eigen::VectorXd lengths, mass;  // mass: n + 1, [0] unused
  Points start, p;                // start: a configuration with the lengths; p: the prediction
};

// A random chain of n links in `dim` dimensions, random masses, and a prediction moved from it
// by `scale` link lengths: each point by a random vector, plus a common pull `pull` (along x).
Case RandomCase(int n, int dim, double scale, double pull, std::mt19937* rng) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Case c;
  c.lengths.resize(n);
  c.mass = Eigen::VectorXd::Zero(n + 1);
  c.start.resize(n + 1, dim);
  c.start.row(0) = Eigen::RowVectorXd::Zero(dim);
  for (int i = 1; i <= n; ++i) {
    c.lengths[i - 1] = 0.5 + 0.5 * (uniform(*rng) + 1.0);
    c.mass[i] = 1.0 + 0.9 * uniform(*rng);
    Eigen::RowVectorXd u(dim);
    for (int k = 0; k < dim; ++k) u[k] = uniform(*rng);
    u[0] += 1.5;  // mostly along x, bending at random
    c.start.row(i) = c.start.row(i - 1) + c.lengths[i - 1] * u.normalized();
  }
  c.mass /= c.mass.sum();
  c.p = c.start;
  for (int i = 1; i <= n; ++i) {
    for (int k = 0; k < dim; ++k) c.p(i, k) += scale * uniform(*rng);
    c.p(i, 0) += pull;
  }
  return c;
}

// The follow-the-leader projection of p from point `head` on (a feasible start).
Points FollowTheLeader(const Case& c, int head) {
  Points x = c.p;
  for (int i = head + 1; i < x.rows(); ++i) {
    const Eigen::RowVectorXd d = c.p.row(i) - x.row(i - 1);
    x.row(i) = x.row(i - 1) + (c.lengths[i - 1] / d.norm()) * d;
  }
  return x;
}

// SolveLeastConstraint on one chain (head held), from `start`; returns whether it converged.
bool Solve(const Case& c, int head, Points* x) {
  const int n = static_cast<int>(c.lengths.size()), dim = static_cast<int>(c.p.cols());
  std::vector<double> work(LeastConstraintWork(dim, n));
  const Eigen::VectorXd inv = c.lengths.cwiseInverse();
  LeastConstraintProblem problem;
  problem.n = n;
  problem.head = head;
  problem.p = c.p.data();
  problem.x = x->data();
  problem.mass = c.mass.data();
  problem.lengths = c.lengths.data();
  problem.inv_lengths = inv.data();
  problem.work = work.data();
  const double ok = dim == 2 ? SolveLeastConstraint<double, 2>(problem)
                             : SolveLeastConstraint<double, 3>(problem);
  return ok != 0.0;
}

// The overall method's general solver on the same problem (point 0 held).
Points Reference(const Case& c) {
  const int n = static_cast<int>(c.lengths.size()), dim = static_cast<int>(c.p.cols());
  OverallOptions options;
  options.weights.squared = 1.0;
  NewtonBuffers buffers;
  buffers.Reserve(n, dim, options.weights);
  const Eigen::VectorXd weights = c.mass / c.mass.tail(n).maxCoeff();
  NewtonSolver solver(c.lengths, c.p, options, n, 0.0, &buffers);
  buffers.sink.point_weights = weights.data();
  Points x = FollowTheLeader(c, 0);
  const OverallReport report = solver.Solve(&x);
  EXPECT_TRUE(report.converged()) << OverallStatusName(report.status);
  return x;
}

double LargestLinkError(const Case& c, const Points& x) {
  double worst = 0.0;
  for (int i = 1; i < x.rows(); ++i) {
    worst = std::fmax(
        worst, std::fabs((x.row(i) - x.row(i - 1)).norm() - c.lengths[i - 1]) / c.lengths[i - 1]);
  }
  return worst;
}

// The first-order conditions: m_i (x_i - p_i) + lambda_i d_i - lambda_{i+1} d_{i+1} = 0 for some
// multipliers. From the free end, lambda_i is fixed by the component along d_i; what is left
// across d_i (relative to the largest force) is returned.
double FirstOrderResidual(const Case& c, const Points& x) {
  const int n = static_cast<int>(c.lengths.size());
  double worst = 0.0, scale = 0.0;
  Eigen::RowVectorXd carried = Eigen::RowVectorXd::Zero(x.cols());  // lambda_{i+1} d_{i+1}
  for (int i = n; i >= 1; --i) {
    const Eigen::RowVectorXd force = c.mass[i] * (x.row(i) - c.p.row(i)) - carried;
    const Eigen::RowVectorXd d = x.row(i) - x.row(i - 1);
    const double lambda = -force.dot(d) / d.squaredNorm();
    worst = std::fmax(worst, (force + lambda * d).norm());
    scale = std::fmax(scale, force.norm());
    carried = lambda * d;
  }
  return worst / std::fmax(scale, std::numeric_limits<double>::min());
}

double Objective(const Case& c, const Points& x) {
  double value = 0.0;
  for (int i = 1; i < x.rows(); ++i)
    value += 0.5 * c.mass[i] * (x.row(i) - c.p.row(i)).squaredNorm();
  return value;
}

// No configuration near `x` with the lengths does better: 200 random ones, each point moved by up
// to 1e-4 of a link and the lengths restored from point 0 (the follow-the-leader sweep).
bool NoBetterNearby(const Case& c, const Points& x, std::mt19937* rng) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const double value = Objective(c, x);
  for (int trial = 0; trial < 200; ++trial) {
    Points y = x;
    for (int i = 1; i < y.rows(); ++i) {
      for (int k = 0; k < y.cols(); ++k) y(i, k) += 1e-4 * c.lengths[i - 1] * uniform(*rng);
      const Eigen::RowVectorXd d = y.row(i) - y.row(i - 1);
      y.row(i) = y.row(i - 1) + (c.lengths[i - 1] / d.norm()) * d;
    }
    if (Objective(c, y) < value - 1e-14 * std::fmax(value, 1e-300)) return false;
  }
  return true;
}

// Small and large predictions, none, tension and compression: the same minimizer as NewtonSolver
// (both from the follow-the-leader projection), where the problem has one minimizer near the
// start. Strong compression and large moves have several local minimizers: where the two solvers
// end at different ones, both meet the first-order conditions, this one is a local minimizer and
// no worse than NewtonSolver's.
TEST(LeastConstraintTest, EqualsTheOverallMethodsNewtonSolver) {
  std::mt19937 rng(7);
  double worst = 0.0, worst_length = 0.0, worst_kkt = 0.0;
  int cases = 0, others = 0;
  for (int dim : {2, 3}) {
    for (int n : {1, 2, 5, 32, 100}) {
      for (double scale : {1e-4, 1e-2, 0.2}) {
        for (double pull : {0.0, 0.3, -0.3}) {  // none, tension, compression
          const Case c = RandomCase(n, dim, scale, pull, &rng);
          const std::string name = std::to_string(dim) + "D, " + std::to_string(n) +
                                   " links, scale " + std::to_string(scale) + ", pull " +
                                   std::to_string(pull);
          Points x = FollowTheLeader(c, 0);
          ASSERT_TRUE(Solve(c, 0, &x)) << name;
          const Points reference = Reference(c);
          double error = 0.0;
          for (int i = 1; i <= n; ++i) {
            error = std::fmax(error, (x.row(i) - reference.row(i)).norm() / c.lengths[i - 1]);
          }
          const double kkt = FirstOrderResidual(c, x);
          worst_length = std::fmax(worst_length, LargestLinkError(c, x));
          worst_kkt = std::fmax(worst_kkt, kkt);
          ++cases;
          if (error < 1e-10) {
            worst = std::fmax(worst, error);
            continue;
          }
          ++others;
          EXPECT_TRUE(pull < 0.0 || scale > 0.01) << name << ": " << error;
          EXPECT_LT(FirstOrderResidual(c, reference), 1e-9) << name;
          EXPECT_LE(Objective(c, x), Objective(c, reference) * (1.0 + 1e-12)) << name;
          EXPECT_TRUE(NoBetterNearby(c, x, &rng)) << name;
          std::printf("%s: another local minimizer than NewtonSolver's, %.4g against %.4g\n",
                      name.c_str(), Objective(c, x), Objective(c, reference));
        }
      }
    }
  }
  EXPECT_LT(worst, 1e-10);
  EXPECT_LT(worst_length, 4e-14);
  EXPECT_LT(worst_kkt, 1e-9);
  std::printf(
      "%d problems: %d at NewtonSolver's minimizer to %.1e of a link; lengths %.1e, "
      "first-order residual %.1e\n",
      cases, cases - others, worst, worst_length, worst_kkt);
}

// The held points 0 .. head: the same answer, bit for bit, as the chain from point `head` alone.
TEST(LeastConstraintTest, HeldPointsAreTheSubChainsHead) {
  std::mt19937 rng(11);
  for (int dim : {2, 3}) {
    const int n = 12, head = 3;
    const Case c = RandomCase(n, dim, 0.05, 0.1, &rng);
    Points x = FollowTheLeader(c, head);
    ASSERT_TRUE(Solve(c, head, &x));
    Case sub;
    sub.lengths = c.lengths.tail(n - head);
    sub.mass = c.mass.tail(n - head + 1);
    sub.p = c.p.bottomRows(n - head + 1);
    Points y = FollowTheLeader(c, head).bottomRows(n - head + 1);
    ASSERT_TRUE(Solve(sub, 0, &y));
    EXPECT_EQ(Points(x.bottomRows(n - head + 1)), y);
    EXPECT_EQ(Points(x.topRows(head + 1)), Points(c.p.topRows(head + 1)));
  }
}

// A prediction that no Newton step can use (not finite): the lane says so and keeps its start.
TEST(LeastConstraintTest, ALaneThatDoesNotConvergeKeepsItsStart) {
  std::mt19937 rng(3);
  Case c = RandomCase(6, 3, 0.05, 0.0, &rng);
  const Points start = FollowTheLeader(c, 0);
  c.p(4, 1) = std::numeric_limits<double>::quiet_NaN();
  Points x = start;
  EXPECT_FALSE(Solve(c, 0, &x));
  EXPECT_EQ(x, start);
}

// Two lanes in an SSE2 batch (interleaved, as the strand engine's blocks): each equal to its
// chain solved alone (the lanes stop together, so a lane may take one more step: to 1e-12).
TEST(LeastConstraintTest, LanesEqualOneChainAtATime) {
  using B = xsimd::batch<double, xsimd::sse2>;
  constexpr int W = B::size;
  std::mt19937 rng(5);
  for (int dim : {2, 3}) {
    const int n = 24;
    Case lanes[W];
    for (int j = 0; j < W; ++j) lanes[j] = RandomCase(n, dim, j == 0 ? 1e-3 : 0.2, 0.2, &rng);
    alignas(64) double p[(n + 1) * 3 * W], x[(n + 1) * 3 * W], mass[(n + 1) * W], len[n * W],
        inv[n * W];
    std::vector<double, xsimd::aligned_allocator<double, 64>> work(LeastConstraintWork(dim, n) * W);
    Points alone[W];
    for (int j = 0; j < W; ++j) {
      const Points start = FollowTheLeader(lanes[j], 0);
      for (int i = 0; i <= n; ++i) {
        for (int k = 0; k < dim; ++k) {
          p[(i * dim + k) * W + j] = lanes[j].p(i, k);
          x[(i * dim + k) * W + j] = start(i, k);
        }
        mass[i * W + j] = lanes[j].mass[i];
        if (i < n) {
          len[i * W + j] = lanes[j].lengths[i];
          inv[i * W + j] = 1.0 / lanes[j].lengths[i];
        }
      }
      alone[j] = start;
      ASSERT_TRUE(Solve(lanes[j], 0, &alone[j]));
    }
    LeastConstraintProblem problem;
    problem.n = n;
    problem.stride = W;
    problem.p = p;
    problem.x = x;
    problem.mass = mass;
    problem.lengths = len;
    problem.inv_lengths = inv;
    problem.work = work.data();
    alignas(64) double ok[W];
    (dim == 2 ? SolveLeastConstraint<B, 2>(problem) : SolveLeastConstraint<B, 3>(problem))
        .store_aligned(ok);
    for (int j = 0; j < W; ++j) {
      EXPECT_EQ(ok[j], 1.0);
      double error = 0.0;
      for (int i = 0; i <= n; ++i) {
        for (int k = 0; k < dim; ++k) {
          error = std::fmax(error, std::fabs(x[(i * dim + k) * W + j] - alone[j](i, k)));
        }
      }
      EXPECT_LT(error, 1e-12 * lanes[j].lengths.minCoeff()) << "lane " << j << ", " << dim << "D";
    }
  }
}

}  // namespace
}  // namespace flexkin::internal
