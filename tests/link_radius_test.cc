// Links with a radius (RunOptions::link_radius, Collider::margin): each link is a capsule about
// its axis, kept outside the colliders by keeping its axis outside each collider grown by the
// radius. A grown sphere or capsule is the sphere or capsule of the larger radius, bit for bit; a
// box's or a floor's distance to every link, measured independently on the shapes as given, never
// falls below the radius; grown distances are the shapes' less the margin; and the radius is
// checked and named where it makes a start invalid.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "collider_test_util.h"
#include "flexkin/chain.h"
#include "flexkin/colliders.h"
#include "flexkin/error.h"
#include "flexkin/run.h"

namespace flexkin {
namespace {

using collider_test::At;
using collider_test::Box;
using collider_test::Capsule;
using collider_test::SampledDistance;
using collider_test::Sphere;
using Eigen::Vector3d;

// A rope of `links` links of total length 2 hanging along -y from the origin (2D) or along -y in
// the plane z = `z` (3D), its leading end pulled up to y = 2 and then along -x: the rope behind
// cuts the corner at (0, 2).
struct Scene {
  Chain chain;
  Points path;
};
Scene Corner(int dim, int links, double z = 0.0) {
  Scene s;
  Points points(links + 1, dim);
  for (int i = 0; i <= links; ++i) {
    points(i, 0) = 0.0;
    points(i, 1) = -2.0 * i / links;
    if (dim == 3) points(i, 2) = z;
  }
  s.chain = MakeChain(points);
  s.path.resize(100, dim);
  for (int k = 0; k < 100; ++k) {
    s.path(k, 0) = k < 40 ? 0.0 : -0.05 * (k - 39);
    s.path(k, 1) = k < 40 ? 0.05 * (k + 1) : 2.0;
    if (dim == 3) s.path(k, 2) = z;
  }
  return s;
}

TEST(LinkRadiusTest, AGrownSphereOrCapsuleIsTheLargerOneBitForBit) {
  for (int dim : {2, 3}) {
    for (Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
      const Scene scene = Corner(dim, 24);
      const double r = 0.0625;  // a power of two: R + r is exact, as the grown shape's sum is
      for (bool capsule : {false, true}) {
        const Vector3d center(-0.35, 1.65, 0.0);
        const Collider given =
            capsule ? Capsule(center, 0.2375, dim == 3 ? 0.5 : 0.0) : Sphere(center, 0.2375);
        Collider larger = given;
        larger.radius = given.radius + r;
        RunOptions grown;
        grown.method = method;
        grown.substeps = 2;
        grown.colliders = {given};
        grown.link_radius = r;
        RunOptions plain = grown;
        plain.colliders = {larger};
        plain.link_radius = 0.0;
        SCOPED_TRACE(std::string("dim ") + std::to_string(dim) + ", " + NameOf(method) +
                     (capsule ? ", capsule" : ", sphere"));
        RunResult a, b;
        try {
          a = flexkin::Run(scene.chain, scene.path, grown);
          b = flexkin::Run(scene.chain, scene.path, plain);
        } catch (const InputError& e) {
          ADD_FAILURE() << e.what();
          continue;
        }
        ASSERT_EQ(a.frames.size(), b.frames.size());
        EXPECT_GT(a.contacts.contact_link_steps, 10) << "the rope must touch the post";
        EXPECT_EQ(a.contacts.contact_link_steps, b.contacts.contact_link_steps);
        for (size_t f = 0; f < a.frames.size(); ++f) {
          ASSERT_TRUE(a.frames[f].points == b.frames[f].points)
              << "dim " << dim << ", " << NameOf(method) << (capsule ? ", capsule" : ", sphere")
              << ", frame " << f;
        }
      }
    }
  }
}

TEST(LinkRadiusTest, EveryLinkStaysItsRadiusAwayFromABoxAndAFloor) {
  for (int dim : {2, 3}) {
    const Scene scene = Corner(dim, 30, 0.2);
    const double r = 0.04;
    // A box at the corner, and (3D) a floor just under the rope's plane, which the rope's
    // thickness reaches: the links slide along it at height r.
    std::vector<Collider> colliders = {Box(Vector3d(-0.4, 1.6, 0.0), Vector3d(0.2, 0.25, 1.0))};
    if (dim == 3) {
      Collider floor;
      floor.shape = ColliderShape::kHalfSpace;
      floor.pose.translation() = Vector3d(0.0, 0.0, 0.2 - r - 0.01);
      colliders.push_back(floor);
    }
    RunOptions options;
    options.substeps = 3;
    options.colliders = colliders;
    options.link_radius = r;
    const RunResult result = flexkin::Run(scene.chain, scene.path, options);
    EXPECT_GT(result.contacts.contact_link_steps, 10);
    EXPECT_LE(result.metrics.max_relative_length_error, 1e-13);
    // The reported clearance is the capsules' surfaces': never below the rounding.
    EXPECT_GE(result.contacts.least_clearance, -1e-13);
    double least = std::numeric_limits<double>::infinity();
    for (const Frame& frame : result.frames) {
      for (Eigen::Index i = 1; i < frame.points.rows(); ++i) {
        for (const Collider& c : colliders) {
          least = std::fmin(least,
                            SampledDistance(c, At(frame.points, i - 1), At(frame.points, i)) - r);
        }
      }
    }
    // Sampling sees a segment's nearest point to within its spacing (1e-3 of a link) squared:
    // the capsules keep out to the rounding.
    EXPECT_GE(least / (2.0 / 30), -1e-12) << "dim " << dim;
    EXPECT_LT(least, 1e-3) << "the rope must touch the box";
  }
}

TEST(LinkRadiusTest, GrownDistancesAreTheShapesLessTheMargin) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  std::vector<Collider> shapes = {Sphere(Vector3d(0.1, 0.2, 0.3), 0.7),
                                  Capsule(Vector3d(0.0, 0.1, 0.0), 0.3, 0.6),
                                  Box(Vector3d(0.2, 0.0, -0.1), Vector3d(0.5, 0.3, 0.4))};
  Collider floor;
  floor.shape = ColliderShape::kHalfSpace;
  shapes.push_back(floor);
  for (Collider c : shapes) {
    for (int k = 0; k < 500; ++k) {
      const Vector3d x(u(rng), u(rng), u(rng));
      c.margin = 0.0;
      const SurfaceQuery base = QuerySurface(c, x);
      c.margin = 0.15;
      const SurfaceQuery grown = QuerySurface(c, x);
      EXPECT_NEAR(grown.distance, base.distance - 0.15, 1e-15);
      // The grown surface's nearest point is the margin out from the shape's, and x's distance to
      // it is the grown distance's size (outside the grown shape, where it is unique).
      if (grown.distance > 0.0) {
        EXPECT_NEAR((x - grown.nearest).norm(), grown.distance, 1e-12);
        EXPECT_NEAR(QuerySurface(c, grown.nearest).distance, 0.0, 1e-12);
      }
    }
  }
}

TEST(LinkRadiusTest, ARadiusThatPutsTheStartInsideIsNamedAndBadRadiiAreRefused) {
  const Scene scene = Corner(2, 10);
  RunOptions options;
  // The post is 0.05 clear of the rope's leading end: a radius of 0.1 puts the start inside.
  options.colliders = {Sphere(Vector3d(-0.35, 0.0, 0.0), 0.3)};
  options.link_radius = 0.1;
  try {
    flexkin::Run(scene.chain, scene.path, options);
    ADD_FAILURE() << "a start within the link radius of a collider must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("grown by the link radius 0.1"), std::string::npos)
        << e.what();
  }
  options.link_radius = 0.04;
  EXPECT_NO_THROW(flexkin::Run(scene.chain, scene.path, options));
  for (double bad :
       {-0.1, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    options.link_radius = bad;
    const Problems problems = options.Validate();
    ASSERT_EQ(problems.size(), 1u) << bad;
    EXPECT_EQ(problems[0].field, "link_radius");
    EXPECT_NE(problems[0].message.find("a finite number >= 0"), std::string::npos)
        << problems[0].message;
  }
  Collider bad = Sphere(Vector3d::Zero(), 1.0);
  bad.margin = -1.0;
  const Problems problems = CheckCollider(bad, "/colliders/0");
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].field, "/colliders/0/margin");
}

}  // namespace
}  // namespace flexkin
