// The contact sweep's broad phase (src/sequential/contact_sweep.cc): colliders farther from the
// head than the chain's length are left out of a sweep only where they cannot lower the least
// clearance measured so far. Checked on the snake of examples/snake_robot_16.urdf (16 links of
// 0.1, pegs grown by its link radius 0.03) threading the 20 pegs of examples/snake_pegs.json: the
// same sweeps with a fresh ContactStats (least clearance +inf, so nothing is left out) give the
// same points bit for bit, and the least clearance over fresh sweeps is the cumulative one.
// The same for the links: a link is not measured against a collider whose bounding ball (for a
// sphere, the sphere; for a mesh, also the box of its hierarchy) it is beyond by more than the
// least clearance so far; checked in 3D on a chain dragged through a tessellated post, a ball,
// a box and past a floor, with every sequential rule.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "flexkin/colliders.h"
#include "flexkin/vocabulary.h"
#include "mesh_test_util.h"
#include "sequential/sweep.h"

namespace flexkin {
namespace {

using mesh_test::CapsuleMesh;
using mesh_test::MeshCollider;

TEST(ContactBroadPhase, SameSweepsBitForBitAndTheSameLeastClearance) {
  constexpr double kPi = 3.14159265358979323846;
  std::vector<Collider> pegs(20);
  for (int k = 0; k < 20; ++k) {
    pegs[k].radius = 0.3;
    pegs[k].margin = 0.03;
    pegs[k].pose.translation() = Eigen::Vector3d(k + 1.0, 0.0, 0.0);
  }
  const int n = 16;
  std::vector<double> lengths(n, 0.1), inv(n, 10.0);
  std::vector<double> a(2 * (n + 1)), b;
  for (int i = 0; i <= n; ++i) a[2 * i] = -0.1 * i, a[2 * i + 1] = -0.5;
  b = a;
  internal::ContactStats cumulative;
  double least_fresh = std::numeric_limits<double>::infinity();
  long long contacts_fresh = 0;
  for (int step = 1; step <= 21 * 160; ++step) {
    const double x = step / 160.0;
    const double head[2] = {x, 0.5 * std::sin(kPi * (x - 0.5))};
    internal::ContactSweep(Method::kTractrix, 2, head, lengths.data(), inv.data(), n, a.data(),
                           pegs, &cumulative);
    internal::ContactStats fresh;
    internal::ContactSweep(Method::kTractrix, 2, head, lengths.data(), inv.data(), n, b.data(),
                           pegs, &fresh);
    least_fresh = std::fmin(least_fresh, fresh.least_clearance);
    contacts_fresh += fresh.contact_link_steps;
    ASSERT_TRUE(a == b) << "step " << step;
  }
  EXPECT_EQ(cumulative.least_clearance, least_fresh);
  EXPECT_EQ(cumulative.contact_link_steps, contacts_fresh);
  EXPECT_GT(contacts_fresh, 1000);
}

TEST(ContactBroadPhase, LinksBeyondABoundAreLeftOutWithTheSameBitsIn3d) {
  // A chain of 20 links of 0.1 hanging along -y from the origin, its head dragged along +x to 3 in
  // 150 steps, past a post (a capsule of 0.1 along z tilted about x, as a mesh of 20 segments
  // round) standing in its way, a ball and a box it passes, and a floor below.
  Eigen::Isometry3d tilt = Eigen::Isometry3d::Identity();
  tilt.translation() = Eigen::Vector3d(0.22, -0.22, 0.1);
  tilt.linear() = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  std::vector<Collider> colliders = {MeshCollider(CapsuleMesh(0.1, 0.5, 20, 5), tilt)};
  Collider ball;
  ball.radius = 0.1;
  ball.margin = 0.01;
  ball.pose.translation() = Eigen::Vector3d(1.0, -1.0, 0.0);
  Collider box;
  box.shape = ColliderShape::kBox;
  box.extents = Eigen::Vector3d(0.08, 0.05, 0.3);
  box.pose.translation() = Eigen::Vector3d(1.5, -0.5, -0.05);
  Collider floor;
  floor.shape = ColliderShape::kHalfSpace;
  floor.pose.translation() = Eigen::Vector3d(0.0, 0.0, -0.4);
  colliders.push_back(ball);
  colliders.push_back(box);
  colliders.push_back(floor);
  const int n = 20;
  std::vector<double> lengths(n, 0.1), inv(n, 10.0);
  for (Method method : {Method::kTractrix, Method::kFollowTheLeader, Method::kMinRotation,
                        Method::kMinJointAngle}) {
    std::vector<double> a(3 * (n + 1), 0.0), b;
    for (int i = 0; i <= n; ++i) a[3 * i + 1] = -0.1 * i;
    b = a;
    internal::ContactStats cumulative;
    double least_fresh = std::numeric_limits<double>::infinity();
    long long contacts_fresh = 0;
    for (int step = 1; step <= 150; ++step) {
      const double head[3] = {0.02 * step, 0.0, 0.0};
      internal::ContactSweep(method, 3, head, lengths.data(), inv.data(), n, a.data(), colliders,
                             &cumulative);
      internal::ContactStats fresh;
      internal::ContactSweep(method, 3, head, lengths.data(), inv.data(), n, b.data(), colliders,
                             &fresh);
      least_fresh = std::fmin(least_fresh, fresh.least_clearance);
      contacts_fresh += fresh.contact_link_steps;
      ASSERT_TRUE(a == b) << NameOf(method) << ", step " << step;
    }
    EXPECT_EQ(cumulative.least_clearance, least_fresh) << NameOf(method);
    EXPECT_EQ(cumulative.contact_link_steps, contacts_fresh) << NameOf(method);
    // min_joint_angle swings the chain round the post: it passes the colliders untouched.
    if (method != Method::kMinJointAngle) {
      EXPECT_GT(contacts_fresh, 20) << NameOf(method) << ": the chain must slide round something";
    }
    EXPECT_GE(cumulative.least_clearance, -1e-12) << NameOf(method);
  }
}

}  // namespace
}  // namespace flexkin
