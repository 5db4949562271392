// The fixed-base arm (include/flexkin/arm.h): kinematics, the solver's invariants, limits,
// unreachable targets and bad input.
#include "flexkin/arm.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "flexkin/error.h"
#include "scenes/scenes.h"

namespace flexkin {
namespace {

using scenes::CircleOfTargets;
using scenes::CircleTilt;
using scenes::CurledArm;
using scenes::RevoluteSnake;

constexpr double kPi = 3.14159265358979323846;

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

// Arms with joint axes: the forward kinematics (rotations carried as a matrix, with plane
// rotations for coordinate axes) equals the rotations composed one by one with Eigen's
// AngleAxis, for coordinate axes of either sign, general axes, links along coordinate axes and
// not, links of length 0 and prismatic joints, at random angles.
TEST(ArmKinematics, AxisArmsMatchRotationsComposedOneByOne) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto random_unit = [&] {
    Eigen::Vector3d v(u(rng), u(rng), u(rng));
    return Eigen::Vector3d(v.normalized());
  };
  const auto coordinate = [&](int k) {
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    v[k % 3] = k < 3 ? 1.0 : -1.0;
    return v;
  };
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 40;
    ArmModel model;
    model.dim = 3;
    model.base = Eigen::Vector3d(u(rng), u(rng), u(rng));
    model.base_direction = Eigen::Vector3d::UnitX();
    model.initial.angle = Eigen::VectorXd::Zero(n);
    model.link_lengths.resize(n);
    model.joint_axes.resize(n, 3);
    model.link_directions.resize(n, 3);
    model.joint_types.assign(n, JointType::kRevolute);
    for (int j = 0; j < n; ++j) {
      const int kind = static_cast<int>(rng() % 8);  // 0-5: +-x, +-y, +-z; 6, 7: general
      model.joint_axes.row(j) = (kind < 6 ? coordinate(kind) : random_unit()).transpose();
      const int rest = static_cast<int>(rng() % 8);
      model.link_directions.row(j) = (rest < 6 ? coordinate(rest) : random_unit()).transpose();
      model.link_lengths[j] = rng() % 5 == 0 ? 0.0 : 0.5 + 0.5 * (u(rng) + 1.0);
      if (rng() % 6 == 0) model.joint_types[j] = JointType::kPrismatic;
    }
    model.tip_rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, random_unit())).coeffs();
    // coeffs() is (x, y, z, w); the model wants (w, x, y, z).
    model.tip_rotation = Eigen::Vector4d(model.tip_rotation[3], model.tip_rotation[0],
                                         model.tip_rotation[1], model.tip_rotation[2]);
    ASSERT_TRUE(model.Validate().empty())
        << model.Validate().front().field << ": " << model.Validate().front().message;
    JointAngles angles;
    angles.angle.resize(n);
    for (int j = 0; j < n; ++j) angles.angle[j] = 3.0 * u(rng);

    Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
    Points expected(n + 1, 3);
    expected.row(0) = model.base.transpose();
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector3d a = model.joint_axes.row(j).transpose();
      const Eigen::Vector3d d =
          model.link_lengths[j] * Eigen::Vector3d(model.link_directions.row(j).transpose());
      Eigen::Vector3d step;
      if (model.prismatic(j)) {
        step = r * (d + angles.angle[j] * a);
      } else {
        r = r * Eigen::AngleAxisd(angles.angle[j], a).toRotationMatrix();
        step = r * d;
      }
      expected.row(j + 1) = expected.row(j) + step.transpose();
    }
    const Points points = ForwardKinematics(model, angles);
    EXPECT_LT((points - expected).cwiseAbs().maxCoeff(), 1e-12) << "trial " << trial;
    const ToolPose tool = ToolPoseAt(model, angles);
    const Eigen::Vector4d& t = model.tip_rotation;
    const Eigen::Matrix3d tool_expected =
        r * Eigen::Quaterniond(t[0], t[1], t[2], t[3]).toRotationMatrix();
    EXPECT_LT((tool.rotation - tool_expected).cwiseAbs().maxCoeff(), 1e-13) << "trial " << trial;
    EXPECT_LT((tool.position - expected.row(n).transpose()).norm(), 1e-12) << "trial " << trial;
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

void ExpectStepInvariants(const ArmModel& model, const ArmStepReport& r, int step) {
  ASSERT_TRUE(r.state.points.allFinite()) << step;
  EXPECT_LT((r.state.points.row(0).transpose() - model.base).norm(), 1e-12) << step;
  EXPECT_LT(MaxLengthError(model, r.state.points), 1e-14) << step;
  EXPECT_LT((ForwardKinematics(model, r.state.angles) - r.state.points).cwiseAbs().maxCoeff(),
            1e-12)
      << step;
  EXPECT_TRUE(WithinLimits(model, r.state.angles, 1e-12)) << step;
  EXPECT_TRUE(std::isfinite(r.ee_error) && std::isfinite(r.base_error)) << step;
}

TEST(ArmStep, FixedBaseHeldAndTargetsReachedOverALongPath) {
  for (int dim : {2, 3}) {
    const ArmModel model = CurledArm(dim, 32, 0.05);
    const Points path = CircleOfTargets(model, 3.0, 1000, CircleTilt::kRising, 2);
    const ArmTrajectory t = TrackPath(model, path, ArmOptions{});
    ASSERT_EQ(t.steps.size(), 1000u);
    EXPECT_EQ(t.unreached, 0) << dim;
    EXPECT_LE(t.max_iterations, 10) << dim;
    for (size_t i = 0; i < t.steps.size(); ++i) {
      const ArmStepReport& r = t.steps[i];
      ExpectStepInvariants(model, r, static_cast<int>(i));
      EXPECT_LE(r.ee_error, 2.1e-10) << dim << " step " << i;
      EXPECT_LE(r.base_error, 1e-10) << dim << " step " << i;
      EXPECT_LT((r.state.points.row(32) - path.row(i)).norm(), 2.1e-10);
    }
  }
}

TEST(ArmStep, NewtonNeedsAFewIterationsWhereTheFixedPointNeedsMany) {
  // Near the edge of the workspace (end effector at 0.98 of the reach), where the base's reply
  // to a move of the end effector is nearly a translation.
  ArmModel model = CurledArm(2, 128, 0.005);
  const Points path = CircleOfTargets(model, 1.0, 40, CircleTilt::kRising);
  ArmOptions newton, fixed;
  fixed.method = FixedBaseMethod::kFixedPoint;
  const ArmTrajectory a = TrackPath(model, path, newton);
  const ArmTrajectory b = TrackPath(model, path, fixed);
  EXPECT_EQ(a.unreached, 0);
  EXPECT_EQ(b.unreached, 0);
  EXPECT_LE(a.max_iterations, 10);
  EXPECT_LE(a.total_passes, 10 * 40);  // passes over the links: the cost
  EXPECT_GT(b.total_passes, 5 * a.total_passes) << a.total_passes << " " << b.total_passes;
  std::printf(
      "128 links, 40 steps near the edge: newton %lld passes (max %d iterations a step), "
      "fixed point %lld passes\n",
      a.total_passes, a.max_iterations, b.total_passes);
  for (const ArmStepReport& r : b.steps) EXPECT_LE(r.ee_error, 2.1e-10);
}

TEST(ArmStep, MotionDiesOutTowardTheBase) {
  for (int dim : {2, 3}) {
    const int n = 24;
    const ArmModel model = CurledArm(dim, n, 0.06);
    const Points path = CircleOfTargets(model, 2.0, 200, CircleTilt::kRising);
    const ArmTrajectory t = TrackPath(model, path, ArmOptions{});
    EXPECT_EQ(t.unreached, 0);
    // Total motion of each joint: its point's path length (angles of spherical joints have an
    // azimuth that is ill-defined near zero bend, so use the points).
    Eigen::VectorXd motion = Eigen::VectorXd::Zero(n + 1);
    Points previous = ForwardKinematics(model, model.initial);
    for (const ArmStepReport& r : t.steps) {
      for (int j = 0; j <= n; ++j) motion[j] += (r.state.points.row(j) - previous.row(j)).norm();
      previous = r.state.points;
    }
    EXPECT_EQ(motion[0], 0.0);
    EXPECT_GT(motion.segment(3 * n / 4, n / 4).mean(), 2.0 * motion.segment(1, n / 4).mean());
    // Joint angles too (planar): the end-effector half turns more than the base half.
    if (dim == 2) {
      Eigen::VectorXd turn = Eigen::VectorXd::Zero(n);
      Eigen::VectorXd before = model.initial.angle;
      for (const ArmStepReport& r : t.steps) {
        turn += (r.state.angles.angle - before).cwiseAbs();
        before = r.state.angles.angle;
      }
      EXPECT_GT(turn.tail(n / 2).sum(), turn.head(n / 2).sum());
    }
  }
}

TEST(ArmStep, JointLimitsAreNeverViolated) {
  for (int dim : {2, 3}) {
    ArmModel model = CurledArm(dim, 16, 0.05);
    if (dim == 2) {
      model.joint_min = Eigen::VectorXd::Constant(16, -0.2);
      model.joint_max = Eigen::VectorXd::Constant(16, 0.12);
    } else {
      model.max_bend = Eigen::VectorXd::Constant(16, 0.15);
    }
    // Most of this circle is out of the limited arm's reach; every unreached step costs up to
    // restarts + 1 joint-space solves (ArmOptions::restarts). Restarts are tested in
    // tests/arm_limits_test.cc; here none keeps the test short.
    ArmOptions options;
    options.restarts = 0;
    const Points path = CircleOfTargets(model, 4.0, 300, CircleTilt::kRising);
    const ArmTrajectory t = TrackPath(model, path, options);
    bool any_limited = false, any_reached = false;
    for (size_t i = 0; i < t.steps.size(); ++i) {
      ExpectStepInvariants(model, t.steps[i], static_cast<int>(i));
      any_limited |= t.steps[i].limited;
      any_reached |= t.steps[i].reached && t.steps[i].limited;
      if (t.steps[i].reached) EXPECT_LE(t.steps[i].ee_error, 2.1e-10);
    }
    EXPECT_TRUE(any_limited) << dim;
    EXPECT_TRUE(any_reached) << dim << ": limits active and the target still reached";
  }
}

TEST(ArmStep, UnreachableTargetsAreReportedWithoutNaN) {
  for (int dim : {2, 3}) {
    const ArmModel model = CurledArm(dim, 10, 0.1);
    const ArmState start = InitialState(model);
    // Beyond reach: stretched toward the target, at distance |target| - reach.
    Eigen::VectorXd far = Eigen::VectorXd::Zero(dim);
    far[1] = 25.0;
    ArmStepReport r = ArmStep(model, start, far, ArmOptions{});
    ExpectStepInvariants(model, r, 0);
    EXPECT_FALSE(r.reached);
    EXPECT_TRUE(r.stretched);
    EXPECT_NEAR(r.ee_error, 15.0, 1e-12);
    // Through the base, and behind it.
    for (double x : {0.0, -0.5}) {
      Eigen::VectorXd at_base = model.base;
      at_base[0] += x;
      r = ArmStep(model, start, at_base, ArmOptions{});
      ExpectStepInvariants(model, r, 1);
      if (!r.reached) EXPECT_GT(r.ee_error, 0.0);
    }
  }
}

TEST(ArmStep, StretchedArmPushedAlongItselfStaysFinite) {
  for (int dim : {2, 3}) {
    const ArmModel model = StraightArm(dim, 12, 1.0);  // straight along +x
    const ArmState start = InitialState(model);
    for (double x : {11.5, 6.0, 12.0, 12.5}) {  // pushed in, far in, on the edge, pulled out
      Eigen::VectorXd target = Eigen::VectorXd::Zero(dim);
      target[0] = x;
      const ArmStepReport r = ArmStep(model, start, target, ArmOptions{});
      ExpectStepInvariants(model, r, static_cast<int>(x));
      EXPECT_EQ(r.reached, r.ee_error <= 2.1e-10);
      if (x > 12.0) EXPECT_FALSE(r.reached);
    }
  }
}

TEST(ArmStep, FixedPointBaselineKeepsTheSameInvariants) {
  const ArmModel model = CurledArm(3, 16, 0.08);
  ArmOptions options;
  options.method = FixedBaseMethod::kFixedPoint;
  const Points path = CircleOfTargets(model, 2.0, 100, CircleTilt::kRising);
  const ArmTrajectory t = TrackPath(model, path, options);
  EXPECT_EQ(t.unreached, 0);
  for (size_t i = 0; i < t.steps.size(); ++i) ExpectStepInvariants(model, t.steps[i], int(i));
}

// The message of the InputError that `f` throws ("" if none).
template <class F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ArmStep, BadInputIsRefusedWithTheField) {
  ArmModel model = StraightArm(2, 4, 1.0);
  const ArmState start = InitialState(model);
  const Eigen::Vector2d target(3.0, 1.0);
  ArmModel bad = model;
  bad.link_lengths[2] = 0.0;
  EXPECT_NE(ErrorOf([&] { ArmStep(bad, start, target, {}); }).find("link_lengths[2]"),
            std::string::npos);
  bad = model;
  bad.dim = 4;
  EXPECT_NE(ErrorOf([&] { InitialState(bad); }).find("dim"), std::string::npos);
  bad = model;
  bad.base_direction.setZero();
  EXPECT_NE(ErrorOf([&] { InitialState(bad); }).find("base_direction"), std::string::npos);
  bad = model;
  bad.joint_min = Eigen::VectorXd::Constant(4, 0.1);
  bad.joint_max = Eigen::VectorXd::Constant(4, 0.2);
  EXPECT_NE(ErrorOf([&] { InitialState(bad); }).find("initial.angle[0]"), std::string::npos);
  bad.joint_max[1] = 0.0;
  EXPECT_NE(ErrorOf([&] { InitialState(bad); }).find("joint_min[1]"), std::string::npos);
  EXPECT_NE(
      ErrorOf([&] { ArmStep(model, start, Eigen::Vector2d(1.0, NAN), {}); }).find("target[1]"),
      std::string::npos);
  EXPECT_NE(
      ErrorOf([&] { ArmStep(model, start, Eigen::Vector3d(1.0, 0.0, 0.0), {}); }).find("target"),
      std::string::npos);
  ArmOptions options;
  options.tolerance = 0.0;
  EXPECT_NE(ErrorOf([&] { ArmStep(model, start, target, options); }).find("options.tolerance"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { ParseFixedBaseMethod("jacobian", "method"); }).find("\"newton\""),
            std::string::npos);
  Points path(2, 2);
  path << 1.0, 1.0, INFINITY, 0.0;
  EXPECT_NE(ErrorOf([&] { TrackPath(model, path, {}); }).find("path[1][0]"), std::string::npos);
}

}  // namespace
}  // namespace flexkin

namespace flexkin {
namespace {

TEST(ArmRevolute, ForwardOfInverseReproducesPoints) {
  ArmModel model = RevoluteSnake(64);
  model.base << 0.5, -1.0, 2.0;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(-0.6, 0.6);
  JointAngles a;
  a.angle.resize(64);
  for (int j = 0; j < 64; ++j) a.angle[j] = angle(rng);
  const Points p = ForwardKinematics(model, a);
  const JointAngles back = JointAnglesFromPoints(model, p);
  EXPECT_LT((back.angle - a.angle).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((ForwardKinematics(model, back) - p).cwiseAbs().maxCoeff(), 1e-12);
  // The quaternion of joint j is the rotation about its axis.
  const Eigen::MatrixXd q = JointQuaternions(model, a);
  EXPECT_NEAR(q(1, 3), std::sin(0.5 * a.angle[1]), 1e-15);
  EXPECT_EQ(q(1, 1), 0.0);
}

// Targets that the snake can reach: end effectors of a smooth family of joint angles within the
// limits (the arm is free to reach them with other angles); `amplitude` (rad) at the end
// effector's joint, less toward the base.
Points ReachablePath(const ArmModel& model, int steps, double amplitude) {
  const int n = model.num_links();
  Points path(steps, 3);
  for (int i = 0; i < steps; ++i) {
    JointAngles a = model.initial;
    const double t = 2.0 * kPi * (i + 1) / steps;
    for (int j = 0; j < n; ++j) a.angle[j] += amplitude * std::sin(t + 0.4 * j) * (j + 1) / n;
    for (int j = 0; j < n; ++j)
      a.angle[j] = std::clamp(a.angle[j], model.joint_min[j], model.joint_max[j]);
    path.row(i) = ForwardKinematics(model, a).row(n);
  }
  return path;
}

// Every step of a tracked path: reached to 2e-10 of a link, the base exact, limits, lengths and
// FK = points. Returns each joint's total motion (rad) along the path.
Eigen::VectorXd CheckEveryStepReached(const ArmModel& model, const ArmTrajectory& t) {
  const int n = model.num_links();
  EXPECT_EQ(t.unreached, 0) << t.BriefReport();
  Eigen::VectorXd motion = Eigen::VectorXd::Zero(n);
  JointAngles previous = model.initial;
  for (const ArmStepReport& step : t.steps) {
    EXPECT_TRUE(step.reached) << step.BriefReport();
    EXPECT_LT(step.ee_error, 2e-10 * model.link_lengths.mean()) << step.BriefReport();
    EXPECT_TRUE(step.state.points.allFinite());
    EXPECT_EQ((step.state.points.row(0).transpose() - model.base).norm(), 0.0);
    EXPECT_TRUE(WithinLimits(model, step.state.angles, 1e-12));
    EXPECT_LT(MaxLengthError(model, step.state.points), 1e-13);
    EXPECT_LT(
        (ForwardKinematics(model, step.state.angles) - step.state.points).cwiseAbs().maxCoeff(),
        1e-12);
    motion += (step.state.angles.angle - previous.angle).cwiseAbs();
    previous = step.state.angles;
  }
  return motion;
}

// The weighted minimum-norm step (src/arm/joint_space.cc) reaches every target in a few
// Gauss-Newton iterations (measured: at most 4), the base fixed and the limits kept, and the
// motion dies out toward the base: measured total motion 0.55 rad at the end effector's joint,
// 0.05 in the middle, 0.10 at the base (the tractrix sweep with Newton on its translation left
// 34 of these 60 steps unreached and moved the joints 7.1 / 3.3 / 2.0 rad).
TEST(ArmRevolute, TracksAReachablePathWithTheBaseFixedAndLimitsKept) {
  const int n = 16;
  const ArmModel model = RevoluteSnake(n);
  const ArmTrajectory t = TrackPath(model, ReachablePath(model, 60, 0.1), ArmOptions());
  const Eigen::VectorXd motion = CheckEveryStepReached(model, t);
  EXPECT_LE(t.max_iterations, 8) << t.BriefReport();
  EXPECT_LE(t.total_passes, 8 * 60) << t.BriefReport();
  EXPECT_GT(motion[n - 1], motion[0]);  // dies out toward the base
  EXPECT_GT(motion[n - 1], motion[n / 2]);
  std::printf(
      "revolute snake, 16 links: %s, %lld passes; joint motion ee %.3f middle %.3f base %.3f\n",
      t.BriefReport().c_str(), t.total_passes, motion[n - 1], motion[n / 2], motion[0]);
}

// Tight limits (+-0.25 rad) and targets from angles pushed against them: the active set holds
// the saturated joints and the others still reach every target.
TEST(ArmRevolute, ReachesTargetsWithJointsAtTheirLimits) {
  const int n = 16;
  ArmModel model = RevoluteSnake(n);
  model.joint_min.setConstant(-0.25);
  model.joint_max.setConstant(0.25);
  const ArmTrajectory t = TrackPath(model, ReachablePath(model, 60, 2.0), ArmOptions());
  const Eigen::VectorXd motion = CheckEveryStepReached(model, t);
  int limited = 0;
  for (const ArmStepReport& step : t.steps) limited += step.limited ? 1 : 0;
  EXPECT_GT(limited, 0);
  EXPECT_GT(motion[n - 1], motion[0]);
  std::printf(
      "revolute snake at +-0.25 rad limits: %s, %d steps limited; joint motion ee %.3f middle %.3f "
      "base %.3f\n",
      t.BriefReport().c_str(), limited, motion[n - 1], motion[n / 2], motion[0]);
}

// Single steps from the initial pose to far targets (100 end effectors of random angles within
// the limits, several link lengths away): all reached on the 16-link snake (measured with 200:
// none missed, even without restarts; the 4- and 64-link snakes need them,
// tests/arm_limits_test.cc).
TEST(ArmRevolute, ReachesFarTargetsInOneStep) {
  const int n = 16;
  const ArmModel model = RevoluteSnake(n);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-0.6, 0.6);
  int max_iterations = 0;
  for (int trial = 0; trial < 100; ++trial) {
    JointAngles a;
    a.angle.resize(n);
    for (int j = 0; j < n; ++j) a.angle[j] = angle(rng);
    const Eigen::VectorXd target = ForwardKinematics(model, a).row(n).transpose();
    const ArmStepReport r = ArmStep(model, InitialState(model), target, ArmOptions());
    EXPECT_TRUE(r.reached) << trial << ": " << r.BriefReport();
    EXPECT_TRUE(WithinLimits(model, r.state.angles, 1e-12));
    EXPECT_LT((ForwardKinematics(model, r.state.angles) - r.state.points).cwiseAbs().maxCoeff(),
              1e-12);
    max_iterations = std::max(max_iterations, r.iterations);
  }
  std::printf("revolute snake, 100 far targets in one step: max %d iterations\n", max_iterations);
}

TEST(ArmRevolute, UnreachableTargetIsReportedWithoutNaN) {
  const ArmModel model = RevoluteSnake(8);
  const ArmStepReport far =
      ArmStep(model, InitialState(model), Eigen::Vector3d(20.0, 0.0, 0.0), ArmOptions());
  EXPECT_FALSE(far.reached);
  EXPECT_TRUE(far.state.points.allFinite());
  // Behind the base, beyond what +-0.6 rad joints can fold to.
  const ArmStepReport back =
      ArmStep(model, InitialState(model), Eigen::Vector3d(-1.0, 0.0, 0.0), ArmOptions());
  EXPECT_FALSE(back.reached);
  EXPECT_TRUE(back.state.points.allFinite());
  EXPECT_TRUE(WithinLimits(model, back.state.angles, 1e-12));
}

TEST(ArmRevolute, BadAxesAreRefusedWithTheField) {
  ArmModel model = RevoluteSnake(4);
  // Along the link: a twist joint, valid; but its angle cannot be read back from the points.
  model.joint_axes.row(2) = Eigen::RowVector3d(1.0, 0.0, 0.0);
  EXPECT_TRUE(model.Validate().empty());
  EXPECT_THROW(JointAnglesFromPoints(model, InitialState(model).points), InputError);
  model.joint_axes.row(2) = Eigen::RowVector3d(0.0, 2.0, 0.0);  // not unit
  ASSERT_EQ(model.Validate().size(), 1u);
  EXPECT_EQ(model.Validate().front().field, "joint_axes[2]");
  model = RevoluteSnake(4);
  model.joint_axes.resize(3, 3);
  ASSERT_EQ(model.Validate().size(), 1u);
  EXPECT_EQ(model.Validate().front().field, "joint_axes");
}

// Validate lists a problem of each independent part, not only the first (before: one).
TEST(ArmModelValidate, ListsAProblemOfEachPart) {
  ArmModel model = StraightArm(2, 3, 1.0);
  model.base_direction = Eigen::Vector2d::Zero();
  model.joint_min = Eigen::VectorXd::Constant(3, -1.0);
  model.joint_max = Eigen::VectorXd::Constant(3, -2.0);  // min > max
  model.joint_names = {"a", "b"};                        // 2 names for 3 joints
  model.initial.angle[1] = 10.0;  // not checked against limits that are themselves invalid
  const Problems problems = model.Validate();
  ASSERT_EQ(problems.size(), 3u);
  EXPECT_EQ(problems[0].field, "base_direction");
  EXPECT_EQ(problems[1].field, "joint_min[0]");
  EXPECT_EQ(problems[2].field, "joint_names");
  ASSERT_TRUE(model.FirstProblem().has_value());
  EXPECT_EQ(model.FirstProblem()->field, "base_direction");
  // Valid limits: the initial angle is checked against them.
  model.joint_max = Eigen::VectorXd::Constant(3, 1.0);
  const Problems again = model.Validate();
  ASSERT_EQ(again.size(), 3u);
  EXPECT_EQ(again[2].field, "initial.angle[1]");
  // Without links nothing else is checked.
  model.link_lengths.resize(0);
  ASSERT_EQ(model.Validate().size(), 1u);
  EXPECT_EQ(model.Validate().front().field, "link_lengths");
}

}  // namespace
}  // namespace flexkin
