// The paper's L2 metric (sum of the distances the points move) in the overall optimization: a sum
// of norms, not differentiable where a point stays still, with a sparse minimizer. Checked here
// independently of the solver: no feasible perturbation improves the returned configuration,
// still points are exactly still, the friction law of the still points against configurations
// worked out by hand, and the derivatives away from the kink against finite differences.

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <vector>

#include "flexkin/curves.h"
#include "flexkin/overall.h"
#include "scenes/scenes.h"
#include "test_util.h"

namespace flexkin {
namespace {

using scenes::CurvedPoints;
using test_util::ExpectInputError;
using test_util::LengthsOf;

ObjectiveWeights L2Weights(double l2, double l2_weighted, double squared, double rotation) {
  ObjectiveWeights w;
  w.l2 = l2;
  w.l2_weighted = l2_weighted;
  w.squared = squared;
  w.rotation = rotation;
  return w;
}

// The metric written out here, term by term, rather than taken from the library.
double Metric(const ObjectiveWeights& w, const Eigen::VectorXd& lengths, const Points& old_points,
              const Points& x) {
  const int n = static_cast<int>(lengths.size());
  double value = 0.0;
  for (int j = 1; j <= n; ++j) {
    const double arc = 0.5 * (lengths[j - 1] + (j < n ? lengths[j] : 0.0));
    const double d = (x.row(j) - old_points.row(j)).norm();
    value += (w.l2 + w.l2_weighted * arc) * d + (w.squared + w.squared_weighted * arc) * d * d;
    const Eigen::RowVectorXd turn =
        (x.row(j) - x.row(j - 1)) - (old_points.row(j) - old_points.row(j - 1));
    value += w.rotation * turn.squaredNorm() / lengths[j - 1];
  }
  return value;
}

// Puts points 1..n back on the constraints (point 0 fixed) by dense Gauss-Newton steps of least
// change, x -= J^T (J J^T)^-1 c: a projection written independently of the solver's.
bool Project(const Eigen::VectorXd& lengths, Points* x) {
  const int n = static_cast<int>(lengths.size());
  const int dim = static_cast<int>(x->cols());
  for (int iteration = 0; iteration < 50; ++iteration) {
    Eigen::VectorXd c(n);
    Eigen::MatrixXd jac = Eigen::MatrixXd::Zero(n, n * dim);
    for (int i = 1; i <= n; ++i) {
      const Eigen::RowVectorXd d = x->row(i) - x->row(i - 1);
      c[i - 1] = (d.squaredNorm() - lengths[i - 1] * lengths[i - 1]) / (2.0 * lengths[i - 1]);
      jac.block(i - 1, (i - 1) * dim, 1, dim) = d / lengths[i - 1];
      if (i > 1) jac.block(i - 1, (i - 2) * dim, 1, dim) = -d / lengths[i - 1];
    }
    if (c.cwiseAbs().maxCoeff() <= 1e-15 * lengths.maxCoeff()) return true;
    const Eigen::VectorXd step = jac.transpose() * (jac * jac.transpose()).ldlt().solve(c);
    for (int j = 1; j <= n; ++j) x->row(j) -= step.segment((j - 1) * dim, dim).transpose();
  }
  return false;
}

// Solves one step and checks what holds for every L2 solution: converged, lengths kept, the head
// where it was sent, points after `moving_points` exactly (bit for bit) where they were and the
// others moved, and no random feasible perturbation (of every point, at three scales) lowering
// the metric. Returns the solution.
Points SolveAndCheck(const ObjectiveWeights& w, const Eigen::VectorXd& lengths,
                     const Points& old_points, const Eigen::VectorXd& head, std::mt19937* rng,
                     OverallReport* report_out = nullptr) {
  const int n = static_cast<int>(lengths.size());
  OverallOptions options;
  options.weights = w;
  Chain moved{old_points, lengths};
  const Points& x = moved.points;
  const OverallReport report = OverallStep(head, options, &moved);
  if (report_out != nullptr) *report_out = report;
  EXPECT_TRUE(report.converged()) << report.BriefReport();
  EXPECT_EQ(x.row(0), head.transpose());
  EXPECT_LE(MaxRelativeLengthError(Chain{x, lengths}), 1e-12);
  EXPECT_GE(report.moving_points, 1);
  EXPECT_LE(report.moving_points, n);
  for (int j = 1; j <= n; ++j) {
    if (j > report.moving_points) {
      EXPECT_EQ(x.row(j), old_points.row(j)) << "point " << j << " should be still";
    } else {
      EXPECT_GT((x.row(j) - old_points.row(j)).norm(), 0.0) << "point " << j << " should move";
    }
  }
  const double best = Metric(w, lengths, old_points, x);
  EXPECT_NEAR(report.objective, best, 1e-12 * (1.0 + best));
  std::normal_distribution<double> normal(0.0, 1.0);
  double worst_gain = 0.0;
  for (const double scale : {1e-2, 1e-4, 1e-6}) {
    for (int trial = 0; trial < 60; ++trial) {
      Points y = x;
      for (int j = 1; j <= n; ++j) {
        for (Eigen::Index k = 0; k < x.cols(); ++k)
          y(j, k) += scale * lengths.minCoeff() * normal(*rng);
      }
      if (!Project(lengths, &y)) continue;
      worst_gain = std::fmax(worst_gain, best - Metric(w, lengths, old_points, y));
    }
  }
  EXPECT_LE(worst_gain, 1e-13 * (1.0 + best)) << "a feasible perturbation lowers the metric";
  return x;
}

TEST(OverallL2Test, GradientAndHessianMatchFiniteDifferencesAwayFromTheKink) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (const int dim : {2, 3}) {
    const Points old_points = CurvedPoints(dim, 6, 1.0, 0.5);
    const Eigen::VectorXd lengths = LengthsOf(old_points);
    Points x = old_points;
    for (Eigen::Index j = 0; j < x.rows(); ++j) {
      for (int k = 0; k < dim; ++k) x(j, k) += 0.1 * uniform(rng);
    }
    for (const ObjectiveWeights& w :
         {L2Weights(1, 0, 0, 0), L2Weights(0, 1, 0, 0), L2Weights(0.5, 2, 1, 0.3)}) {
      Eigen::VectorXd g;
      Eigen::MatrixXd h;
      const double f = OverallObjective(w, lengths, old_points, x, &g, &h);
      EXPECT_NEAR(f, Metric(w, lengths, old_points, x), 1e-14 * f);
      const double step = 1e-6;
      for (int col = 0; col < g.size(); ++col) {
        Points plus = x, minus = x;
        plus(1 + col / dim, col % dim) += step;
        minus(1 + col / dim, col % dim) -= step;
        Eigen::VectorXd gp, gm;
        const double fp = OverallObjective(w, lengths, old_points, plus, &gp);
        const double fm = OverallObjective(w, lengths, old_points, minus, &gm);
        EXPECT_NEAR((fp - fm) / (2 * step), g[col], 1e-7 * (1.0 + g.cwiseAbs().maxCoeff()));
        EXPECT_LE(((gp - gm) / (2 * step) - h.col(col)).cwiseAbs().maxCoeff(),
                  1e-6 * (1.0 + h.cwiseAbs().maxCoeff()));
      }
    }
  }
}

// At a still point the L2 term contributes the subgradient 0 and no curvature.
TEST(OverallL2Test, StillPointContributesTheZeroSubgradient) {
  const Points old_points = CurvedPoints(2, 3, 1.0, 0.5);
  const Eigen::VectorXd lengths = LengthsOf(old_points);
  Eigen::VectorXd g;
  Eigen::MatrixXd h;
  EXPECT_EQ(OverallObjective(L2Weights(1, 1, 0, 0), lengths, old_points, old_points, &g, &h), 0.0);
  EXPECT_EQ(g.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(h.cwiseAbs().maxCoeff(), 0.0);
}

TEST(OverallL2Test, NoFeasiblePerturbationImprovesTheReturnedConfiguration) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (const int dim : {2, 3}) {
    for (const int links : {1, 2, 5, 12, 30}) {
      for (int trial = 0; trial < 5; ++trial) {
        const Points old_points = CurvedPoints(dim, links, 1.0, 0.1 + 0.15 * trial);
        const Eigen::VectorXd lengths = LengthsOf(old_points);
        Eigen::VectorXd head = old_points.row(0).transpose();
        const double size = std::vector<double>{0.02, 0.1, 0.4, 0.8, 0.3}[trial];
        for (int k = 0; k < dim; ++k) head[k] += size * uniform(rng);
        for (const ObjectiveWeights& w : {L2Weights(1, 0, 0, 0), L2Weights(0, 1, 0, 0),
                                          L2Weights(1, 0, 1, 0), L2Weights(1, 0, 0, 0.5)}) {
          SCOPED_TRACE(std::to_string(dim) + "D, " + std::to_string(links) + " links, trial " +
                       std::to_string(trial) + ", weights l2 " + std::to_string(w.l2) +
                       " l2_weighted " + std::to_string(w.l2_weighted) + " squared " +
                       std::to_string(w.squared) + " rotation " + std::to_string(w.rotation));
          SolveAndCheck(w, lengths, old_points, head, &rng);
        }
      }
    }
  }
}

// Section 5.1's parabola, y = x^2 in 20 links of 0.25 pulled 0.7 at 45 degrees: under the L2
// metric few points move and the rest stay exactly still; under the squared metric all move.
TEST(OverallL2Test, MinimizerIsSparse) {
  std::mt19937 rng(5);
  const Points p = scenes::PaperParabolaByBisection();
  const Eigen::VectorXd lengths = LengthsOf(p);
  for (const double pull : {0.14, 0.7}) {
    const Eigen::Vector2d head = scenes::PaperPull(pull);  // from the vertex, at the origin
    OverallReport report;
    SolveAndCheck(L2Weights(1, 0, 0, 0), lengths, p, head, &rng, &report);
    EXPECT_LE(report.moving_points, 3) << "pull " << pull;
    OverallOptions squared;
    Chain moved{p, lengths};
    const Points& x = moved.points;
    const OverallReport dense = OverallStep(head, squared, &moved);
    EXPECT_EQ(dense.moving_points, 20);
    for (int j = 1; j <= 20; ++j) EXPECT_NE(x.row(j), p.row(j)) << "squared metric, point " << j;
  }
}

// One link: the nearest point of the circle around the new head, the follow-the-leader step.
TEST(OverallL2Test, OneLinkIsTheNearestPointOfTheCircle) {
  Points p(2, 2);
  p << 0.0, 0.0, 1.0, 0.0;
  const Eigen::VectorXd lengths = Eigen::VectorXd::Ones(1);
  const Eigen::Vector2d head(-0.3, 0.4);
  OverallOptions options;
  options.weights = L2Weights(1, 0, 0, 0);
  Chain moved{p, lengths};
  ASSERT_TRUE(OverallStep(head, options, &moved).converged());
  p = moved.points;
  const Eigen::Vector2d expected = head + (Eigen::Vector2d(1.0, 0.0) - head).normalized();
  EXPECT_NEAR((p.row(1).transpose() - expected).norm(), 0.0, 1e-15);
}

// A straight chain pulled away along its axis: no point can stay (each still point would have to
// be farther from the head than the links before it reach), so all translate.
TEST(OverallL2Test, StraightPullTranslatesTheChain) {
  const Points p = MakeLine({Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), 5, 0.5});
  const Eigen::VectorXd lengths = LengthsOf(p);
  const Eigen::Vector3d head(-0.2, 0.0, 0.0);
  OverallOptions options;
  options.weights = L2Weights(1, 0, 0, 0);
  Chain moved{p, lengths};
  const Points& x = moved.points;
  const OverallReport report = OverallStep(head, options, &moved);
  ASSERT_TRUE(report.converged()) << report.BriefReport();
  EXPECT_EQ(report.moving_points, 5);
  for (int i = 1; i <= 5; ++i) EXPECT_NEAR(x(i, 0), 0.5 * i - 0.2, 1e-14);
  EXPECT_NEAR(report.objective, 5 * 0.2, 1e-13);
}

// The friction law worked out by hand. Chain (0,0), (1,0), then links at angle phi; the head is
// pulled a little along -x. If only point 1 moves, it goes (-d, d cot phi) (it keeps both its
// links' lengths), and its balance w u_1 + lambda_1 e_1 - lambda_2 e_2 = 0 needs the pull
// lambda_2 = cot phi on point 2. With plain L2 weights (1 each), point 2 alone holds a pull of
// at most 1, so it stays for phi above 45 degrees; with two more links straight after it, the
// tail holds 1 + 2 = 3 along the line, so point 2 stays above atan(1/3) = 18.4 degrees.
TEST(OverallL2Test, StillPointsHoldThePullOfTheirFrictionAndNoMore) {
  struct Case {
    int tail_links;  // links after the first, all along phi
    double phi_degrees;
    bool point2_still;
  };
  std::mt19937 rng(8);
  for (const Case c :
       {Case{1, 35.0, false}, Case{1, 55.0, true}, Case{3, 14.0, false}, Case{3, 23.0, true}}) {
    const double phi = c.phi_degrees * M_PI / 180.0;
    const int n = 1 + c.tail_links;
    Points p(n + 1, 2);
    p.row(0) << 0.0, 0.0;
    p.row(1) << 1.0, 0.0;
    for (int i = 2; i <= n; ++i)
      p.row(i) = p.row(i - 1) + Eigen::RowVector2d(std::cos(phi), std::sin(phi));
    const Eigen::VectorXd lengths = LengthsOf(p);
    const Eigen::Vector2d head(-1e-3, 0.0);
    OverallReport report;
    const Points x = SolveAndCheck(L2Weights(1, 0, 0, 0), lengths, p, head, &rng, &report);
    SCOPED_TRACE("phi " + std::to_string(c.phi_degrees) + ", " + std::to_string(n) + " links");
    if (c.point2_still) {
      EXPECT_EQ(report.moving_points, 1);
      // Point 1 where both its links reach: (about (-d, d cot phi), as above).
      const Eigen::Vector2d a2 = p.row(2).transpose();
      const Eigen::Vector2d mid = 0.5 * (head + a2), along = (a2 - head).normalized();
      const double half = 0.5 * (a2 - head).norm();
      const Eigen::Vector2d expected =
          mid + std::sqrt(1.0 - half * half) * Eigen::Vector2d(along.y(), -along.x());
      EXPECT_NEAR((x.row(1).transpose() - expected).norm(), 0.0, 1e-14);
      EXPECT_NEAR(x(1, 1), 1e-3 / std::tan(phi), 1e-4);
    } else {
      EXPECT_GE(report.moving_points, 2);
    }
  }
}

TEST(OverallL2Test, StillHeadLeavesTheChainInPlace) {
  const Points p = CurvedPoints(3, 4, 1.0, 0.4);
  OverallOptions options;
  options.weights = L2Weights(1, 0, 0, 0);
  Chain moved{p, LengthsOf(p)};
  const Points& x = moved.points;
  const OverallReport report = OverallStep(p.row(0).transpose(), options, &moved);
  EXPECT_TRUE(report.converged());
  EXPECT_EQ(report.moving_points, 0);
  EXPECT_EQ(x, p);
}

TEST(OverallL2Test, RejectsTheCombinationWithTheJointAngleTerm) {
  const Points p = CurvedPoints(2, 4, 1.0, 0.4);
  OverallOptions options;
  options.weights = L2Weights(1, 0, 0, 0);
  options.weights.joint_angle = 1.0;
  Chain x{p, LengthsOf(p)};
  ExpectInputError([&] { OverallStep(Eigen::Vector2d(1.1, 0.1), options, &x); },
                   "weights.joint_angle", "cannot be combined with the L2 metric");
  options.weights = L2Weights(-1, 0, 0, 0);
  ExpectInputError([&] { OverallStep(Eigen::Vector2d(1.1, 0.1), options, &x); }, "weights.l2",
                   "must be a finite number >= 0");
}

}  // namespace
}  // namespace flexkin
