// The overall (whole-curve) optimization of one step: derivatives against finite differences,
// first- and second-order optimality checked with dense linear algebra independent of the
// solver, known minimizers, the weighted metric moving continuously, and every failure reported.

#include "flexkin/overall.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <vector>

#include "flexkin/link_step.h"
#include "scenes/scenes.h"
#include "test_util.h"

namespace flexkin {
namespace {

using scenes::CurvedPoints;
using test_util::ExpectInputError;
using test_util::LengthsOf;

// The weight mixes tested: each term alone and mixtures (the joint-angle term only in 2D).
std::vector<ObjectiveWeights> Mixes(int dim) {
  std::vector<ObjectiveWeights> mixes = {
      {1, 0, 0, 0}, {0, 1, 0, 0}, {1, 0, 1, 0}, {0.3, 0.5, 2, 0}};
  if (dim == 2) {
    mixes.push_back({1, 0, 0, 1});
    mixes.push_back({0.2, 0.1, 0.5, 3});
  }
  return mixes;
}

TEST(OverallObjectiveTest, GradientAndHessianMatchFiniteDifferences) {
  std::mt19937 rng(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (const int dim : {2, 3}) {
    for (const double size : {1e-8, 0.1, 1.0}) {  // tiny, moderate and large displacements
      const Points old_points = CurvedPoints(dim, 6, 1.0, 0.5);
      const Eigen::VectorXd lengths = LengthsOf(old_points);
      Points x = old_points;
      for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] += size * normal(rng);
      for (const ObjectiveWeights& w : Mixes(dim)) {
        Eigen::VectorXd g;
        Eigen::MatrixXd h;
        OverallObjective(w, lengths, old_points, x, &g, &h);
        EXPECT_LE((h - h.transpose()).cwiseAbs().maxCoeff(), 1e-12 * (1.0 + h.norm()));
        const double step = 1e-6;
        double worst_g = 0.0, worst_h = 0.0;
        for (int j = 1; j < x.rows(); ++j) {
          for (int k = 0; k < dim; ++k) {
            Points plus = x, minus = x;
            plus(j, k) += step;
            minus(j, k) -= step;
            Eigen::VectorXd gp, gm;
            const double fp = OverallObjective(w, lengths, old_points, plus, &gp);
            const double fm = OverallObjective(w, lengths, old_points, minus, &gm);
            const int col = (j - 1) * dim + k;
            worst_g = std::fmax(worst_g, std::fabs((fp - fm) / (2 * step) - g[col]));
            worst_h =
                std::fmax(worst_h, ((gp - gm) / (2 * step) - h.col(col)).cwiseAbs().maxCoeff());
          }
        }
        EXPECT_LE(worst_g, 1e-7 * (1.0 + g.cwiseAbs().maxCoeff())) << dim << "D, size " << size;
        EXPECT_LE(worst_h, 1e-6 * (1.0 + h.cwiseAbs().maxCoeff())) << dim << "D, size " << size;
      }
    }
  }
}

// First- and second-order conditions at a returned configuration, computed here with dense
// linear algebra: the least-squares multipliers leave a Lagrangian gradient of (relative) size
// `first_order`; the Lagrangian's Hessian on the tangent space of the constraints has smallest
// eigenvalue `second_order` (> 0: a strict local minimizer).
struct Optimality {
  double first_order = 0.0;
  double second_order = 0.0;
};

Optimality CheckOptimality(const ObjectiveWeights& w, const Eigen::VectorXd& lengths,
                           const Points& old_points, const Points& x) {
  const int n = static_cast<int>(lengths.size());
  const int dim = static_cast<int>(x.cols());
  Eigen::VectorXd g;
  Eigen::MatrixXd h;
  OverallObjective(w, lengths, old_points, x, &g, &h);
  // Constraint gradients: c_i = (|x_i - x_{i-1}|^2 - L_i^2) / (2 L_i).
  Eigen::MatrixXd jac = Eigen::MatrixXd::Zero(n, n * dim);
  for (int i = 1; i <= n; ++i) {
    const Eigen::VectorXd e = (x.row(i) - x.row(i - 1)).transpose() / lengths[i - 1];
    jac.block(i - 1, (i - 1) * dim, 1, dim) = e.transpose();
    if (i > 1) jac.block(i - 1, (i - 2) * dim, 1, dim) = -e.transpose();
  }
  const Eigen::VectorXd lambda = jac.transpose().colPivHouseholderQr().solve(-g);
  Optimality result;
  result.first_order = (g + jac.transpose() * lambda).cwiseAbs().maxCoeff() /
                       std::fmax(g.cwiseAbs().maxCoeff(), 1e-300);
  Eigen::MatrixXd lagrangian_hessian = h;
  for (int i = 1; i <= n; ++i) {
    const double s = lambda[i - 1] / lengths[i - 1];
    const Eigen::MatrixXd id = Eigen::MatrixXd::Identity(dim, dim);
    lagrangian_hessian.block((i - 1) * dim, (i - 1) * dim, dim, dim) += s * id;
    if (i > 1) {
      lagrangian_hessian.block((i - 2) * dim, (i - 2) * dim, dim, dim) += s * id;
      lagrangian_hessian.block((i - 1) * dim, (i - 2) * dim, dim, dim) -= s * id;
      lagrangian_hessian.block((i - 2) * dim, (i - 1) * dim, dim, dim) -= s * id;
    }
  }
  const Eigen::MatrixXd z = Eigen::FullPivLU<Eigen::MatrixXd>(jac).kernel();
  Eigen::MatrixXd q =
      z.householderQr().householderQ() * Eigen::MatrixXd::Identity(z.rows(), z.cols());
  const Eigen::MatrixXd reduced = q.transpose() * lagrangian_hessian * q;
  result.second_order =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(reduced).eigenvalues().minCoeff();
  return result;
}

TEST(OverallStepTest, ReturnsAStrictLocalMinimizerThatKeepsEveryLength) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (const int dim : {2, 3}) {
    for (const int links : {1, 2, 5, 20}) {
      for (int trial = 0; trial < 4; ++trial) {
        const Points old_points = CurvedPoints(dim, links, 1.0, 0.4 + 0.2 * trial);
        const Eigen::VectorXd lengths = LengthsOf(old_points);
        Eigen::VectorXd head = old_points.row(0).transpose();
        for (int k = 0; k < dim; ++k) head[k] += 0.6 * uniform(rng);
        for (const ObjectiveWeights& w : Mixes(dim)) {
          SCOPED_TRACE(std::to_string(dim) + "D, " + std::to_string(links) + " links, trial " +
                       std::to_string(trial) + ", weights " + std::to_string(w.squared) + " " +
                       std::to_string(w.squared_weighted) + " " + std::to_string(w.rotation) + " " +
                       std::to_string(w.joint_angle));
          OverallOptions options;
          options.weights = w;
          Chain moved{old_points, lengths};
          const Points& x = moved.points;
          const OverallReport report = OverallStep(head, options, &moved);
          ASSERT_TRUE(report.converged()) << report.BriefReport();
          EXPECT_EQ(x.row(0), head.transpose());
          Chain chain{x, lengths};
          EXPECT_LE(MaxRelativeLengthError(chain), 1e-12);
          EXPECT_LE(report.constraint_violation, 1e-12);
          const Optimality check = CheckOptimality(w, lengths, old_points, x);
          EXPECT_LE(check.first_order, 1e-8)
              << dim << "D " << links << " links: " << report.BriefReport();
          if (links > 1 || w.rotation + w.squared + w.squared_weighted > 0) {
            EXPECT_GT(check.second_order, 0.0) << dim << "D " << links << " links";
          }
          EXPECT_NEAR(report.objective, OverallObjective(w, lengths, old_points, x),
                      1e-12 * (1.0 + report.objective));
        }
      }
    }
  }
}

// One link with the squared metric: the nearest point of the circle (sphere) around the new head,
// which is exactly the follow-the-leader step.
TEST(OverallStepTest, OneLinkSquaredIsTheFollowTheLeaderStep) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> uniform(-2.0, 2.0);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector3d head_old(uniform(rng), uniform(rng), uniform(rng));
    const Eigen::Vector3d tail(uniform(rng), uniform(rng), uniform(rng));
    const Eigen::Vector3d head_new(uniform(rng), uniform(rng), uniform(rng));
    Points p(2, 3);
    p.row(0) = head_old.transpose();
    p.row(1) = tail.transpose();
    const Eigen::VectorXd lengths = LengthsOf(p);
    OverallOptions options;
    Chain moved{p, lengths};
    const Points& x = moved.points;
    const OverallReport report = OverallStep(head_new, options, &moved);
    ASSERT_TRUE(report.converged()) << report.BriefReport();
    const Eigen::Vector3d expected = FollowTheLeaderStep(head_old, head_new, tail, lengths[0]);
    // The projection is ill-conditioned when the old tail is near the new head (its direction
    // from the head decides everything): the reduced Hessian is 2 |tail - head_new| / L.
    const double conditioning = std::fmax(1.0, lengths[0] / (tail - head_new).norm());
    EXPECT_LE((x.row(1).transpose() - expected).norm(),
              1e-12 * (1.0 + expected.norm()) * conditioning);
  }
}

// Body rotation alone: nothing needs to rotate, so the whole chain translates (paper Fig. 8).
TEST(OverallStepTest, RotationAloneTranslatesTheChain) {
  for (const int dim : {2, 3}) {
    const Points old_points = CurvedPoints(dim, 12, 1.0, 0.5);
    const Eigen::VectorXd lengths = LengthsOf(old_points);
    Eigen::VectorXd shift = Eigen::VectorXd::Zero(dim);
    shift[0] = -0.3;
    shift[1] = 0.2;
    OverallOptions options;
    options.weights = {0, 0, 1, 0};
    Chain moved{old_points, lengths};
    const Points& x = moved.points;
    const OverallReport report =
        OverallStep(old_points.row(0).transpose() + shift, options, &moved);
    ASSERT_TRUE(report.converged()) << report.BriefReport();
    EXPECT_LE((x - (old_points.rowwise() + shift.transpose())).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LE(report.objective, 1e-24);
  }
}

// A head that does not move: the old configuration is optimal for every metric.
TEST(OverallStepTest, StillHeadLeavesTheChainInPlace) {
  for (const int dim : {2, 3}) {
    const Points old_points = CurvedPoints(dim, 10, 1.0, 0.5);
    const Eigen::VectorXd lengths = LengthsOf(old_points);
    for (const ObjectiveWeights& w : Mixes(dim)) {
      OverallOptions options;
      options.weights = w;
      Chain moved{old_points, lengths};
      const Points& x = moved.points;
      const OverallReport report = OverallStep(old_points.row(0).transpose(), options, &moved);
      ASSERT_TRUE(report.converged()) << report.BriefReport();
      EXPECT_LE((x - old_points).cwiseAbs().maxCoeff(), 1e-14);
    }
  }
}

// squared + t rotation: the minimizer moves continuously with t, from the squared-only minimizer
// (t -> 0) to the pure translation (t -> infinity), and the rotation of the chain falls as t grows.
TEST(OverallStepTest, WeightedMetricMovesContinuouslyBetweenItsLimits) {
  const Points old_points = CurvedPoints(2, 15, 1.0, 0.4);
  const Eigen::VectorXd lengths = LengthsOf(old_points);
  const Eigen::VectorXd head = old_points.row(0).transpose() + Eigen::Vector2d(-0.4, 0.3);
  auto solve = [&](double squared, double rotation) {
    OverallOptions options;
    options.weights = {squared, 0, rotation, 0};
    Chain moved{old_points, lengths};
    const OverallReport report = OverallStep(head, options, &moved);
    EXPECT_TRUE(report.converged()) << report.BriefReport();
    return moved.points;
  };
  const Points rope = solve(1, 0);
  const Points rod = old_points.rowwise() + (head - old_points.row(0).transpose()).transpose();
  auto rotation_of = [&](const Points& x) {
    return OverallObjective({0, 0, 1, 0}, lengths, old_points, x);
  };
  Points previous = rope;
  double previous_rotation = rotation_of(rope);
  for (double t = 1e-4; t <= 1e4; t *= std::pow(2.0, 0.25)) {
    const Points x = solve(1, t);
    // Continuity: a step of 2^(1/4) in t moves no point by much.
    EXPECT_LE((x - previous).rowwise().norm().maxCoeff(), 0.05) << "t = " << t;
    const double rotation = rotation_of(x);
    EXPECT_LE(rotation, previous_rotation * (1 + 1e-9) + 1e-15) << "t = " << t;
    previous = x;
    previous_rotation = rotation;
  }
  EXPECT_LE((solve(1, 1e-8) - rope).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LE((solve(1, 1e8) - rod).cwiseAbs().maxCoeff(), 1e-6);
}

// A workspace kept from step to step holds what a solve may keep (the KKT storage, the metric's
// Hessian terms summed once per solve where they are constant): steps under other weights, on
// other chains, in between change nothing, to the last bit, against a fresh workspace.
TEST(OverallStepTest, AKeptWorkspaceGivesTheResultOfAFreshOne) {
  OverallWorkspace kept;
  for (const int dim : {2, 3}) {
    for (const int links : {20, 3, 9}) {
      const Points old_points = CurvedPoints(dim, links, 1.0, 0.5);
      const Eigen::VectorXd lengths = LengthsOf(old_points);
      std::vector<ObjectiveWeights> mixes = Mixes(dim);
      mixes.push_back({0, 0, 0, 0, 1, 0});        // L2: the active set's solver
      mixes.push_back({0.5, 0, 0.2, 0, 0, 0.5});  // L2 weighted, with smooth terms
      for (const ObjectiveWeights& w : mixes) {
        for (const double move : {0.05, 0.9}) {  // one sub-step, and several
          SCOPED_TRACE(std::to_string(dim) + "D, " + std::to_string(links) + " links, move " +
                       std::to_string(move));
          OverallOptions options;
          options.weights = w;
          Eigen::VectorXd head = old_points.row(0).transpose();
          head[0] -= move;
          head[1] += 0.5 * move;
          Chain with_kept{old_points, lengths}, with_fresh{old_points, lengths};
          const OverallReport a = OverallStep(head, options, &with_kept, &kept);
          OverallWorkspace fresh;
          const OverallReport b = OverallStep(head, options, &with_fresh, &fresh);
          ASSERT_TRUE(a.converged()) << a.BriefReport();
          EXPECT_EQ(a.iterations, b.iterations);
          EXPECT_EQ(a.start, b.start);
          EXPECT_EQ(a.objective, b.objective);
          EXPECT_EQ(a.optimality, b.optimality);
          EXPECT_TRUE(with_kept.points == with_fresh.points);
        }
      }
    }
  }
}

TEST(OverallStepTest, ReportsInsteadOfFailingSilently) {
  const Points old_points = CurvedPoints(2, 30, 1.0, 0.4);
  const Eigen::VectorXd lengths = LengthsOf(old_points);
  OverallOptions options;
  options.max_iterations = 1;
  Chain moved{old_points, lengths};
  const Points& x = moved.points;
  const OverallReport report =
      OverallStep(old_points.row(0).transpose() + Eigen::Vector2d(-2.0, 1.0), options, &moved);
  EXPECT_EQ(report.status, OverallStatus::kMaxIterations);
  EXPECT_FALSE(report.converged());
  EXPECT_NE(report.BriefReport().find("max_iterations"), std::string::npos);
  EXPECT_TRUE(x.allFinite());
}

TEST(OverallStepTest, RejectsInvalidInputNamingTheField) {
  const Points p2 = CurvedPoints(2, 4, 1.0, 0.4);
  const Points p3 = CurvedPoints(3, 4, 1.0, 0.4);
  const Eigen::VectorXd lengths = LengthsOf(p2);
  OverallOptions options;
  auto step = [&](const Points& p, const Eigen::VectorXd& head, const OverallOptions& o) {
    Chain x{p, LengthsOf(p)};
    OverallStep(head, o, &x);
  };
  ExpectInputError([&] { step(p2, Eigen::Vector3d(0, 0, 0), options); }, "head");
  ExpectInputError([&] { step(p2, Eigen::Vector2d(NAN, 0), options); }, "head[0]");
  OverallOptions bad = options;
  bad.weights = {0, 0, 0, 0};
  ExpectInputError([&] { step(p2, Eigen::Vector2d(0, 0), bad); }, "weights");
  bad.weights = {-1, 0, 0, 0};
  ExpectInputError([&] { step(p2, Eigen::Vector2d(0, 0), bad); }, "weights.squared");
  bad = options;
  bad.max_iterations = 0;
  ExpectInputError([&] { step(p2, Eigen::Vector2d(0, 0), bad); }, "max_iterations");
  bad = options;
  bad.weights = {1, 0, 0, 1};
  ExpectInputError([&] { step(p3, Eigen::Vector3d(0, 0, 0), bad); }, "weights.joint_angle");
  Chain x{p2, Eigen::VectorXd::Ones(2)};
  ExpectInputError([&] { OverallStep(Eigen::Vector2d(0, 0), options, &x); }, "points.lengths");
}

}  // namespace
}  // namespace flexkin
