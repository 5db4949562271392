// A robot tree's forward kinematics (flexkin/robot_tree.h, read by RobotTreeFromUrdf) against
// Orocos KDL's tree of the same URDF text, read by Debian's kdl_parser (testing/kdl_urdf_peer.h):
// every joint's origin, every tool's point and looking axis, at random angles, to rounding.
// Not under the sanitizers (tests/CMakeLists.txt: KDL's Eigen allocator).
#include <gtest/gtest.h>

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

TEST(RobotTreeKdl, ForwardKinematicsMatchesKdlsTree) {
  const std::string text = SourceFileText("examples/robot_two_arms.urdf");
  // Tools with offsets and axes off the links' own: a point and a direction of each frame.
  const std::vector<UrdfTool> tools = {{"l_tool", {0.02, 0.03, -0.01}, {0, 1, 0}},
                                       {"r_hand", {0.0, -0.05, 0.02}, {1, 1, 0}},
                                       {"camera", {0, 0, 0}, {1, 0, 0}}};
  const RobotTree robot = RobotTreeFromUrdf(text, "", tools);
  const peers::KdlUrdfTree kdl = peers::KdlTreeFromUrdf(text);
  ASSERT_EQ(kdl.num_joints(), robot.joints());
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
      ASSERT_FALSE(link.empty()) << robot.joint_names[j];
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
  RecordProperty("largest_joint_origin_difference", std::to_string(worst));
}

}  // namespace
}  // namespace flexkin
