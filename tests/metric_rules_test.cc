// The sequential rules of the rotation and joint-angle metrics (paper Sec. 4.1, 4.2): what each
// must do, checked against independent computations, in 2D and 3D.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "flexkin/link_step.h"
#include "flexkin/propagate.h"
#include "flexkin/run.h"
#include "scenes/scenes.h"

namespace flexkin {
namespace {

using scenes::CurvedChain;

Eigen::VectorXd RandomMove(int dim, std::mt19937& rng) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::VectorXd d(dim);
  for (int k = 0; k < dim; ++k) d[k] = uniform(rng);
  return d;
}

// Minimum rotation: zero rotation is possible, so every point moves by the head's displacement,
// however the move is split.
TEST(MinRotationTest, TheChainTranslates) {
  std::mt19937 rng(4);
  for (const int dim : {2, 3}) {
    for (const int substeps : {1, 7}) {
      Chain chain = CurvedChain(dim, 12, 1.0, 0.5);
      const Points start = chain.points;
      const Eigen::VectorXd shift = 3.0 * RandomMove(dim, rng);
      MoveLeader(Method::kMinRotation, start.row(0).transpose() + shift, substeps, &chain);
      EXPECT_LE((chain.points - (start.rowwise() + shift.transpose())).cwiseAbs().maxCoeff(),
                1e-14);
      EXPECT_LE(MaxRelativeLengthError(chain), 1e-14);
    }
  }
}

// Minimum joint-angle change: the first link takes the tractrix step; behind it the chain moves
// rigidly, so every distance between points 1..n and every joint angle is unchanged.
TEST(MinJointAngleTest, FirstLinkIsTractrixAndTheRestMovesRigidly) {
  std::mt19937 rng(8);
  for (const int dim : {2, 3}) {
    for (int trial = 0; trial < 10; ++trial) {
      Chain chain = CurvedChain(dim, 9, 1.0, 0.3 + 0.05 * trial);
      const Points start = chain.points;
      const Eigen::VectorXd head = start.row(0).transpose() + RandomMove(dim, rng);
      MoveLeader(Method::kMinJointAngle, head, 1, &chain);
      const Points& x = chain.points;
      // The first link: the tractrix step of its own move.
      Eigen::VectorXd expected(dim);
      if (dim == 2) {
        expected = TractrixStep(Eigen::Vector2d(start.row(0).transpose()), Eigen::Vector2d(head),
                                Eigen::Vector2d(start.row(1).transpose()), chain.lengths[0]);
      } else {
        expected = TractrixStep(Eigen::Vector3d(start.row(0).transpose()), Eigen::Vector3d(head),
                                Eigen::Vector3d(start.row(1).transpose()), chain.lengths[0]);
      }
      EXPECT_LE((x.row(1).transpose() - expected).norm(), 1e-14);
      // Rigid: all pairwise distances of points 0..n other than those involving point 0 and
      // the first link's own direction are kept, and so are the joint angles.
      for (int i = 1; i <= 9; ++i) {
        for (int j = i + 1; j <= 9; ++j) {
          EXPECT_NEAR((x.row(i) - x.row(j)).norm(), (start.row(i) - start.row(j)).norm(), 1e-13);
        }
      }
      for (int i = 1; i < 9; ++i) {
        auto cos_angle = [&](const Points& p) {
          const Eigen::VectorXd a = (p.row(i) - p.row(i - 1)).transpose().normalized();
          const Eigen::VectorXd b = (p.row(i + 1) - p.row(i)).transpose().normalized();
          return a.dot(b);
        };
        EXPECT_NEAR(cos_angle(x), cos_angle(start), 1e-13) << "joint " << i;
      }
      EXPECT_LE(MaxRelativeLengthError(chain), 1e-14);
    }
  }
}

// In 2D the signed joint angles are kept too (no reflection), over many sub-steps.
TEST(MinJointAngleTest, PlanarSignedAnglesAreKeptOverManySteps) {
  Chain chain = CurvedChain(2, 6, 1.0, 0.4);
  const Points start = chain.points;
  for (int s = 0; s < 200; ++s) {
    const Eigen::Vector2d target =
        chain.points.row(0).transpose() + Eigen::Vector2d(-0.02, 0.01 * std::sin(0.1 * s));
    MoveLeader(Method::kMinJointAngle, target, 3, &chain);
  }
  for (int i = 1; i < 6; ++i) {
    auto turn = [&](const Points& p) {
      const Eigen::Vector2d a = (p.row(i) - p.row(i - 1)).transpose();
      const Eigen::Vector2d b = (p.row(i + 1) - p.row(i)).transpose();
      return std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
    };
    EXPECT_NEAR(turn(chain.points), turn(start), 1e-12) << "joint " << i;
  }
  EXPECT_LE(MaxRelativeLengthError(chain), 1e-14);
}

TEST(MetricRulesTest, NamesParseAndAccuracyControlIsRefused) {
  EXPECT_EQ(ParseMethod("min_rotation"), Method::kMinRotation);
  EXPECT_EQ(ParseMethod("min_joint_angle"), Method::kMinJointAngle);
  EXPECT_STREQ(MethodName(Method::kMinJointAngle), "min_joint_angle");
  RunOptions options;
  options.method = Method::kMinRotation;
  options.tolerance = 1e-6;
  const Problems problems = options.Validate();
  ASSERT_FALSE(problems.empty());
  EXPECT_EQ(problems.front().field, "tolerance");
  EXPECT_NE(problems.front().message.find("tractrix and ftl"), std::string::npos);
}

}  // namespace
}  // namespace flexkin
