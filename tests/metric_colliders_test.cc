// The minimum-rotation and minimum joint-angle rules with colliders (docs/colliders.md, "The other
// sequential metrics"): each link's rule step is kept where the link stays outside every collider;
// where it would enter one, its trailing end takes the clear direction nearest in angle to the
// rule's, and the links behind it move relative to that link (min_rotation: their old directions;
// min_joint_angle: their joint angles). Checked: chains pulled past a sphere, a capsule and a box
// (2D and 3D, 1 and 3 sub-steps) stay outside, sampled along every link with QuerySurface, while
// the free runs cut through; a run that touches nothing is the run without colliders bit for bit;
// the contact step's direction against a dense grid of clear directions; the joint angles behind a
// contact kept.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "chain/substep.h"
#include "collider_test_util.h"
#include "flexkin/chain.h"
#include "flexkin/colliders.h"
#include "flexkin/curves.h"
#include "flexkin/error.h"
#include "flexkin/run.h"
#include "run/sweep_pipeline.h"
#include "scenes/scenes.h"
#include "sequential/sweep.h"
#include "test_util.h"
#include "world/contact.h"

namespace flexkin {
namespace {

using collider_test::At;
using collider_test::Box;
using collider_test::Capsule;
using collider_test::CapsuleBetween;
using collider_test::SampledDistance;
using collider_test::Sphere;
using Eigen::Vector3d;

constexpr Method kMethods[] = {Method::kMinRotation, Method::kMinJointAngle};

// A straight chain of `links` links of 0.5 along +x from the origin, its leading end pulled along
// +y by `pull` in `steps` leader steps.
struct Pulled {
  Chain chain;
  Points path;
};
Pulled PulledChain(int dim, int links, double pull, int steps) {
  Pulled r;
  Points p = Points::Zero(links + 1, dim);
  for (int i = 0; i <= links; ++i) p(i, 0) = 0.5 * i;
  r.chain = MakeChain(p);
  r.path = Points::Zero(steps, dim);
  for (int s = 0; s < steps; ++s) r.path(s, 1) = pull * (s + 1) / steps;
  return r;
}

// The colliders the chain is pulled past: the minimum-rotation chain translates up through the
// region above it, the joint-angle chain swings down about its first link (it ends hanging from
// the leading end), so each meets a collider placed on its own sweep.
std::vector<Collider> Obstacles(Method method, int dim) {
  const double z = dim == 3 ? 0.1 : 0.0;
  const Vector3d at =
      method == Method::kMinRotation ? Vector3d(3.2, 1.5, z) : Vector3d(2.5, -1.6, z);
  return {Sphere(at, 0.5), Capsule(at, 0.4, 1.0), Box(at, Vector3d(0.4, 0.3, 0.5))};
}

// The least sampled distance of any link of any frame of `frames` to `c`, relative to its length
// (0.5 here).
double LeastDistance(const Frames& frames, const Collider& c, int samples = 500) {
  double least = std::numeric_limits<double>::infinity();
  for (const Frame& f : frames) {
    const Points p = f.points;
    for (Eigen::Index i = 1; i < p.rows(); ++i) {
      least = std::fmin(least, SampledDistance(c, At(p, i - 1), At(p, i), samples) / 0.5);
    }
  }
  return least;
}

TEST(MetricCollidersTest, ChainsPulledPastAColliderStayOutsideWhereTheFreeRunCutsThrough) {
  double least_overall = std::numeric_limits<double>::infinity(), worst_length = 0.0;
  for (Method method : kMethods) {
    for (int dim : {2, 3}) {
      for (const Collider& c : Obstacles(method, dim)) {
        for (int substeps : {1, 3}) {
          // Under the sanitizers one sub-step (the same code; test_util::kSanitized).
          if (test_util::kSanitized && substeps > 1) continue;
          SCOPED_TRACE(std::string(MethodName(method)) + " " + std::to_string(dim) + "D " +
                       ColliderShapeName(c.shape) + " substeps " + std::to_string(substeps));
          const Pulled r = PulledChain(dim, 12, 3.0, 60);
          RunOptions options;
          options.method = method;
          options.substeps = substeps;
          const RunResult free = flexkin::Run(r.chain, r.path, options);
          const double free_least = LeastDistance(free.frames, c);
          EXPECT_LT(free_least, -0.1);  // the free run cuts through
          options.colliders = {c};
          const RunResult result = flexkin::Run(r.chain, r.path, options);
          ASSERT_EQ(result.frames.size(), 61u);
          const double least = LeastDistance(result.frames, c);
          double length_error = 0.0;
          for (const Frame& f : result.frames) {
            const Points p = f.points;
            for (Eigen::Index i = 1; i < p.rows(); ++i) {
              length_error =
                  std::fmax(length_error, std::fabs((p.row(i) - p.row(i - 1)).norm() - 0.5));
            }
          }
          EXPECT_GE(least, -1e-12);
          EXPECT_LE(length_error, 1e-13);
          EXPECT_GT(result.contacts.contact_link_steps, 0);
          EXPECT_GE(result.contacts.least_clearance, -1e-12);
          EXPECT_LE(result.metrics.max_relative_length_error, 2e-13);
          // The leading end follows its path.
          EXPECT_LT((Points(result.frames.back().points).row(0) - r.path.row(59)).norm(), 1e-14);
          least_overall = std::fmin(least_overall, least);
          worst_length = std::fmax(worst_length, length_error);
          std::printf(
              "  %-15s %dD %-8s substeps %d: contact link steps %6lld, least sampled "
              "clearance %.2e, run's %.2e, length error %.1e (free run: %.3f)\n",
              MethodName(method), dim, ColliderShapeName(c.shape), substeps,
              static_cast<long long>(result.contacts.contact_link_steps), least,
              result.contacts.least_clearance, length_error, LeastDistance(free.frames, c));
        }
      }
    }
  }
  std::printf("least sampled clearance %.2e of a link, largest length error %.1e\n", least_overall,
              worst_length);
}

TEST(MetricCollidersTest, ARunThatNeverTouchesAColliderIsTheRunWithoutBitForBit) {
  for (Method method : kMethods) {
    for (int dim : {2, 3}) {
      SCOPED_TRACE(std::string(MethodName(method)) + " " + std::to_string(dim) + "D");
      const Chain chain = scenes::CurvedChain(dim, 30, 2.0, 0.08);
      Points path(40, dim);
      for (int s = 0; s < 40; ++s) {
        path.row(s) = chain.points.row(0);
        path(s, 0) += 0.03 * (s + 1);
        path(s, 1) += 0.02 * std::sin(0.2 * s);
        if (dim == 3) path(s, 2) += 0.01 * s;
      }
      RunOptions options;
      options.method = method;
      options.substeps = 3;
      FrameRecorder without;  // the run without colliders on the scalar path the sweep uses
      const RunResult a = internal::RunSubstepBySubstep(chain, path, options, &without);
      // A sphere near the chain's motion that it never reaches (0.05 short of the least distance
      // to its centre of the chain after any sub-step: the run of the sub-steps' heads, one
      // sub-step each, recording every one), and one far away (left out by the broad phase).
      Points heads(3 * path.rows(), dim);
      for (Eigen::Index t = 0; t < path.rows(); ++t) {
        for (int j = 1; j <= 3; ++j) {
          for (int k = 0; k < dim; ++k) {
            heads(3 * t + j - 1, k) = internal::SubstepHead(
                t == 0 ? chain.points(0, k) : path(t - 1, k), path(t, k), j, 3);
          }
        }
      }
      RunOptions each = options;
      each.substeps = 1;
      const RunResult substeps = flexkin::Run(chain, heads, each);
      Vector3d centre;
      double reach = std::numeric_limits<double>::infinity();
      for (double r : {0.3, 0.6, 0.9}) {
        for (int k = 0; k < 8; ++k) {
          const Vector3d candidate = At(chain.points, 15) + r * Vector3d(std::cos(M_PI * k / 4),
                                                                         std::sin(M_PI * k / 4), 0);
          const double distance = LeastDistance(substeps.frames, Sphere(candidate, 0.0), 50) * 0.5;
          if (distance > 0.1 && distance < reach) reach = distance, centre = candidate;
        }
      }
      ASSERT_LT(reach, 1.0);
      options.colliders = {Sphere(centre, reach - 0.05), Sphere(Vector3d(50.0, 50.0, 0.0), 1.0)};
      const RunResult b = flexkin::Run(chain, path, options);
      ASSERT_EQ(b.frames.size(), without.frames.size());
      EXPECT_TRUE(b.frames.all_points() == without.frames.all_points());
      for (size_t f = 0; f < b.frames.size(); ++f) {
        EXPECT_TRUE(b.frames[f].link_angles == without.frames[f].link_angles) << "frame " << f;
      }
      EXPECT_TRUE(a.metrics.l2_per_step == b.metrics.l2_per_step);
      EXPECT_TRUE(a.metrics.l2_weighted_per_step == b.metrics.l2_weighted_per_step);
      EXPECT_TRUE(a.metrics.path_length == b.metrics.path_length);
      EXPECT_EQ(a.metrics.l2_total, b.metrics.l2_total);
      EXPECT_EQ(a.metrics.max_relative_length_error, b.metrics.max_relative_length_error);
      EXPECT_EQ(b.contacts.num_colliders, 2);
      EXPECT_EQ(b.contacts.contact_link_steps, 0);
      EXPECT_GT(b.contacts.least_clearance, 0.0);
      EXPECT_LT(b.contacts.least_clearance, 10.0);  // the near sphere was measured
    }
  }
}

// One sweep of `method` without and with colliders from the same chain: the rule's points and the
// contact sweep's.
struct OneSweep {
  Points free, moved;
  internal::ContactStats stats;
  int first = 0;  // the first link where they differ (0: none)
};
OneSweep Sweep(Method method, const Points& start, const Eigen::VectorXd& head,
               const std::vector<Collider>& colliders) {
  const Chain chain = MakeChain(start);
  const int dim = chain.dim(), n = static_cast<int>(chain.lengths.size());
  const Eigen::VectorXd inv = chain.lengths.cwiseInverse();
  OneSweep s;
  s.free = start;
  s.moved = start;
  // Row-major points (Points is row-major): one sweep of the rule, then of the contact sweep.
  (method == Method::kMinRotation)
      ? internal::SweepsMinRotation(dim, head.data(), 1, n, s.free.data())
      : internal::SweepsMinJointAngle(dim, head.data(), 1, chain.lengths.data(), inv.data(), n,
                                      s.free.data());
  internal::ContactSweep(method, dim, head.data(), chain.lengths.data(), inv.data(), n,
                         s.moved.data(), colliders, &s.stats);
  for (int i = 0; i <= n && s.first == 0; ++i) {
    if (s.free.row(i) != s.moved.row(i)) s.first = i;
  }
  return s;
}

// Unit direction of `d` (2D or 3D row) in 3D.
Vector3d Dir(const Eigen::RowVectorXd& d) {
  return Vector3d(d[0], d[1], d.size() == 3 ? d[2] : 0.0).normalized();
}

TEST(MetricCollidersTest, TheContactStepIsTheClearDirectionNearestTheRulesOne) {
  double worst = -1.0, grid = 0.0;  // found - best: largest; best - found: largest
  for (Method method : kMethods) {
    for (int dim : {2, 3}) {
      // A chain of 6 links of 0.5 along +x; the head moves up by 0.3. Each collider is placed
      // where the rule's link 3 lies after the sweep, a little to one side, so that the rule
      // puts link 3 into it and the links before it (and the old chain) stay clear.
      Points start = Points::Zero(7, dim);
      for (int i = 0; i <= 6; ++i) start(i, 0) = 0.5 * i;
      Eigen::VectorXd head = Eigen::VectorXd::Zero(dim);
      head[1] = 0.3;
      const OneSweep rule = Sweep(method, start, head, {});
      const Vector3d a = At(rule.free, 2), b = At(rule.free, 3), mid = 0.5 * (a + b);
      // Away from the old chain: up for the translated chain, down (across the link, on the
      // side it turned to) for the joint-angle chain.
      const Vector3d across = (method == Method::kMinRotation ? 1.0 : -1.0) *
                              Vector3d(-(b - a).y(), (b - a).x(), 0.0).normalized();
      const Vector3d centre = mid + 0.2 * across + Vector3d(0.05, 0.0, dim == 3 ? 0.04 : 0.0);
      for (const Collider& c : {Sphere(centre, 0.26), Capsule(centre, 0.24, dim == 3 ? 0.3 : 0.0),
                                CapsuleBetween(centre - Vector3d(0.1, 0.05, 0.3),
                                               centre + Vector3d(0.1, 0.0, 0.3), 0.24),
                                Box(centre, Vector3d(0.15, 0.22, 0.3))}) {
        SCOPED_TRACE(std::string(MethodName(method)) + " " + std::to_string(dim) + "D " +
                     ColliderShapeName(c.shape));
        for (int i = 1; i <= 6; ++i) {  // the old chain is clear
          ASSERT_GT(SampledDistance(c, At(start, i - 1), At(start, i)), 0.0) << "link " << i;
        }
        const OneSweep s = Sweep(method, start, head, {c});
        ASSERT_EQ(s.first, 3);  // links 1 and 2 as the rule has them, link 3 in contact
        ASSERT_LT(SampledDistance(c, At(s.free, 2), At(s.free, 3)), 0.0);
        const Vector3d lead = At(s.moved, 2), rule_dir = Dir(s.free.row(3) - s.free.row(2));
        const Vector3d found = Dir(s.moved.row(3) - s.moved.row(2));
        EXPECT_GE(internal::SegmentClearance(c, lead, At(s.moved, 3)), -1e-13 * 0.5);
        const double found_angle = std::acos(std::fmin(1.0, found.dot(rule_dir)));
        // The grid: every clear direction, its angle to the rule's.
        double best = std::numeric_limits<double>::infinity();
        const auto consider = [&](const Vector3d& d) {
          if (internal::SegmentClearance(c, lead, lead + 0.5 * d) >= 0.0) {
            best = std::fmin(best, std::acos(std::fmin(1.0, d.dot(rule_dir))));
          }
        };
        if (dim == 2) {
          for (int k = 0; k < 4000; ++k) {
            const double t = 2.0 * M_PI * k / 4000;
            consider(Vector3d(std::cos(t), std::sin(t), 0.0));
          }
        } else {
          // A fine grid on the cap about the rule's direction that holds the answer: polar angle
          // up to 1.5 times the found one, 300 x 720.
          Vector3d e1 = rule_dir.unitOrthogonal(), e2 = rule_dir.cross(e1);
          for (int i = 1; i <= 300; ++i) {
            const double theta = 1.5 * found_angle * i / 300;
            for (int j = 0; j < 720; ++j) {
              const double phi = 2.0 * M_PI * j / 720;
              consider(std::cos(theta) * rule_dir +
                       std::sin(theta) * (std::cos(phi) * e1 + std::sin(phi) * e2));
            }
          }
        }
        EXPECT_LE(found_angle, best + 1e-9);
        EXPECT_GT(found_angle, best - (dim == 2 ? 2e-3 : 1e-2));  // the grid finds about the same
        EXPECT_GE(s.stats.contact_link_steps, 1);
        worst = std::fmax(worst, found_angle - best);
        grid = std::fmax(grid, best - found_angle);
      }
    }
  }
  std::printf(
      "found angle - grid's best: at most %.2e rad; the grid's best at most %.2e rad "
      "beyond the found one\n",
      worst, grid);
}

// Signed angle from link i to link i + 1 (2D), i = 1 .. n - 1.
double Joint(const Points& p, int i) {
  const Eigen::Vector2d u = (p.row(i) - p.row(i - 1)).transpose();
  const Eigen::Vector2d v = (p.row(i + 1) - p.row(i)).transpose();
  return std::atan2(u.x() * v.y() - u.y() * v.x(), u.dot(v));
}

TEST(MetricCollidersTest, JointAnglesBehindAContactAreKept) {
  // A curved 2D chain swung by the joint-angle rule into a sphere that only link k meets: every
  // joint angle but the one at the contact's leading end (between links k - 1 and k) is the old
  // one, the joints behind link k included.
  const Chain chain = scenes::CurvedChain(2, 10, 2.0, 0.1);
  const Eigen::VectorXd head = chain.points.row(0).transpose() + Eigen::Vector2d(0.05, 0.25);
  const OneSweep rule = Sweep(Method::kMinJointAngle, chain.points, head, {});
  double worst = 0.0;
  for (int k : {3, 5, 8}) {
    SCOPED_TRACE("link " + std::to_string(k));
    const Vector3d a = At(rule.free, k - 1), b = At(rule.free, k);
    const Vector3d old_mid = 0.5 * (At(chain.points, k - 1) + At(chain.points, k));
    const Vector3d mid = 0.5 * (a + b);
    const double length = (b - a).norm();
    // On the far side of the link's new place from its old one.
    const Vector3d centre = mid + 0.28 * length * (mid - old_mid).normalized();
    const Collider c = Sphere(centre, 0.3 * length);
    const OneSweep s = Sweep(Method::kMinJointAngle, chain.points, head, {c});
    ASSERT_EQ(s.first, k);
    ASSERT_EQ(s.stats.contact_link_steps, 1);
    const int n = static_cast<int>(chain.lengths.size());
    for (int j = 1; j < n; ++j) {
      const double change = Joint(s.moved, j) - Joint(chain.points, j);
      if (j == k - 1) {
        EXPECT_GT(std::fabs(change), 1e-3) << "joint " << j;  // the contact turned link k
      } else {
        EXPECT_NEAR(change, 0.0, 1e-12) << "joint " << j;
        worst = std::fmax(worst, std::fabs(change));
      }
    }
    // The links keep their lengths.
    for (int j = 1; j <= n; ++j) {
      EXPECT_NEAR((s.moved.row(j) - s.moved.row(j - 1)).norm(), chain.lengths[j - 1], 1e-14);
    }
  }
  std::printf("largest change of a kept joint angle: %.1e rad\n", worst);
}

TEST(MetricCollidersTest, MinRotationKeepsTheOldDirectionsBehindAContact) {
  // Behind a contact at link k every later link keeps its old direction (no rotation), where it
  // meets nothing.
  const Chain chain = scenes::CurvedChain(3, 10, 2.0, 0.1);
  Eigen::VectorXd head = chain.points.row(0).transpose();
  head += Eigen::Vector3d(0.1, 0.2, -0.05);
  const OneSweep rule = Sweep(Method::kMinRotation, chain.points, head, {});
  const int k = 4;
  const Vector3d a = At(rule.free, k - 1), b = At(rule.free, k), mid = 0.5 * (a + b);
  const Vector3d old_mid = 0.5 * (At(chain.points, k - 1) + At(chain.points, k));
  const double length = (b - a).norm();
  const Collider c = Sphere(mid + 0.28 * length * (mid - old_mid).normalized(), 0.3 * length);
  const OneSweep s = Sweep(Method::kMinRotation, chain.points, head, {c});
  ASSERT_EQ(s.first, k);
  ASSERT_EQ(s.stats.contact_link_steps, 1);
  for (int j = k + 1; j <= 10; ++j) {
    EXPECT_LT((Dir(s.moved.row(j) - s.moved.row(j - 1)) -
               Dir(chain.points.row(j) - chain.points.row(j - 1)))
                  .norm(),
              1e-14)
        << "link " << j;
  }
}

TEST(MetricCollidersTest, BothMethodsTakeColliders) {
  RunOptions options;
  options.colliders = {Sphere(Vector3d(0.0, -5.0, 0.0), 0.5)};
  for (Method method : kMethods) {
    options.method = method;
    EXPECT_TRUE(options.Validate().empty()) << MethodName(method);
  }
}

}  // namespace
}  // namespace flexkin
