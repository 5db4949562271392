// Robot trees (flexkin/robot_tree.h, docs/trees.md "Robot trees"): the URDF reader, the layout of
// points, the joint-space solve of several tools (reached to the tolerance, within the limits,
// the least weighted motion to first order, looking goals) and the tree scenario with "robot"
// through the front door. Forward kinematics against KDL: robot_tree_kdl_test.cc.
#include "flexkin/robot_tree.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <system_error>
#include <vector>

#include "flexkin/any_scenario.h"
#include "flexkin/tree_scenario.h"
#include "flexkin/urdf.h"
#include "test_util.h"

namespace flexkin {
namespace {

using test_util::SourceFileText;

const std::string& TwoArms() {
  static const std::string text = SourceFileText("examples/robot_two_arms.urdf");
  return text;
}

RobotTree TwoArmRobot(bool camera = false) {
  std::vector<UrdfTool> tools = {{"l_tool"}, {"r_tool"}};
  if (camera) tools.push_back({"camera"});
  return RobotTreeFromUrdf(TwoArms(), "", tools);
}

// The two arms with three sliding joints (test_util::SlidingTwoArms): a lift under the torso,
// a telescoping left upper arm and a neck that rises from its pan joint's point.
RobotTree LiftRobot(bool camera = false) {
  std::vector<UrdfTool> tools = {{"l_tool"}, {"r_tool"}};
  if (camera) tools.push_back({"camera"});
  return RobotTreeFromUrdf(test_util::SlidingTwoArms(), "", tools);
}

int JointIndex(const RobotTree& robot, const std::string& name) {
  return static_cast<int>(std::find(robot.joint_names.begin(), robot.joint_names.end(), name) -
                          robot.joint_names.begin());
}

// Random angles within the limits, `spread` rad about 0 at most.
Eigen::VectorXd RandomAngles(const RobotTree& robot, std::mt19937* rng, double spread) {
  std::uniform_real_distribution<double> u(-spread, spread);
  Eigen::VectorXd q(robot.joints());
  for (int j = 0; j < robot.joints(); ++j) {
    q[j] = std::clamp(u(*rng), robot.joint_min[j], robot.joint_max[j]);
  }
  return q;
}

TEST(RobotTreeUrdf, ReadsTheJointsAsATreeWithTheirLimits) {
  const RobotTree robot = TwoArmRobot();
  ASSERT_EQ(robot.joints(), 15);
  EXPECT_TRUE(robot.Validate().empty());
  for (int j = 0; j < robot.joints(); ++j) {
    EXPECT_LT(robot.joint_parents[j], j);
    EXPECT_NEAR(robot.axes.row(j).norm(), 1.0, 1e-15);
  }
  auto index = [&](const std::string& name) {
    const auto at = std::find(robot.joint_names.begin(), robot.joint_names.end(), name);
    return static_cast<int>(at - robot.joint_names.begin());
  };
  const int waist = index("waist"), elbow = index("l_elbow"), tilt = index("neck_tilt");
  EXPECT_EQ(robot.joint_parents[waist], -1);
  EXPECT_EQ(robot.joint_parents[index("l_shoulder_roll")], waist);
  EXPECT_EQ(robot.joint_parents[index("r_shoulder_roll")], waist);
  EXPECT_EQ(robot.joint_parents[tilt], index("neck_pan"));
  // As written in the URDF: the elbow at (0, 0.22 + 0.05 + 0.15 + 0.15, 0.5 + 0.55) about z.
  EXPECT_NEAR((robot.origins.row(elbow) - Eigen::RowVector3d(0, 0.57, 1.05)).norm(), 0, 1e-15);
  EXPECT_EQ(robot.axes.row(elbow), Eigen::RowVector3d(0, 0, 1));
  EXPECT_EQ(robot.joint_min[elbow], -2.6);
  EXPECT_EQ(robot.joint_max[waist], 1.6);
  // The tools: the hands' fixed links, 0.1 beyond the wrists, which are 0.3 ahead of the elbows.
  ASSERT_EQ(robot.tools.size(), 2u);
  EXPECT_EQ(robot.tools[0].joint, index("l_wrist_flex"));
  EXPECT_NEAR((robot.tools[0].point - Eigen::Vector3d(0.4, 0.57, 1.05)).norm(), 0, 1e-15);
  EXPECT_NEAR((robot.tools[1].point - Eigen::Vector3d(0.4, -0.57, 1.05)).norm(), 0, 1e-15);
}

TEST(RobotTreeUrdf, RefusesWhatItCannotDriveNamingIt) {
  auto message = [](const std::string& text, const std::string& base,
                    const std::vector<UrdfTool>& tools) {
    try {
      RobotTreeFromUrdf(text, base, tools);
    } catch (const InputError& e) {
      return e.problem().field + " | " + e.problem().message;
    }
    return std::string("accepted");
  };
  EXPECT_EQ(
      message(TwoArms(), "", {{"l_tol"}}).rfind("tools[0].link | link \"l_tol\" is not in", 0), 0u);
  EXPECT_EQ(message(TwoArms(), "torsoo", {{"l_tool"}}).rfind("base_link", 0), 0u);
  // A tool above the base: not below it.
  EXPECT_NE(message(TwoArms(), "l_forearm", {{"r_tool"}}).find("is not below base link"),
            std::string::npos);
  // The base link itself moves with no joint.
  EXPECT_NE(message(TwoArms(), "", {{"base_link"}}).find("below no revolute"), std::string::npos);
  std::string floating = TwoArms();
  const std::string revolute = "\"l_elbow\" type=\"revolute\"";
  const size_t at = floating.find(revolute);
  ASSERT_NE(at, std::string::npos);
  floating.replace(at, revolute.size(), "\"l_elbow\" type=\"floating\"");
  EXPECT_EQ(message(floating, "", {{"l_tool"}}).rfind("joint \"l_elbow\" | has type floating", 0),
            0u);
  EXPECT_EQ(message("<robot", "", {{"l_tool"}}).rfind("urdf |", 0), 0u);
}

TEST(RobotTreeLayout, MergesJointsOnOnePointAndKeepsEveryLinkLength) {
  const RobotTree robot = TwoArmRobot(true);
  const RobotTreeLayout layout = MakeRobotTreeLayout(robot);
  // 15 joints: the two wrists' flex joints share the wrists' points and the neck's pan and the
  // waist have their own; 3 tools: the hands and the camera (off the tilt joint's point).
  EXPECT_EQ(layout.parents.size(), 1u + 15u - 2u + 3u);
  Tree tree{RobotTreePoints(robot, layout, robot.initial), layout.parents};
  EXPECT_NO_THROW(ValidateTree(tree, "tree"));
  std::mt19937 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    const Points p = RobotTreePoints(robot, layout, RandomAngles(robot, &rng, 3.0));
    for (size_t i = 1; i < layout.parents.size(); ++i) {
      const int u = layout.parents[i];
      const double length = (tree.points.row(i) - tree.points.row(u)).norm();
      EXPECT_NEAR((p.row(i) - p.row(u)).norm(), length, 4e-16 * 4) << "link " << i;
    }
  }
}

TEST(RobotTreeUrdf, ReadsPrismaticJointsAsSlidingOnes) {
  const RobotTree robot = LiftRobot(true);
  ASSERT_EQ(robot.joints(), 15);
  ASSERT_EQ(robot.prismatic.size(), 15u);
  const std::vector<std::string> sliding = {"waist", "l_upper_arm_twist", "neck_tilt"};
  for (int j = 0; j < robot.joints(); ++j) {
    const bool slides =
        std::find(sliding.begin(), sliding.end(), robot.joint_names[j]) != sliding.end();
    EXPECT_EQ(robot.prismatic[j], slides ? 1 : 0) << robot.joint_names[j];
  }
  // Limits in the length unit, as written.
  EXPECT_EQ(robot.joint_min[JointIndex(robot, "waist")], -0.1);
  EXPECT_EQ(robot.joint_max[JointIndex(robot, "waist")], 0.3);
  EXPECT_EQ(robot.joint_max[JointIndex(robot, "neck_tilt")], 0.1);
  // The neck's sliding joint starts on the pan joint's point and still has a point of its own.
  const RobotTreeLayout layout = MakeRobotTreeLayout(robot);
  const int tilt = JointIndex(robot, "neck_tilt"), pan = JointIndex(robot, "neck_pan");
  EXPECT_EQ(layout.parents[layout.joint_point[tilt]], layout.joint_point[pan]);
  ASSERT_EQ(layout.sliding.size(), layout.parents.size());
  int count = 0;
  for (size_t i = 0; i < layout.sliding.size(); ++i) count += layout.sliding[i];
  EXPECT_EQ(count, 3);
  for (const std::string& name : sliding) {
    EXPECT_EQ(layout.sliding[layout.joint_point[JointIndex(robot, name)]], 1) << name;
  }
}

// Every link keeps its length as the joints turn and slide, but the link into a sliding joint's
// point, whose length is its offset along the axis plus the displacement (from the URDF: the lift
// 0.5 above the base along z, the upper arm's 0.15 along its own axis y, the neck's 0).
TEST(RobotTreeLayout, OnlyTheLinksIntoSlidingJointsChangeLength) {
  const RobotTree robot = LiftRobot(true);
  const RobotTreeLayout layout = MakeRobotTreeLayout(robot);
  const Points start = RobotTreePoints(robot, layout, Eigen::VectorXd::Zero(robot.joints()));
  std::map<int, std::pair<int, double>> sliding;  // point: its joint and the offset
  sliding[layout.joint_point[JointIndex(robot, "waist")]] = {JointIndex(robot, "waist"), 0.5};
  sliding[layout.joint_point[JointIndex(robot, "l_upper_arm_twist")]] = {
      JointIndex(robot, "l_upper_arm_twist"), 0.15};
  sliding[layout.joint_point[JointIndex(robot, "neck_tilt")]] = {JointIndex(robot, "neck_tilt"),
                                                                 0.0};
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double worst = 0.0;
  for (int trial = 0; trial < 50; ++trial) {
    Eigen::VectorXd q(robot.joints());
    for (int j = 0; j < robot.joints(); ++j) {
      q[j] = robot.joint_min[j] + u(rng) * (robot.joint_max[j] - robot.joint_min[j]);
    }
    const Points p = RobotTreePoints(robot, layout, q);
    for (size_t i = 1; i < layout.parents.size(); ++i) {
      const int up = layout.parents[i];
      const double length = (p.row(i) - p.row(up)).norm();
      const auto at = sliding.find(static_cast<int>(i));
      const double expected = at == sliding.end()
                                  ? (start.row(i) - start.row(up)).norm()
                                  : std::abs(at->second.second + q[at->second.first]);
      worst = std::max(worst, std::abs(length - expected));
      EXPECT_NEAR(length, expected, 1e-15 * 8) << "link " << i << ", trial " << trial;
    }
  }
  RecordProperty("worst_length_difference", std::to_string(worst));
}

// The position misses of the tools at q (largest).
double Miss(const RobotTree& robot, const Eigen::VectorXd& q, const Points& goals) {
  Points tools, axes;
  RobotTreeTools(robot, q, &tools, &axes);
  return (tools - goals).rowwise().norm().maxCoeff();
}

// 40 trials: from random joint values (`spread` about 0) to goals the robot reaches, its tools at
// other values not far away (`step`), each reached to the tolerance within the limits. The
// joints' motion summed over the trials.
Eigen::VectorXd ReachNearbyGoals(const RobotTree& robot, uint32_t seed, double spread,
                                 double step) {
  const RobotTreeSolver solver(robot);
  std::mt19937 rng(seed);
  Eigen::VectorXd moved = Eigen::VectorXd::Zero(robot.joints());
  for (int trial = 0; trial < 40; ++trial) {
    const Eigen::VectorXd from = RandomAngles(robot, &rng, spread);
    const Eigen::VectorXd there = (from + RandomAngles(robot, &rng, step))
                                      .cwiseMax(robot.joint_min)
                                      .cwiseMin(robot.joint_max);
    Points goals, axes;
    RobotTreeTools(robot, there, &goals, &axes);
    const RobotTreeSolve s = solver.Solve(from, goals);
    EXPECT_TRUE(s.converged) << "trial " << trial << ": miss " << s.residual;
    EXPECT_LE(Miss(robot, s.angles, goals), 1e-10 * solver.layout().longest_link);
    EXPECT_EQ(s.residual, Miss(robot, s.angles, goals));
    for (int j = 0; j < robot.joints(); ++j) {
      EXPECT_GE(s.angles[j], robot.joint_min[j]);
      EXPECT_LE(s.angles[j], robot.joint_max[j]);
    }
    moved += (s.angles - from).cwiseAbs();
  }
  return moved;
}

TEST(RobotTreeSolver, ReachesReachableGoalsToTheToleranceWithinTheLimits) {
  ReachNearbyGoals(TwoArmRobot(), 3, 1.0, 0.3);
}

TEST(RobotTreeSolver, JointsWithNoToolBelowThemDoNotMove) {
  const RobotTree robot = TwoArmRobot();  // the neck carries no tool
  const RobotTreeSolver solver(robot);
  std::mt19937 rng(5);
  const Eigen::VectorXd from = RandomAngles(robot, &rng, 0.8);
  Points goals, axes;
  RobotTreeTools(robot, from, &goals, &axes);
  goals.row(0) += Eigen::RowVector3d(0.05, -0.02, 0.03);
  goals.row(1) += Eigen::RowVector3d(-0.03, 0.02, 0.04);
  const RobotTreeSolve s = solver.Solve(from, goals);
  ASSERT_TRUE(s.converged);
  for (const char* neck : {"neck_pan", "neck_tilt"}) {
    const auto j = std::find(robot.joint_names.begin(), robot.joint_names.end(), neck) -
                   robot.joint_names.begin();
    EXPECT_EQ(s.angles[j], from[j]) << neck;
  }
}

// A small move of the two hands from `from` (1e-6), solved: the joints' motion, and what it is to
// first order, the smallest joint motion in the weighted norm that takes the tools there: dq =
// W^-1 J' (J W^-1 J')^-1 dx, with J by central differences of the tools' points (not the solver's
// analytic Jacobian).
struct SmallMove {
  Eigen::VectorXd dq, expected;
};
SmallMove SolveSmallMove(const RobotTree& robot, const RobotTreeSolver& solver,
                         const Eigen::VectorXd& from) {
  const int n = robot.joints();
  Points at, axes;
  RobotTreeTools(robot, from, &at, &axes);
  Eigen::MatrixXd jac(6, n);
  const double h = 1e-6;
  for (int j = 0; j < n; ++j) {
    Eigen::VectorXd plus = from, minus = from;
    plus[j] += h;
    minus[j] -= h;
    Points a, b;
    RobotTreeTools(robot, plus, &a, &axes);
    RobotTreeTools(robot, minus, &b, &axes);
    const Points d = (a - b) / (2 * h);
    jac.col(j) << d.row(0).transpose(), d.row(1).transpose();
  }
  Eigen::VectorXd dx(6);
  dx << 1, -2, 0.5, -1, 1.5, 2;
  dx *= 1e-6;
  Points goals = at;
  goals.row(0) += dx.head<3>().transpose();
  goals.row(1) += dx.tail<3>().transpose();
  const Eigen::VectorXd winv = solver.inverse_weights();
  const Eigen::MatrixXd weighted = winv.asDiagonal() * jac.transpose();
  SmallMove out;
  out.expected = weighted * (jac * weighted).ldlt().solve(dx);
  const RobotTreeSolve s = solver.Solve(from, goals);
  EXPECT_TRUE(s.converged);
  out.dq = s.angles - from;
  return out;
}

TEST(RobotTreeSolver, ASmallMoveIsTheLeastWeightedJointMotion) {
  const RobotTree robot = TwoArmRobot();
  const RobotTreeSolver solver(robot);
  std::mt19937 rng(11);
  const SmallMove move = SolveSmallMove(robot, solver, RandomAngles(robot, &rng, 0.7));
  // Second-order terms: |dq|^2 ~ 1e-11 against |dq| ~ 1e-5.
  EXPECT_LT((move.dq - move.expected).norm(), 1e-4 * move.expected.norm());
  // The weights favour the joints near the hands: the wrists move more than the waist.
  const Eigen::VectorXd& winv = solver.inverse_weights();
  EXPECT_GT(winv[JointIndex(robot, "l_wrist_pitch")], winv[0]);
}

// The sliding joints take part: goals reached to the tolerance within the limits (the
// displacements included), and the lift and the telescoping arm move.
TEST(RobotTreeSolver, ReachesGoalsWithSlidingJoints) {
  const RobotTree robot = LiftRobot();
  const Eigen::VectorXd moved = ReachNearbyGoals(robot, 23, 0.8, 0.2);
  EXPECT_GT(moved[JointIndex(robot, "waist")], 1e-3);
  EXPECT_GT(moved[JointIndex(robot, "l_upper_arm_twist")], 1e-3);
}

// As ASmallMoveIsTheLeastWeightedJointMotion, with sliding joints: a sliding joint's inverse
// weight the mean link squared.
TEST(RobotTreeSolver, ASmallMoveWithSlidingJointsIsTheLeastWeightedJointMotion) {
  const RobotTree robot = LiftRobot();
  const RobotTreeSolver solver(robot);
  const double mean = solver.layout().mean_link;
  for (int j = 0; j < robot.joints(); ++j) {
    if (robot.prismatic[j]) EXPECT_EQ(solver.inverse_weights()[j], mean * mean);
  }
  std::mt19937 rng(29);
  const SmallMove move = SolveSmallMove(robot, solver, RandomAngles(robot, &rng, 0.05));
  EXPECT_LT((move.dq - move.expected).norm(), 1e-4 * move.expected.norm());
  EXPECT_GT(std::abs(move.expected[JointIndex(robot, "waist")]), 1e-3 * move.expected.norm());
}

TEST(RobotTreeSolver, HoldsJointsOnTheirLimits) {
  const RobotTree free = TwoArmRobot();
  auto index = [&](const char* name) {
    return static_cast<int>(std::find(free.joint_names.begin(), free.joint_names.end(), name) -
                            free.joint_names.begin());
  };
  const int elbow = index("l_elbow");
  // Goals the left arm reaches with its elbow straight: its hand where these angles put it.
  Eigen::VectorXd there = free.initial;
  there[index("l_shoulder_roll")] = 0.3;
  there[index("l_shoulder_yaw")] = -0.5;
  there[index("l_upper_arm_twist")] = 0.4;
  there[index("l_wrist_pitch")] = 0.3;
  Points goals, axes;
  RobotTreeTools(free, there, &goals, &axes);
  // Without limits on it, the elbow (near the hand, so cheap to move) takes part of the motion.
  const RobotTreeSolve unlimited = RobotTreeSolver(free).Solve(free.initial, goals);
  ASSERT_TRUE(unlimited.converged);
  const double bend = std::abs(unlimited.angles[elbow]);
  ASSERT_GT(bend, 0.01);
  // The elbow allowed a third of that: it is held on its limit and the other joints reach.
  RobotTree robot = free;
  robot.joint_min[elbow] = -bend / 3;
  robot.joint_max[elbow] = bend / 3;
  const RobotTreeSolver solver(robot);
  const RobotTreeSolve s = solver.Solve(robot.initial, goals);
  EXPECT_EQ(std::abs(s.angles[elbow]), bend / 3);
  EXPECT_TRUE(s.limited);
  EXPECT_TRUE(s.converged) << s.residual;  // the other joints reach it
  EXPECT_LE(Miss(robot, s.angles, goals), 1e-10 * solver.layout().longest_link);
  for (int j = 0; j < robot.joints(); ++j) {
    EXPECT_GE(s.angles[j], robot.joint_min[j]);
    EXPECT_LE(s.angles[j], robot.joint_max[j]);
  }
}

TEST(RobotTreeSolver, EndsNearTheGoalsItCannotReachAndSaysSo) {
  const RobotTree robot = TwoArmRobot();
  const RobotTreeSolver solver(robot);
  Points goals(2, 3);
  goals << 3.0, 3.0, 3.0, 0.4, -0.57, 1.05;  // the left hand's far out of reach
  const RobotTreeSolve s = solver.Solve(robot.initial, goals);
  EXPECT_FALSE(s.converged);
  EXPECT_LT(s.iterations, 200);
  EXPECT_EQ(s.residual, Miss(robot, s.angles, goals));
  // No closer than the left shoulder's distance to the goal less the arm's reach (0.75)...
  const Eigen::Vector3d shoulder(0, 0.22, 1.05), goal(3, 3, 3);
  EXPECT_GE(s.residual, (goal - shoulder).norm() - 0.75 - 0.22);
  // ...and well on the way: within 1% of the best a straight arm from the torso can do.
  EXPECT_LT(s.residual, 1.01 * ((goal - Eigen::Vector3d(0, 0, 1.05)).norm() - 0.97));
  for (int j = 0; j < robot.joints(); ++j) {
    EXPECT_GE(s.angles[j], robot.joint_min[j]);
    EXPECT_LE(s.angles[j], robot.joint_max[j]);
  }
}

// The camera turned to look at the left hand, also with the neck's tilt made a rise (a sliding
// joint below the pan: its column of the looking goal's Jacobian turns nothing and moves the
// camera along z).
class LookingTool : public ::testing::TestWithParam<bool> {};
INSTANTIATE_TEST_SUITE_P(RobotTreeSolver, LookingTool, ::testing::Values(false, true),
                         [](const auto& info) { return info.param ? "sliding" : "turning"; });
TEST_P(LookingTool, TurnsToItsGoalPoint) {
  const RobotTree robot = GetParam() ? LiftRobot(true) : TwoArmRobot(true);
  RobotTreeOptions options;
  options.looks = {0, 0, 1};
  const RobotTreeSolver solver(robot, options);
  Points goals(3, 3);
  goals << 0.3, 0.4, 1.2, 0.35, -0.35, 0.95, 0.3, 0.4, 1.2;  // the camera watches the left hand
  if (GetParam()) {
    // Where the hands and the camera are at other joint values (the rise up 0.06), the camera
    // looking at a point ahead of it there: reachable by the sliding robot.
    Eigen::VectorXd there = robot.initial;
    there[JointIndex(robot, "neck_tilt")] = 0.06;
    there[JointIndex(robot, "neck_pan")] = 0.3;
    there[JointIndex(robot, "l_elbow")] = -0.5;
    Points tools, axes;
    RobotTreeTools(robot, there, &tools, &axes);
    goals.topRows(2) = tools.topRows(2);
    goals.row(2) = tools.row(2) + 0.7 * axes.row(2);
  }
  const RobotTreeSolve s = solver.Solve(robot.initial, goals);
  ASSERT_TRUE(s.converged) << s.residual << " " << s.angle_residual;
  Points tools, axes;
  RobotTreeTools(robot, s.angles, &tools, &axes);
  const Eigen::Vector3d want = (goals.row(2) - tools.row(2)).transpose();
  const Eigen::Vector3d axis = axes.row(2).transpose();
  EXPECT_LT(std::atan2(want.cross(axis).norm(), want.dot(axis)), 1e-9);
  EXPECT_LE(s.angle_residual, 1e-10);
  EXPECT_LE((tools.topRows(2) - goals.topRows(2)).rowwise().norm().maxCoeff(),
            1e-10 * solver.layout().longest_link);
}

// Gauss-Newton with the exact Jacobian converges quadratically: a small look away (the camera's
// goal point where a rise of 1e-3 more of the sliding neck puts it) is met in at most 3
// iterations, which a wrong column for the sliding joint (tried: one scaled by 0.3) does not do.
TEST(RobotTreeSolver, ASmallLookWithASlidingJointConvergesQuadratically) {
  const RobotTree robot = LiftRobot(true);
  RobotTreeOptions options;
  options.looks = {0, 0, 1};
  const RobotTreeSolver solver(robot, options);
  const int rise = JointIndex(robot, "neck_tilt");
  Eigen::VectorXd from = robot.initial;
  from[rise] = 0.03;
  from[JointIndex(robot, "neck_pan")] = 0.2;
  Eigen::VectorXd there = from;
  there[rise] += 1e-3;
  Points tools, axes, moved, moved_axes;
  RobotTreeTools(robot, from, &tools, &axes);
  RobotTreeTools(robot, there, &moved, &moved_axes);
  Points goals = tools;
  goals.row(2) = moved.row(2) + 0.7 * moved_axes.row(2);
  const RobotTreeSolve s = solver.Solve(from, goals);
  ASSERT_TRUE(s.converged) << s.angle_residual;
  EXPECT_LE(s.iterations, 3);
  EXPECT_GT(std::abs(s.angles[rise] - from[rise]), 1e-4);
}

TEST(RobotTreeSolver, RefusesBadGoalsAndOptions) {
  const RobotTree robot = TwoArmRobot();
  const RobotTreeSolver solver(robot);
  Points goals = Points::Zero(2, 3);
  goals(1, 2) = std::nan("");
  try {
    solver.Solve(robot.initial, goals);
    FAIL() << "accepted a NaN goal";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "goals[1]");
  }
  EXPECT_THROW(solver.Solve(robot.initial, Points::Zero(3, 3)), InputError);
  Eigen::VectorXd nan_angle = robot.initial;
  nan_angle[4] = std::nan("");
  try {
    solver.Solve(nan_angle, Points::Zero(2, 3));
    FAIL() << "accepted a NaN angle";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "from[4]");
  }
  RobotTreeOptions bad;
  bad.weights = {1.0, -1.0};
  try {
    RobotTreeSolver s(robot, bad);
    FAIL() << "accepted a negative weight";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "weights[1]");
  }
}

TEST(RobotTreeScenario, RunsTheExampleThroughTheFrontDoor) {
  ScenarioReadOptions read;
  read.robot = UrdfRobotScenarioOptions();
  const AnyScenario s = ReadScenarioFile(
      std::string(FLEXKIN_SOURCE_DIR) + "/examples/tree_robot_two_arms.json", read);
  ASSERT_TRUE(s.valid()) << s.problems.front().Text();
  ASSERT_TRUE(s.tree.has_value());
  ASSERT_TRUE(s.tree->robot);
  EXPECT_NE(s.Summary().find("robot tree \"two-armed robot\": 15 joints"), std::string::npos)
      << s.Summary();
  const TreeRunResult r = RunTree(*s.tree);
  ASSERT_EQ(r.frames.size(), 181u);
  EXPECT_EQ(r.failures(), 0) << r.BriefReport();
  EXPECT_LT(r.max_length_error, 1e-14);
  // Every frame: the hands on their paths, the camera on the left hand's path, to the tolerance.
  const RobotTree& robot = *s.tree->robot;
  for (size_t f = 1; f < r.frames.size(); ++f) {
    Points tools, axes;
    RobotTreeTools(robot, r.angles[f], &tools, &axes);
    for (int k = 0; k < 2; ++k) {
      EXPECT_LE((tools.row(k) - s.tree->paths[k].row(f - 1)).norm(), 1e-10);
      EXPECT_EQ(r.frames[f].row(s.tree->targets[k]), tools.row(k));
    }
    const Eigen::Vector3d look = (s.tree->paths[2].row(f - 1) - tools.row(2)).transpose();
    const Eigen::Vector3d axis = axes.row(2).transpose();
    EXPECT_LT(std::atan2(look.cross(axis).norm(), look.dot(axis)), 1e-9);
  }
  // No flips: the joints move little from frame to frame.
  double step = 0.0;
  for (size_t f = 1; f < r.angles.size(); ++f) {
    step = std::max(step, (r.angles[f] - r.angles[f - 1]).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(step, 0.15);
  // Written and read back, with the joint angles.
  const std::string dir = ::testing::TempDir();
  for (const char* name : {"robot_tree.npz", "robot_tree.json"}) {
    const std::string path = dir + "/" + name;
    WriteTreeResult(path, *s.tree, r);
    const TreeResultFile back = ReadTreeResultFile(path);
    EXPECT_TRUE(back.robot);
    EXPECT_EQ(back.joints, robot.joint_names);
    ASSERT_EQ(back.angles.size(), r.angles.size());
    EXPECT_EQ(back.angles.back(), r.angles.back());
    EXPECT_EQ(back.frames.back(), r.frames.back());
    EXPECT_EQ(back.parents, s.tree->tree.parents);
    std::filesystem::remove(path);
  }
}

// A smooth motion of every joint at time t in [0, 1]: q_j = a_j sin(pi t (1 + j mod 3)) within
// the limits, a_j `slide` for a sliding joint and 0.4 for a turning one.
Eigen::VectorXd SmoothMotion(const RobotTree& robot, double t, double slide) {
  Eigen::VectorXd q(robot.joints());
  for (int j = 0; j < robot.joints(); ++j) {
    const double amplitude = robot.prismatic[j] ? slide : 0.4;
    q[j] = std::clamp(amplitude * std::sin(M_PI * t * (1 + j % 3)), robot.joint_min[j],
                      robot.joint_max[j]);
  }
  return q;
}

// A robot tree with sliding joints through the front door: a scenario whose two hands follow
// where a smooth motion of every joint (the lift and the telescoping arm included) takes them, so
// that every frame is reachable. Every frame reached, the rigid links' lengths kept, the sliding
// links' lengths the lift's and the telescope's, and the result written and read back with its
// sliding links and joints (the neck's link of length 0 at the start accepted).
TEST(RobotTreeScenario, RunsSlidingJointsThroughTheFrontDoor) {
  const std::string dir = ::testing::TempDir() + "/sliding_robot";
  std::filesystem::create_directories(dir);
  {
    std::ofstream urdf(dir + "/lift.urdf");
    urdf << test_util::SlidingTwoArms();
  }
  const RobotTree robot = LiftRobot();
  const int frames = 40;
  std::string paths[2];
  for (int f = 1; f <= frames; ++f) {
    Points tools, axes;
    RobotTreeTools(robot, SmoothMotion(robot, static_cast<double>(f) / frames, 0.08), &tools,
                   &axes);
    for (int k = 0; k < 2; ++k) {
      paths[k] += std::string(f > 1 ? ", " : "") + "[" + std::to_string(tools(k, 0)) + ", " +
                  std::to_string(tools(k, 1)) + ", " + std::to_string(tools(k, 2)) + "]";
    }
  }
  {
    std::ofstream scenario(dir + "/lift.json");
    scenario << R"({"format": "flexkin-tree", "name": "lift", "robot": {"urdf": "lift.urdf"},
                   "targets": [{"link": "l_tool", "path": [)"
             << paths[0] << R"(]}, {"link": "r_tool", "path": [)" << paths[1] << "]}]}";
  }
  ScenarioReadOptions read;
  read.robot = UrdfRobotScenarioOptions();
  const AnyScenario s = ReadScenarioFile(dir + "/lift.json", read);
  ASSERT_TRUE(s.valid()) << s.problems.front().Text();
  ASSERT_TRUE(s.tree.has_value() && s.tree->robot);
  const TreeRunResult r = RunTree(*s.tree);
  ASSERT_EQ(r.frames.size(), static_cast<size_t>(frames + 1));
  EXPECT_EQ(r.failures(), 0) << r.BriefReport();
  EXPECT_LT(r.max_length_error, 1e-14);
  const RobotTreeLayout layout = MakeRobotTreeLayout(*s.tree->robot);
  const int waist = JointIndex(robot, "waist"), twist = JointIndex(robot, "l_upper_arm_twist");
  double lift = 0.0;
  for (size_t f = 0; f < r.frames.size(); ++f) {
    for (const auto& [joint, offset] : {std::pair<int, double>{waist, 0.5}, {twist, 0.15}}) {
      const int i = layout.joint_point[joint];
      const double length = (r.frames[f].row(i) - r.frames[f].row(layout.parents[i])).norm();
      EXPECT_NEAR(length, offset + r.angles[f][joint], 1e-15 * 4) << "frame " << f;
    }
    lift = std::max(lift, std::abs(r.angles[f][waist]));
  }
  EXPECT_GT(lift, 0.01);  // the lift took part
  for (const char* name : {"lift.npz", "lift_result.json"}) {
    const std::string path = dir + "/" + name;
    WriteTreeResult(path, *s.tree, r);
    const TreeResultFile back = ReadTreeResultFile(path);
    std::vector<int> sliding;
    for (size_t i = 0; i < layout.sliding.size(); ++i) {
      if (layout.sliding[i]) sliding.push_back(static_cast<int>(i));
    }
    EXPECT_EQ(back.sliding, sliding);
    EXPECT_EQ(back.prismatic, robot.prismatic);
    EXPECT_EQ(back.frames.back(), r.frames.back());
  }
  std::filesystem::remove_all(dir);
}

TEST(RobotTreeScenario, NamesEveryProblemByItsJsonPointer) {
  ScenarioReadOptions read;
  read.robot = UrdfRobotScenarioOptions();
  read.robot.directory = std::string(FLEXKIN_SOURCE_DIR) + "/examples";
  auto first = [&](const std::string& text) {
    const AnyScenario s = ReadScenarioText(text, read);
    return s.valid() ? std::string("valid") : s.problems.front().Text();
  };
  const std::string head =
      R"({"format": "flexkin-tree", "robot": {"urdf": "robot_two_arms.urdf"}, )";
  EXPECT_EQ(first(head + R"("targets": [{"link": "l_tool", "path": [[0, 0.97, 1.05]]}]})"),
            "valid");
  EXPECT_EQ(first(head + R"("targets": [{"link": "l_tool", "path": [[0, 0.97, 1.05]]},
      {"link": "r_toool", "path": [[0, -0.97, 1.05]]}]})")
                .rfind("/targets/1/link: link \"r_toool\" is not in the URDF", 0),
            0u);
  EXPECT_EQ(first(head + R"("targets": [{"link": "l_tool", "path": [[0, 0.97, 1.05]]}],
      "fixed": [0]})")
                .rfind("/fixed: is not an option of a robot tree", 0),
            0u);
  EXPECT_EQ(first(head + R"("targets": [{"point": 3, "path": [[0, 0.97, 1.05]]}]})")
                .rfind("/targets/0", 0),
            0u);
  EXPECT_EQ(first(head + R"("targets": [{"link": "l_tool", "path": [[0, 0.97]]}]})")
                .rfind("/targets/0/path/0", 0),
            0u);
  EXPECT_EQ(first(head + R"("targets": [{"link": "camera", "axis": [0, 0, 0],
      "look_at": [[1, 0, 1]]}]})")
                .rfind("/targets/0/axis", 0),
            0u);
  EXPECT_THROW(ReadScenarioText(R"({"format": "flexkin-tree", "robot": {"urdf": "missing.urdf"},
      "targets": [{"link": "l_tool", "path": [[0, 0.97, 1.05]]}]})",
                                read),
               std::system_error);
}

// examples/robot_lift.urdf is SlidingTwoArms (its comment aside), and the hands' paths of
// examples/tree_robot_lift.json are where the forward kinematics put them under the motion
// q_j(t) = clamp(a_j sin(pi t (1 + j mod 3))), a_j 0.1 for a sliding joint and 0.4 for a turning
// one, t = f / 60 for frames 1 to 60 (printed to 6 decimals); the example runs through the front
// door with every frame reached.
TEST(RobotTreeScenario, TheLiftExampleIsTheSlidingRobotOnAReachablePath) {
  const auto strip = [](std::string text) {
    const size_t from = text.find("<!--"), to = text.find("-->");
    if (from != std::string::npos && to != std::string::npos) text.erase(from, to + 3 - from);
    return text;
  };
  const std::string urdf = test_util::SourceFileText("examples/robot_lift.urdf");
  ASSERT_FALSE(urdf.empty());
  EXPECT_EQ(strip(urdf), strip(test_util::SlidingTwoArms()));
  const RobotTree robot = LiftRobot();
  ScenarioReadOptions read;
  read.robot = UrdfRobotScenarioOptions();
  const AnyScenario s =
      ReadScenarioFile(std::string(FLEXKIN_SOURCE_DIR) + "/examples/tree_robot_lift.json", read);
  ASSERT_TRUE(s.valid()) << s.problems.front().Text();
  ASSERT_TRUE(s.tree.has_value() && s.tree->robot);
  ASSERT_EQ(s.tree->paths.size(), 2u);
  const int frames = 60;
  double worst = 0.0;
  for (int f = 1; f <= frames; ++f) {
    Points tools, axes;
    RobotTreeTools(robot, SmoothMotion(robot, static_cast<double>(f) / frames, 0.1), &tools, &axes);
    for (int k = 0; k < 2; ++k) {
      ASSERT_EQ(s.tree->paths[k].rows(), frames);
      worst = std::max(worst, (s.tree->paths[k].row(f - 1) - tools.row(k)).cwiseAbs().maxCoeff());
    }
  }
  EXPECT_LE(worst, 5e-7);
  const TreeRunResult r = RunTree(*s.tree);
  EXPECT_EQ(r.failures(), 0) << r.BriefReport();
}

}  // namespace
}  // namespace flexkin
