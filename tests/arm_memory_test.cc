// The Newton fixed-base step's memory (ArmSolverMemory, include/flexkin/arm.h): a step started
// from the last step's translation reaches the same configuration as one started afresh, a
// stale or wrong memory still converges, and on a path the memory saves passes over the links.
#include <gtest/gtest.h>

#include <cmath>

#include "flexkin/arm.h"
#include "scenes/scenes.h"

namespace flexkin {
namespace {

using scenes::ArcArm;
using scenes::CircleOfTargets;

TEST(ArmMemory, WithAndWithoutMemoryReachTheSameConfiguration) {
  for (int links : {8, 64}) {
    const ArmModel model = ArcArm(2, links, 2.0 / links);
    const Points path = CircleOfTargets(model, 0.5, 16);
    const ArmTrajectory t = TrackPath(model, path, ArmOptions{});
    ASSERT_EQ(t.unreached, 0);
    for (int i = 1; i < path.rows(); ++i) {
      const ArmState& before = t.steps[i - 1].state;
      ASSERT_TRUE(before.memory.Usable(2)) << i;  // TrackPath passes the memory on
      ArmState bare = before;
      bare.memory = ArmSolverMemory{};
      const ArmStepReport cold = ArmStep(model, bare, path.row(i).transpose(), ArmOptions{});
      const ArmStepReport& warm = t.steps[i];
      ASSERT_TRUE(cold.reached && warm.reached) << i;
      EXPECT_LT((cold.state.points - warm.state.points).cwiseAbs().maxCoeff(), 1e-9)
          << links << " " << i;
      EXPECT_LT((cold.state.angles.angle - warm.state.angles.angle).cwiseAbs().maxCoeff(), 1e-9);
    }
  }
}

TEST(ArmMemory, StaleOrWrongMemoryStillConverges) {
  const ArmModel model = ArcArm(2, 32, 0.05);
  const ArmState start = InitialState(model);
  const Eigen::VectorXd target = start.points.row(32).transpose() + Eigen::Vector2d(-0.3, 0.4);
  const ArmStepReport fresh = ArmStep(model, start, target, ArmOptions{});
  ASSERT_TRUE(fresh.reached);
  for (const Eigen::Vector2d& remembered :
       {Eigen::Vector2d(0.01, -0.02), Eigen::Vector2d(5.0, -7.0), Eigen::Vector2d(1e6, 1e6)}) {
    ArmState state = start;
    state.memory.translation = remembered;
    const ArmStepReport r = ArmStep(model, state, target, ArmOptions{});
    EXPECT_TRUE(r.reached) << remembered.transpose() << ": " << r.BriefReport();
    EXPECT_LT((r.state.points - fresh.state.points).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_TRUE(r.state.memory.Usable(2));
  }
  // Memories of the wrong size or with NaN are ignored.
  for (const Eigen::VectorXd& bad : {Eigen::VectorXd(Eigen::Vector3d(0.1, 0.2, 0.3)),
                                     Eigen::VectorXd(Eigen::Vector2d(NAN, 0.0))}) {
    ArmState state = start;
    state.memory.translation = bad;
    EXPECT_FALSE(state.memory.Usable(2));
    const ArmStepReport r = ArmStep(model, state, target, ArmOptions{});
    EXPECT_TRUE(r.reached);
    EXPECT_LT((r.state.points - fresh.state.points).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST(ArmMemory, MemorySavesPassesOnAPath) {
  for (int dim : {2, 3}) {
    const ArmModel model = ArcArm(dim, 64, 0.03, 0.5);
    const Points path = CircleOfTargets(model, 1.0, 48);
    const ArmTrajectory warm = TrackPath(model, path, ArmOptions{});
    ASSERT_EQ(warm.unreached, 0) << dim;
    // The same steps, each started from the state without its memory.
    long long cold_passes = 0;
    ArmState state = InitialState(model);
    for (int i = 0; i < path.rows(); ++i) {
      state.memory = ArmSolverMemory{};
      const ArmStepReport r = ArmStep(model, state, path.row(i).transpose(), ArmOptions{});
      ASSERT_TRUE(r.reached) << dim << " " << i;
      cold_passes += r.passes;
      state = r.state;
    }
    EXPECT_LT(warm.total_passes, cold_passes) << dim;
    EXPECT_LE(warm.total_passes, 4 * path.rows()) << dim;
    std::printf("dim %d, 64 links, 48 steps: %lld passes with memory, %lld without\n", dim,
                warm.total_passes, cold_passes);
  }
}

TEST(ArmMemory, FixedPointAndStretchedStepsLeaveNoMemory) {
  const ArmModel model = ArcArm(2, 16, 0.1);
  const ArmState start = InitialState(model);
  ArmOptions fixed;
  fixed.method = FixedBaseMethod::kFixedPoint;
  const Eigen::VectorXd near = start.points.row(16).transpose() + Eigen::Vector2d(0.1, 0.1);
  EXPECT_FALSE(ArmStep(model, start, near, fixed).state.memory.Usable(2));
  const Eigen::VectorXd far = Eigen::Vector2d(100.0, 0.0);
  const ArmStepReport stretched = ArmStep(model, start, far, ArmOptions{});
  EXPECT_TRUE(stretched.stretched);
  EXPECT_FALSE(stretched.state.memory.Usable(2));
}

}  // namespace
}  // namespace flexkin
