// Snake arms and arms with prismatic, multi-turn and continuous joints read from URDF
// (include/flexkin/urdf.h, issue 15), against Orocos KDL reading the same text with kdl_parser
// (testing/kdl_urdf_peer.h): the designs of testing/snake_urdfs.h track circles and lines with
// every step reached, limits held, flexkin's and KDL's forward kinematics in agreement at every
// reported step (every joint origin, the end effector, the tool frame's rotation), and the
// motion largest at the end effector; pointing the tool along a direction or at a point; and
// URDFs that are not serial chains of revolute and prismatic joints refused by name. The timing
// against KDL lives in bench/urdf_kdl_benchmark.cc.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/urdf.h"
#include "kdl_urdf_peer.h"
#include "snake_urdfs.h"

namespace flexkin {
namespace {

using ::testing::HasSubstr;
constexpr double kPi = 3.14159265358979323846;
constexpr int kModules = 12;

struct Arm {
  ArmModel model;
  peers::KdlUrdfChain kdl;
};

Arm Load(const std::string& urdf, const Eigen::Vector3d& tip_offset = Eigen::Vector3d::Zero()) {
  UrdfChain chain;
  chain.base_link = "base_link";  // the root: flexkin's and KDL's frames agree
  chain.tip_link = "tip_link";
  chain.tip_offset = tip_offset;
  Arm arm{ArmFromUrdf(urdf, chain),
          peers::KdlChainFromUrdf(urdf, "base_link", "tip_link", tip_offset)};
  EXPECT_EQ(arm.model.dim, 3);
  EXPECT_EQ(arm.model.num_links(), arm.kdl.num_joints());
  // flexkin's joint j is KDL's joint j: the j-th movable joint from the base.
  EXPECT_EQ(arm.model.joint_names, arm.kdl.joint_names);
  return arm;
}

Arm LoadDesign(const snakes::SnakeDesign& design) { return Load(design.urdf, design.tip_offset); }

double MeanLink(const ArmModel& model) { return model.link_lengths.mean(); }

Eigen::Vector3d EndEffector(const ArmModel& model, const JointAngles& angles) {
  return ForwardKinematics(model, angles).row(model.num_links()).transpose();
}

// flexkin's and KDL's forward kinematics at `angles`: every joint origin and the end effector,
// and the tool frame's rotation.
void ExpectSameKinematics(const Arm& arm, const JointAngles& angles, const std::string& what) {
  const Points ours = ForwardKinematics(arm.model, angles);
  const peers::KdlUrdfPose kdl = peers::KdlUrdfForward(arm.kdl, peers::KdlJointArray(angles.angle));
  ASSERT_EQ(ours.rows(), kdl.points.rows()) << what;
  ASSERT_EQ(ours.cols(), 3) << what;
  EXPECT_LT((ours - kdl.points).cwiseAbs().maxCoeff(), 1e-11) << what;
  const ToolPose tool = ToolPoseAt(arm.model, angles);
  EXPECT_LT((tool.position - kdl.points.row(arm.model.num_links()).transpose()).norm(), 1e-11)
      << what;
  EXPECT_LT((tool.rotation - kdl.tip_rotation).cwiseAbs().maxCoeff(), 1e-11) << what;
}

// The total path length of each chain point (ChainPoints: one per distinct joint position and the
// end effector), from the initial state through every step.
Eigen::VectorXd ChainPointTravel(const ArmModel& model, const std::vector<ArmStepReport>& steps) {
  Points last = ChainPoints(model, ForwardKinematics(model, model.initial));
  Eigen::VectorXd travel = Eigen::VectorXd::Zero(last.rows());
  for (const ArmStepReport& step : steps) {
    const Points now = ChainPoints(model, step.state.points);
    EXPECT_EQ(now.rows(), last.rows());
    if (now.rows() != last.rows()) return travel;
    travel += (now - last).rowwise().norm();
    last = now;
  }
  return travel;
}

// Every step of `trajectory` (TrackPath of `path`) reached its target within the tolerance, with
// the limits held, its points those of its angles, and KDL agreeing.
void ExpectTracked(const Arm& arm, const Points& path, const ArmOptions& options,
                   const ArmTrajectory& trajectory, const std::string& what) {
  const ArmModel& model = arm.model;
  const int n = model.num_links();
  const double tolerance = options.tolerance * MeanLink(model);
  ASSERT_EQ(static_cast<Eigen::Index>(trajectory.steps.size()), path.rows()) << what;
  EXPECT_EQ(trajectory.unreached, 0) << what;
  for (size_t i = 0; i < trajectory.steps.size(); ++i) {
    const ArmStepReport& step = trajectory.steps[i];
    const std::string at = what + ", step " + std::to_string(i);
    EXPECT_TRUE(step.reached) << at << ": " << step.BriefReport();
    EXPECT_LE(step.ee_error, tolerance) << at;
    ASSERT_EQ(step.state.points.rows(), n + 1) << at;
    EXPECT_LE((step.state.points.row(n) - path.row(i)).norm(), tolerance) << at;
    EXPECT_TRUE(WithinLimits(model, step.state.angles, 1e-12)) << at;
    EXPECT_LT(
        (ForwardKinematics(model, step.state.angles) - step.state.points).cwiseAbs().maxCoeff(),
        1e-12)
        << at;
    ExpectSameKinematics(arm, step.state.angles, at);
  }
}

// The end effector travels farther than the middle of the chain, which travels farther than the
// moving point nearest the base. On the two small arms (6 joints, not snakes) only the end
// effector against the point nearest the base is checked: there the middle of the chain is the
// wrist, a few centimetres from the end effector, and may travel as far (prismatic arm's circle:
// wrist 0.944 m, end effector 0.942 m).
void ExpectMotionLargestAtEndEffector(const ArmModel& model, const ArmTrajectory& trajectory,
                                      const std::string& what, bool snake = true) {
  const Eigen::VectorXd travel = ChainPointTravel(model, trajectory.steps);
  const int last = static_cast<int>(travel.size()) - 1;
  int first = 0;
  while (first < last && travel[first] <= 1e-12) ++first;  // the base and points on its axes
  const int middle = (first + last) / 2;
  ASSERT_LT(first, middle) << what;
  EXPECT_GT(travel[last], travel[first]) << what << ": travel " << travel.transpose();
  if (!snake) return;
  EXPECT_GT(travel[last], travel[middle]) << what << ": travel " << travel.transpose();
  EXPECT_GT(travel[middle], travel[first]) << what << ": travel " << travel.transpose();
}

// Two unit vectors perpendicular to each other and to `d`.
std::pair<Eigen::Vector3d, Eigen::Vector3d> PlaneAcross(const Eigen::Vector3d& d) {
  const Eigen::Vector3d a = d.normalized();
  Eigen::Vector3d u = a.cross(Eigen::Vector3d(0.2, 0.3, 1.0)).normalized();
  return {u, a.cross(u).normalized()};
}

// A circle of `radius` through the end effector's start, tilted out of the plane across the
// chain's start-to-end direction, and a line of `line_length` from the start.
struct TestPaths {
  Points circle, line;
};
TestPaths PathsFor(const ArmModel& model, double radius, double line_length, int steps) {
  const Points start = ForwardKinematics(model, model.initial);
  const Eigen::Vector3d ee = start.row(model.num_links()).transpose();
  const Eigen::Vector3d along = ee - model.base.head<3>();
  const auto [u, v] = PlaneAcross(along);
  const Eigen::Vector3d tilted_u = (u + 0.5 * along.normalized()).normalized();
  TestPaths paths;
  paths.circle = snakes::CircleThrough(ee, tilted_u, v, radius, steps);
  paths.line = snakes::LineTo(ee, ee + line_length * (v - 0.3 * u).normalized(), steps);
  return paths;
}

// A design bent out of its straight rest pose, tracking a circle and a line.
// The bends put the end effector at about 70% of the reach; `radius` and `line` (m) keep the paths
// inside 90% of it.
void ExpectDesignTracks(const snakes::SnakeDesign& design, double pitch, double yaw, double roll,
                        double radius, double line) {
  Arm arm = LoadDesign(design);
  snakes::BendInitial(&arm.model, pitch, yaw, roll);
  ASSERT_TRUE(WithinLimits(arm.model, arm.model.initial));
  ExpectSameKinematics(arm, arm.model.initial, design.name + " initial");
  const TestPaths paths = PathsFor(arm.model, radius, line, 64);
  // The paths stay well inside the reach (a prismatic joint's stroke adds to it).
  double reach = arm.model.reach();
  for (int j = 0; j < arm.model.num_links(); ++j) {
    if (arm.model.prismatic(j)) reach += arm.model.joint_max[j];
  }
  for (const Points* path : {&paths.circle, &paths.line}) {
    for (Eigen::Index i = 0; i < path->rows(); ++i) {
      ASSERT_LT((path->row(i) - arm.model.base.head<3>().transpose()).norm(), 0.9 * reach)
          << design.name;
    }
  }
  const ArmOptions options;
  const ArmTrajectory circle = TrackPath(arm.model, paths.circle, options);
  ExpectTracked(arm, paths.circle, options, circle, design.name + " circle");
  const bool snake = design.name != "prismatic" && design.name != "multi_turn";
  ExpectMotionLargestAtEndEffector(arm.model, circle, design.name + " circle", snake);
  const ArmTrajectory line = TrackPath(arm.model, paths.line, options);
  ExpectTracked(arm, paths.line, options, line, design.name + " line");
  ExpectMotionLargestAtEndEffector(arm.model, line, design.name + " line", snake);
}

snakes::SnakeDesign Design(const std::string& name, int modules = kModules) {
  for (const snakes::SnakeDesign& d : snakes::AllSnakeDesigns(modules)) {
    if (d.name == name) return d;
  }
  ADD_FAILURE() << "no design " << name;
  return {};
}

// --- The URDF texts and KDL alone (no flexkin reader involved). ---

TEST(SnakeUrdfs, KdlReadsEveryDesignWithTheExpectedJoints) {
  const std::vector<std::pair<std::string, int>> expected = {{"pitch_yaw", kModules},
                                                             {"universal", 2 * kModules},
                                                             {"roll", 3 * kModules},
                                                             {"prismatic", 6},
                                                             {"multi_turn", 6}};
  for (const auto& [name, joints] : expected) {
    const snakes::SnakeDesign d = Design(name);
    const peers::KdlUrdfChain kdl =
        peers::KdlChainFromUrdf(d.urdf, "base_link", "tip_link", d.tip_offset);
    EXPECT_EQ(kdl.num_joints(), joints) << name;
    EXPECT_EQ(static_cast<int>(kdl.chain.getNrOfJoints()), joints) << name;
  }
  // Joint names, base first: KDL's order is the chain's.
  const peers::KdlUrdfChain universal =
      peers::KdlChainFromUrdf(snakes::UniversalSnakeUrdf(2), "base_link", "tip_link");
  EXPECT_EQ(universal.joint_names,
            (std::vector<std::string>{"pitch_0", "yaw_0", "pitch_1", "yaw_1"}));
}

TEST(SnakeUrdfs, KdlForwardKinematicsAtRestIsTheDesign) {
  const double module = snakes::kSnakeModuleLength;
  // Pitch-yaw: joints one module apart along x, the tip on the last joint, its rotation the tip
  // joint's rpy (roll 0.3, pitch -0.2, yaw 0.25) through the brackets' rotations undone.
  {
    const peers::KdlUrdfChain kdl =
        peers::KdlChainFromUrdf(snakes::PitchYawSnakeUrdf(5), "base_link", "tip_link");
    const peers::KdlUrdfPose pose = peers::KdlUrdfForward(kdl, KDL::JntArray(5));
    for (int j = 0; j < 5; ++j) {
      EXPECT_LT((pose.points.row(j) - Eigen::RowVector3d(module * j, 0, 0)).norm(), 1e-14) << j;
    }
    EXPECT_LT((pose.points.row(5) - pose.points.row(4)).norm(), 1e-15);
    const Eigen::Matrix3d tip = (Eigen::AngleAxisd(0.25, Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()))
                                    .toRotationMatrix();
    EXPECT_LT((pose.tip_rotation - tip).cwiseAbs().maxCoeff(), 1e-14);
  }
  // Universal: pairs of joints at one point, one module apart; the tip one module beyond.
  {
    const peers::KdlUrdfChain kdl =
        peers::KdlChainFromUrdf(snakes::UniversalSnakeUrdf(3), "base_link", "tip_link");
    const peers::KdlUrdfPose pose = peers::KdlUrdfForward(kdl, KDL::JntArray(6));
    for (int j = 0; j < 6; ++j) {
      EXPECT_LT((pose.points.row(j) - Eigen::RowVector3d(module * (j / 2), 0, 0)).norm(), 1e-14);
    }
    EXPECT_LT((pose.points.row(6) - Eigen::RowVector3d(3 * module, 0, 0)).norm(), 1e-14);
  }
  // Prismatic arm: extension 0.1 moves the wrist joints and the tool point (0.08 along the tool
  // frame's z, which is the arm's x), not the extension joint itself.
  {
    const peers::KdlUrdfChain kdl = peers::KdlChainFromUrdf(
        snakes::PrismaticArmUrdf(), "base_link", "tip_link", snakes::PrismaticToolOffset());
    Eigen::VectorXd q = Eigen::VectorXd::Zero(6);
    q[3] = 0.1;
    const peers::KdlUrdfPose pose = peers::KdlUrdfForward(kdl, peers::KdlJointArray(q));
    Points expected(7, 3);
    expected << 0, 0, 0, 0, 0, 0.1, 0.3, 0, 0.1, 0.5, 0, 0.1, 0.7, 0, 0.1, 0.75, 0, 0.1, 0.86, 0,
        0.1;
    EXPECT_LT((pose.points - expected).cwiseAbs().maxCoeff(), 1e-14) << pose.points;
  }
}

TEST(SnakeUrdfs, CommittedExamplesAreTheGeneratorsOutput) {
  const std::vector<std::pair<std::string, std::string>> files = {
      {"examples/robot_pitch_yaw_snake.urdf", snakes::PitchYawSnakeUrdf(8)},
      {"examples/robot_universal_snake.urdf", snakes::UniversalSnakeUrdf(8)}};
  for (const auto& [file, text] : files) {
    std::ifstream in(std::string(FLEXKIN_SOURCE_DIR) + "/" + file);
    ASSERT_TRUE(in) << file;
    std::stringstream buffer;
    buffer << in.rdbuf();
    EXPECT_EQ(buffer.str(), text) << file << " differs from testing/snake_urdf_writer's output";
  }
}

// KDL's trackers on a bent universal snake (start angles set directly): both reach a circle.
TEST(SnakeUrdfs, KdlTrackersReachACircle) {
  const peers::KdlUrdfChain kdl =
      peers::KdlChainFromUrdf(snakes::UniversalSnakeUrdf(8), "base_link", "tip_link");
  Eigen::VectorXd start(16);
  for (int k = 0; k < 8; ++k) start.segment<2>(2 * k) << 0.2, 0.05;
  const peers::KdlUrdfPose pose = peers::KdlUrdfForward(kdl, peers::KdlJointArray(start));
  const Eigen::Vector3d ee = pose.points.row(16).transpose();
  const Points path = snakes::CircleThrough(ee, Eigen::Vector3d(0, 1, 0).normalized(),
                                            Eigen::Vector3d(0.3, 0, 1).normalized(), 0.1, 40);
  peers::KdlUrdfOptions options;
  options.tolerance = 1e-10 * 0.05;
  for (peers::KdlUrdfSolver solver :
       {peers::KdlUrdfSolver::kNewtonPinv, peers::KdlUrdfSolver::kLma}) {
    const peers::KdlUrdfTrajectory t =
        peers::TrackUrdfPathWithKdl(kdl, start, path, solver, options);
    EXPECT_EQ(t.unreached, 0) << peers::KdlUrdfSolverName(solver);
    EXPECT_LE(t.max_ee_error, 2 * options.tolerance) << peers::KdlUrdfSolverName(solver);
  }
}

// --- flexkin's reader and tracker against KDL. ---

TEST(UrdfSnakes, ModelsAreReadAsWritten) {
  // Pitch-yaw: the tip on its joint (a last link of length 0), the tool frame's rotation kept.
  const Arm pitch_yaw = LoadDesign(Design("pitch_yaw"));
  ASSERT_EQ(pitch_yaw.model.num_links(), kModules);
  EXPECT_LT(pitch_yaw.model.link_lengths[kModules - 1], 1e-15);
  EXPECT_NEAR(pitch_yaw.model.link_lengths.head(kModules - 1).minCoeff(), 0.1, 1e-14);
  EXPECT_EQ(pitch_yaw.model.joint_min, Eigen::VectorXd::Constant(kModules, -1.2));
  EXPECT_EQ(pitch_yaw.model.joint_max, Eigen::VectorXd::Constant(kModules, 1.2));
  EXPECT_EQ(pitch_yaw.model.max_velocity, Eigen::VectorXd::Constant(kModules, 2.0));
  ExpectSameKinematics(pitch_yaw, pitch_yaw.model.initial, "pitch_yaw initial");
  // Universal: joints in pairs at one point.
  const Arm universal = LoadDesign(Design("universal"));
  const std::vector<std::vector<int>> groups = JointGroups(universal.model);
  ASSERT_EQ(groups.size(), static_cast<size_t>(kModules));
  for (int k = 0; k < kModules; ++k) {
    EXPECT_EQ(groups[k], (std::vector<int>{2 * k, 2 * k + 1})) << k;
  }
  EXPECT_EQ(
      ChainPoints(universal.model, ForwardKinematics(universal.model, universal.model.initial))
          .rows(),
      kModules + 1);
  // Prismatic: the joint type and its limits in metres.
  const Arm prismatic = LoadDesign(Design("prismatic"));
  ASSERT_EQ(prismatic.model.num_links(), 6);
  for (int j = 0; j < 6; ++j) EXPECT_EQ(prismatic.model.prismatic(j), j == 3) << j;
  EXPECT_EQ(prismatic.model.joint_min[3], 0.0);
  EXPECT_EQ(prismatic.model.joint_max[3], 0.3);
  EXPECT_EQ(prismatic.model.max_velocity[3], 0.5);
  // Multi-turn: limits as written, continuous joints unlimited.
  const Arm multi = LoadDesign(Design("multi_turn"));
  ASSERT_EQ(multi.model.num_links(), 6);
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(multi.model.joint_min[0], -inf);
  EXPECT_EQ(multi.model.joint_max[0], inf);
  EXPECT_EQ(multi.model.joint_min[2], -2 * kPi);
  EXPECT_EQ(multi.model.joint_max[2], 2 * kPi);
  EXPECT_EQ(multi.model.joint_min[4], -inf);
  EXPECT_EQ(multi.model.joint_max[5], 2 * kPi);
}

// Random poses within the limits: flexkin's FK is KDL's for every design.
TEST(UrdfSnakes, ForwardKinematicsMatchesKdlAtRandomPoses) {
  std::mt19937 rng(15);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const snakes::SnakeDesign& d : snakes::AllSnakeDesigns(kModules)) {
    const Arm arm = LoadDesign(d);
    const int n = arm.model.num_links();
    for (int trial = 0; trial < 10; ++trial) {
      JointAngles q;
      q.angle.resize(n);
      for (int j = 0; j < n; ++j) {
        const double lo = std::isfinite(arm.model.joint_min[j]) ? arm.model.joint_min[j] : -10.0;
        const double hi = std::isfinite(arm.model.joint_max[j]) ? arm.model.joint_max[j] : 10.0;
        q.angle[j] = lo + (hi - lo) * unit(rng);
      }
      ExpectSameKinematics(arm, q, d.name + " trial " + std::to_string(trial));
    }
  }
}

TEST(UrdfSnakes, PitchYawSnakeTracksCircleAndLine) {
  ExpectDesignTracks(Design("pitch_yaw"), 0.45, 0.1, 0.0, 0.15, 0.2);
}
TEST(UrdfSnakes, UniversalSnakeTracksCircleAndLine) {
  ExpectDesignTracks(Design("universal"), 0.22, 0.05, 0.0, 0.15, 0.2);
}
TEST(UrdfSnakes, RollSnakeTracksCircleAndLine) {
  ExpectDesignTracks(Design("roll"), 0.22, 0.05, 0.1, 0.15, 0.2);
}
TEST(UrdfSnakes, PrismaticArmTracksCircleAndLine) {
  ExpectDesignTracks(Design("prismatic"), 0.6, 0.3, 0.1, 0.15, 0.2);
}
TEST(UrdfSnakes, MultiTurnArmTracksCircleAndLine) {
  ExpectDesignTracks(Design("multi_turn"), 1.0, 0.9, 0.1, 0.1, 0.12);
}

// Out along the arm beyond its length with the slide retracted: the prismatic joint extends,
// within its limits.
TEST(UrdfSnakes, PrismaticJointExtendsWithinItsLimits) {
  Arm arm = LoadDesign(Design("prismatic"));
  snakes::BendInitial(&arm.model, 0.3, 0.2, 0.1);
  arm.model.initial.angle[3] = 0.05;
  const Eigen::Vector3d ee = EndEffector(arm.model, arm.model.initial);
  // reach() has every joint at 0: the slide retracted.
  const double reach_retracted = arm.model.reach() + 0.05;
  const Eigen::Vector3d far = ee.normalized() * (reach_retracted + 0.1);
  const Points path = snakes::LineTo(ee, far, 60);
  const ArmOptions options;
  const ArmTrajectory t = TrackPath(arm.model, path, options);
  ExpectTracked(arm, path, options, t, "prismatic outward");
  double lowest = arm.model.initial.angle[3], highest = lowest;
  for (const ArmStepReport& step : t.steps) {
    lowest = std::min(lowest, step.state.angles.angle[3]);
    highest = std::max(highest, step.state.angles.angle[3]);
  }
  EXPECT_GE(lowest, 0.0);
  EXPECT_LE(highest, 0.3);
  EXPECT_GT(highest, 0.05 + 0.09) << "the slide must extend to reach the far end";
}

// The end effector circles the turntable twice: the continuous base joint turns beyond pi (to
// about 4 pi) without wrapping, and every step moves every joint a little.
TEST(UrdfSnakes, ContinuousJointTurnsTwiceWithoutWrapping) {
  Arm arm = LoadDesign(Design("multi_turn"));
  arm.model.initial.angle << 0.0, 0.2, 0.5, -0.3, 0.1, 0.4;
  const Eigen::Vector3d ee = EndEffector(arm.model, arm.model.initial);
  const double radius = ee.head<2>().norm(), start = std::atan2(ee.y(), ee.x());
  const int steps = 100;
  Points path(steps, 3);
  for (int k = 0; k < steps; ++k) {
    const double a = start + 4.0 * kPi * (k + 1) / steps;
    path.row(k) << radius * std::cos(a), radius * std::sin(a), ee.z();
  }
  const ArmOptions options;
  const ArmTrajectory t = TrackPath(arm.model, path, options);
  ExpectTracked(arm, path, options, t, "two turns");
  Eigen::VectorXd last = arm.model.initial.angle;
  double largest = 0.0;
  for (const ArmStepReport& step : t.steps) {
    EXPECT_LT((step.state.angles.angle - last).cwiseAbs().maxCoeff(), 1.0) << "a wrap";
    last = step.state.angles.angle;
    largest = std::max(largest, step.state.angles.angle.cwiseAbs().maxCoeff());
  }
  EXPECT_GT(largest, kPi);
  EXPECT_GT(std::abs(t.steps.back().state.angles.angle[0]), 3.0 * kPi)
      << "the turntable turned " << t.steps.back().state.angles.angle[0];
}

// The tool frame's x axis (in the tip link's frame) held along a world direction 0.3 rad from
// where it starts, while the end effector tracks a circle: KDL's tip frame agrees.
TEST(UrdfSnakes, PitchYawSnakePointsAlongADirection) {
  Arm arm = LoadDesign(Design("pitch_yaw"));
  snakes::BendInitial(&arm.model, 0.45, 0.1, 0.0);
  const ToolPose tool = ToolPoseAt(arm.model, arm.model.initial);
  const Eigen::Vector3d axis0 = tool.rotation.col(0);
  const auto [u, v] = PlaneAcross(axis0);
  const Eigen::Vector3d direction = Eigen::AngleAxisd(0.3, u) * axis0;
  ArmOptions options;
  options.pointing.enabled = true;
  options.pointing.axis = Eigen::Vector3d::UnitX();
  options.pointing.direction = direction;
  options.pointing.angle_tolerance = 1e-9;
  const Points path = PathsFor(arm.model, 0.1, 0.1, 64).circle;
  const ArmTrajectory t = TrackPath(arm.model, path, options);
  ExpectTracked(arm, path, options, t, "pointing along");
  for (size_t i = 0; i < t.steps.size(); ++i) {
    const ArmStepReport& step = t.steps[i];
    EXPECT_LE(step.pointing_error, 1e-8) << i;
    const peers::KdlUrdfPose kdl =
        peers::KdlUrdfForward(arm.kdl, peers::KdlJointArray(step.state.angles.angle));
    const Eigen::Vector3d pointed = kdl.tip_rotation.col(0);
    EXPECT_LE(std::atan2(pointed.cross(direction).norm(), pointed.dot(direction)), 1e-8) << i;
  }
  EXPECT_LE(t.max_pointing_error, 1e-8);
  // KDL's trackers given the frames flexkin reached (the benchmark's position + pointing task)
  // reach them too, to KDL's resolution of rotations: KDL's frame difference (Rotation::GetRot)
  // reads a rotation whose off-diagonal terms are within KDL::epsilon = 1e-6 of symmetric as no
  // rotation at all, so neither NR's stopping test nor LMA's error sees an angle below about
  // 1e-6 rad (measured here: up to 5.6e-7 rad left where both report success).
  std::vector<Eigen::Matrix3d> frames;
  for (const ArmStepReport& step : t.steps) {
    frames.push_back(ToolPoseAt(arm.model, step.state.angles).rotation);
  }
  peers::KdlUrdfOptions kdl_options;
  kdl_options.tolerance = options.tolerance * MeanLink(arm.model);
  kdl_options.angle_tolerance = 1e-6;
  kdl_options.rotation_weight = MeanLink(arm.model);
  for (peers::KdlUrdfSolver solver :
       {peers::KdlUrdfSolver::kNewtonPinv, peers::KdlUrdfSolver::kLma}) {
    const peers::KdlUrdfTrajectory kdl = peers::TrackUrdfPathWithKdl(
        arm.kdl, arm.model.initial.angle, path, solver, kdl_options, frames);
    EXPECT_EQ(kdl.unreached, 0) << peers::KdlUrdfSolverName(solver);
    EXPECT_LE(kdl.max_angle_error, 1e-6) << peers::KdlUrdfSolverName(solver);
  }
}

// The universal snake's tool x axis looking at a point half a metre ahead while the end effector
// tracks a circle.
TEST(UrdfSnakes, UniversalSnakeLooksAtAPoint) {
  Arm arm = LoadDesign(Design("universal"));
  snakes::BendInitial(&arm.model, 0.22, 0.05, 0.0);
  const ToolPose tool = ToolPoseAt(arm.model, arm.model.initial);
  const Eigen::Vector3d look =
      tool.position + 0.5 * tool.rotation.col(0) + 0.1 * tool.rotation.col(1);
  ArmOptions options;
  options.pointing.enabled = true;
  options.pointing.axis = Eigen::Vector3d::UnitX();
  options.pointing.look_at = true;
  options.pointing.point = look;
  options.pointing.angle_tolerance = 1e-9;
  const Points path = PathsFor(arm.model, 0.1, 0.1, 64).circle;
  const ArmTrajectory t = TrackPath(arm.model, path, options);
  ExpectTracked(arm, path, options, t, "looking at");
  for (size_t i = 0; i < t.steps.size(); ++i) {
    const ArmStepReport& step = t.steps[i];
    EXPECT_LE(step.pointing_error, 1e-8) << i;
    const peers::KdlUrdfPose kdl =
        peers::KdlUrdfForward(arm.kdl, peers::KdlJointArray(step.state.angles.angle));
    const Eigen::Vector3d pointed = kdl.tip_rotation.col(0);
    const Eigen::Vector3d wanted = look - kdl.points.row(arm.model.num_links()).transpose();
    EXPECT_LE(std::atan2(pointed.cross(wanted).norm(), pointed.dot(wanted)), 1e-8) << i;
  }
}

// The URDF's velocity limits (2 rad/s) with a time step of 10 ms between path points: steps that
// would turn a joint faster are split into legs, and no joint moves more than its limit allows
// over the legs of its step.
TEST(UrdfSnakes, UniversalSnakeKeepsVelocityLimits) {
  Arm arm = LoadDesign(Design("universal"));
  snakes::BendInitial(&arm.model, 0.22, 0.05, 0.0);
  ArmOptions options;
  options.time_step = 0.01;
  const Points path = PathsFor(arm.model, 0.15, 0.2, 64).circle;
  const ArmTrajectory t = TrackPath(arm.model, path, options);
  ExpectTracked(arm, path, options, t, "velocity limits");
  Eigen::VectorXd last = arm.model.initial.angle;
  long long legs = 0;
  for (size_t i = 0; i < t.steps.size(); ++i) {
    const ArmStepReport& step = t.steps[i];
    ASSERT_GE(step.velocity_legs, 1) << i;
    EXPECT_LE(step.velocity_ratio, 1.0 + 1e-12) << i;
    const Eigen::VectorXd speed =
        (step.state.angles.angle - last).cwiseAbs() / (step.velocity_legs * options.time_step);
    EXPECT_LE((speed.array() / arm.model.max_velocity.array()).maxCoeff(), 1.0 + 1e-9) << i;
    last = step.state.angles.angle;
    legs += step.velocity_legs;
  }
  EXPECT_EQ(t.velocity_legs, legs);
  EXPECT_GT(legs, static_cast<long long>(t.steps.size())) << "no step needed more than one leg";
}

// --- Refusals: not a serial chain of revolute and prismatic joints. ---

std::string InputErrorOf(const std::string& urdf, const UrdfChain& chain) {
  try {
    ArmFromUrdf(urdf, chain);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

// base_link -j0-> upper -j1-> elbow_link -j2-> fore -j3-> tip_link, then `extra` added, with
// joint `replaced`'s type set to `type`.
std::string SmallArm(const std::string& replaced = "", const std::string& type = "",
                     const std::string& extra = "") {
  const char* names[] = {"j0", "j1", "j2", "j3"};
  const char* links[] = {"base_link", "upper", "elbow_link", "fore", "tip_link"};
  std::ostringstream out;
  out << "<?xml version=\"1.0\"?>\n<robot name=\"small\">\n";
  for (const char* link : links) out << "  <link name=\"" << link << "\"/>\n";
  for (int j = 0; j < 4; ++j) {
    const std::string t = names[j] == replaced ? type : (j == 3 ? "fixed" : "revolute");
    out << "  <joint name=\"" << names[j] << "\" type=\"" << t << "\"><parent link=\"" << links[j]
        << "\"/><child link=\"" << links[j + 1] << "\"/>"
        << "<origin xyz=\"" << (j == 0 ? 0.0 : 0.2) << " 0 0\"/><axis xyz=\"0 " << (j % 2) << " "
        << (1 - j % 2) << "\"/>"
        << "<limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>\n";
  }
  out << extra << "</robot>\n";
  return out.str();
}

TEST(UrdfSnakes, RefusalsNameTheElement) {
  UrdfChain chain;
  chain.base_link = "base_link";
  chain.tip_link = "tip_link";
  ASSERT_NO_THROW(ArmFromUrdf(SmallArm(), chain));
  EXPECT_THAT(InputErrorOf(SmallArm("j1", "floating"), chain), HasSubstr("j1"));
  EXPECT_THAT(InputErrorOf(SmallArm("j2", "planar"), chain), HasSubstr("j2"));
  // A branch at elbow_link and no tip link named: which leaf is the tip?
  const std::string branch = SmallArm(
      "", "",
      "  <link name=\"thumb\"/>\n  <joint name=\"jt\" type=\"revolute\"><parent "
      "link=\"elbow_link\"/><child link=\"thumb\"/><origin xyz=\"0 0.1 0\"/><axis xyz=\"0 0 1\"/>"
      "<limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>\n");
  UrdfChain no_tip;
  no_tip.base_link = "base_link";
  EXPECT_THAT(InputErrorOf(branch, no_tip), HasSubstr("elbow_link"));
  EXPECT_NO_THROW(ArmFromUrdf(branch, chain));  // with the tip named, the branch is off the chain
  // A loop: "fore" is the child of j2 and of a second joint from base_link.
  const std::string loop =
      SmallArm("", "",
               "  <joint name=\"j_loop\" type=\"revolute\"><parent link=\"base_link\"/><child "
               "link=\"fore\"/><origin xyz=\"0 0.3 0\"/><axis xyz=\"0 0 1\"/>"
               "<limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>\n");
  EXPECT_THAT(InputErrorOf(loop, chain), HasSubstr("fore"));
}

}  // namespace
}  // namespace flexkin
