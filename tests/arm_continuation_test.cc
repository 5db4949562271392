// The Newton fixed-base step's continuation along a path (ArmSolverMemory: the extrapolated start
// and the curvature probe, src/arm/solver.cc) and the planar arm's batched re-anchoring
// (src/arm/anchor.h): two passes per step on a smooth path, convergence through sharp
// corners and broken memories, and the batched atan2 / sine / cosine equal to the C library's.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "arm/internal.h"
#include "flexkin/arm.h"
#include "scenes/scenes.h"

namespace flexkin {
namespace {

using scenes::ArcArm;
using scenes::CircleOfTargets;

// Every step's reported base residual is a measured one within the tolerance.
void ExpectConverged(const ArmModel& model, const ArmTrajectory& t) {
  EXPECT_EQ(t.unreached, 0);
  for (const ArmStepReport& s : t.steps) {
    EXPECT_TRUE(s.converged);
    EXPECT_LE(s.base_error, 1e-10 * model.link_lengths.mean());
    EXPECT_LT((s.state.points.row(0).transpose() - model.base).norm(), 1e-12);
  }
}

TEST(ArmContinuation, SmoothPathTakesTwoPassesPerStep) {
  // The KDL benchmark's scene, 64 links: an arc with the end effector at ~70% of the reach
  // (turn 2.0 / 64 per joint), a circle of one link in 64 steps.
  const ArmModel model = ArcArm(2, 64, 0.0315);
  const Points path = CircleOfTargets(model, 1.0, 64);
  const ArmTrajectory t = TrackPath(model, path, ArmOptions{});
  ExpectConverged(model, t);
  int two = 0;
  for (const ArmStepReport& s : t.steps) two += s.passes <= 2 ? 1 : 0;
  std::printf("64 links, 64 steps: %lld passes, %d steps in 2 passes\n", t.total_passes, two);
  if (arm_internal::HasAvx2Fma()) {
    // Measured: 2.1 to 2.3 passes per step (the first steps, before the memory has three
    // translations, take 3).
    EXPECT_GE(two, 48);
    EXPECT_LE(t.total_passes, 2.5 * path.rows());
  } else {
    EXPECT_LE(t.total_passes, 4 * path.rows());  // no spare lane for the probe
  }
}

TEST(ArmContinuation, SharpCornersAndReversalsConverge) {
  const ArmModel model = ArcArm(2, 32, 0.06);
  const Eigen::Vector2d ee = ForwardKinematics(model, model.initial).row(32).transpose();
  // A square (corners of 90 degrees) traced in steps of 0.1, then back along its last side.
  std::vector<Eigen::Vector2d> targets;
  const Eigen::Vector2d sides[4] = {{0.1, 0.0}, {0.0, 0.1}, {-0.1, 0.0}, {0.0, -0.1}};
  Eigen::Vector2d p = ee;
  for (const Eigen::Vector2d& side : sides) {
    for (int i = 0; i < 8; ++i) targets.push_back(p += side);
  }
  for (int i = 0; i < 8; ++i) targets.push_back(p -= sides[3]);
  Points path(targets.size(), 2);
  for (size_t i = 0; i < targets.size(); ++i) path.row(i) = targets[i].transpose();
  const ArmTrajectory t = TrackPath(model, path, ArmOptions{});
  ExpectConverged(model, t);
  ArmState state = InitialState(model);
  for (int i = 0; i < path.rows(); ++i) {
    // The same step without memory reaches the same configuration.
    state.memory = ArmSolverMemory{};
    const ArmStepReport cold = ArmStep(model, state, path.row(i).transpose(), ArmOptions{});
    EXPECT_LT((cold.state.points - t.steps[i].state.points).cwiseAbs().maxCoeff(), 1e-9) << i;
    // A corner costs a few passes (the scalar sweeper's Jacobian takes passes of its own).
    EXPECT_LE(t.steps[i].passes, arm_internal::HasAvx2Fma() ? 6 : 10) << i;
    state = t.steps[i].state;
  }
}

TEST(ArmContinuation, BrokenHistoryIsIgnored) {
  const ArmModel model = ArcArm(2, 32, 0.05);
  const ArmTrajectory t = TrackPath(model, CircleOfTargets(model, 0.5, 8), ArmOptions{});
  ASSERT_EQ(t.unreached, 0);
  const ArmState& good = t.steps[6].state;
  ASSERT_EQ(good.memory.earlier_translations.cols(), 2);
  ASSERT_EQ(good.memory.move_lengths.size(), 3);
  const Eigen::VectorXd target = CircleOfTargets(model, 0.5, 8).row(7).transpose();
  const ArmStepReport reference = ArmStep(model, good, target, ArmOptions{});
  ASSERT_TRUE(reference.reached);
  std::vector<ArmSolverMemory> broken(6, good.memory);
  broken[0].earlier_translations(1, 1) = NAN;
  broken[1].move_lengths[1] = -1.0;
  broken[2].move_lengths.resize(1);
  broken[3].earlier_translations = Eigen::MatrixXd::Ones(3, 2);
  broken[4].prediction_error = Eigen::Vector2d(1e6, -1e6);
  broken[5].prediction_error = Eigen::Vector2d(NAN, 0.0);
  for (size_t i = 0; i < broken.size(); ++i) {
    ArmState state = good;
    state.memory = broken[i];
    const ArmStepReport r = ArmStep(model, state, target, ArmOptions{});
    EXPECT_TRUE(r.reached) << i << ": " << r.BriefReport();
    EXPECT_LT((r.state.points - reference.state.points).cwiseAbs().maxCoeff(), 1e-9) << i;
    EXPECT_TRUE(r.state.memory.Usable(2));
  }
}

TEST(ArmAnchor, BatchedAtan2AndSinCosEqualTheCLibrary) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coordinate(-2.0, 2.0), angle(-1000.0, 1000.0);
  const int count = 1003;  // not a multiple of the batch width
  std::vector<double> x(count), y(count), a(count);
  for (int i = 0; i < count; ++i) x[i] = coordinate(rng), y[i] = coordinate(rng), a[i] = angle(rng);
  // Edge cases: axes, signed zeros, half turns, large and huge angles (the C library's range).
  const double edges[][2] = {{0.0, 1.0},   {0.0, -1.0},   {1.0, 0.0},    {-1.0, 0.0},
                             {-0.0, -1.0}, {1e-300, 1.0}, {1.0, 1e-300}, {-1e-300, -1.0}};
  for (int i = 0; i < 8; ++i) y[i] = edges[i][0], x[i] = edges[i][1];
  const double big[] = {M_PI, -M_PI, M_PI / 2, 0.785398163397448, 1.5e6, -2e6, 1e9, 0.0};
  for (int i = 0; i < 8; ++i) a[i] = big[i];
  std::vector<double> fast(count), slow(count), fs(count), fc(count), ss(count), sc(count);
  arm_internal::Atan2All(y.data(), x.data(), count, fast.data());
  arm_internal::Atan2All(y.data(), x.data(), count, slow.data(), /*batched=*/false);
  arm_internal::SinCosAll(a.data(), count, fs.data(), fc.data());
  arm_internal::SinCosAll(a.data(), count, ss.data(), sc.data(), /*batched=*/false);
  double worst_atan2 = 0.0, worst_sincos = 0.0;
  for (int i = 0; i < count; ++i) {
    EXPECT_EQ(slow[i], std::atan2(y[i], x[i]));
    EXPECT_NEAR(fast[i], slow[i], 1e-15 * std::max(1.0, std::abs(slow[i]))) << y[i] << " " << x[i];
    EXPECT_NEAR(fs[i], ss[i], 1e-15) << a[i];
    EXPECT_NEAR(fc[i], sc[i], 1e-15) << a[i];
    worst_atan2 = std::max(worst_atan2, std::abs(fast[i] - slow[i]));
    worst_sincos = std::max({worst_sincos, std::abs(fs[i] - ss[i]), std::abs(fc[i] - sc[i])});
  }
  std::printf("batched vs C library: atan2 %.3g, sin/cos %.3g\n", worst_atan2, worst_sincos);
}

TEST(ArmAnchor, ReanchoringEqualsTheScalarFormulas) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> turn(-M_PI, M_PI), small(-0.3, 0.3);
  for (int links : {1, 5, 128, 515}) {
    ArmModel model = StraightArm(2, links, 1.0);
    for (int j = 0; j < links; ++j) model.link_lengths[j] = 0.5 + 0.01 * (j % 7);
    model.base = Eigen::Vector2d(0.3, -1.2);
    model.base_direction = Eigen::Vector2d(-0.4, 0.9);
    JointAngles angles;
    angles.angle.resize(links);
    for (int j = 0; j < links; ++j) angles.angle[j] = links < 10 ? turn(rng) : small(rng);
    // The scalar formulas (the C library's cos, sin and atan2, the same sums).
    Points reference(links + 1, 2);
    reference.row(0) = model.base.transpose();
    double heading = std::atan2(0.9, -0.4);
    for (int j = 0; j < links; ++j) {
      heading += angles.angle[j];
      reference(j + 1, 0) = reference(j, 0) + model.link_lengths[j] * std::cos(heading);
      reference(j + 1, 1) = reference(j, 1) + model.link_lengths[j] * std::sin(heading);
    }
    const Points points = ForwardKinematics(model, angles);
    EXPECT_LT((points - reference).cwiseAbs().maxCoeff(), 1e-14 * links) << links;
    const JointAngles back = JointAnglesFromPoints(model, reference);
    Eigen::VectorXd scalar(links);
    heading = std::atan2(0.9, -0.4);
    for (int j = 0; j < links; ++j) {
      const double theta = std::remainder(
          std::atan2(reference(j + 1, 1) - reference(j, 1), reference(j + 1, 0) - reference(j, 0)) -
              heading,
          2.0 * M_PI);
      scalar[j] = theta;
      heading += theta;
    }
    EXPECT_LT((back.angle - scalar).cwiseAbs().maxCoeff(), 1e-14) << links;
    EXPECT_LT((back.angle - angles.angle).cwiseAbs().maxCoeff(), 1e-12) << links;
    // The round trip keeps every link's length to rounding.
    const Points again = ForwardKinematics(model, back);
    for (int j = 0; j < links; ++j) {
      EXPECT_NEAR((again.row(j + 1) - again.row(j)).norm(), model.link_lengths[j], 1e-14);
    }
  }
}

}  // namespace
}  // namespace flexkin
