// The KDL pseudo-inverse peer (testing/kdl_peer.h) and the comparison measures
// (testing/arm_metrics.h): KDL's chain is flexkin's arm, its trackers reach reachable targets,
// and the measures are right on cases checked by hand. The timing lives in
// bench/arm_kdl_benchmark.cc.
#include "kdl_peer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "arm_metrics.h"
#include "flexkin/error.h"
#include "scenes/scenes.h"

namespace flexkin::peers {
namespace {

constexpr double kPi = 3.14159265358979323846;

// An arm with uneven links, a tilted base direction and random joint angles.
ArmModel RandomArm(int dim, int links, std::mt19937* rng) {
  std::uniform_real_distribution<double> length(0.5, 1.5), turn(-2.5, 2.5), bend(0.0, 2.5);
  ArmModel model = StraightArm(dim, links, 1.0);
  for (int k = 0; k < links; ++k) model.link_lengths[k] = length(*rng);
  model.base.setConstant(0.3);
  model.base_direction = dim == 2 ? Eigen::VectorXd(Eigen::Vector2d(0.4, -1.0))
                                  : Eigen::VectorXd(Eigen::Vector3d(-0.2, 0.7, 0.5));
  for (int j = 0; j < links; ++j) {
    model.initial.angle[j] = dim == 2 ? turn(*rng) : bend(*rng);
    if (dim == 3) model.initial.azimuth[j] = turn(*rng);
  }
  return model;
}

TEST(KdlPeer, ForwardKinematicsMatchesFlexkinPlanarAndSpatial) {
  std::mt19937 rng(7);
  for (int dim : {2, 3}) {
    for (int trial = 0; trial < 20; ++trial) {
      const ArmModel model = RandomArm(dim, 1 + trial * 3, &rng);
      const KDL::Chain chain = KdlChain(model);
      ASSERT_EQ(chain.getNrOfJoints(), unsigned(model.num_links() * KdlJointsPerLink(model)));
      const Points kdl = KdlPoints(model, chain, KdlJoints(model, model.initial));
      const Points ours = ForwardKinematics(model, model.initial);
      ASSERT_EQ(kdl.rows(), ours.rows());
      EXPECT_LT((kdl - ours).cwiseAbs().maxCoeff(), 1e-12) << "dim " << dim << " trial " << trial;
    }
  }
}

// A 6-link arm curled into an arc, the end effector moving 0.05 of a link per step on a short
// straight path: both KDL trackers reach every target, warm-started.
void ExpectTracksShortPath(int dim) {
  const ArmModel model = scenes::ArcArm(dim, 6, 0.4, 0.2);
  const Points start = ForwardKinematics(model, model.initial);
  Points path(10, dim);
  for (int i = 0; i < 10; ++i) {
    path.row(i) = start.row(6);
    path(i, 0) -= 0.05 * (i + 1);
    path(i, 1) += 0.02 * (i + 1);
  }
  for (KdlSolver solver : {KdlSolver::kNewtonPinv, KdlSolver::kLma}) {
    const KdlTrajectory t = TrackPathWithKdl(model, path, solver, KdlOptions{});
    ASSERT_EQ(t.steps.size(), 10u);
    EXPECT_EQ(t.unreached, 0) << KdlSolverName(solver) << " dim " << dim << ": "
                              << t.steps.back().status_name;
    EXPECT_LT(t.max_ee_error, 2e-10) << KdlSolverName(solver);
    for (const KdlStepReport& s : t.steps) {
      EXPECT_GE(s.iterations, 1);
      // The reported points are FK of the reported angles, and every link keeps its length.
      EXPECT_LT((ForwardKinematics(model, s.angles) - s.points).cwiseAbs().maxCoeff(), 1e-12);
      EXPECT_NEAR(s.points.row(0).norm(), 0.0, 1e-15);
    }
    if (solver == KdlSolver::kNewtonPinv && dim == 2) {
      // NR holds the end effector's orientation: the sum of the planar angles stays put.
      EXPECT_NEAR(t.steps.back().angles.angle.sum(), model.initial.angle.sum(), 1e-9);
    }
  }
}

TEST(KdlPeer, TrackersReachReachableTargetsPlanar) { ExpectTracksShortPath(2); }
TEST(KdlPeer, TrackersReachReachableTargetsSpatial) { ExpectTracksShortPath(3); }

TEST(KdlPeer, LimitsAndBadInputAreRefusedWithTheField) {
  ArmModel model = StraightArm(2, 4, 1.0);
  model.joint_min = Eigen::VectorXd::Constant(4, -1.0);
  model.joint_max = Eigen::VectorXd::Constant(4, 1.0);
  try {
    KdlChain(model);
    FAIL() << "limits accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("joint_limits"), std::string::npos);
  }
  const ArmModel plain = StraightArm(2, 4, 1.0);
  Points path(1, 2);
  path << 1.0, NAN;
  EXPECT_THROW(TrackPathWithKdl(plain, path, KdlSolver::kLma, {}), InputError);
  KdlOptions bad;
  bad.tolerance = 0.0;
  path << 1.0, 1.0;
  EXPECT_THROW(TrackPathWithKdl(plain, path, KdlSolver::kLma, bad), InputError);
}

// By hand: a 3-joint planar arm moving joint 0 by +0.1 then -0.3, joint 2 by +0.5 across the
// +-pi cut (3.0 -> -2.783..., a turn of 0.5 the short way): totals 0.4, 0, 0.5.
TEST(ArmMetrics, TotalJointMotionPlanarByHand) {
  const ArmModel model = StraightArm(2, 3, 1.0);
  JointAngles start{Eigen::Vector3d(0.0, 0.2, 3.0), {}};
  JointAngles a{Eigen::Vector3d(0.1, 0.2, 3.0), {}};
  JointAngles b{Eigen::Vector3d(-0.2, 0.2, 3.5 - 2.0 * kPi), {}};
  const Eigen::VectorXd total = TotalJointMotion(model, start, {a, b});
  EXPECT_NEAR(total[0], 0.4, 1e-15);
  EXPECT_NEAR(total[1], 0.0, 1e-15);
  EXPECT_NEAR(total[2], 0.5, 1e-14);
}

// By hand, spatial: bending a joint from 0 to 0.3 at any azimuth turns it by 0.3; turning the
// azimuth of a bend b by pi (the bend flips to the other side) turns it by 2b.
TEST(ArmMetrics, TotalJointMotionSpatialByHand) {
  const ArmModel model = StraightArm(3, 2, 1.0);
  JointAngles start{Eigen::Vector2d(0.0, 0.2), Eigen::Vector2d(0.0, 0.0)};
  JointAngles a{Eigen::Vector2d(0.3, 0.2), Eigen::Vector2d(1.0, 0.0)};
  JointAngles b{Eigen::Vector2d(0.3, 0.2), Eigen::Vector2d(1.0, kPi)};
  const Eigen::VectorXd total = TotalJointMotion(model, start, {a, b});
  EXPECT_NEAR(total[0], 0.3, 1e-12);
  EXPECT_NEAR(total[1], 0.4, 1e-12);
}

// The flexkin side of the comparison: AnglesOf keeps the order of the steps, and the total
// motion of a flexkin trajectory equals the sum of its steps' motions.
TEST(ArmMetrics, AnglesOfFlexkinTrajectory) {
  const ArmModel model = scenes::ArcArm(2, 5, 0.3);
  const Points start = ForwardKinematics(model, model.initial);
  Points path(3, 2);
  for (int i = 0; i < 3; ++i) path.row(i) = start.row(5) + Eigen::RowVector2d(-0.1 * (i + 1), 0.0);
  const ArmTrajectory t = TrackPath(model, path, ArmOptions{});
  const std::vector<JointAngles> angles = AnglesOf(t);
  ASSERT_EQ(angles.size(), 3u);
  EXPECT_EQ(angles[2].angle, t.steps[2].state.angles.angle);
  Eigen::VectorXd sum = JointMotionStep(model, model.initial, angles[0]) +
                        JointMotionStep(model, angles[0], angles[1]) +
                        JointMotionStep(model, angles[1], angles[2]);
  EXPECT_LT((TotalJointMotion(model, model.initial, angles) - sum).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_GT(sum.maxCoeff(), 0.0);
}

}  // namespace
}  // namespace flexkin::peers
