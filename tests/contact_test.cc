// Chains against colliders (world/contact.h, RunOptions::colliders): the contact step against an
// independent solution of the same constrained minimization (IPOPT, for spheres) and against a
// brute-force search over directions (every shape, 2D and 3D); runs that never touch a collider
// equal the runs without colliders bit for bit; runs that do keep every link outside every
// collider, sampled independently of the clearance the run uses, with the lengths kept; and bad
// input is refused by field.
#include "world/contact.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "collider_test_util.h"
#include "contact_peer.h"
#include "flexkin/colliders.h"
#include "flexkin/curves.h"
#include "flexkin/run.h"
#include "run/sweep_pipeline.h"
#include "scenes/scenes.h"

namespace flexkin {
namespace {

using collider_test::Sphere;
using Eigen::Vector3d;

// A random unit vector (3D), or one in the plane z = 0 (2D).
Vector3d RandomDirection(int dim, std::mt19937* rng) {
  std::normal_distribution<double> normal;
  Vector3d v(normal(*rng), normal(*rng), dim == 3 ? normal(*rng) : 0.0);
  return v.normalized();
}

// Least signed distance of the link [a, b] to the colliders, by sampling `samples` + 1 points
// along it with QuerySurface (independent of SegmentClearance's closed forms and searches).
double SampledClearance(const std::vector<Collider>& colliders, const Vector3d& a,
                        const Vector3d& b, int samples = 2000) {
  double least = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= samples; ++i) {
    const Vector3d p = a + (static_cast<double>(i) / samples) * (b - a);
    for (const Collider& c : colliders) least = std::fmin(least, QuerySurface(c, p).distance);
  }
  return least;
}

TEST(ContactTest, TheContactStepIsIpoptsSolutionForSpheres) {
  std::mt19937 rng(26);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  int compared = 0;
  double worst = 0.0;
  for (int trial = 0; trial < 400 && compared < 60; ++trial) {
    // One or two spheres; the head on or near the first; the old tail on the far side of it.
    std::vector<Collider> colliders = {Sphere(Vector3d::Zero(), 1.0)};
    std::vector<peers::SphereObstacle> spheres = {{Vector3d::Zero(), 1.0}};
    if (trial % 3 == 2) {
      const Vector3d center = 1.6 * RandomDirection(3, &rng);
      colliders.push_back(Sphere(center, 0.5));
      spheres.push_back({center, 0.5});
    }
    const double length = 0.2 + 0.6 * uniform(rng);
    const Vector3d head = (1.0 + 0.2 * uniform(rng)) * RandomDirection(3, &rng);
    const Vector3d tail = head + length * (-head.normalized() + 0.8 * RandomDirection(3, &rng));
    if (internal::SegmentClearance(colliders, head, head) < 0.0) continue;
    const Vector3d ftl = head + length * (tail - head).normalized();
    if (internal::SegmentClearance(colliders, head, ftl) >= 0.0) continue;  // no contact
    Vector3d ours;
    ASSERT_TRUE(internal::ContactTail(3, head, tail, length, colliders, &ours));
    // IPOPT from the unconstrained step and from points around the head; its best solution.
    Vector3d best;
    double best_objective = std::numeric_limits<double>::infinity();
    std::vector<Vector3d> starts = {ftl};
    for (int k = 0; k < 2; ++k) starts.push_back(head + length * RandomDirection(3, &rng));
    for (const Vector3d& start : starts) {
      Vector3d x;
      if (!peers::IpoptContactTail(head, tail, length, spheres, start, &x)) continue;
      if (internal::SegmentClearance(colliders, head, x) < -1e-10) continue;
      if ((x - tail).squaredNorm() < best_objective) {
        best_objective = (x - tail).squaredNorm();
        best = x;
      }
    }
    if (!std::isfinite(best_objective)) continue;
    SCOPED_TRACE("trial " + std::to_string(trial));
    // Ours is feasible, never worse than IPOPT's best, and the same point.
    EXPECT_NEAR((ours - head).norm(), length, 1e-14);
    EXPECT_GE(internal::SegmentClearance(colliders, head, ours), -1e-13 * length);
    EXPECT_LE((ours - tail).squaredNorm(), best_objective + 1e-12);
    // The same point to 1e-8 (the first sphere's radius is 1).
    EXPECT_LE((ours - best).norm(), 1e-8)
        << "ours " << ours.transpose() << " ipopt " << best.transpose();
    worst = std::fmax(worst, (ours - best).norm());
    if (colliders.size() == 1) {
      // First-order optimality, independent of either solver: x - tail in the span of the
      // length constraint's gradient (x - head) and the clearance's (envelope theorem: s times
      // the unit vector from the center to the segment's nearest point).
      const Vector3d ab = ours - head;
      const double s = std::clamp((-head).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
      Eigen::Matrix<double, 3, 2> basis;
      basis << ab.normalized(), s * (head + s * ab).normalized();
      const Eigen::Vector2d coef = basis.colPivHouseholderQr().solve(ours - tail);
      EXPECT_LE(((ours - tail) - basis * coef).norm(), 1e-9);
    }
    ++compared;
  }
  EXPECT_GE(compared, 50);
  std::cout << compared << " contact steps compared with IPOPT; largest difference " << worst
            << "\n";
}

// Every shape, in 2D and 3D: no direction of a fine grid that keeps the link outside is nearer
// the old tail than the contact step's.
TEST(ContactTest, NoFeasibleDirectionIsNearerThanTheContactStep) {
  std::mt19937 rng(2026);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  int compared = 0;
  for (ColliderShape shape :
       {ColliderShape::kSphere, ColliderShape::kCapsule, ColliderShape::kCylinder,
        ColliderShape::kBox, ColliderShape::kEllipsoid, ColliderShape::kHalfSpace}) {
    for (int dim : {2, 3}) {
      int done = 0;
      for (int trial = 0; trial < 1000 && done < 6; ++trial) {
        Collider c;
        c.shape = shape;
        c.radius = 0.6;
        c.half_length = 0.5;
        c.extents = Vector3d(0.7, 0.5, 0.6);
        if (dim == 3) {
          const Eigen::Quaterniond q = Eigen::Quaterniond::UnitRandom();
          c.pose.linear() = q.toRotationMatrix();
        } else {
          // The shape's z axis (the half-space's normal, the capsule's and cylinder's axis) in
          // the plane.
          c.pose.linear() = (Eigen::AngleAxisd(6.0 * uniform(rng), Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitX()))
                                .matrix();
        }
        const std::vector<Collider> colliders = {c};
        const double length = 0.3 + 0.4 * uniform(rng);
        const Vector3d head = 1.2 * RandomDirection(dim, &rng);
        const Vector3d tail = head + length * (-head.normalized() + RandomDirection(dim, &rng));
        if (internal::SegmentClearance(colliders, head, head) < 0.01) continue;
        const Vector3d ftl = head + length * (tail - head).normalized();
        if (internal::SegmentClearance(colliders, head, ftl) >= 0.0) continue;
        Vector3d ours;
        ASSERT_TRUE(internal::ContactTail(dim, head, tail, length, colliders, &ours));
        SCOPED_TRACE(std::string(ColliderShapeName(shape)) + " dim " + std::to_string(dim));
        EXPECT_NEAR((ours - head).norm(), length, 1e-14);
        EXPECT_GE(SampledClearance(colliders, head, ours), -1e-12 * length);
        if (dim == 2) EXPECT_EQ(ours.z(), 0.0);
        // The grid: 4,000 angles round the circle, or 60 x 120 directions on the cap of the
        // sphere that holds the answer, each link checked at 101 points (a grid point between
        // them could dip in by a little and beat the answer by that little: 1e-6 allowed).
        // A grid point nearer than the answer is checked again at 20,001 points.
        double best = std::numeric_limits<double>::infinity();
        const double ours_objective = (ours - tail).squaredNorm();
        const auto consider = [&](const Vector3d& d) {
          const Vector3d x = head + length * d;
          const double objective = (x - tail).squaredNorm();
          if (objective >= best || SampledClearance(colliders, head, x, 100) < 0.0) return;
          if (objective < ours_objective - 1e-6 &&
              SampledClearance(colliders, head, x, 20000) < 0.0) {
            return;
          }
          best = objective;
        };
        if (dim == 2) {
          for (int k = 0; k < 4000; ++k) {
            const double a = 2.0 * M_PI * k / 4000;
            consider(Vector3d(std::cos(a), std::sin(a), 0.0));
          }
        } else {
          // Only near the answer and the old tail's direction, where the nearest can be.
          const Vector3d d0 = (tail - head).normalized();
          const double reach =
              std::acos(std::clamp((ours - head).normalized().dot(d0), -1.0, 1.0)) + 0.05;
          const Vector3d e1 = d0.unitOrthogonal(), e2 = d0.cross(e1);
          for (int i = 1; i <= 60; ++i) {
            const double theta = reach * i / 60;
            for (int j = 0; j < 120; ++j) {
              const double psi = 2.0 * M_PI * j / 120;
              consider(std::cos(theta) * d0 +
                       std::sin(theta) * (std::cos(psi) * e1 + std::sin(psi) * e2));
            }
          }
        }
        EXPECT_LE((ours - tail).squaredNorm(), best + 1e-6);
        ++done;
        ++compared;
      }
      EXPECT_GE(done, 3) << ColliderShapeName(shape) << " dim " << dim;
    }
  }
  EXPECT_GE(compared, 36);
}

// A rope dragged round a post: a 2D chain hanging along -y from its leading end at the origin,
// which is pulled up to (0, 2) and then along -x; the chain behind cuts the corner, where a post
// (a sphere in the plane) stands 0.05 clear of the leading end's path.
struct PostScene {
  Chain chain;
  Points path;
  std::vector<Collider> colliders;
};
PostScene Post(int links) {
  PostScene scene;
  scene.chain = MakeChain(
      MakeLine(LineDef{Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(0.0, -1.0), links, 2.0 / links}));
  scene.path.resize(100, 2);
  for (int s = 0; s < 100; ++s) {
    scene.path.row(s) = s < 40 ? Eigen::RowVector2d(0.0, 0.05 * (s + 1))
                               : Eigen::RowVector2d(-0.05 * (s - 39), 2.0);
  }
  scene.colliders = {Sphere(Vector3d(-0.35, 1.65, 0.0), 0.3)};
  return scene;
}

// A link nearly parallel to a capsule's axis (hair hanging along a neck), one end inside by a
// hair: its clearance is no more than either end's own distance, however small the angle (the
// closest points of nearly parallel segments are ill-conditioned; once the segment's clearance
// came out 1e-8 of the link above its end's depth, and a chain lying on the neck got wedged).
// The contact search's link test (SegmentClearanceBelow) stops its golden-section search early;
// it must answer as the full search does (SegmentClearance < threshold) for every link and
// threshold: links placed at random about a posed ellipsoid, cylinder and box (through them,
// grazing them, clear of them, and with an end inside), each with thresholds at its clearance, a
// few ulps and a hair either side of it, and far from it. Both sides of the boundary must occur.
// (The test caught links deep in the ellipsoid where its computed distance is not convex: below.)
// Each shape also with a margin, and a fifth of the links from a point of the surface nearly
// along it, a hair in or out (the contact search's links: its head on the surface), which the
// closed-form bound of SegmentClearanceBelow must answer as the search does. With a band (the
// contact search's, a slack above the threshold), the answer is yes wherever the search's is,
// and no wherever the clearance is at least the threshold plus the band.
TEST(ContactTest, TheStoppedLinkTestAnswersAsTheFullSearch) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Collider> shapes(6);
  shapes[0].shape = ColliderShape::kEllipsoid;
  shapes[0].extents = Vector3d(0.3, 0.5, 0.2);
  shapes[1].shape = ColliderShape::kCylinder;
  shapes[1].radius = 0.25;
  shapes[1].half_length = 0.4;
  shapes[2].shape = ColliderShape::kBox;
  shapes[2].extents = Vector3d(0.2, 0.35, 0.15);
  shapes[2].margin = 0.01;
  for (int k = 3; k < 6; ++k) shapes[k] = shapes[k - 3];
  shapes[3].margin = 0.02;
  shapes[4].margin = 0.03;
  shapes[5].margin = 0.0;
  int below = 0, above = 0, checked = 0, held_within_band = 0;
  for (Collider& c : shapes) {
    c.pose.translation() = Vector3d(0.1, -0.2, 0.05);
    c.pose.linear() = Eigen::AngleAxisd(0.7, Vector3d(1.0, 2.0, -0.5).normalized()).matrix();
    for (int k = 0; k < 1000; ++k) {
      Vector3d a = c.pose.translation() + 0.8 * Vector3d(u(rng), u(rng), u(rng));
      Vector3d b = a + (k % 4 == 0 ? 0.05 : 0.6) * Vector3d(u(rng), u(rng), u(rng));
      if (k % 5 == 1) {
        const SurfaceQuery at = QuerySurface(c, a);
        a = at.nearest;
        const Vector3d along = at.normal.cross(Vector3d(u(rng), u(rng), u(rng))).normalized();
        const double tilt = std::pow(10.0, -2.0 - 11.0 * (0.5 + 0.5 * u(rng)));
        b = a + 0.05 * (along + (u(rng) < 0.0 ? -tilt : tilt) * at.normal).normalized();
      }
      const double clearance = internal::SegmentClearance(c, a, b);
      // Deep inside an ellipsoid, near the disc in the plane of its two longer axes from which
      // two points of the surface are nearest (at least 0.08 deep here), its computed distance
      // (Eberly's root near its pole) is noisy at 1e-8 of the depth and not convex at that level,
      // so neither search is exact there; the contact search's thresholds are at the surface
      // (a link that deep is blocked at its first values). Links reaching that deep are left out.
      if (c.shape == ColliderShape::kEllipsoid && clearance + c.margin < -0.05) continue;
      const double ulp =
          4.0 * std::numeric_limits<double>::epsilon() * (1.0 + std::fabs(clearance));
      for (double offset : {0.0, -ulp,   ulp,   -1e-12, 1e-12, -1e-9, 1e-9, -0.1,  0.1,  -1.0,
                            1.0, -1e-13, 1e-13, -3e-14, 3e-14, -1e-6, 1e-6, -1e-3, 1e-3, 0.05}) {
        const double threshold = clearance + offset;
        const bool full = clearance < threshold;
        ASSERT_EQ(internal::SegmentClearanceBelow(c, a, b, threshold), full)
            << ColliderShapeName(c.shape) << " link " << k << " clearance " << clearance
            << " threshold " << threshold << " a " << a.transpose() << " b " << b.transpose();
        (full ? below : above) += 1;
        ++checked;
        const double band = 1e-13 * (b - a).norm();
        const bool banded = internal::SegmentClearanceBelow(c, a, b, threshold, band);
        if (full) ASSERT_TRUE(banded) << ColliderShapeName(c.shape) << " link " << k;
        if (clearance >= threshold + band) {
          ASSERT_FALSE(banded) << ColliderShapeName(c.shape) << " link " << k << " clearance "
                               << clearance << " threshold " << threshold;
        }
        if (banded != full) ++held_within_band;
      }
    }
  }
  std::printf("with the band: %d of %d links held that the search lets through\n", held_within_band,
              checked);
  EXPECT_GT(held_within_band, 0);
  EXPECT_GT(checked, 100000);
  EXPECT_GT(below, 40000);
  EXPECT_GT(above, 40000);
}

TEST(ContactTest, ALinkAlongACapsuleIsNoClearerThanItsEnds) {
  Collider capsule;
  capsule.shape = ColliderShape::kCapsule;
  capsule.radius = 0.05;
  capsule.half_length = 0.105;
  capsule.pose.translation() = Eigen::Vector3d(0.0, 0.0, -0.195);  // from z -0.09 to -0.3
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = -std::numeric_limits<double>::infinity();
  for (int trial = 0; trial < 2000; ++trial) {
    const double length = 0.006;
    const double around = M_PI * u(rng);
    const Eigen::Vector3d radial(std::cos(around), std::sin(around), 0.0);
    const Eigen::Vector3d tangent(-radial.y(), radial.x(), 0.0);
    // Tilts from 1e-16 to 1e-2 rad, toward the axis or away, and a little sideways.
    const double tilt = std::pow(10.0, -16.0 + 14.0 * (0.5 + 0.5 * u(rng))) * (u(rng) < 0 ? -1 : 1);
    Eigen::Vector3d dir = Eigen::Vector3d(0.0, 0.0, -1.0) + tilt * radial + 0.1 * tilt * tangent;
    dir.normalize();
    const Eigen::Vector3d a =
        Eigen::Vector3d(0.0, 0.0, -0.15 + 0.05 * u(rng)) + (0.05 + 1e-9 * u(rng)) * radial;
    const Eigen::Vector3d b = a + length * dir;
    const double ends =
        std::min(QuerySurface(capsule, a).distance, QuerySurface(capsule, b).distance);
    const double clearance = internal::SegmentClearance(capsule, a, b);
    worst = std::max(worst, (clearance - ends) / length);
    EXPECT_LE(clearance, ends + 1e-15 * length) << "trial " << trial << " tilt " << tilt;
    // and no lower than any point of the link is (sampled)
    double sampled = ends;
    for (int k = 1; k < 100; ++k) {
      sampled = std::min(sampled, QuerySurface(capsule, a + (k / 100.0) * (b - a)).distance);
    }
    EXPECT_GE(clearance, sampled - 1e-15 * length) << "trial " << trial;
  }
  std::printf("the segment's clearance above its ends': at most %.2e of the link\n", worst);
}

TEST(ContactTest, ARunThatNeverTouchesAColliderIsTheRunWithout) {
  for (Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
    for (int dim : {2, 3}) {
      const Chain chain = scenes::CurvedChain(dim, 30, 2.0, 1.2);
      Points path(40, dim);
      for (int s = 0; s < 40; ++s) {
        path.row(s) = chain.points.row(0);
        path(s, 0) += 0.03 * (s + 1);
        path(s, 1) += 0.02 * std::sin(0.2 * s);
      }
      RunOptions options;
      options.method = method;
      options.substeps = 3;
      // On the run's pipeline (the wavefront, 30 links) and sub-step by sub-step (the contact
      // sweep): each the same path's run without colliders, bit for bit.
      for (const bool piped : {true, false}) {
        const auto run = [&](const RunOptions& o, FrameRecorder* frames) {
          return piped ? flexkin::Run(chain, path, o, frames)
                       : internal::RunSubstepBySubstep(chain, path, o, frames);
        };
        FrameRecorder without, with;
        RunOptions among = options;
        among.colliders = {Sphere(Vector3d(50.0, 50.0, 0.0), 1.0)};
        const RunResult a = run(options, &without), b = run(among, &with);
        ASSERT_EQ(with.frames.size(), without.frames.size());
        for (size_t f = 0; f < with.frames.size(); ++f) {
          EXPECT_TRUE(with.frames[f].points == without.frames[f].points) << "frame " << f;
        }
        EXPECT_TRUE(a.metrics.l2_per_step == b.metrics.l2_per_step);
        EXPECT_TRUE(a.metrics.path_length == b.metrics.path_length);
        EXPECT_EQ(b.contacts.num_colliders, 1);
        EXPECT_EQ(b.contacts.contact_link_steps, 0);
        EXPECT_GT(b.contacts.least_clearance, 10.0);
      }
    }
  }
}

TEST(ContactTest, ARopeDraggedRoundAPostWrapsRoundItAndNeverEntersIt) {
  for (Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
    const PostScene scene = Post(20);
    RunOptions options;
    options.method = method;
    options.substeps = 4;
    options.colliders = scene.colliders;
    const RunResult result = flexkin::Run(scene.chain, scene.path, options);
    EXPECT_GT(result.contacts.contact_link_steps, 20);
    EXPECT_GE(result.contacts.least_clearance, -1e-13);
    EXPECT_LE(result.metrics.max_relative_length_error, 1e-13);
    double least = std::numeric_limits<double>::infinity();
    for (const Frame& frame : result.frames) {
      for (Eigen::Index i = 1; i < frame.points.rows(); ++i) {
        const Vector3d a(frame.points(i - 1, 0), frame.points(i - 1, 1), 0.0);
        const Vector3d b(frame.points(i, 0), frame.points(i, 1), 0.0);
        least =
            std::fmin(least, SampledClearance(scene.colliders, a, b) / scene.chain.lengths[i - 1]);
      }
    }
    EXPECT_GE(least, -1e-12) << NameOf(method);
    EXPECT_LT(least, 1e-3) << "the chain touched the post";
    // Without the post the chain passes through it.
    options.colliders.clear();
    const RunResult free = flexkin::Run(scene.chain, scene.path, options);
    double free_least = std::numeric_limits<double>::infinity();
    for (const Frame& frame : free.frames) {
      for (Eigen::Index i = 0; i < frame.points.rows(); ++i) {
        free_least = std::fmin(
            free_least,
            QuerySurface(scene.colliders[0], Vector3d(frame.points(i, 0), frame.points(i, 1), 0.0))
                .distance);
      }
    }
    EXPECT_LT(free_least, -0.1 * scene.colliders[0].radius)
        << "the scene must push the chain into the post";
  }
}

TEST(ContactTest, BadInputIsRefusedByField) {
  const PostScene scene = Post(20);
  const auto refused = [&](const RunOptions& options, const std::string& expected) {
    try {
      flexkin::Run(scene.chain, scene.path, options);
      ADD_FAILURE() << "was run; expected a refusal with " << expected;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  RunOptions options;
  options.colliders = {Sphere(Vector3d(0.0, -0.5, 0.0), 0.2)};  // on the chain
  refused(options, "lies inside colliders[0] (sphere)");
  options.colliders = {Sphere(Vector3d(0.03, -0.55, 0.0), 0.04)};  // across link 6 only
  refused(options, "passes through colliders[0]");
  options.colliders = {Sphere(Vector3d(-1.0, 2.0, 0.0), 0.1)};  // on the leader's path
  refused(options, "leader_steps[");
  options.colliders = {Sphere(Vector3d(5.0, 0.0, 0.0), -1.0)};
  refused(options, "colliders[0].radius");
  options.colliders = {Sphere(Vector3d(5.0, 0.0, 0.0), 1.0)};
  options.tolerance = 1e-6;
  refused(options, "accuracy control does not account for colliders");
}

}  // namespace
}  // namespace flexkin
