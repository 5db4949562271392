// Tests of leader motions: a split pull ends exactly at start + pull in equal steps; a resampled
// path has no step longer than max_step, visits every vertex exactly, and takes the fewest steps
// that allow that.
#include "flexkin/leader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "flexkin/error.h"
#include "test_util.h"

namespace flexkin {
namespace {

using test_util::ExpectInputError;

Points Rows(std::initializer_list<std::initializer_list<double>> rows) {
  Points p(rows.size(), rows.begin()->size());
  Eigen::Index i = 0;
  for (const auto& row : rows) {
    Eigen::Index k = 0;
    for (double x : row) p(i, k++) = x;
    ++i;
  }
  return p;
}

// Checks the properties of ResamplePath(start, path, max_step) and returns the targets.
Points CheckResample(const Eigen::VectorXd& start, const Points& path, double max_step) {
  const Points t = ResamplePath(start, path, max_step);
  EXPECT_EQ(t.cols(), path.cols());
  // No step longer than max_step (with the documented 1e-12 relative slack).
  Eigen::VectorXd from = start;
  for (Eigen::Index s = 0; s < t.rows(); ++s) {
    EXPECT_LE((t.row(s).transpose() - from).norm(), max_step * (1 + 1e-12)) << "step " << s;
    from = t.row(s).transpose();
  }
  // Every vertex is a target, bit for bit, in order, after the right number of steps: the
  // fewest steps of at most max_step, ceil(length / max_step).
  Eigen::Index row = -1;
  from = start;
  for (Eigen::Index i = 0; i < path.rows(); ++i) {
    const double length = (path.row(i).transpose() - from).norm();
    row += static_cast<Eigen::Index>(std::ceil(length / max_step * (1 - 1e-12)));
    if (length > 0.0) {
      EXPECT_GE(row, 0);
      if (row >= 0 && row < t.rows()) EXPECT_EQ(t.row(row), path.row(i)) << "vertex " << i;
    }
    from = path.row(i).transpose();
  }
  EXPECT_EQ(row + 1, t.rows());
  return t;
}

TEST(LeaderSplitPullTest, EqualStepsEndingExactlyAtStartPlusPull) {
  const Eigen::Vector2d start(0.3, -1.1);
  const Eigen::Vector2d pull(0.7 / std::sqrt(2.0), 0.7 / std::sqrt(2.0));
  const Points t = SplitPull(start, pull, 5);
  ASSERT_EQ(t.rows(), 5);
  ASSERT_EQ(t.cols(), 2);
  EXPECT_EQ(t.row(4), (start + pull).transpose());
  Eigen::VectorXd from = start;
  for (Eigen::Index s = 0; s < 5; ++s) {
    EXPECT_NEAR((t.row(s).transpose() - from).norm(), 0.14, 1e-15) << "step " << s;
    from = t.row(s).transpose();
  }
}

TEST(LeaderSplitPullTest, OneStepIsThePullItselfAndZeroPullStaysPut) {
  const Eigen::Vector3d start(1, 2, 3), pull(-4, 0.5, 2);
  EXPECT_EQ(SplitPull(start, pull, 1).row(0), (start + pull).transpose());
  const Points still = SplitPull(start, Eigen::Vector3d::Zero(), 3);
  for (Eigen::Index s = 0; s < 3; ++s) EXPECT_EQ(still.row(s), start.transpose());
}

TEST(LeaderSplitPullTest, BadInput) {
  const Eigen::Vector2d start(0, 0), pull(1, 0);
  ExpectInputError([&] { SplitPull(start, pull, 0); }, "steps",
                   "value 0 is not valid; expected an integer from 1");
  ExpectInputError([&] { SplitPull(start, pull, kMaxLeaderSteps + 1); }, "steps", "10000000");
  ExpectInputError([&] { SplitPull(start, Eigen::Vector3d(1, 0, 0), 2); }, "pull", "expected 2");
  ExpectInputError([&] { SplitPull(start, Eigen::Vector2d(NAN, 0), 2); }, "pull[0]",
                   "not a finite number");
  ExpectInputError([&] { SplitPull(Eigen::VectorXd::Zero(1), Eigen::VectorXd::Zero(1), 2); },
                   "start", "expected 2 (planar) or 3");
}

TEST(LeaderResamplePathTest, SegmentsOfExactMultiplesTakeExactlyThatManySteps) {
  // 0.75 / 0.075 is 10.000000000000002 in doubles; it must still take 10 steps, not 11.
  const Points t = CheckResample(Eigen::Vector2d(0, 0), Rows({{0.75, 0}, {0.75, 0.75}}), 0.075);
  EXPECT_EQ(t.rows(), 20);
}

TEST(LeaderResamplePathTest, ShortSegmentsAreOneStepAndZeroSegmentsNone) {
  const Points path = Rows({{0.01, 0}, {0.01, 0}, {0.5, 0}, {0.5, 0.2}});
  const Points t = CheckResample(Eigen::Vector2d(0, 0), path, 0.1);
  // 1 step to (0.01, 0), none for the repeated vertex, ceil(0.49 / 0.1) = 5, then 2.
  EXPECT_EQ(t.rows(), 1 + 0 + 5 + 2);
}

TEST(LeaderResamplePathTest, RandomPathsKeepEveryProperty) {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> coord(-3.0, 3.0), step(1e-3, 2.0);
  for (int trial = 0; trial < 200; ++trial) {
    const int dim = 2 + trial % 2;
    Points path(1 + trial % 7, dim);
    for (Eigen::Index i = 0; i < path.rows(); ++i) {
      for (int k = 0; k < dim; ++k) path(i, k) = coord(rng);
    }
    Eigen::VectorXd start(dim);
    for (int k = 0; k < dim; ++k) start[k] = coord(rng);
    CheckResample(start, path, step(rng));
  }
}

TEST(LeaderResamplePathTest, ZeroLengthPathHasNoSteps) {
  EXPECT_EQ(ResamplePath(Eigen::Vector2d(1, 1), Rows({{1, 1}, {1, 1}}), 0.1).rows(), 0);
}

TEST(LeaderResamplePathTest, BadInput) {
  const Eigen::Vector2d start(0, 0);
  const Points path = Rows({{1, 0}});
  ExpectInputError([&] { ResamplePath(start, path, 0.0); }, "max_step",
                   "value 0 is not valid; expected a finite number > 0");
  ExpectInputError([&] { ResamplePath(start, path, -0.5); }, "max_step", "-0.5");
  ExpectInputError([&] { ResamplePath(start, path, NAN); }, "max_step", "nan");
  ExpectInputError([&] { ResamplePath(start, path, 1e-9); }, "max_step", "at most 10000000");
  ExpectInputError([&] { ResamplePath(start, Rows({{1, 0, 0}}), 0.1); }, "path", "expected 2");
  ExpectInputError(
      [&] {
        ResamplePath(start, Rows({{1, 0}, {INFINITY, 0}}), 0.1);
      },
      "path[1][0]", "not a finite number");
  ExpectInputError([&] { ResamplePath(start, Points(0, 2), 0.1); }, "path", "is empty");
}

TEST(LeaderExplicitPathTest, ReturnsTheTargetsAsGivenOrNamesTheProblem) {
  const Points path = Rows({{1, 2}, {3, 4}});
  EXPECT_EQ(ExplicitPath(path, 2), path);
  ExpectInputError([&] { ExplicitPath(path, 3, "/leader/path"); }, "/leader/path", "expected 3");
  ExpectInputError([&] { ExplicitPath(Rows({{1, NAN}}), 2); }, "path[0][1]", "not a finite");
}

}  // namespace
}  // namespace flexkin
