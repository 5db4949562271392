// Robot trees (flexkin/robot_tree.h) against Orocos KDL's tree solvers in the same run: the
// two-armed robot of examples/robot_two_arms.urdf (15 revolute joints with limits) tracking its
// hands' paths of examples/tree_robot_two_arms.json (180 frames), every solve from the last one's
// answer, as an animation runs.
//
// KDL as its users set it up: the tree read from the same URDF text by Debian's kdl_parser
// (testing/kdl_urdf_peer.h), TreeIkSolverPos_NR_JL with TreeIkSolverVel_wdls over the two hands'
// segments, the URDF's joint limits, the solvers built once, only CartToJnt inside the timer.
// Position only: the task-space weights of the rotations are 0 (and a damping of 1e-6, without
// which wdls inverts their zero singular values). Accuracy: KDL's eps and flexkin's tolerance
// 1e-10 (flexkin's of the longest link, 0.3); the largest distance of a hand from its target
// after each solve is measured by KDL's forward kinematics (KDL) or flexkin's, and reported.
// flexkin: RobotTreeSolver, the same two hands; and with the camera watching the left hand (a
// looking goal KDL's solvers do not have), for its cost.
// Run: build/bench/robot_tree_kdl_benchmark --benchmark_repetitions=5
//      --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <fstream>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/treefksolverpos_recursive.hpp>
#include <kdl/treeiksolverpos_nr_jl.hpp>
#include <kdl/treeiksolvervel_wdls.hpp>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "flexkin/any_scenario.h"
#include "flexkin/robot_tree.h"
#include "flexkin/urdf.h"
#include "kdl_urdf_peer.h"
#include "solve_counters.h"

namespace flexkin {
namespace {

constexpr double kTolerance = 1e-10;

std::string Source(const std::string& file) {
  std::ifstream in(std::string(FLEXKIN_SOURCE_DIR) + "/" + file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The example scenario: its robot (with the camera) and paths.
const TreeScenario& Example() {
  static const TreeScenario scenario = [] {
    ScenarioReadOptions read;
    read.robot = UrdfRobotScenarioOptions();
    AnyScenario s = ReadScenarioFile(
        std::string(FLEXKIN_SOURCE_DIR) + "/examples/tree_robot_two_arms.json", read);
    s.ThrowIfInvalid();
    return *s.tree;
  }();
  return scenario;
}

void BM_Kdl(benchmark::State& state) {
  const TreeScenario& scenario = Example();
  const RobotTree& robot = *scenario.robot;
  const peers::KdlUrdfTree kdl = peers::KdlTreeFromUrdf(Source("examples/robot_two_arms.urdf"));
  const std::vector<std::string> endpoints = {"l_tool", "r_tool"};
  const unsigned joints = kdl.tree.getNrOfJoints();
  KDL::JntArray q_min(joints), q_max(joints);
  for (unsigned i = 0; i < joints; ++i) {
    for (int j = 0; j < robot.joints(); ++j) {
      if (robot.joint_names[j] == kdl.joint_names[i]) {
        q_min(i) = robot.joint_min[j];
        q_max(i) = robot.joint_max[j];
      }
    }
  }
  KDL::TreeFkSolverPos_recursive fk(kdl.tree);
  KDL::TreeIkSolverVel_wdls vel(kdl.tree, endpoints);
  Eigen::MatrixXd weights = Eigen::MatrixXd::Zero(12, 12);
  for (int e = 0; e < 2; ++e) {
    for (int r = 0; r < 3; ++r) weights(6 * e + r, 6 * e + r) = 1.0;  // positions only
  }
  vel.setWeightTS(weights);
  vel.setLambda(std::pow(10.0, -static_cast<double>(state.range(0))));
  if (state.range(1) == 0) {  // without the limits
    for (unsigned i = 0; i < joints; ++i) {
      q_min(i) = -std::numeric_limits<double>::max();
      q_max(i) = std::numeric_limits<double>::max();
    }
  }
  KDL::TreeIkSolverPos_NR_JL ik(kdl.tree, endpoints, q_min, q_max, fk, vel, 500, kTolerance);
  const int frames = scenario.frames();
  std::vector<KDL::Frames> goals(frames);
  for (int f = 0; f < frames; ++f) {
    for (int e = 0; e < 2; ++e) {
      const auto& p = scenario.paths[e];
      goals[f][endpoints[e]] = KDL::Frame(KDL::Vector(p(f, 0), p(f, 1), p(f, 2)));
    }
  }
  KDL::JntArray start = peers::KdlTreeJoints(kdl, robot.joint_names, robot.initial);
  KDL::JntArray q = start, q_out(joints);
  int64_t solves = 0, failed = 0;
  double worst = 0.0;
  KDL::Frame at;
  for (auto _ : state) {
    const int f = static_cast<int>(solves % frames);
    if (f == 0) q = start;  // each pass over the path from the start
    const KDL::Frames& goal = goals[f];
    const double status = ik.CartToJnt(q, goal, q_out);
    state.PauseTiming();
    double error = 0.0;
    for (const std::string& e : endpoints) {
      fk.JntToCart(q_out, at, e);
      error = std::max(error, (at.p - goal.at(e).p).Norm());
    }
    failed += status < 0 || !(error <= 1e3 * kTolerance);
    if (std::isfinite(error)) worst = std::max(worst, error);
    q = q_out;
    ++solves;
    state.ResumeTiming();
  }
  SetSolveCounters(state, solves, failed, worst);
}

// Arg: 0 the two hands, 1 the hands and the camera watching the left hand.
void BM_Flexkin(benchmark::State& state) {
  const TreeScenario& scenario = Example();
  const bool camera = state.range(0) != 0;
  RobotTree robot = *scenario.robot;
  RobotTreeOptions options;
  options.tolerance = kTolerance;
  options.angle_tolerance = kTolerance;
  if (camera) {
    options.looks = {0, 0, 1};
  } else {
    robot.tools.resize(2);
  }
  const RobotTreeSolver solver(robot, options);
  const int frames = scenario.frames();
  const int k = static_cast<int>(robot.tools.size());
  std::vector<Points> goals(frames, Points(k, 3));
  for (int f = 0; f < frames; ++f) {
    for (int e = 0; e < k; ++e) goals[f].row(e) = scenario.paths[e].row(f);
  }
  Eigen::VectorXd q = robot.initial;
  int64_t solves = 0, failed = 0;
  double worst = 0.0;
  Points tools, axes;
  int64_t iterations = 0;
  for (auto _ : state) {
    const int f = static_cast<int>(solves % frames);
    if (f == 0) q = robot.initial;
    const RobotTreeSolve s = solver.Solve(q, goals[f]);
    state.PauseTiming();
    RobotTreeTools(robot, s.angles, &tools, &axes);
    const double error = (tools.topRows(2) - goals[f].topRows(2)).rowwise().norm().maxCoeff();
    failed += !s.converged;
    iterations += s.iterations;
    worst = std::max(worst, error);
    q = s.angles;
    ++solves;
    state.ResumeTiming();
  }
  SetSolveCounters(state, solves, failed, worst);
  state.counters["iterations"] = static_cast<double>(iterations) / static_cast<double>(solves);
}

// Args: the damping 10^-lambda, and the URDF's joint limits (1) or none (0).
BENCHMARK(BM_Kdl)
    ->ArgsProduct({{6, 4, 3, 2, 1}, {1, 0}})
    ->ArgNames({"lambda", "limits"})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Flexkin)->Arg(0)->Arg(1)->ArgName("camera")->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace flexkin

BENCHMARK_MAIN();
