// The fixed-base arm (include/flexkin/arm.h): kinematics, the solver's invariants, limits,
// unreachable targets and bad input.
#include "flexkin/arm.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "flexkin/error.h"

namespace flexkin {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A gently curled arm: every joint turned by `turn` (planar) or bent by `turn` about a slowly
// turning azimuth (spatial).
ArmModel CurledArm(int dim, int links, double turn) {
  ArmModel model = StraightArm(dim, links, 1.0);
  model.initial.angle.setConstant(dim == 2 ? turn : std::abs(turn));
  if (dim == 3) {
    for (int j = 0; j < links; ++j) model.initial.azimuth[j] = 0.3 * j - kPi * std::floor(0.3 * j / kPi);
  }
  return model;
}

double MaxLengthError(const ArmModel& model, const Points& p) {
  double worst = 0.0;
  for (int k = 0; k < model.num_links(); ++k) {
    const double l = (p.row(k + 1) - p.row(k)).norm();
    worst = std::max(worst, std::abs(l - model.link_lengths[k]) / model.link_lengths[k]);
  }
  return worst;
}

TEST(ArmKinematics, ForwardOfInverseReproducesPointsPlanarAndSpatial) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-2.5, 2.5), bend(0.0, 2.5), len(0.2, 2.0);
  for (int dim : {2, 3}) {
    for (int links : {1, 2, 16, 128}) {
      ArmModel model = StraightArm(dim, links, 1.0);
      for (int k = 0; k < links; ++k) model.link_lengths[k] = len(rng);
      model.base = Eigen::VectorXd::Constant(dim, 0.5);
      model.base_direction = Eigen::VectorXd::Constant(dim, -1.0);
      JointAngles a;
      a.angle.resize(links);
      for (int k = 0; k < links; ++k) a.angle[k] = dim == 2 ? angle(rng) : bend(rng);
      if (dim == 3) {
        a.azimuth.resize(links);
        for (int k = 0; k < links; ++k) a.azimuth[k] = angle(rng);
      }
      const Points p = ForwardKinematics(model, a);
      EXPECT_LT(MaxLengthError(model, p), 1e-14);
      EXPECT_EQ((p.row(0).transpose() - model.base).norm(), 0.0);
      const JointAngles back = JointAnglesFromPoints(model, p);
      EXPECT_LT((back.angle - a.angle).cwiseAbs().maxCoeff(), 1e-9) << dim << " " << links;
      const Points again = ForwardKinematics(model, back);
      EXPECT_LT((again - p).cwiseAbs().maxCoeff(), 1e-12) << dim << " " << links;
    }
  }
}

TEST(ArmKinematics, QuaternionsAreUnitAndTurnTheLinkDirection) {
  const ArmModel model = CurledArm(3, 6, 0.4);
  const Points p = ForwardKinematics(model, model.initial);
  const Eigen::MatrixXd q = JointQuaternions(model, model.initial);
  ASSERT_EQ(q.rows(), 6);
  for (int j = 0; j < 6; ++j) {
    EXPECT_NEAR(q.row(j).norm(), 1.0, 1e-15);
    EXPECT_EQ(q(j, 1), 0.0);  // no twist: the axis is perpendicular to the link (x)
    EXPECT_NEAR(2.0 * std::acos(q(j, 0)), model.initial.angle[j], 1e-12);
  }
  // Bend angles are the angles between consecutive link directions.
  for (int j = 1; j < 6; ++j) {
    const Eigen::Vector3d a = (p.row(j) - p.row(j - 1)).transpose().normalized();
    const Eigen::Vector3d b = (p.row(j + 1) - p.row(j)).transpose().normalized();
    EXPECT_NEAR(std::acos(std::clamp(a.dot(b), -1.0, 1.0)), 0.4, 1e-7);
  }
}

TEST(ArmKinematics, PlanarAnglesAreCounterClockwise) {
  ArmModel model = StraightArm(2, 2, 1.0);
  model.initial.angle << kPi / 2, -kPi / 2;
  const Points p = ForwardKinematics(model, model.initial);
  EXPECT_NEAR(p(1, 0), 0.0, 1e-15);
  EXPECT_NEAR(p(1, 1), 1.0, 1e-15);
  EXPECT_NEAR(p(2, 0), 1.0, 1e-15);
  EXPECT_NEAR(p(2, 1), 1.0, 1e-15);
}

}  // namespace
}  // namespace flexkin
