// Several targets on trees against Orocos KDL's tree solvers (Debian's liborocos-kdl), in the same
// run: TreeIkSolverPos_NR_JL with TreeIkSolverVel_wdls (Newton-Raphson on the stacked Jacobians of
// every endpoint, weighted damped least squares), as KDL's users set them up, against
// ReachTargets (the natural passes) and StepTreeOverall (the exact least-motion step).
//
// The same kinematic trees: scenes::TreeShape's (3D, unit links, the base fixed) as KDL trees,
// each link two revolute joints (about the parent frame's z, then the new y) and a segment of
// its length along x: a link's two angles are its direction, as a point tree's link has two
// degrees of freedom. The joints start at the angles of the shape's points (checked: KDL's
// forward kinematics puts the endpoints on the points to 1e-12). Targets: scenes::TreeTips's
// points, each round a circle of radius 0.3 (120 frames a turn), every solve from the last one's
// answer, as an animation runs. Position only: the task-space weights of the rotations are 0.
// Accuracy: KDL's eps and flexkin's tolerance both 1e-10 (of a unit link); the largest distance
// of an endpoint from its target after each solve is measured by KDL's own forward kinematics
// (for KDL) and from the points (flexkin), and reported.
// Run: build/bench/tree_kdl_benchmark --benchmark_repetitions=3
//      --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/tree.hpp>
#include <kdl/treefksolverpos_recursive.hpp>
#include <kdl/treeiksolverpos_nr_jl.hpp>
#include <kdl/treeiksolvervel_wdls.hpp>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "flexkin/tree.h"
#include "flexkin/tree_overall.h"
#include "scenes/scenes.h"
#include "solve_counters.h"

namespace flexkin {
namespace {

std::string PointName(int i) { return "p" + std::to_string(i); }

// The KDL tree of a 3D point tree rooted at point 0 (at the origin), at joint angles 0 on the
// tree's points. Segment "p<i>" ends at point i; "p<i>_z" holds its first joint, whose fixed
// frame turns the parent's x axis onto the link (so the two joints start away from their
// gimbal lock, each link's direction being the joints' zero).
KDL::Tree MakeKdlTree(const Tree& t) {
  KDL::Tree tree("p0");
  const int count = static_cast<int>(t.parents.size());
  std::vector<KDL::Rotation> frame(count);  // each point's segment frame, in the world
  std::vector<std::vector<int>> children(count);
  for (int i = 1; i < count; ++i) children[t.parents[i]].push_back(i);
  std::vector<int> stack{0};
  while (!stack.empty()) {
    const int u = stack.back();
    stack.pop_back();
    for (int c : children[u]) {
      const Eigen::Vector3d d = (t.points.row(c) - t.points.row(u)).transpose();
      const double length = d.norm();
      KDL::Vector e = frame[u].Inverse() * KDL::Vector(d.x(), d.y(), d.z());
      e.Normalize();
      // The least rotation taking x to e (half a turn about z for e = -x).
      KDL::Vector axis = KDL::Vector(1, 0, 0) * e;
      const double sine = axis.Normalize();
      const KDL::Rotation turn = sine > 1e-12 ? KDL::Rotation::Rot2(axis, std::atan2(sine, e.x()))
                                 : e.x() > 0  ? KDL::Rotation::Identity()
                                              : KDL::Rotation::RotZ(M_PI);
      frame[c] = frame[u] * turn;
      const std::string z = PointName(c) + "_z";
      tree.addSegment(KDL::Segment(z, KDL::Joint(z + "j", KDL::Joint::RotZ), KDL::Frame(turn)),
                      PointName(u));
      tree.addSegment(KDL::Segment(PointName(c), KDL::Joint(PointName(c) + "j", KDL::Joint::RotY),
                                   KDL::Frame(KDL::Vector(length, 0, 0))),
                      z);
      stack.push_back(c);
    }
  }
  return tree;
}

constexpr int kFrames = 120;

constexpr double kTolerance = 1e-10;

// Args: shape (scenes::TreeKind).
void BM_Kdl(benchmark::State& state) {
  const auto kind = static_cast<scenes::TreeKind>(state.range(0));
  const Tree tree = scenes::TreeShape(kind);
  const std::vector<int> tips = scenes::TreeTips(kind);
  const KDL::Tree kdl = MakeKdlTree(tree);
  std::vector<std::string> endpoints;
  for (int t : tips) endpoints.push_back(PointName(t));
  const unsigned joints = kdl.getNrOfJoints();
  KDL::JntArray q_min(joints), q_max(joints);
  for (unsigned j = 0; j < joints; ++j) {
    q_min(j) = -std::numeric_limits<double>::max();
    q_max(j) = std::numeric_limits<double>::max();
  }
  KDL::TreeFkSolverPos_recursive fk(kdl);
  KDL::TreeIkSolverVel_wdls vel(kdl, endpoints);
  Eigen::MatrixXd weights = Eigen::MatrixXd::Zero(6 * tips.size(), 6 * tips.size());
  for (size_t e = 0; e < tips.size(); ++e) {
    for (int r = 0; r < 3; ++r) weights(6 * e + r, 6 * e + r) = 1.0;  // positions only
  }
  vel.setWeightTS(weights);
  // The damping: KDL's default, 0, gives NaN once the rotations' weights are 0 (the zero
  // singular values are inverted); 1e-6 changes the steps by less than rounding here and the
  // iterations converge as without it (3 for a step of 0.1 on the chain).
  vel.setLambda(1e-6);
  KDL::TreeIkSolverPos_NR_JL ik(kdl, endpoints, q_min, q_max, fk, vel, 500, kTolerance);
  const std::vector<Points> targets = scenes::TipCircles(tree, tips, kFrames);
  // The start, checked: the endpoints on the tree's points.
  double start_error = 0.0;
  for (size_t e = 0; e < tips.size(); ++e) {
    KDL::Frame f;
    fk.JntToCart(KDL::JntArray(joints), f, endpoints[e]);
    start_error = std::max(
        start_error,
        (Eigen::Vector3d(f.p.x(), f.p.y(), f.p.z()) - tree.points.row(tips[e]).transpose()).norm());
  }
  if (start_error > 1e-12) {
    state.SkipWithError(
        ("the KDL tree does not match the shape: " + std::to_string(start_error)).c_str());
    return;
  }
  KDL::JntArray q(joints), q_out(joints);
  std::vector<KDL::Frames> goals(kFrames);
  for (int f = 0; f < kFrames; ++f) {
    for (size_t e = 0; e < tips.size(); ++e) {
      goals[f][endpoints[e]] =
          KDL::Frame(KDL::Vector(targets[f](e, 0), targets[f](e, 1), targets[f](e, 2)));
    }
  }
  int64_t solves = 0, failed = 0;
  double worst = 0.0;
  KDL::Frame f;
  for (auto _ : state) {
    const KDL::Frames& goal = goals[solves % kFrames];
    const double status = ik.CartToJnt(q, goal, q_out);  // KDL's own stopping test, at eps
    state.PauseTiming();
    double error = 0.0;
    for (size_t e = 0; e < tips.size(); ++e) {
      fk.JntToCart(q_out, f, endpoints[e]);
      error = std::max(error, (f.p - goal.at(endpoints[e]).p).Norm());
    }
    failed += status < 0 || !(error <= 1e3 * kTolerance);  // (NaN fails)
    if (std::isfinite(error)) worst = std::max(worst, error);
    q = q_out;
    ++solves;
    state.ResumeTiming();
  }
  SetSolveCounters(state, solves, failed, worst);
}

// Args: shape, 0 the natural passes (tractrix, centroid) or 1 the overall step.
void BM_Flexkin(benchmark::State& state) {
  const auto kind = static_cast<scenes::TreeKind>(state.range(0));
  const Tree tree = scenes::TreeShape(kind);
  const std::vector<int> tips = scenes::TreeTips(kind);
  ReachOptions options;
  options.tolerance = kTolerance;
  const TreeReacher reacher = MakeTreeReacher(tree, tips, {0}, {}, options);
  const std::vector<Points> targets = scenes::TipCircles(tree, tips, kFrames);
  const bool overall = state.range(1) != 0;
  const TreeOverallOptions overall_options;
  Points points = tree.points;
  int64_t solves = 0, failed = 0;
  double worst = 0.0;
  for (auto _ : state) {
    const Points& goal = targets[solves % kFrames];
    const bool ok = overall ? StepTreeOverall(reacher, goal, overall_options, &points).converged
                            : ReachTargets(reacher, goal, &points).reached;
    state.PauseTiming();
    failed += !ok;
    for (size_t e = 0; e < tips.size(); ++e) {
      worst = std::max(worst, (points.row(tips[e]) - goal.row(e)).norm());
    }
    ++solves;
    state.ResumeTiming();
  }
  SetSolveCounters(state, solves, failed, worst);
}

BENCHMARK(BM_Kdl)->Arg(0)->Arg(1)->Arg(2)->ArgName("shape")->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Flexkin)
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->ArgNames({"shape", "overall"})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace flexkin

BENCHMARK_MAIN();
