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
// A run among static colliders on the sweep pipeline: its lanes keep every link outside, report
// the least clearance over every sweep, and move as the contact sweep does (within the rounding
// of the wavefront's exp; bit for bit on the one-pass loop).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "flexkin/colliders.h"
#include "flexkin/run.h"
#include "flexkin/vocabulary.h"
#include "mesh_test_util.h"
#include "run/sweep_pipeline.h"
#include "sequential/sweep.h"
#include "world/contact.h"

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

// The ball and the box the 3D chain of the tests below passes, and the floor below it.
std::vector<Collider> BallBoxAndFloor() {
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
  return {ball, box, floor};
}

TEST(ContactBroadPhase, LinksBeyondABoundAreLeftOutWithTheSameBitsIn3d) {
  // A chain of 20 links of 0.1 hanging along -y from the origin, its head dragged along +x to 3 in
  // 150 steps, past a post (a capsule of 0.1 along z tilted about x, as a mesh of 20 segments
  // round) standing in its way, a ball and a box it passes, and a floor below.
  Eigen::Isometry3d tilt = Eigen::Isometry3d::Identity();
  tilt.translation() = Eigen::Vector3d(0.22, -0.22, 0.1);
  tilt.linear() = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  std::vector<Collider> colliders = {MeshCollider(CapsuleMesh(0.1, 0.5, 20, 5), tilt)};
  for (const Collider& c : BallBoxAndFloor()) colliders.push_back(c);
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

// A run among static colliders goes through the run's sweep pipeline (src/run/sweep_pipeline.h):
// on the wavefront the lanes test their links against the colliders near their group of sweeps
// and take the contact steps lane by lane. Checked against the sub-step by sub-step run (the
// contact sweep, one sweep at a time), which shares no code with the lanes' tests.
struct PipedAndReference {
  RunResult piped, reference;
  FrameRecorder piped_frames, reference_frames;
};

PipedAndReference RunBoth(const Chain& chain, const Points& path, const RunOptions& options) {
  PipedAndReference r;
  r.piped = flexkin::Run(chain, path, options, &r.piped_frames);
  r.reference = internal::RunSubstepBySubstep(chain, path, options, &r.reference_frames);
  return r;
}

// Over every recorded frame after the first: the least clearance of any link to `colliders`
// relative to its length (SegmentClearance, every collider), the largest relative length error,
// and the largest difference of a coordinate between the two runs.
struct Measured {
  double least = std::numeric_limits<double>::infinity();
  double length_error = 0.0;
  double apart = 0.0;
};

Measured Measure(const PipedAndReference& r, const std::vector<Collider>& colliders,
                 const Eigen::VectorXd& lengths) {
  Measured m;
  const auto at = [](const Points& p, Eigen::Index i) {
    return Eigen::Vector3d(p(i, 0), p(i, 1), p.cols() == 3 ? p(i, 2) : 0.0);
  };
  for (size_t f = 1; f < r.piped_frames.frames.size(); ++f) {
    const Points& p = r.piped_frames.frames[f].points;
    for (Eigen::Index i = 1; i < p.rows(); ++i) {
      const double length = lengths[i - 1];
      m.least = std::fmin(m.least,
                          internal::SegmentClearance(colliders, at(p, i - 1), at(p, i)) / length);
      m.length_error =
          std::fmax(m.length_error, std::fabs((p.row(i) - p.row(i - 1)).norm() - length) / length);
    }
    m.apart = std::fmax(m.apart, (p - r.reference_frames.frames[f].points).cwiseAbs().maxCoeff());
  }
  return m;
}

std::vector<Collider> Pegs() {
  std::vector<Collider> pegs(20);
  for (int k = 0; k < 20; ++k) {
    pegs[k].radius = 0.3;
    pegs[k].margin = 0.03;
    pegs[k].pose.translation() = Eigen::Vector3d(k + 1.0, 0.0, 0.0);
  }
  return pegs;
}

// The snake of the first test (n links of `link`, 0.1 there) and its slalom of 21 x 160 steps.
Chain Snake(int n, double link) {
  Points p(n + 1, 2);
  for (int i = 0; i <= n; ++i) p.row(i) << -link * i, -0.5;
  return MakeChain(p);
}

Points Slalom() {
  constexpr double kPi = 3.14159265358979323846;
  Points path(21 * 160, 2);
  for (Eigen::Index s = 0; s < path.rows(); ++s) {
    const double x = (s + 1) / 160.0;
    path.row(s) << x, 0.5 * std::sin(kPi * (x - 0.5));
  }
  return path;
}

TEST(ContactPipeline, TheSnakeAmongPegsKeepsOutAndReportsItsLeastClearance) {
  const std::vector<Collider> pegs = Pegs();
  const Chain chain = Snake(16, 0.1);  // 16 links: on the wavefront where the CPU has one
  RunOptions options;
  options.colliders = pegs;
  const PipedAndReference r = RunBoth(chain, Slalom(), options);
  const Measured m = Measure(r, pegs, chain.lengths);
  EXPECT_GE(m.least, -1e-12);
  EXPECT_LT(m.length_error, 1e-13);
  // The least clearance reported is the least over every link of every sweep (one sweep a frame
  // here), to the rounding of the lanes' own measure.
  EXPECT_NEAR(r.piped.contacts.least_clearance, m.least, 1e-15);
  // The same motion as the contact sweep's where the two measure the same: a link whose rule step
  // enters a peg by about the slack (1e-13 of a link) is kept by one run and given its contact
  // step by the other where their clearances differ in the last bits, and for a link nearly
  // tangent to a peg the two positions differ by up to sqrt(2 slack L D) (D the distance to the
  // peg's centre): about 1e-8 here. 6.4e-9 measured.
  EXPECT_LT(m.apart, 1e-7);
  EXPECT_GT(r.reference.contacts.contact_link_steps, 5000);
  EXPECT_NEAR(static_cast<double>(r.piped.contacts.contact_link_steps),
              static_cast<double>(r.reference.contacts.contact_link_steps), 5.0);
  EXPECT_NEAR(r.piped.metrics.l2_total, r.reference.metrics.l2_total,
              1e-9 * r.reference.metrics.l2_total);

  // The pegs moved up by 1, beside the slalom's crests: nothing touches them, and the least
  // clearance is the lanes' own measure alone.
  std::vector<Collider> beside = pegs;
  for (Collider& c : beside) c.pose.translation().y() = 1.0;
  options.colliders = beside;
  const PipedAndReference clear = RunBoth(chain, Slalom(), options);
  const Measured n = Measure(clear, beside, chain.lengths);
  EXPECT_EQ(clear.piped.contacts.contact_link_steps, 0);
  EXPECT_GT(n.least, 0.5);  // relative to the links' 0.1
  EXPECT_LT(n.least, 2.0);
  EXPECT_NEAR(clear.piped.contacts.least_clearance, n.least, 1e-14);
  EXPECT_EQ(clear.piped.contacts.least_clearance, clear.reference.contacts.least_clearance);
}

TEST(ContactPipeline, TheOnePassLoopIsTheSubStepBySubStepRunBitForBit) {
  // 6 links of 0.25: the pipeline's one-pass loop (the wavefront takes 8 or more), 2 sub-steps.
  const std::vector<Collider> pegs = Pegs();
  const Chain chain = Snake(6, 0.25);
  for (Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
    RunOptions options;
    options.method = method;
    options.substeps = 2;
    options.colliders = pegs;
    const PipedAndReference r = RunBoth(chain, Slalom(), options);
    EXPECT_EQ(Measure(r, pegs, chain.lengths).apart, 0.0) << NameOf(method);
    EXPECT_EQ(r.piped.contacts.contact_link_steps, r.reference.contacts.contact_link_steps);
    EXPECT_GT(r.piped.contacts.contact_link_steps, 1000) << NameOf(method);
    EXPECT_EQ(r.piped.contacts.least_clearance, r.reference.contacts.least_clearance);
    EXPECT_TRUE(r.piped.metrics.l2_per_step == r.reference.metrics.l2_per_step);
    EXPECT_TRUE(r.piped.metrics.path_length == r.reference.metrics.path_length);
  }
}

TEST(ContactPipeline, OtherShapesAndAFloorIn3dOnTheWavefront) {
  // The 3D chain of the test above (20 links of 0.1 hanging along -y), dragged along +x past a
  // capsule in its way, a ball, a box and above a floor: the lanes' test for colliders that are
  // not all spheres (each lane within reach of a ball takes the contact sweep's own test).
  Collider post;
  post.shape = ColliderShape::kCapsule;
  post.radius = 0.1;
  post.half_length = 0.5;
  post.pose.translation() = Eigen::Vector3d(0.22, -0.22, 0.1);
  post.pose.linear() = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const std::vector<Collider> others = BallBoxAndFloor();
  const Collider &ball = others[0], &box = others[1], &floor = others[2];
  const int n = 20;
  Points p = Points::Zero(n + 1, 3);
  for (int i = 0; i <= n; ++i) p(i, 1) = -0.1 * i;
  const Chain chain = MakeChain(p);
  Points path = Points::Zero(150, 3);
  for (int s = 0; s < 150; ++s) path(s, 0) = 0.02 * (s + 1);
  for (const auto& set :
       {std::vector<Collider>{post, ball, box, floor}, std::vector<Collider>{post, ball, box}}) {
    for (Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
      RunOptions options;
      options.method = method;
      options.substeps = 1;
      options.colliders = set;
      const PipedAndReference r = RunBoth(chain, path, options);
      const Measured m = Measure(r, set, chain.lengths);
      EXPECT_GE(m.least, -1e-12) << NameOf(method);
      EXPECT_LT(m.length_error, 1e-13) << NameOf(method);
      EXPECT_NEAR(r.piped.contacts.least_clearance, m.least, 1e-15) << NameOf(method);
      // The contact steps against the capsule and the box are searches, accurate to about 1e-9
      // of a link: the sub-step by sub-step run itself moves by up to 1.7e-6 when its first
      // target moves by 1e-15 (tractrix; 4e-9 ftl). 4e-7 and 5e-9 measured.
      EXPECT_LT(m.apart, 1e-5) << NameOf(method);
      EXPECT_GT(r.piped.contacts.contact_link_steps, 20) << NameOf(method);
      EXPECT_EQ(r.piped.contacts.contact_link_steps, r.reference.contacts.contact_link_steps)
          << NameOf(method);
    }
  }
}

}  // namespace
}  // namespace flexkin
