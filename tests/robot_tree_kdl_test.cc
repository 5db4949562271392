// A robot tree's forward kinematics (flexkin/robot_tree.h, read by RobotTreeFromUrdf) against
// Orocos KDL's tree of the same URDF text, read by Debian's kdl_parser (testing/kdl_urdf_peer.h):
// every joint's origin, every tool's point and looking axis, at random angles, to rounding.
// Not under the sanitizers (tests/CMakeLists.txt: KDL's Eigen allocator).
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "flexkin/robot_tree.h"
#include "flexkin/urdf.h"
#include "kdl_urdf_peer.h"
#include "test_util.h"

namespace flexkin {
namespace {

using test_util::SourceFileText;

// Every joint's origin (the child link's frame: for a prismatic joint, where it has slid to),
// every tool's point and looking axis, at 100 random configurations within the limits; the
// largest joint origin difference.
double CompareWithKdl(const std::string& text, const std::vector<UrdfTool>& tools) {
  const RobotTree robot = RobotTreeFromUrdf(text, "", tools);
  const peers::KdlUrdfTree kdl = peers::KdlTreeFromUrdf(text);
  EXPECT_EQ(kdl.num_joints(), robot.joints());
  const RobotTreeLayout layout = MakeRobotTreeLayout(robot);
  std::mt19937 rng(1);
  double worst = 0.0;
  for (int trial = 0; trial < 100; ++trial) {
    Eigen::VectorXd q(robot.joints());
    for (int j = 0; j < robot.joints(); ++j) {
      q[j] = std::uniform_real_distribution<double>(robot.joint_min[j], robot.joint_max[j])(rng);
    }
    const KDL::JntArray kq = peers::KdlTreeJoints(kdl, robot.joint_names, q);
    const Points points = RobotTreePoints(robot, layout, q);
    for (int j = 0; j < robot.joints(); ++j) {
      const std::string link = peers::KdlTreeChildLink(kdl, robot.joint_names[j]);
      EXPECT_FALSE(link.empty()) << robot.joint_names[j];
      if (link.empty()) return worst;
      const peers::KdlLinkPose pose = peers::KdlTreeLinkPose(kdl, kq, link);
      const double d = (points.row(layout.joint_point[j]).transpose() - pose.origin).norm();
      worst = std::max(worst, d);
      EXPECT_LT(d, 1e-14) << robot.joint_names[j];
    }
    Points at, axes;
    RobotTreeTools(robot, q, &at, &axes);
    for (size_t k = 0; k < tools.size(); ++k) {
      const peers::KdlLinkPose pose = peers::KdlTreeLinkPose(kdl, kq, tools[k].link);
      const Eigen::Vector3d point = pose.rotation * tools[k].offset + pose.origin;
      const Eigen::Vector3d axis = (pose.rotation * tools[k].axis).normalized();
      EXPECT_LT((at.row(k).transpose() - point).norm(), 1e-14) << tools[k].link;
      EXPECT_LT((axes.row(k).transpose() - axis).norm(), 1e-14) << tools[k].link;
      EXPECT_EQ(points.row(layout.tool_point[k]), at.row(k));
    }
  }
  return worst;
}

// Tools with offsets and axes off the links' own: a point and a direction of each frame.
const std::vector<UrdfTool> kTools = {{"l_tool", {0.02, 0.03, -0.01}, {0, 1, 0}},
                                      {"r_hand", {0.0, -0.05, 0.02}, {1, 1, 0}},
                                      {"camera", {0, 0, 0}, {1, 0, 0}}};

TEST(RobotTreeKdl, ForwardKinematicsMatchesKdlsTree) {
  const double worst = CompareWithKdl(SourceFileText("examples/robot_two_arms.urdf"), kTools);
  RecordProperty("largest_joint_origin_difference", std::to_string(worst));
}

// Prismatic joints (test_util::SlidingTwoArms: a lift, a telescoping arm, a rising neck): KDL
// slides them by its own joint type (TransAxis).
TEST(RobotTreeKdl, SlidingJointsMatchKdlsTree) {
  const std::string text = test_util::SlidingTwoArms();
  ASSERT_FALSE(text.empty());
  const std::vector<char> sliding = RobotTreeFromUrdf(text, "", kTools).prismatic;
  ASSERT_EQ(std::count(sliding.begin(), sliding.end(), char(1)), 3);
  const double worst = CompareWithKdl(text, kTools);
  RecordProperty("largest_joint_origin_difference", std::to_string(worst));
}

}  // namespace
}  // namespace flexkin
