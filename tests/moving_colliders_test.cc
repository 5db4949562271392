// Keyframed colliders in chain runs (Collider::motion, docs/colliders.md "Moving colliders"): a
// collider is placed by its motion at the time of every sub-step (leader steps: sub-step j of m of
// step s at s - 1 + j / m), and each link takes the least motion that keeps it outside, so a
// collider that sweeps across a resting chain pushes it aside. Checked: every link of every
// sub-step outside the collider where its motion has it (sampled along the link, independent of
// the run's clearances), the lengths kept, the step the nearest clear position (a dense search of
// directions), the motion's pose (interpolation, composition with the collider's own pose), the
// times of sub-steps (through the refusal that names them), bits unchanged for a motion that
// stands still or never reaches the chain, and the refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "collider_test_util.h"
#include "flexkin/chain.h"
#include "flexkin/colliders.h"
#include "flexkin/error.h"
#include "flexkin/run.h"
#include "run/sweep_pipeline.h"
#include "world/contact.h"

namespace flexkin {
namespace {

using collider_test::At;
using collider_test::Box;
using collider_test::Capsule;
using collider_test::SampledDistance;
using collider_test::Sphere;
using Eigen::Vector3d;

std::shared_ptr<const ColliderMotion> Slide(const Vector3d& from, const Vector3d& to, double t0,
                                            double t1, KeyframeInterpolation interpolation) {
  auto m = std::make_shared<ColliderMotion>();
  BodyKeyframe a, b;
  a.time = t0;
  a.pose.translation = from;
  b.time = t1;
  b.pose.translation = to;
  m->keyframes = {a, b};
  m->interpolation = interpolation;
  return m;
}

// A straight chain of `links` unit links along +x from the origin, its leading end (point 0)
// held still for `steps` leader steps.
struct Resting {
  Chain chain;
  Points path;
};
Resting RestingChain(int dim, int links, int steps) {
  Resting r;
  Points p = Points::Zero(links + 1, dim);
  for (int i = 0; i <= links; ++i) p(i, 0) = i;
  r.chain = MakeChain(p);
  r.path = Points::Zero(steps, dim);
  return r;
}

TEST(MovingCollidersTest, ASphereSweepingAcrossARestingChainPushesEveryLinkAsideAndNeverIn) {
  for (int dim : {2, 3}) {
    for (Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
      for (int substeps : {1, 3}) {
        const Resting r = RestingChain(dim, 12, 120);
        RunOptions options;
        options.method = method;
        options.substeps = substeps;
        // A sphere of radius 0.8 crossing the chain at x = 6 from y = -2 to y = +2 (a little off
        // z = 0 in 3D), over leader steps 10 to 100.
        Collider c = Sphere(Vector3d(6.0, 0.0, dim == 3 ? 0.1 : 0.0), 0.8);
        c.motion = Slide(Vector3d(0, -2.0, 0), Vector3d(0, 2.0, 0), 10.0, 100.0,
                         KeyframeInterpolation::kSmooth);
        options.colliders = {c};
        const RunResult result = flexkin::Run(r.chain, r.path, options);
        ASSERT_EQ(result.frames.size(), 121u);
        double least = std::numeric_limits<double>::infinity(), moved = 0.0;
        for (const Frame& f : result.frames) {
          const Points p = f.points;
          const Collider at = ColliderAt(c, double(f.step));
          for (Eigen::Index i = 1; i < p.rows(); ++i) {
            least = std::fmin(least, SampledDistance(at, At(p, i - 1), At(p, i), 400));
            EXPECT_NEAR((p.row(i) - p.row(i - 1)).norm(), 1.0, 1e-13);
          }
          moved = std::fmax(moved, (p - r.chain.points).rowwise().norm().maxCoeff());
        }
        SCOPED_TRACE(std::to_string(dim) + "D " + MethodName(method) + " substeps " +
                     std::to_string(substeps));
        EXPECT_GE(least, -1e-12);
        EXPECT_GT(moved, 0.5);  // the sphere moved the chain aside (it would have cut through)
        EXPECT_GT(result.contacts.contact_link_steps, 10);
        EXPECT_EQ(result.frames[0].points, r.chain.points);
        // The leading end stays where it is held.
        EXPECT_EQ(Points(result.frames.back().points).row(0), r.chain.points.row(0));
      }
    }
  }
}

TEST(MovingCollidersTest, AStepFromATailInsideIsTheNearestClearPositionOfAllDirections) {
  // The contact step when the collider has moved onto the old tail: no direction round the head
  // is clear and nearer the old tail (200,000 directions in 2D; a 400 x 800 grid in 3D).
  const Vector3d head(0.0, 0.0, 0.0);
  for (int dim : {2, 3}) {
    for (const Collider& c : {Sphere(Vector3d(1.0, 0.3, 0.0), 0.5),
                              Box(Vector3d(1.1, -0.2, 0.0), Vector3d(0.3, 0.4, 0.5)),
                              Capsule(Vector3d(0.9, 0.1, 0.0), 0.3, dim == 3 ? 0.6 : 0.0)}) {
      const Vector3d tail_old(1.0, 0.05, dim == 3 ? 0.02 : 0.0);
      ASSERT_LT(QuerySurface(c, tail_old).distance, 0.0);
      Vector3d x;
      ASSERT_TRUE(internal::ContactTail(dim, head, tail_old, 1.0, {c}, &x));
      EXPECT_NEAR((x - head).norm(), 1.0, 1e-14);
      EXPECT_GE(internal::SegmentClearance(c, head, x), -1e-13);
      const double found = (x - tail_old).norm();
      double best = std::numeric_limits<double>::infinity();
      const auto consider = [&](const Vector3d& d) {
        const Vector3d y = head + d;
        if (internal::SegmentClearance(c, head, y) >= 0.0) {
          best = std::fmin(best, (y - tail_old).norm());
        }
      };
      if (dim == 2) {
        for (int k = 0; k < 200000; ++k) {
          const double a = 2.0 * M_PI * k / 200000;
          consider(Vector3d(std::cos(a), std::sin(a), 0.0));
        }
      } else {
        for (int i = 0; i <= 400; ++i) {
          const double theta = M_PI * i / 400;
          for (int j = 0; j < 800; ++j) {
            const double phi = 2.0 * M_PI * j / 800;
            consider(Vector3d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                              std::cos(theta)));
          }
        }
      }
      SCOPED_TRACE(std::string(ColliderShapeName(c.shape)) + " " + std::to_string(dim) + "D");
      EXPECT_LE(found, best + 1e-9);
      EXPECT_GT(found, best - (dim == 2 ? 1e-4 : 1e-2));  // the grid finds nearly the same
    }
  }
}

TEST(MovingCollidersTest, TheMotionCarriesTheCollidersOwnPose) {
  // Linear: halfway between two keyframes, half the translation; smooth: 3u^2 - 2u^3 of it; the
  // collider's own pose is carried (motion pose * pose), and outside the keyframes the pose
  // stays.
  Collider c = Capsule(Vector3d(1.0, 2.0, 3.0), 0.5, 1.0);
  auto m = std::make_shared<ColliderMotion>();
  BodyKeyframe a, b;
  a.time = 2.0;
  b.time = 6.0;
  b.pose = BodyPose::FromQuaternion(std::cos(M_PI / 4), 0.0, 0.0, std::sin(M_PI / 4),
                                    Vector3d(10.0, 0.0, 0.0));  // a quarter turn about z
  m->keyframes = {a, b};
  m->interpolation = KeyframeInterpolation::kLinear;
  c.motion = m;
  EXPECT_EQ(ColliderAt(c, 0.0).pose.translation(), Vector3d(1.0, 2.0, 3.0));
  EXPECT_TRUE(ColliderAt(c, 2.0).pose.isApprox(c.pose, 0.0));
  EXPECT_EQ(ColliderAt(c, 2.0).motion, nullptr);
  const Collider end = ColliderAt(c, 9.0);
  EXPECT_NEAR((end.pose.translation() - Vector3d(10.0 - 2.0, 1.0, 3.0)).norm(), 0.0, 1e-14);
  const Collider mid = ColliderAt(c, 4.0);  // u = 1/2: 45 degrees, translation (5, 0, 0)
  const double h = std::sqrt(0.5);
  EXPECT_NEAR(
      (mid.pose.translation() - Vector3d(5.0 + h * 1.0 - h * 2.0, h * 1.0 + h * 2.0, 3.0)).norm(),
      0.0, 1e-14);
  m->interpolation = KeyframeInterpolation::kSmooth;
  const Collider quarter = ColliderAt(c, 3.0);  // u = 1/4: s = 3/16 - 2/64 = 5/32
  const double angle = (5.0 / 32.0) * (M_PI / 2);
  const Vector3d rotated(std::cos(angle) * 1.0 - std::sin(angle) * 2.0,
                         std::sin(angle) * 1.0 + std::cos(angle) * 2.0, 3.0);
  EXPECT_NEAR((quarter.pose.translation() - (rotated + Vector3d(10.0 * 5.0 / 32.0, 0, 0))).norm(),
              0.0, 1e-14);
}

TEST(MovingCollidersTest, AMotionThatStaysOrNeverReachesTheChainChangesNoBit) {
  for (int dim : {2, 3}) {
    Points p(9, dim);
    p.setZero();
    for (int i = 0; i <= 8; ++i) p(i, 1) = -0.5 * i;
    const Chain chain = MakeChain(p);
    Points path(60, dim);
    path.setZero();
    for (int s = 0; s < 60; ++s) path(s, 0) = 0.05 * (s + 1);
    RunOptions options;
    options.substeps = 2;
    // A sphere below the chain's reach, held where it is by a motion: the run with it static,
    // bit for bit (sub-step by sub-step, as runs with moving colliders go).
    options.colliders = {Sphere(Vector3d(0.0, -6.0, 0.0), 0.2)};
    FrameRecorder still_frames;
    const RunResult still = internal::RunSubstepBySubstep(chain, path, options, &still_frames);
    RunOptions held = options;
    Collider c = options.colliders[0];
    auto stays = std::make_shared<ColliderMotion>();
    stays->keyframes.resize(1);  // one keyframe at the identity: the collider where it is
    c.motion = stays;
    held.colliders = {c};
    const RunResult same = flexkin::Run(chain, path, held);
    EXPECT_EQ(same.frames.all_points(), still_frames.frames.all_points());
    EXPECT_EQ(same.contacts.contact_link_steps, still.contacts.contact_link_steps);
    // Moving far away, never near the chain: the run without colliders, bit for bit.
    c.pose.translation() = Vector3d(50.0, 0.0, 0.0);
    c.motion = Slide(Vector3d::Zero(), Vector3d(0.0, 30.0, 0.0), 0.0, 60.0,
                     KeyframeInterpolation::kLinear);
    held.colliders = {c};
    RunOptions none = options;
    none.colliders.clear();
    FrameRecorder without;  // the run without colliders on the scalar path the contact sweep uses
    internal::RunSubstepBySubstep(chain, path, none, &without);
    EXPECT_EQ(flexkin::Run(chain, path, held).frames.all_points(), without.frames.all_points());
  }
}

TEST(MovingCollidersTest, AColliderReachingTheLeadingEndIsRefusedWithItsSubStep) {
  // The sphere reaches the held leading end after time 2.4: with 2 sub-steps the first sub-step
  // that sees it is sub-step 1 of leader step 3 (leader_steps[2], time 2.5), with 4 sub-steps
  // sub-step 2 of it (time 2.5; at 2.25 it is still 0.15 away).
  const Resting r = RestingChain(2, 4, 6);
  Collider c = Sphere(Vector3d(-3.4, 0.0, 0.0), 1.0);
  c.motion = Slide(Vector3d::Zero(), Vector3d(3.0, 0.0, 0.0), 0.0, 3.0,
                   KeyframeInterpolation::kLinear);  // its edge at x = -2.4 + t
  for (const auto& [substeps, substep] : {std::pair{2, 1}, std::pair{4, 2}}) {
    RunOptions options;
    options.substeps = substeps;
    options.colliders = {c};
    try {
      flexkin::Run(r.chain, r.path, options);
      ADD_FAILURE() << "not refused";
    } catch (const InputError& e) {
      EXPECT_EQ(e.problem().field, "leader_steps[2]");
      EXPECT_NE(std::string(e.what()).find("sub-step " + std::to_string(substep) + " "),
                std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find("moving"), std::string::npos) << e.what();
    }
  }
}

TEST(MovingCollidersTest, StartsAndMotionsThatAreNotValidAreRefusedByName) {
  const Resting r = RestingChain(3, 4, 6);
  RunOptions options;
  // Inside at time 0 of the motion (where the motion puts it, not where its pose alone does).
  Collider c = Sphere(Vector3d(20.0, 0.0, 0.0), 0.5);
  c.motion =
      Slide(Vector3d(-18.0, 0.0, 0.0), Vector3d::Zero(), 0.0, 5.0, KeyframeInterpolation::kSmooth);
  options.colliders = {c};
  try {
    flexkin::Run(r.chain, r.path, options);
    ADD_FAILURE() << "not refused";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem().field, "points[2]");
    EXPECT_NE(std::string(e.what()).find("at time 0 of its motion"), std::string::npos) << e.what();
  }
  // Keyframe times that do not increase, a pose that is not a rotation, no keyframes.
  auto bad = std::make_shared<ColliderMotion>(*c.motion);
  bad->keyframes[1].time = 0.0;
  bad->keyframes[0].pose.rotation(0, 0) = 2.0;
  c.motion = bad;
  Problems problems = CheckCollider(c, "colliders[0]");
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0].field, "colliders[0].motion.keyframes[0].pose");
  EXPECT_EQ(problems[1].field, "colliders[0].motion.keyframes[1].time");
  c.motion = std::make_shared<ColliderMotion>();
  problems = CheckCollider(c, "/colliders/0");
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].field, "/colliders/0/motion/keyframes");
  // The overall method's L2 metric takes static colliders only (its still points are a tail).
  c.motion = Slide(Vector3d::Zero(), Vector3d::UnitX(), 0.0, 1.0, KeyframeInterpolation::kLinear);
  options.colliders = {c};
  options.method = Method::kOverall;
  options.overall.weights.l2 = 1.0;
  try {
    flexkin::Run(r.chain, r.path, options);
    ADD_FAILURE() << "not refused";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem().field, "overall.weights.l2");
    EXPECT_NE(std::string(e.what()).find("moving collider"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace flexkin
