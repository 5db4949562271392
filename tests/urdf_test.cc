// URDF arms (include/flexkin/urdf.h): the round trip arm -> URDF -> arm, a hand-written planar
// URDF, and bad URDFs refused with the element named.
#include "flexkin/urdf.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "flexkin/error.h"

namespace flexkin {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A spatial snake: links along +x, joints alternately pitch (y) and yaw (z), limits +-1 rad.
ArmModel Snake(int links) {
  ArmModel m = StraightArm(3, links, 0.1);
  m.joint_axes.resize(links, 3);
  for (int j = 0; j < links; ++j)
    m.joint_axes.row(j) = j % 2 == 0 ? Eigen::RowVector3d::UnitY() : Eigen::RowVector3d::UnitZ();
  m.joint_min = Eigen::VectorXd::Constant(links, -1.0);
  m.joint_max = Eigen::VectorXd::Constant(links, 1.0);
  m.initial.azimuth.resize(0);  // revolute joints have none
  return m;
}

std::string InputErrorOf(const std::string& urdf, const UrdfChain& chain = {}) {
  try {
    ArmFromUrdf(urdf, chain);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(Urdf, RoundTripKeepsLengthsAxesLimitsBaseAndKinematics) {
  ArmModel arm = Snake(7);
  arm.base << 0.5, -0.25, 1.5;
  // Uneven lengths and tilted rest directions and axes, all exactly representable round trips.
  for (int k = 0; k < 7; ++k) {
    arm.link_lengths[k] = 0.05 + 0.013 * k;
    const Eigen::Vector3d d = Eigen::Vector3d(1.0, 0.1 * k, -0.05 * k).normalized();
    const Eigen::Vector3d a = d.cross(Eigen::Vector3d(0.3, 1.0, 0.2 * k)).normalized();
    arm.joint_axes.row(k) = a.transpose();
    if (arm.link_directions.size() == 0) arm.link_directions.resize(7, 3);
    arm.link_directions.row(k) = d.transpose();
    arm.joint_min[k] = -0.5 - 0.1 * k;
    arm.joint_max[k] = 0.25 + 0.2 * k;
  }
  arm.base_direction = arm.link_directions.row(0).transpose();
  ASSERT_TRUE(arm.Validate().empty()) << arm.Validate().front().Text();
  const std::string text = UrdfFromArm(arm, "snake");
  const ArmModel back = ArmFromUrdf(text);
  ASSERT_EQ(back.dim, 3);
  ASSERT_EQ(back.num_links(), 7);
  EXPECT_LT((back.link_lengths - arm.link_lengths).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LT((back.base - arm.base).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LT((back.joint_axes - arm.joint_axes).cwiseAbs().maxCoeff(), 1e-14);  // renormalized
  EXPECT_LT((back.link_directions - arm.link_directions).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_EQ(back.joint_min, arm.joint_min);
  EXPECT_EQ(back.joint_max, arm.joint_max);
  JointAngles q;
  q.angle = Eigen::VectorXd::LinSpaced(7, -0.4, 0.9);
  const Points p = ForwardKinematics(arm, q), p_back = ForwardKinematics(back, q);
  EXPECT_LT((p - p_back).cwiseAbs().maxCoeff(), 1e-12);
  // The URDF's own text has what we wrote: 7 revolute joints and a fixed tip.
  EXPECT_NE(text.find("<robot name=\"snake\">"), std::string::npos);
  EXPECT_NE(text.find("type=\"fixed\""), std::string::npos);
}

TEST(Urdf, PlanarArmRoundTripStaysPlanar) {
  ArmModel arm = StraightArm(2, 4, 0.07);
  arm.base << 1.0, 2.0;
  const ArmModel back = ArmFromUrdf(UrdfFromArm(arm));
  ASSERT_EQ(back.dim, 2);
  EXPECT_EQ(back.base, arm.base);
  EXPECT_LT((back.link_lengths - arm.link_lengths).cwiseAbs().maxCoeff(), 1e-16);
  EXPECT_EQ(back.joint_min.size(), 0);  // continuous joints: no limits
}

// A hand-written 3-link planar arm: a fixed mount on the world, link lengths 0.3, 0.2, 0.1 in the
// x-y plane, joint limits, and a fixed tool frame.
const char* kPlanarUrdf = R"(<?xml version="1.0"?>
<robot name="three">
  <link name="world"/> <link name="mount"/> <link name="upper"/> <link name="fore"/>
  <link name="hand"/> <link name="tool"/>
  <joint name="bolt" type="fixed"><parent link="world"/><child link="mount"/>
    <origin xyz="1 0 0"/></joint>
  <joint name="shoulder" type="revolute"><parent link="mount"/><child link="upper"/>
    <origin xyz="0 0.5 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 0 1"/><limit lower="-2" upper="2.5" effort="1" velocity="1"/></joint>
  <joint name="wrist" type="continuous"><parent link="fore"/><child link="hand"/>
    <origin xyz="0.2 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="tool_joint" type="fixed"><parent link="hand"/><child link="tool"/>
    <origin xyz="0.1 0 0"/></joint>
</robot>)";

TEST(Urdf, HandWrittenPlanarArmIsReadCorrectly) {
  const ArmModel arm = ArmFromUrdf(kPlanarUrdf);
  ASSERT_EQ(arm.dim, 2);
  ASSERT_EQ(arm.num_links(), 3);
  EXPECT_NEAR(arm.link_lengths[0], 0.3, 1e-15);
  EXPECT_NEAR(arm.link_lengths[1], 0.2, 1e-15);
  EXPECT_NEAR(arm.link_lengths[2], 0.1, 1e-15);
  EXPECT_EQ(arm.base, Eigen::Vector2d(1.0, 0.5));
  EXPECT_EQ(arm.base_direction, Eigen::Vector2d(1.0, 0.0));
  EXPECT_EQ(arm.joint_min, Eigen::Vector3d(-1.0, -2.0, -kPi));
  EXPECT_EQ(arm.joint_max, Eigen::Vector3d(1.0, 2.5, kPi));
  // Shoulder +90 degrees, elbow -90: the tool at (1 + 0.2 + 0.1, 0.5 + 0.3).
  JointAngles q;
  q.angle = Eigen::Vector3d(kPi / 2, -kPi / 2, 0.0);
  const Points p = ForwardKinematics(arm, q);
  EXPECT_NEAR(p(3, 0), 1.3, 1e-15);
  EXPECT_NEAR(p(3, 1), 0.8, 1e-15);
  // A sub-chain: from the upper arm to the tool (elbow and wrist).
  const ArmModel sub = ArmFromUrdf(kPlanarUrdf, {"upper", "tool"});
  ASSERT_EQ(sub.num_links(), 2);
  EXPECT_NEAR(sub.link_lengths[0], 0.2, 1e-15);
  EXPECT_NEAR(sub.link_lengths[1], 0.1, 1e-15);
  EXPECT_NEAR((sub.base - Eigen::Vector2d(1.3, 0.5)).norm(), 0.0, 1e-15);
  // Ending at the hand, the tip sits on the wrist: a link of length 0, accepted (a spatial arm
  // with axes then, whose wrist turns the tool frame only).
  const ArmModel on_joint = ArmFromUrdf(kPlanarUrdf, {"upper", "hand"});
  ASSERT_EQ(on_joint.num_links(), 2);
  EXPECT_EQ(on_joint.dim, 3);
  EXPECT_NEAR(on_joint.link_lengths[0], 0.2, 1e-15);
  EXPECT_EQ(on_joint.link_lengths[1], 0.0);
  EXPECT_EQ(JointGroups(on_joint), (std::vector<std::vector<int>>{{0}, {1}}));
  JointAngles wrist;
  wrist.angle = Eigen::Vector2d(0.0, 1.0);
  EXPECT_EQ(ChainPoints(on_joint, ForwardKinematics(on_joint, wrist)).rows(), 2);
  EXPECT_NEAR((ToolPoseAt(on_joint, wrist).position - Eigen::Vector3d(1.5, 0.5, 0.0)).norm(), 0.0,
              1e-15);
  EXPECT_NEAR(ToolPoseAt(on_joint, wrist).rotation(1, 0), std::sin(1.0), 1e-15);
}

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  const size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? s : s.replace(at, from.size(), to);
}

TEST(Urdf, BadUrdfsNameTheElement) {
  const std::string good = kPlanarUrdf;
  EXPECT_NE(InputErrorOf(Replace(good, "\"continuous\">", "\"floating\">"))
                .find("joint \"wrist\": has type floating"),
            std::string::npos);
  EXPECT_NE(InputErrorOf(Replace(good, "\"continuous\">", "\"planar\">"))
                .find("joint \"wrist\": has type planar"),
            std::string::npos);
  // A closed loop: "fore" the child of a second joint.
  const std::string loop = Replace(good, "</robot>",
                                   "<joint name=\"again\" type=\"fixed\"><parent link=\"mount\"/>"
                                   "<child link=\"fore\"/></joint></robot>");
  EXPECT_NE(InputErrorOf(loop).find("link \"fore\": is the child of joints \"again\" and "
                                    "\"elbow\": a closed loop"),
            std::string::npos)
      << InputErrorOf(loop);
  // A cycle of joints cut off from the root (fore -> hand -> fore): refused before urdfdom builds
  // it (whose links would hold each other, never freed), naming a link of it.
  const std::string cycle = Replace(good, "<parent link=\"upper\"/><child link=\"fore\"/>",
                                    "<parent link=\"hand\"/><child link=\"fore\"/>");
  EXPECT_NE(InputErrorOf(cycle).find("link \"hand\": is its own ancestor: joint \"wrist\" and the "
                                     "joints above it form a cycle"),
            std::string::npos)
      << InputErrorOf(cycle);
  // Text that is not UTF-8 is refused before any XML parse: a multi-byte sequence cut off by the
  // end of the text made TinyXML read past it (the urdf fuzzer's find); also a stray continuation
  // byte, an overlong form and a surrogate. UTF-8 names are read.
  EXPECT_NE(InputErrorOf(good + "\xDC")
                .find("urdf: byte " + std::to_string(good.size()) + " (0xDC) is not valid UTF-8"),
            std::string::npos)
      << InputErrorOf(good + "\xDC");
  for (const char* bad : {"\x80", "\xC0\xAF", "\xED\xA0\x80", "\xF4\x90\x80\x80"}) {
    EXPECT_NE(InputErrorOf(Replace(good, "</robot>", std::string("<!--") + bad + "--></robot>"))
                  .find("is not valid UTF-8"),
              std::string::npos)
        << bad;
  }
  EXPECT_EQ(
      ArmFromUrdf(Replace(good, "</robot>", "<!-- \xC3\xA9l\xC3\xA8ve \xE2\x86\x92 --></robot>"))
          .num_links(),
      ArmFromUrdf(good).num_links());
  EXPECT_NE(InputErrorOf(good, {"", "elbowx"}).find("\"elbowx\" is not in the URDF"),
            std::string::npos);
  EXPECT_NE(InputErrorOf(good, {"nowhere", ""}).find("base_link"), std::string::npos);
  EXPECT_NE(InputErrorOf(good, {"hand", "upper"}).find("tip_link"), std::string::npos);
  EXPECT_NE(InputErrorOf("<robot name=\"x\"><link name=\"a\"></robot>").find("not a valid URDF"),
            std::string::npos);
  EXPECT_NE(InputErrorOf("not xml at all").find("urdf"), std::string::npos);
  // A branch: a second child under "fore".
  const std::string branch = Replace(good, "</robot>",
                                     "<link name=\"thumb\"/><joint name=\"t\" "
                                     "type=\"fixed\"><parent link=\"fore\"/><child link=\"thumb\"/>"
                                     "<origin xyz=\"0 0.1 0\"/></joint></robot>");
  EXPECT_NE(InputErrorOf(branch).find("link \"fore\""), std::string::npos);
  EXPECT_NO_THROW(ArmFromUrdf(branch, {"", "tool"}));
  // Everything at one point: no length to scale the arm by.
  EXPECT_NE(InputErrorOf(good, {"fore", "hand"}).find("at one point"), std::string::npos);
  EXPECT_THROW(ArmFromUrdfFile("/nonexistent/arm.urdf"), std::system_error);
  // Spherical arms have no URDF form.
  EXPECT_THROW(UrdfFromArm(StraightArm(3, 2, 1.0)), InputError);
}

}  // namespace
}  // namespace flexkin
