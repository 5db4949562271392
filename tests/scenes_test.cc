// The shared scenes (scenes/scenes.h) are what their comments say: the shapes, sizes, lengths and
// reaches that the tests and benchmarks built on them rely on.
#include "scenes/scenes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "flexkin/curves.h"

namespace flexkin::scenes {
namespace {

TEST(ScenesTest, PaperParabolaIsTwentyLinksOfAQuarterOnYEqualsXSquared) {
  const Chain paper = PaperParabola();
  ASSERT_EQ(paper.points.rows(), 21);
  ASSERT_EQ(paper.points.cols(), 2);
  EXPECT_EQ(paper.lengths, Eigen::VectorXd::Constant(20, 0.25));
  EXPECT_EQ(paper.points.row(0), Eigen::RowVector2d(0.0, 0.0));
  for (int i = 1; i <= 20; ++i) {
    EXPECT_GT(paper.points(i, 0), paper.points(i - 1, 0));
    EXPECT_EQ(paper.points(i, 1), paper.points(i, 0) * paper.points(i, 0));
    EXPECT_NEAR((paper.points.row(i) - paper.points.row(i - 1)).norm(), 0.25, 1e-14);
  }
  // The bisection sampling is the same curve to rounding.
  const Points bisection = PaperParabolaByBisection();
  ASSERT_EQ(bisection.rows(), 21);
  EXPECT_LT((bisection - paper.points).cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_NEAR(PaperPull().norm(), 0.7, 1e-15);
  EXPECT_EQ(PaperPull(0.14)[0], PaperPull(0.14)[1]);
}

TEST(ScenesTest, CurvedPointsLieOnTheirCircleWithUnequalLinks) {
  for (int dim : {2, 3}) {
    const Points p = CurvedPoints(dim, 12, 0.5, 0.4);
    ASSERT_EQ(p.rows(), 13);
    ASSERT_EQ(p.cols(), dim);
    for (int i = 0; i <= 12; ++i) {
      EXPECT_NEAR(std::hypot(p(i, 0), p(i, 1)), 0.5, 1e-15);
      EXPECT_NEAR(std::atan2(p(i, 1), p(i, 0)), std::remainder(0.4 * i, 2.0 * M_PI), 1e-14);
    }
    const Chain chain = CurvedChain(dim, 12, 0.5, 0.4);
    EXPECT_EQ(chain.points, p);
    EXPECT_NEAR(chain.lengths.mean(), 0.5 * 0.4, 0.01);
    if (dim == 3) EXPECT_GT(chain.lengths.maxCoeff() - chain.lengths.minCoeff(), 1e-4);
  }
}

TEST(ScenesTest, StraightPullsEndTheirDistanceAway) {
  const Eigen::Vector2d start(1.0, 2.0), direction(0.6, -0.8);
  const Points pull = StraightPull(start, direction, 5.0, 10);
  ASSERT_EQ(pull.rows(), 10);
  ASSERT_EQ(pull.cols(), 2);
  EXPECT_NEAR((pull.row(0).transpose() - start).norm(), 0.5, 1e-15);
  EXPECT_NEAR((pull.row(9).transpose() - start).norm(), 5.0, 1e-14);
}

TEST(ScenesTest, RandomSmoothChainsAreSmoothAndDrawnLengthsAreTheLinks) {
  std::mt19937 rng(1);
  for (int dim : {2, 3}) {
    for (double bend : {0.5, 0.6}) {
      const Chain chain = RandomSmoothChain(dim, 40, bend, &rng);
      ASSERT_EQ(chain.points.rows(), 41);
      EXPECT_EQ(chain.points.row(0).norm(), 0.0);
      EXPECT_GE(chain.lengths.minCoeff(), 0.5);
      EXPECT_LE(chain.lengths.maxCoeff(), 1.5);
      EXPECT_LE(MaxRelativeLengthError(chain), 1e-13);
      const double max_turn = std::atan(bend * std::sqrt(dim));
      for (int i = 1; i < 40; ++i) {
        const Eigen::VectorXd a = (chain.points.row(i) - chain.points.row(i - 1)).normalized();
        const Eigen::VectorXd b = (chain.points.row(i + 1) - chain.points.row(i)).normalized();
        EXPECT_LE(std::acos(std::fmin(1.0, a.dot(b))), max_turn + 1e-9) << dim << " " << i;
      }
    }
  }
  // The same seed gives the same chain.
  std::mt19937 a(7), b(7);
  EXPECT_EQ(RandomSmoothChain(3, 10, 0.6, &a).points, RandomSmoothChain(3, 10, 0.6, &b).points);
}

TEST(ScenesTest, HelixAndCoil) {
  const Chain helix = Helix(100);
  EXPECT_EQ(helix.lengths, Eigen::VectorXd::Constant(100, 0.25));
  EXPECT_NEAR(std::hypot(helix.points(100, 0), helix.points(100, 1)), 1.0, 1e-14);
  const Chain coil = Coil(50);
  ASSERT_EQ(coil.points.rows(), 51);
  EXPECT_NEAR(coil.points(50, 2), 2.5, 1e-15);
  EXPECT_NEAR(coil.lengths.mean(), 0.303, 1e-3);
}

// The continuous arc's chord is the fraction asked for; the arm, a polygon of unit links each
// turned by phi / links, reaches sin(phi / 2) / sin(phi / (2 links)): a little farther.
TEST(ScenesTest, ArcArmReachesAboutTheAskedFractionOfItsReach) {
  for (int dim : {2, 3}) {
    for (int links : {8, 128}) {
      for (double fraction : {0.3, 0.7, 0.99}) {
        const double turn = ArcTurnForReach(links, fraction);
        const double phi = turn * links;
        EXPECT_NEAR(std::sin(0.5 * phi) / (0.5 * phi), fraction, 1e-15);
        const ArmModel model = ArcArm(dim, links, turn);
        const Points p = InitialState(model).points;
        const double reach = p.row(links).norm() / links;
        EXPECT_GE(reach, fraction) << dim << " " << links;
        EXPECT_NEAR(reach, std::sin(0.5 * phi) / std::sin(0.5 * turn) / links, 1e-12)
            << dim << " " << links;
        if (dim == 3) EXPECT_EQ(p.col(2).cwiseAbs().maxCoeff(), 0.0);  // azimuth 0: in x-y
      }
    }
  }
  const ArmModel spatial = ArcArm(3, 6, 0.4, 0.2);
  EXPECT_EQ(spatial.initial.azimuth, Eigen::VectorXd::Constant(6, 0.2));
  EXPECT_EQ(CurledArm(2, 5, 0.1).initial.angle, ArcArm(2, 5, 0.1).initial.angle);
}

TEST(ScenesTest, LimitedArmsAndTheSnakeStartWithinTheirLimits) {
  for (const ArmModel& model : {RevoluteSnake(8), LimitedArm(2, 16, 0.6, 0.12),
                                LimitedArm(3, 16, 0.6, 0.12), CurledArm(3, 10, -0.1)}) {
    const ArmState start = InitialState(model);  // throws if the model is not valid
    EXPECT_TRUE(WithinLimits(model, start.angles, 0.0));
  }
}

TEST(ScenesTest, CirclesOfTargetsCloseAndKeepTheirRadius) {
  for (int dim : {2, 3}) {
    const ArmModel model = CurledArm(dim, 16, 0.05);
    const Eigen::VectorXd ee = InitialState(model).points.row(16).transpose();
    for (CircleTilt tilt : {CircleTilt::kFlat, CircleTilt::kRising, CircleTilt::kTilted45}) {
      const Points path = CircleOfTargets(model, 2.0, 40, tilt, 2);
      ASSERT_EQ(path.rows(), 40);
      ASSERT_EQ(path.cols(), dim);
      EXPECT_LT((path.row(39).transpose() - ee).norm(), 1e-13);  // back at the start
      EXPECT_LT((path.row(19).transpose() - ee).norm(), 1e-13);  // after the first turn
      // Opposite the start: two radii along -x.
      EXPECT_NEAR(path(9, 0), ee[0] - 4.0, 1e-13);
      if (dim == 2 || tilt == CircleTilt::kFlat) {
        EXPECT_NEAR((path.row(4).transpose() - ee).norm(), 2.0 * std::sqrt(2.0), 1e-13);
      }
      if (dim == 3 && tilt == CircleTilt::kTilted45) {
        EXPECT_NEAR((path.row(4).transpose() - ee).norm(), 2.0 * std::sqrt(2.0), 1e-13);
        EXPECT_NEAR(path(4, 1) - ee[1], path(4, 2) - ee[2], 1e-13);
      }
    }
  }
}

TEST(ScenesTest, SaturatingPathsAreWithinReachAndRepeatable) {
  for (int dim : {2, 3}) {
    const ArmModel model = LimitedArm(dim, 16, 0.2, 0.0);
    std::mt19937 rng(3), again(3);
    const Points path = SaturatingPath(model, 0.2, 100, &rng);
    ASSERT_EQ(path.rows(), 100);
    ASSERT_EQ(path.cols(), dim);
    EXPECT_TRUE(path.allFinite());
    EXPECT_LE(path.rowwise().norm().maxCoeff(), 16.0);
    EXPECT_EQ(SaturatingPath(model, 0.2, 100, &again), path);
  }
}

}  // namespace
}  // namespace flexkin::scenes
