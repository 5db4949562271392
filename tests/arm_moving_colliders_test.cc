// Keyframed colliders for fixed-base arms (Collider::motion in ArmOptions::colliders;
// docs/robots.md "Colliders", docs/colliders.md "Moving colliders"): time in leader steps of the
// end effector's path, step i (toward path row i) spanning [i, i + 1], each sub-step of the sweep
// at its own time, the state after step i where the collider is at i + 1. Checked: a ball sweeping
// onto a planar and a spherical arm whose end effector is held (or moves slowly) leaves every link
// capsule of every frame outside the ball where its motion has it then (the test's own distances:
// closed-form point-to-segment and sampled QuerySurface), the lengths and the base kept, the arm
// moved aside; a motion that stands still gives the static collider's steps bit for bit, one that
// never reaches the arm the free steps; the start checked at time 0 (named), not later; a ball
// that comes onto the target or the base blocks the steps honestly; an arm with joint axes meets
// the ball where it is at each step's end; the times of sub-steps and legs; a robot scenario file
// with a moving collider reads, runs and writes the motion back.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "arm/colliders.h"
#include "collider_test_util.h"
#include "flexkin/arm.h"
#include "flexkin/colliders.h"
#include "flexkin/error.h"
#include "flexkin/robot_scenario.h"
#include "scenes/scenes.h"
#include "test_util.h"

namespace flexkin {
namespace {

using collider_test::At;
using collider_test::SampledDistance;
using collider_test::Sphere;
using Eigen::Vector3d;
using test_util::ExpectInputError;

// A motion through `keys` (time, translation) pairs.
std::shared_ptr<const ColliderMotion> Through(
    const std::vector<std::pair<double, Vector3d>>& keys,
    KeyframeInterpolation interpolation = KeyframeInterpolation::kSmooth) {
  auto m = std::make_shared<ColliderMotion>();
  for (const auto& [time, translation] : keys) {
    BodyKeyframe k;
    k.time = time;
    k.pose.translation = translation;
    m->keyframes.push_back(k);
  }
  m->interpolation = interpolation;
  return m;
}

// The distance from x to the segment [a, b] (closed form).
double PointSegment(const Vector3d& x, const Vector3d& a, const Vector3d& b) {
  const Vector3d d = b - a;
  const double dd = d.squaredNorm();
  const double t = dd > 0.0 ? std::clamp((x - a).dot(d) / dd, 0.0, 1.0) : 0.0;
  return (x - (a + t * d)).norm();
}

// The least clearance of the arm's link capsules from the ball `c` where its motion has it at
// `time`, relative to each link's length: the closed-form distance of the ball's centre to each
// link, and (in *sampled) the least QuerySurface distance of 401 points along each link, both
// less the link's radius.
double BallClearance(const ArmModel& model, const Points& p, const Collider& c, double time,
                     double* sampled = nullptr) {
  const Collider at = ColliderAt(c, time);
  double least = std::numeric_limits<double>::infinity();
  double least_sampled = least;
  for (int k = 0; k < model.num_links(); ++k) {
    const double r = model.link_radii.size() > 0 ? model.link_radii[k] : 0.0;
    const double length = model.link_lengths[k];
    const double d = PointSegment(at.pose.translation(), At(p, k), At(p, k + 1)) - at.radius - r;
    least = std::min(least, d / length);
    if (sampled != nullptr) {
      least_sampled =
          std::min(least_sampled, (SampledDistance(at, At(p, k), At(p, k + 1), 400) - r) / length);
    }
  }
  if (sampled != nullptr) *sampled = least_sampled;
  return least;
}

// Every step of `run` against `ball` where its motion has it at the step's frame (step s: time
// s + 1): finite points, the library's clearance the test's own, and every link outside unless
// the step is blocked. Returns the least clearance (relative to a link's length).
double CheckEveryFrame(const ArmModel& model, const ArmTrajectory& run, const Collider& ball) {
  double least = std::numeric_limits<double>::infinity();
  for (size_t s = 0; s < run.steps.size(); ++s) {
    const ArmStepReport& step = run.steps[s];
    EXPECT_TRUE(step.state.points.allFinite()) << "step " << s;
    const double own = BallClearance(model, step.state.points, ball, s + 1.0);
    EXPECT_NEAR(step.clearance, own * model.link_lengths[0], 1e-9) << "step " << s;
    if (!step.blocked) EXPECT_GE(own, -1e-12) << "step " << s << ": " << step.BriefReport();
    least = std::min(least, own);
  }
  return least;
}

// The largest distance between corresponding points of two runs' steps.
double LargestMove(const ArmTrajectory& a, const ArmTrajectory& b) {
  double most = 0.0;
  for (size_t s = 0; s < a.steps.size(); ++s) {
    most = std::max(
        most, (a.steps[s].state.points - b.steps[s].state.points).rowwise().norm().maxCoeff());
  }
  return most;
}

// The largest change of any joint angle (the bend angle of spherical joints) between two runs.
double LargestAngleChange(const ArmTrajectory& a, const ArmTrajectory& b) {
  double most = 0.0;
  for (size_t s = 0; s < a.steps.size(); ++s) {
    const Eigen::VectorXd d = a.steps[s].state.angles.angle - b.steps[s].state.angles.angle;
    most = std::max(most, d.cwiseAbs().maxCoeff());
  }
  return most;
}

// A curled arm of 12 unit links (scenes::CurledArm), link radius 0.05.
ArmModel Arm(int dim) {
  ArmModel model = scenes::CurledArm(dim, 12, 0.15);
  model.link_radii = Eigen::VectorXd::Constant(12, 0.05);
  return model;
}

// `steps` targets from the initial end effector, moving `drift` (length unit) a step along +y.
Points HeldOrDrifting(const ArmModel& model, int steps, double drift) {
  const Points start = ForwardKinematics(model, model.initial);
  Points path(steps, model.dim);
  for (int s = 0; s < steps; ++s) {
    path.row(s) = start.row(model.num_links());
    path(s, 1) += drift * (s + 1);
  }
  return path;
}

// A ball of radius 1 sweeping onto the middle of the arm's initial pose from the side away from
// its curl and back: clear (1.5 beyond touching) at times 0 to 5, `depth` into where link 7 was at
// times 30 to 35, clear again from time 60. In 3D a little off the arm's plane of curl.
Collider SweepingBall(const ArmModel& model, double depth) {
  const Points p = ForwardKinematics(model, model.initial);
  const Vector3d a = At(p, 6), b = At(p, 7);
  const Vector3d mid = 0.5 * (a + b);
  // Away from the arm's other points: the side of the link that the base is not on.
  Vector3d across = (b - a).cross(Vector3d::UnitZ());
  if (model.dim == 3) across = (b - a).unitOrthogonal();
  across.normalize();
  if (across.dot(At(p, 0) - mid) > 0.0) across = -across;
  const double touch = 1.0 + model.link_radii[6];
  Collider ball = Sphere(mid, 1.0);
  ball.motion = Through({{5.0, (touch + 1.5) * across},
                         {30.0, (touch - depth) * across},
                         {35.0, (touch - depth) * across},
                         {60.0, (touch + 1.5) * across}});
  return ball;
}

struct SweepCase {
  int dim;
  int substeps;
  double drift;  // the end effector's move per step (0: held still)
};

class ArmMovingBall : public ::testing::TestWithParam<SweepCase> {};

TEST_P(ArmMovingBall, EveryLinkStaysOutsideWhereTheBallIsAndTheArmMovesAside) {
  const SweepCase param = GetParam();
  const ArmModel model = Arm(param.dim);
  const Points path = HeldOrDrifting(model, 70, param.drift);
  ArmOptions options;
  options.substeps = param.substeps;
  const ArmTrajectory free = TrackPath(model, path, options);
  ASSERT_EQ(free.unreached, 0);
  const Collider ball = SweepingBall(model, 0.4);
  options.colliders = {ball};
  // Without the arm moving aside the ball would cut 0.4 into link 7 at time 30.
  double free_least = std::numeric_limits<double>::infinity();
  for (size_t s = 0; s < free.steps.size(); ++s) {
    free_least =
        std::min(free_least, BallClearance(model, free.steps[s].state.points, ball, s + 1.0));
  }
  EXPECT_LT(free_least, -0.1);

  const ArmTrajectory run = TrackPath(model, path, options);
  ASSERT_EQ(run.steps.size(), path.rows());
  EXPECT_EQ(run.blocked_steps, 0);
  const double least = CheckEveryFrame(model, run, ball);  // none blocked: every link outside
  const Points start = ForwardKinematics(model, model.initial);
  double least_sampled = std::numeric_limits<double>::infinity();
  for (size_t s = 0; s < run.steps.size(); ++s) {
    const Points& p = run.steps[s].state.points;
    double sampled = 0.0;
    BallClearance(model, p, ball, s + 1.0, &sampled);
    least_sampled = std::min(least_sampled, sampled);
    EXPECT_EQ(At(p, 0), At(start, 0)) << "step " << s;
    for (int k = 0; k < model.num_links(); ++k) {
      EXPECT_NEAR((At(p, k + 1) - At(p, k)).norm(), model.link_lengths[k], 1e-12);
    }
  }
  EXPECT_GE(least_sampled, -1e-12);
  const double moved = LargestMove(run, free);
  const double turned = LargestAngleChange(run, free);
  EXPECT_GT(moved, 0.2);  // the ball pushed the arm aside (it would have cut into it)
  EXPECT_GT(turned, 0.05);
  EXPECT_GE(run.contact_steps, 5);
  EXPECT_LE(run.unreached, 2) << run.BriefReport();
  // Before the ball comes and after it has gone the steps are the free ones (no contact).
  EXPECT_FALSE(run.steps[0].contact);
  EXPECT_TRUE(run.steps[0].state.points == free.steps[0].state.points);
  std::printf(
      "%dD, %d sub-steps, drift %g: free run %.3g deep; least clearance %.3g (sampled %.3g) of a "
      "link, points moved up to %.3g, joints up to %.3g rad; %d contact steps, %d not reached\n",
      param.dim, param.substeps, param.drift, -free_least, least, least_sampled, moved, turned,
      run.contact_steps, run.unreached);
}

INSTANTIATE_TEST_SUITE_P(Arms, ArmMovingBall,
                         ::testing::Values(SweepCase{2, 1, 0.0}, SweepCase{2, 3, 0.0},
                                           SweepCase{2, 1, 0.01}, SweepCase{3, 1, 0.0},
                                           SweepCase{3, 3, 0.01}),
                         [](const ::testing::TestParamInfo<SweepCase>& info) {
                           return std::string(info.param.dim == 2 ? "Planar" : "Spherical") +
                                  std::to_string(info.param.substeps) + "Substeps" +
                                  (info.param.drift > 0.0 ? "Drifting" : "Held");
                         });

// Steps compared bit for bit.
void ExpectSameSteps(const ArmTrajectory& a, const ArmTrajectory& b, const std::string& what) {
  ASSERT_EQ(a.steps.size(), b.steps.size()) << what;
  for (size_t s = 0; s < a.steps.size(); ++s) {
    SCOPED_TRACE(what + ", step " + std::to_string(s));
    EXPECT_TRUE(a.steps[s].state.points == b.steps[s].state.points);
    EXPECT_TRUE(a.steps[s].state.angles.angle == b.steps[s].state.angles.angle);
    EXPECT_TRUE(a.steps[s].state.angles.azimuth == b.steps[s].state.angles.azimuth);
    EXPECT_EQ(a.steps[s].base_error, b.steps[s].base_error);
    EXPECT_EQ(a.steps[s].ee_error, b.steps[s].ee_error);
    EXPECT_EQ(a.steps[s].passes, b.steps[s].passes);
    EXPECT_EQ(a.steps[s].contact, b.steps[s].contact);
    EXPECT_EQ(a.steps[s].blocked, b.steps[s].blocked);
  }
}

// A ball that stands still (two keyframes at one pose) is the static ball where that pose puts
// it, step for step and bit for bit, contact steps included; a ball whose motion never comes near
// the arm changes no bit of the run without it.
TEST(ArmMovingColliders, AStillOrUnreachedMotionChangesNoBit) {
  for (int dim : {2, 3}) {
    const ArmModel model = Arm(dim);
    // The end effector drifts 0.05 a step toward +y, bending the arm against a ball placed
    // beside link 7 of the free run's step 30, 0.1 into it.
    const Points path = HeldOrDrifting(model, 40, 0.05);
    ArmOptions options;
    const ArmTrajectory free = TrackPath(model, path, options);
    const Points& p30 = free.steps[30].state.points;
    const Points start = ForwardKinematics(model, model.initial);
    Vector3d across = (At(p30, 7) - At(p30, 6)).cross(Vector3d::UnitZ()).normalized();
    if (dim == 3) across = (At(p30, 7) - At(p30, 6)).unitOrthogonal();
    const Vector3d mid = 0.5 * (At(p30, 6) + At(p30, 7));
    // The side the arm moved from: the start is clear of the ball there.
    if (across.dot(At(start, 6) + At(start, 7) - 2.0 * mid) > 0.0) across = -across;
    const Vector3d centre = mid + (0.5 + 0.05 - 0.1) * across;
    const Vector3d shift(0.25, -0.5, dim == 3 ? 0.125 : 0.0);

    Collider still = Sphere(centre - shift, 0.5);  // carried to `centre` by its motion
    still.motion = Through({{3.0, shift}, {20.0, shift}}, KeyframeInterpolation::kLinear);
    Collider placed = Sphere(centre, 0.5);
    ASSERT_TRUE(ColliderAt(still, 10.0).pose.matrix() == placed.pose.matrix());
    options.colliders = {placed};
    const ArmTrajectory fixed = TrackPath(model, path, options);
    options.colliders = {still};
    const ArmTrajectory carried = TrackPath(model, path, options);
    EXPECT_GT(fixed.contact_steps, 0) << "the test needs a ball the arm touches";
    ExpectSameSteps(carried, fixed, std::to_string(dim) + "D still");
    EXPECT_EQ(carried.min_clearance, fixed.min_clearance);

    // A ball far off, moving across nothing.
    Collider far = Sphere(Vector3d(100.0, -50.0, 0.0), 1.0);
    far.motion = Through({{0.0, Vector3d::Zero()}, {40.0, Vector3d(0.0, 100.0, 0.0)}});
    options.colliders = {far};
    const ArmTrajectory away = TrackPath(model, path, options);
    ExpectSameSteps(away, free, std::to_string(dim) + "D far");
    EXPECT_EQ(away.contact_steps, 0);
    std::printf("%dD: still ball %d contact steps, least clearance %.3g, the same bits moving\n",
                dim, fixed.contact_steps, fixed.min_clearance);
  }
}

// The start is checked where the colliders are at time 0: a ball whose motion starts on the arm
// is refused by name; one that comes onto it later is not (it pushes the arm aside).
TEST(ArmMovingColliders, TheStartIsCheckedAtTimeZero) {
  const ArmModel model = Arm(2);
  const Points start = ForwardKinematics(model, model.initial);
  const Points path = HeldOrDrifting(model, 20, 0.0);
  const Vector3d on = 0.5 * (At(start, 4) + At(start, 5));
  Collider away = Sphere(Vector3d(-30.0, 0.0, 0.0), 1.0);
  Collider ball = Sphere(on, 0.3);
  ball.motion = Through({{0.0, Vector3d::Zero()}, {10.0, Vector3d(0.0, -3.0, 0.0)}});
  ArmOptions options;
  options.colliders = {away, ball};
  ExpectInputError([&] { TrackPath(model, path, options); }, "initial",
                   "collider 1 (sphere) at time 0 of its motion");
  // The same through ArmStep at its time; at time 10 the ball is off the arm.
  const Eigen::VectorXd target = path.row(0).transpose();
  ExpectInputError([&] { ArmStep(model, InitialState(model), target, options); }, "state.points",
                   "at time 0 of its motion");
  ExpectInputError([&] { ArmStep(model, InitialState(model), target, options, 0.5); },
                   "state.points", "at time 0.5 of its motion");
  EXPECT_NO_THROW(ArmStep(model, InitialState(model), target, options, /*time=*/10.0));

  // On the arm only from time 10 on (off it before): not refused; from the side, it pushes the
  // arm aside, and no frame has a link inside it.
  Vector3d across = (At(start, 5) - At(start, 4)).cross(Vector3d::UnitZ()).normalized();
  Collider later = Sphere(on + 0.2 * across, 0.3);
  later.motion = Through({{0.0, 2.0 * across}, {10.0, Vector3d::Zero()}});
  options.colliders = {away, later};
  ArmTrajectory run;
  ASSERT_NO_THROW(run = TrackPath(model, path, options));
  EXPECT_GT(run.contact_steps, 0);
  for (size_t s = 0; s < run.steps.size(); ++s) {
    EXPECT_GE(BallClearance(model, run.steps[s].state.points, later, s + 1.0), -1e-12) << s;
  }
}

// A ball that comes onto the end effector's target (held still) or onto the base leaves no
// solution with every link outside: those steps are blocked, the arm held where it was, the
// clearance reported where the ball then is (negative where it covers the held arm), and the run
// goes on to the end without a throw or a NaN.
TEST(ArmMovingColliders, ABallOntoTheTargetOrTheBaseBlocksHonestly) {
  for (int dim : {2, 3}) {
    for (int onto : {12, 0}) {  // the end effector, then the base
      const ArmModel model = Arm(dim);
      const Points start = ForwardKinematics(model, model.initial);
      const Points path = HeldOrDrifting(model, 30, 0.0);
      const Vector3d point = At(start, onto);
      // From 4 beyond the point, away from the arm's middle.
      const Vector3d from =
          point + 4.0 * (point - 0.5 * (At(start, 0) + At(start, 12))).normalized();
      Collider ball = Sphere(from, 0.5);
      ball.motion = Through({{0.0, Vector3d::Zero()}, {15.0, point - from}});
      ArmOptions options;
      options.colliders = {ball};
      ArmTrajectory run;
      ASSERT_NO_THROW(run = TrackPath(model, path, options));
      ASSERT_EQ(run.steps.size(), path.rows());
      SCOPED_TRACE(std::to_string(dim) + "D onto point " + std::to_string(onto));
      EXPECT_GT(run.blocked_steps, 0) << run.BriefReport();
      // A step that is not blocked keeps every link outside; a blocked one holds the arm.
      const double least = CheckEveryFrame(model, run, ball);
      for (size_t s = 0; s < run.steps.size(); ++s) {
        if (!run.steps[s].blocked) continue;
        EXPECT_FALSE(run.steps[s].reached) << s;
        const Points& before = s > 0 ? run.steps[s - 1].state.points : start;
        EXPECT_TRUE(run.steps[s].state.points == before) << s;
      }
      EXPECT_LT(least, 0.0);  // the ball came onto the held arm: reported, not hidden
      EXPECT_EQ(run.min_clearance, run.steps.back().clearance);
      EXPECT_NE(run.BriefReport().find("BLOCKED"), std::string::npos);
      std::printf("%dD, ball onto point %d: %d of %lld steps blocked, least clearance %.3g\n", dim,
                  onto, run.blocked_steps, run.num_steps, run.min_clearance);
    }
  }
}

// Arms with joint axes (their joint-space step among colliders, which has no sub-steps) take the
// colliders where they are at the end of each step: a ball pushed onto a held pitch/yaw snake
// leaves every step that is not blocked with every link outside it where it is then.
TEST(ArmMovingColliders, AnArmWithJointAxesMeetsTheBallWhereItIsAtEachStep) {
  ArmModel model = scenes::RevoluteSnake(12);
  model.link_radii = Eigen::VectorXd::Constant(12, 0.05);
  const Points path = HeldOrDrifting(model, 70, 0.0);
  ArmOptions options;
  const ArmTrajectory free = TrackPath(model, path, options);
  const Collider ball = SweepingBall(model, 0.3);
  options.colliders = {ball};
  const ArmTrajectory run = TrackPath(model, path, options);
  ASSERT_EQ(run.steps.size(), path.rows());
  const double least = CheckEveryFrame(model, run, ball);
  EXPECT_GT(run.contact_steps, 0);
  EXPECT_GT(LargestMove(run, free), 0.1);
  std::printf("joint axes: %s; least clearance %.3g of a link, points moved up to %.3g\n",
              run.BriefReport().c_str(), least, LargestMove(run, free));
}

// The times of sub-steps and legs: step i of TrackPath spans [i, i + 1], sub-step j of m at
// i + j / m as in chain runs (bit for bit), legs share the window and the last ends at its end.
TEST(ArmMovingColliders, StepWindowsCountLeaderSteps) {
  for (int i = 0; i < 50; ++i) {
    const arm_internal::StepWindow w{double(i), double(i + 1)};
    for (int m : {1, 2, 3, 7}) {
      for (int j = 1; j <= m; ++j) {
        EXPECT_EQ(w.Substep(j, m), double(i) + double(j) / double(m));
      }
    }
    for (int legs : {2, 3, 8}) {
      double at = w.start;
      for (int leg = 1; leg <= legs; ++leg) {
        const arm_internal::StepWindow l = w.Leg(leg, legs);
        EXPECT_EQ(l.start, at);
        EXPECT_NEAR(l.end - l.start, 1.0 / legs, 1e-14);
        at = l.end;
      }
      EXPECT_EQ(at, w.end);
    }
  }
}

// A robot scenario file with a moving collider: read (no refusal of "motion", and a target
// inside the ball's path is not refused either: the ball is there only for a while), run, and
// written back with its motion in the trajectory's "colliders".
TEST(ArmMovingColliders, ARobotScenarioFileWithAMovingBallReadsRunsAndWritesItsMotion) {
  const std::string text = R"({"format": "flexkin-robot", "name": "ball sweep",
    "arm": {"links": 12, "link_length": 0.1, "initial_angles": 0.15},
    "link_radius": 0.01,
    "path": {"type": "line", "to": [0.8, 0.6], "steps": 30},
    "colliders": [{"shape": "sphere", "center": [0.5, -0.4], "radius": 0.1,
                   "motion": {"interpolation": "linear", "keyframes": [
                     {"time": 0}, {"time": 20, "translation": [0, 0.6]},
                     {"time": 30, "translation": [0, 0.6]}]}}]})";
  EXPECT_TRUE(ValidateRobotScenarioText(text).empty())
      << ValidateRobotScenarioText(text).front().Text();
  const RobotScenario s = ParseRobotScenarioText(text);
  ASSERT_EQ(s.options.colliders.size(), 1u);
  ASSERT_TRUE(s.options.colliders[0].motion);
  EXPECT_EQ(s.options.colliders[0].motion->keyframes.size(), 3u);
  const ArmTrajectory t = TrackPath(s.model, s.path, s.options);
  ASSERT_EQ(t.steps.size(), 30u);
  const double least = CheckEveryFrame(s.model, t, s.options.colliders[0]);
  std::printf("scenario file: %s; least clearance %.3g of a link\n", t.BriefReport().c_str(),
              least);
  std::ostringstream out;
  WriteRobotTrajectoryJson(s, t, out);
  const nlohmann::json doc = nlohmann::json::parse(out.str());
  const nlohmann::json& motion = doc.at("colliders").at(0).at("motion");
  EXPECT_EQ(motion.at("interpolation"), "linear");
  ASSERT_EQ(motion.at("keyframes").size(), 3u);
  EXPECT_EQ(motion.at("keyframes").at(1).at("time"), 20.0);
  EXPECT_EQ(motion.at("keyframes").at(1).at("translation"), nlohmann::json({0.0, 0.6}));
  EXPECT_EQ(doc.at("summary").at("blocked_steps"), t.blocked_steps);

  // A ball whose motion starts on the arm: refused by pointer, naming the time.
  std::string on = text;
  on.replace(on.find("[0.5, -0.4]"), 11, "[0.3, 0.1]");
  const Problems problems = ValidateRobotScenarioText(on);
  ASSERT_FALSE(problems.empty());
  EXPECT_EQ(problems.front().field, "/colliders") << problems.front().Text();
  EXPECT_NE(problems.front().Text().find("at time 0 of its motion"), std::string::npos)
      << problems.front().Text();
}

}  // namespace
}  // namespace flexkin
