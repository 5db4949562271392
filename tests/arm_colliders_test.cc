// Fixed-base arms among colliders (ArmOptions::colliders, ArmModel::link_radii; docs/robots.md
// "Colliders"): after every step no link capsule lies inside a collider beyond 1e-12 of its
// length, measured here by the test's own distance computation (not the library's), the base is
// held and the lengths kept, while the same path without the colliders cuts into them; colliders
// that nothing reaches change no bit; starts and targets inside colliders, bad colliders, and
// method fixed_point with colliders on arms with joint axes is refused by name; arms with joint
// axes keep their capsules outside with position targets and with pointing.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "flexkin/arm.h"
#include "flexkin/colliders.h"
#include "flexkin/error.h"
#include "flexkin/robot_scenario.h"
#include "flexkin/urdf.h"
#include "mesh_test_util.h"
#include "scenes/scenes.h"

namespace flexkin {
namespace {

using scenes::CircleOfTargets;
using scenes::CircleTilt;
using scenes::CurledArm;

Eigen::Vector3d At(const Points& p, int i) {
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  for (int k = 0; k < p.cols(); ++k) x[k] = p(i, k);
  return x;
}

// The distance from x to the segment [a, b] (closed form).
double PointSegment(const Eigen::Vector3d& x, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d d = b - a;
  const double dd = d.squaredNorm();
  const double t = dd > 0.0 ? std::clamp((x - a).dot(d) / dd, 0.0, 1.0) : 0.0;
  return (x - (a + t * d)).norm();
}

// A round collider's core, for the test's own distances: a sphere is a capsule of half length 0.
struct Round {
  Eigen::Vector3d a, b;  // the core segment (world)
  double radius;
};

Round CoreOf(const Collider& c) {
  const Eigen::Vector3d axis = c.pose.linear().col(2);
  const double h = c.shape == ColliderShape::kCapsule ? c.half_length : 0.0;
  const Eigen::Vector3d centre = c.pose.translation();
  return {centre - h * axis, centre + h * axis, c.radius + c.margin};
}

// The least signed distance between the link [p, q] (a capsule of radius r) and a round
// collider: the segment-to-segment distance by ternary search along the link of the point's
// distance to the core (a convex function of the link parameter), refined to 200 rounds, less
// both radii.
double LinkClearance(const Eigen::Vector3d& p, const Eigen::Vector3d& q, double r, const Round& c) {
  auto f = [&](double t) { return PointSegment(p + t * (q - p), c.a, c.b); };
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 200; ++i) {
    const double m1 = lo + (hi - lo) / 3.0, m2 = hi - (hi - lo) / 3.0;
    if (f(m1) < f(m2)) {
      hi = m2;
    } else {
      lo = m1;
    }
  }
  const double best = std::min({f(0.0), f(1.0), f(0.5 * (lo + hi))});
  return best - c.radius - r;
}

// The least clearance of the arm's links from the colliders, relative to each link's length.
double RelativeClearance(const ArmModel& model, const Points& points,
                         const std::vector<Collider>& colliders) {
  double least = std::numeric_limits<double>::infinity();
  for (int k = 0; k < model.num_links(); ++k) {
    const double r = model.link_radii.size() > 0 ? model.link_radii[k] : 0.0;
    for (const Collider& c : colliders) {
      least = std::min(least, LinkClearance(At(points, k), At(points, k + 1), r, CoreOf(c)) /
                                  model.link_lengths[k]);
    }
  }
  return least;
}

// The centre of a round collider of radius `reach` (its radius and the link radius) that the free
// run's middle link cuts into by `depth` at some step: beside that link's midpoint, `reach` -
// `depth` away across the link, at least 0.3 clear of the initial arm and of every target, so
// the start and the targets are outside.
bool PlaceObstacle(const ArmModel& model, const Points& path, const ArmTrajectory& free,
                   double reach, double depth, Eigen::Vector3d* centre) {
  const Points start = ForwardKinematics(model, model.initial);
  const int n = model.num_links();
  for (int s = static_cast<int>(free.steps.size()) / 3; s < static_cast<int>(free.steps.size());
       ++s) {
    for (int k = n / 3; k < 2 * n / 3; ++k) {
      const Points& p = free.steps[s].state.points;
      const Eigen::Vector3d along = (At(p, k + 1) - At(p, k)).normalized();
      const Eigen::Vector3d across = along.cross(Eigen::Vector3d::UnitZ()).normalized();
      const Eigen::Vector3d c = 0.5 * (At(p, k) + At(p, k + 1)) + (reach - depth) * across;
      bool clear = true;
      for (int i = 0; i < n && clear; ++i) {
        clear = PointSegment(c, At(start, i), At(start, i + 1)) > reach + 0.3;
      }
      for (int i = 0; i < path.rows() && clear; ++i) clear = (At(path, i) - c).norm() > reach + 0.3;
      if (clear) {
        *centre = c;
        return true;
      }
    }
  }
  return false;
}

// A round collider of radius 0.3 (a capsule: half length 0.5 along z) that the free run's middle
// links cut 0.1 into (PlaceObstacle), into `*obstacle`; how deep the free run cuts into it,
// relative to a link, into `*free_least`.
void ObstacleInTheWay(const ArmModel& model, const Points& path, const ArmTrajectory& free,
                      ColliderShape shape, Collider* obstacle, double* free_least) {
  obstacle->shape = shape;
  obstacle->radius = 0.3;
  if (shape == ColliderShape::kCapsule) obstacle->half_length = 0.5;  // along z
  Eigen::Vector3d centre;
  ASSERT_TRUE(PlaceObstacle(model, path, free, obstacle->radius + 0.05, 0.1, &centre));
  obstacle->pose.translation() = centre;
  *free_least = std::numeric_limits<double>::infinity();
  for (const ArmStepReport& step : free.steps) {
    *free_least = std::min(*free_least, RelativeClearance(model, step.state.points, {*obstacle}));
  }
}

struct Case {
  int dim;
  ColliderShape shape;
  // A cap against regressions that block the arm wholesale, above what was measured
  // (docs/robots.md, "Colliders"): which steps near the collider end blocked depends on the
  // rounding of the Newton solve (planar sphere: 1 blocked in the release build, 3 in the
  // sanitizers' RelWithDebInfo build).
  int max_blocked;
};

class ArmColliders : public ::testing::TestWithParam<Case> {};

// Tracks a circle of targets with a collider in the way of the free motion.
TEST_P(ArmColliders, NoLinkEntersAndTheBaseIsHeld) {
  const Case param = GetParam();
  ArmModel model = CurledArm(param.dim, 12, 0.15);
  model.link_radii = Eigen::VectorXd::Constant(12, 0.05);
  const Points path = CircleOfTargets(model, 2.0, 60, CircleTilt::kRising);
  ArmOptions options;
  const ArmTrajectory free = TrackPath(model, path, options);
  ASSERT_EQ(free.unreached, 0);

  Collider obstacle;
  double free_least = 0.0;
  ObstacleInTheWay(model, path, free, param.shape, &obstacle, &free_least);
  options.colliders = {obstacle};
  EXPECT_LT(free_least, -0.05) << "the free run should cut into the obstacle";

  const ArmTrajectory run = TrackPath(model, path, options);
  const double scale = model.link_lengths.mean();
  int contact_steps = 0;
  for (size_t s = 0; s < run.steps.size(); ++s) {
    const ArmStepReport& step = run.steps[s];
    const Points& p = step.state.points;
    EXPECT_GE(RelativeClearance(model, p, {obstacle}), -1e-12) << "step " << s;
    EXPECT_EQ(At(p, 0), At(ForwardKinematics(model, model.initial), 0)) << "step " << s;
    for (int k = 0; k < model.num_links(); ++k) {
      EXPECT_NEAR((At(p, k + 1) - At(p, k)).norm(), model.link_lengths[k], 1e-12);
    }
    // Contact makes the base's reply piecewise smooth and, in 3D, the contact step a search exact
    // to ~1e-9 of a link: a step either reaches the target to the tolerance, or stalls within
    // 1e-8 of a link (reported, not reached), or is blocked (the arm held where it was).
    const double miss = (At(p, model.num_links()) - At(path, static_cast<int>(s))).norm();
    if (step.reached) {
      EXPECT_LE(step.base_error, 1e-10 * scale) << "step " << s;
      EXPECT_LE(miss, 2e-10 * scale) << "step " << s;
    } else if (!step.blocked) {
      EXPECT_LE(miss, 1e-8 * scale) << "step " << s << ": " << step.BriefReport();
    } else {
      EXPECT_TRUE(p == run.steps[s > 0 ? s - 1 : 0].state.points || s == 0) << "step " << s;
    }
    contact_steps += step.contact ? 1 : 0;
    // The library's clearance agrees with the test's own (relative 1e-9: the library bisects).
    EXPECT_NEAR(step.clearance / scale, RelativeClearance(model, p, {obstacle}), 1e-9);
  }
  EXPECT_GT(contact_steps, 0);
  EXPECT_EQ(run.contact_steps, contact_steps);
  EXPECT_LE(run.blocked_steps, param.max_blocked);
  std::printf(
      "%s: free run %.3g deep; %d contact steps, %d not reached (%d blocked), "
      "least clearance %.3g\n",
      ColliderShapeName(param.shape), -free_least, contact_steps, run.unreached, run.blocked_steps,
      run.min_clearance);
  EXPECT_GE(run.min_clearance, -1e-12 * scale);
}

INSTANTIATE_TEST_SUITE_P(Shapes, ArmColliders,
                         ::testing::Values(Case{2, ColliderShape::kSphere, 4},
                                           Case{3, ColliderShape::kSphere, 2},
                                           Case{3, ColliderShape::kCapsule, 9}),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           return std::string(info.param.dim == 2 ? "Planar" : "Spherical") +
                                  ColliderShapeName(info.param.shape);
                         });

// Colliders that nothing reaches: every step is the free step, bit for bit.
TEST(ArmCollidersFar, ChangeNoBit) {
  for (int dim : {2, 3}) {
    ArmModel model = CurledArm(dim, 16, 0.12);
    model.link_radii = Eigen::VectorXd::Constant(16, 0.1);
    const Points path = CircleOfTargets(model, 2.0, 40, CircleTilt::kTilted45);
    ArmOptions options;
    const ArmTrajectory free = TrackPath(model, path, options);
    Collider far;
    far.radius = 1.0;
    far.pose.translation() = Eigen::Vector3d(100.0, -50.0, 0.0);
    Collider floor;
    floor.shape = ColliderShape::kHalfSpace;
    floor.pose.translation() = Eigen::Vector3d(0.0, 0.0, -40.0);
    options.colliders = {far, floor};
    const ArmTrajectory run = TrackPath(model, path, options);
    ASSERT_EQ(run.steps.size(), free.steps.size());
    for (size_t s = 0; s < run.steps.size(); ++s) {
      EXPECT_TRUE(run.steps[s].state.points == free.steps[s].state.points) << dim << " " << s;
      EXPECT_TRUE(run.steps[s].state.angles.angle == free.steps[s].state.angles.angle);
      EXPECT_EQ(run.steps[s].base_error, free.steps[s].base_error);
      EXPECT_EQ(run.steps[s].passes, free.steps[s].passes);
      EXPECT_FALSE(run.steps[s].contact);
      EXPECT_GT(run.steps[s].clearance, 10.0);
      EXPECT_FALSE(std::isfinite(free.steps[s].clearance));
    }
    EXPECT_EQ(run.contact_steps, 0);
  }
}

std::string MessageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

TEST(ArmCollidersRefused, StartTargetBadColliderAndJointAxes) {
  ArmModel model = StraightArm(2, 8, 1.0);  // points (0,0) ... (8,0)
  model.link_radii = Eigen::VectorXd::Constant(8, 0.1);
  ArmOptions options;
  Collider post;
  post.radius = 0.5;
  post.pose.translation() = Eigen::Vector3d(3.5, 0.45, 0.0);  // 0.15 deep with the radius
  Collider away = post;
  away.pose.translation() = Eigen::Vector3d(-5.0, -5.0, 0.0);
  options.colliders = {away, post};
  Points path(2, 2);
  path << 7.0, 2.0, 6.0, 3.0;
  std::string m = MessageOf([&] { TrackPath(model, path, options); });
  EXPECT_NE(m.find("initial"), std::string::npos) << m;
  EXPECT_NE(m.find("link 4 "), std::string::npos) << m;
  EXPECT_NE(m.find("collider 1 (sphere)"), std::string::npos) << m;
  EXPECT_NE(m.find("by 0.15"), std::string::npos) << m;

  post.pose.translation() = Eigen::Vector3d(6.0, 3.2, 0.0);
  options.colliders = {away, post};
  m = MessageOf([&] { TrackPath(model, path, options); });
  EXPECT_NE(m.find("path[1]"), std::string::npos) << m;
  EXPECT_NE(m.find("collider 1"), std::string::npos) << m;
  m = MessageOf([&] { ArmStep(model, InitialState(model), Eigen::Vector2d(6.0, 3.0), options); });
  EXPECT_NE(m.find("target"), std::string::npos) << m;

  Collider bad;
  bad.radius = -1.0;
  options.colliders = {bad};
  m = MessageOf([&] { TrackPath(model, path, options); });
  EXPECT_NE(m.find("colliders[0]"), std::string::npos) << m;

  model.link_radii = Eigen::VectorXd::Constant(8, -0.1);
  options.colliders = {away};
  m = MessageOf([&] { TrackPath(model, path, options); });
  EXPECT_NE(m.find("link_radii[0]"), std::string::npos) << m;

  // Arms with joint axes take colliders with method newton.
  const ArmModel snake = scenes::RevoluteSnake(8);
  Points p3(1, 3);
  p3.row(0) = ForwardKinematics(snake, snake.initial).row(8);
  ArmOptions fixed_point = options;
  fixed_point.method = FixedBaseMethod::kFixedPoint;
  m = MessageOf([&] { TrackPath(snake, p3, fixed_point); });
  EXPECT_NE(m.find("method"), std::string::npos) << m;
}

// An arm with joint axes (the pitch/yaw snake) tracking a circle with a collider in the way of
// its free motion: the joint-space step with the capsules' clearances as constraints
// (src/arm/joint_space_contact.h). Every link outside after every step, measured by the test's
// own distances; the base held, the lengths kept, the targets reached.
TEST(ArmCollidersJointAxes, NoLinkEntersAndTheTargetsAreReached) {
  for (const ColliderShape shape : {ColliderShape::kSphere, ColliderShape::kCapsule}) {
    SCOPED_TRACE(ColliderShapeName(shape));
    ArmModel model = scenes::RevoluteSnake(12);
    model.link_radii = Eigen::VectorXd::Constant(12, 0.05);
    const Points path = CircleOfTargets(model, 2.0, 60, CircleTilt::kRising);
    ArmOptions options;
    const ArmTrajectory free = TrackPath(model, path, options);
    ASSERT_EQ(free.unreached, 0);
    Collider obstacle;
    double free_least = 0.0;
    ObstacleInTheWay(model, path, free, shape, &obstacle, &free_least);
    options.colliders = {obstacle};
    EXPECT_LT(free_least, -0.05) << "the free run should cut into the obstacle";

    const ArmTrajectory run = TrackPath(model, path, options);
    const double scale = model.link_lengths.mean();
    const Points start = ForwardKinematics(model, model.initial);
    int contact_steps = 0;
    for (size_t s = 0; s < run.steps.size(); ++s) {
      const ArmStepReport& step = run.steps[s];
      const Points& p = step.state.points;
      EXPECT_GE(RelativeClearance(model, p, {obstacle}), -1e-12) << "step " << s;
      EXPECT_EQ(At(p, 0), At(start, 0)) << "step " << s;
      for (int k = 0; k < model.num_links(); ++k) {
        EXPECT_NEAR((At(p, k + 1) - At(p, k)).norm(), model.link_lengths[k], 1e-12);
      }
      contact_steps += step.contact ? 1 : 0;
    }
    EXPECT_GT(contact_steps, 0);
    EXPECT_EQ(run.unreached, 0) << "blocked " << run.blocked_steps;
    EXPECT_LE(run.max_ee_error, 1e-10 * scale);
    EXPECT_GE(run.min_clearance, -1e-12 * scale);
    std::printf(
        "joint axes, %s: free run %.3g deep; %d contact steps, %d not reached, least "
        "clearance %.3g, largest miss %.3g\n",
        ColliderShapeName(shape), -free_least, contact_steps, run.unreached, run.min_clearance,
        run.max_ee_error);
  }
}

// The same snake pointing its tool axis (along a direction 0.3 rad from where it starts, or at a
// point) while it tracks the circle round an obstacle in the way of the free motion: every link
// outside after every step (the test's own distances), the targets reached but for two steps
// where the local step stalls against the obstacle, and the tool axis, from the tool frame at the
// step's joint values, on its goal to 1e-8 rad where the target is reached.
TEST(ArmCollidersJointAxes, PointingRoundAnObstacle) {
  for (const bool look_at : {false, true}) {
    SCOPED_TRACE(look_at ? "looking at a point" : "pointing along a direction");
    ArmModel model = scenes::RevoluteSnake(12);
    model.link_radii = Eigen::VectorXd::Constant(12, 0.05);
    const Points path = CircleOfTargets(model, 2.0, 60, CircleTilt::kRising);
    const ToolPose tool = ToolPoseAt(model, model.initial);
    const Eigen::Vector3d axis0 = tool.rotation.col(0);
    ArmOptions options;
    options.pointing.enabled = true;
    options.pointing.axis = Eigen::Vector3d::UnitX();
    options.pointing.angle_tolerance = 1e-9;
    const Eigen::Vector3d across = axis0.unitOrthogonal();
    const Eigen::Vector3d direction = Eigen::AngleAxisd(0.1, across) * axis0;
    if (look_at) {
      options.pointing.look_at = true;
      options.pointing.point = tool.position + 100.0 * direction;
    } else {
      options.pointing.direction = direction;
    }
    const auto goal_of = [&](const Eigen::Vector3d& end) {
      return look_at ? Eigen::Vector3d((options.pointing.point - end).normalized()) : direction;
    };
    const ArmTrajectory free = TrackPath(model, path, options);
    ASSERT_EQ(free.unreached, 0);
    Collider obstacle;
    double free_least = 0.0;
    ObstacleInTheWay(model, path, free, ColliderShape::kSphere, &obstacle, &free_least);
    options.colliders = {obstacle};
    EXPECT_LT(free_least, -0.05) << "the free run should cut into the obstacle";

    const ArmTrajectory run = TrackPath(model, path, options);
    int contact_steps = 0, not_reached = 0;
    double worst_angle = 0.0, worst_miss = 0.0;
    for (size_t s = 0; s < run.steps.size(); ++s) {
      const ArmStepReport& step = run.steps[s];
      EXPECT_GE(RelativeClearance(model, step.state.points, {obstacle}), -1e-12) << "step " << s;
      contact_steps += step.contact ? 1 : 0;
      if (!step.reached) {
        ++not_reached;
        worst_miss = std::max(worst_miss, step.ee_error);
        continue;
      }
      const ToolPose at = ToolPoseAt(model, step.state.angles);
      const Eigen::Vector3d pointed = at.rotation.col(0), wanted = goal_of(at.position);
      const double angle = std::atan2(pointed.cross(wanted).norm(), pointed.dot(wanted));
      worst_angle = std::max(worst_angle, angle);
      EXPECT_LE(angle, 1e-8) << "step " << s;
      EXPECT_NEAR(step.pointing_error, angle, 1e-9) << "step " << s;
    }
    EXPECT_GT(contact_steps, 0);
    // Measured: 2 of the 60 steps end short of the target (pointing along: misses of 7e-4 and
    // 9e-4 of a link, the arm pressed against the obstacle where the local step stalls;
    // looking at: 5e-10 and 3e-7), reported as not reached, the arm outside; the next steps
    // reach theirs again (docs/robots.md, "Colliders").
    EXPECT_LE(not_reached, 2);
    EXPECT_EQ(run.unreached, not_reached);
    EXPECT_EQ(run.blocked_steps, 0);
    EXPECT_LE(worst_miss, 1e-3 * model.link_lengths.mean());
    std::printf(
        "joint axes, pointing%s: free run %.3g deep; %d contact steps, %d not reached (largest "
        "miss %.3g), least clearance %.3g, largest pointing error %.3g rad\n",
        look_at ? " (look at)" : "", -free_least, contact_steps, not_reached, worst_miss,
        run.min_clearance, worst_angle);
  }
}

// The snake round a triangle mesh: the ball of the test above tessellated (24 round, 12 rings;
// its vertices on the sphere), in the way of the free motion. Every link's capsule outside the
// mesh after every step, by the test's own brute force over every triangle (mesh_test_util.h:
// the side by the winding number, the distance by dense sampling along the link), the targets
// reached.
TEST(ArmCollidersJointAxes, NoLinkEntersAMesh) {
  ArmModel model = scenes::RevoluteSnake(12);
  model.link_radii = Eigen::VectorXd::Constant(12, 0.05);
  const Points path = CircleOfTargets(model, 2.0, 60, CircleTilt::kRising);
  const ArmTrajectory free = TrackPath(model, path, ArmOptions());
  ASSERT_EQ(free.unreached, 0);
  Collider ball;
  double free_least = 0.0;
  ObstacleInTheWay(model, path, free, ColliderShape::kSphere, &ball, &free_least);
  std::vector<std::pair<double, double>> profile;
  for (int i = 0; i <= 12; ++i) {
    const double a = M_PI * i / 12;
    profile.emplace_back(ball.radius * std::sin(a), ball.radius * std::cos(a));
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = ball.pose.translation();
  const Collider mesh = mesh_test::MeshCollider(mesh_test::Lathe(profile, 24), pose);
  const mesh_test::World world = mesh_test::Placed(mesh);
  ArmOptions options;
  options.colliders = {mesh};
  const ArmTrajectory run = TrackPath(model, path, options);
  int contact_steps = 0;
  double least = std::numeric_limits<double>::infinity();
  for (size_t s = 0; s < run.steps.size(); ++s) {
    const ArmStepReport& step = run.steps[s];
    contact_steps += step.contact ? 1 : 0;
    const Points& p = step.state.points;
    for (int k = 0; k < model.num_links(); ++k) {
      const Eigen::Vector3d a = At(p, k), b = At(p, k + 1);
      // Links that cannot come within 0.1 of the ball the mesh lies in are not measured.
      const Eigen::Vector3d c = ball.pose.translation();
      const double t = std::clamp((c - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
      if ((a + t * (b - a) - c).norm() > ball.radius + 0.1) continue;
      bool inside = false;
      for (int i = 0; i <= 40 && !inside; ++i) {
        inside = mesh_test::Winding(world, a + (i / 40.0) * (b - a)) > 0.5;
      }
      const double clearance =
          (inside ? -1.0 : mesh_test::BruteSegmentDistance(world, a, b)) - model.link_radii[k];
      least = std::min(least, clearance / model.link_lengths[k]);
      EXPECT_GE(clearance, -1e-12 * model.link_lengths[k]) << "step " << s << " link " << k;
    }
  }
  EXPECT_GT(contact_steps, 0);
  EXPECT_EQ(run.unreached, 0) << "blocked " << run.blocked_steps;
  EXPECT_LE(run.max_ee_error, 1e-10 * model.link_lengths.mean());
  std::printf(
      "joint axes, mesh (%d triangles): %d contact steps, %lld not reached, least clearance %.3g "
      "(brute force %.3g), largest miss %.3g\n",
      static_cast<int>(mesh.mesh->triangles.rows()), contact_steps,
      static_cast<long long>(run.unreached), run.min_clearance, least, run.max_ee_error);
}

// Robot scenario files: every bad value named by its JSON pointer.
TEST(ArmCollidersScenario, ProblemsNamedByPointer) {
  const std::string head =
      R"({"format": "flexkin-robot", "arm": {"links": 16, "link_length": 0.1}, )";
  const std::string line = R"("path": {"type": "line", "to": [1.2, 0.6], "steps": 40}})";
  auto first = [&](const std::string& middle) {
    const Problems problems = ValidateRobotScenarioText(head + middle + line);
    return problems.empty() ? std::string("(none)") : problems.front().Text();
  };
  EXPECT_EQ(first(R"("colliders": [{"shape": "sphere", "center": [0.8, 0.3], "radius": 0.1}], )"),
            "(none)");
  std::string m =
      first(R"("colliders": [{"shape": "sphere", "center": [0.8, 0], "radius": 0.15}], )");
  EXPECT_NE(m.find("/colliders: link 9 (points 8 to 9"), std::string::npos) << m;
  EXPECT_NE(m.find("collider 0 (sphere) by 0.15"), std::string::npos) << m;
  m = first(R"("colliders": [{"shape": "sphere", "center": [1.2, 0.6], "radius": 0.15}], )");
  EXPECT_NE(m.find("/path (target"), std::string::npos) << m;
  m = first(R"("colliders": [{"shape": "sphere", "center": [1, 1], "radius": -1}], )");
  EXPECT_NE(m.find("/colliders/0/radius"), std::string::npos) << m;
  m = first(R"("link_radius": -2, )");
  EXPECT_NE(m.find("/link_radius"), std::string::npos) << m;
  EXPECT_NE(m.find("-2"), std::string::npos) << m;
  m = first(R"("link_radius": [1, 2], )");
  EXPECT_NE(m.find("/link_radius"), std::string::npos) << m;
  EXPECT_NE(m.find("16"), std::string::npos) << m;
  const RobotScenario s = ParseRobotScenarioText(head + R"("link_radius": 0.02, )" + line);
  EXPECT_TRUE(s.model.link_radii == Eigen::VectorXd::Constant(16, 0.02));
}

// The demo's URDF: the link radius from each module's collision cylinder, the scenario's value
// only for links without one.
TEST(ArmCollidersUrdf, RadiusFromCollisionGeometry) {
  const std::string urdf = std::string(FLEXKIN_SOURCE_DIR) + "/examples/snake_robot_16.urdf";
  const ArmModel model = ArmFromUrdfFile(urdf);
  ASSERT_EQ(model.dim, 2);  // every joint about z: a planar arm, which takes colliders
  ASSERT_EQ(model.num_links(), 16);
  EXPECT_TRUE(model.link_lengths.isApproxToConstant(0.1, 1e-15));
  EXPECT_TRUE(model.link_radii == Eigen::VectorXd::Constant(16, 0.03));
  EXPECT_EQ(model.joint_max[1], 0.8);
  const std::string text = R"({"format": "flexkin-robot", "urdf": ")" + urdf +
                           R"(", "link_radius": 0.01, "colliders": [{"shape": "sphere",
      "center": [0.8, 0.25], "radius": 0.15}], "path": {"type": "line", "to": [1.2, 0.6],
      "steps": 40}})";
  const RobotScenario s = ParseRobotScenarioText(text, UrdfRobotScenarioOptions());
  EXPECT_TRUE(s.model.link_radii == Eigen::VectorXd::Constant(16, 0.03));
  const ArmTrajectory t = TrackPath(s.model, s.path, s.options);
  EXPECT_EQ(t.unreached, 0);
  for (const ArmStepReport& step : t.steps) {
    EXPECT_GE(RelativeClearance(s.model, step.state.points, s.options.colliders), -1e-12);
  }
}

}  // namespace
}  // namespace flexkin
