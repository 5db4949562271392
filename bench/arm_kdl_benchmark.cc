// flexkin's fixed-base arm (TrackPath, Newton fixed base) against Orocos KDL's Jacobian
// pseudo-inverse (ChainIkSolverPos_NR + ChainIkSolverVel_pinv) and Levenberg-Marquardt
// (ChainIkSolverPos_LMA), testing/kdl_peer.h, on the same arm and the same end-effector path:
// a planar arm of 8 to 512 unit links bent into a circular arc with the end effector at 70% of
// the reach, the end effector tracing a circle of one link radius in 64 steps; the same as a
// spatial arm with spherical joints (8 to 128 links), the circle tilted out of the arc's plane
// (KDL: a universal joint per link, the same two degrees of freedom as flexkin's joint,
// testing/kdl_peer.h). Each KDL step warm-started from the previous one, tolerance 1e-10 of a
// link for all three; KDL's solvers made once per path.
//   build/bench/arm_kdl_benchmark --benchmark_counters_tabular=true
// Timing: one path per iteration, manual time = the solver's own work: flexkin's TrackPath call,
// KDL's CartToJnt calls summed (its goal orientation, and the points and angles read back from
// its joints, are outside the clock); Google Benchmark's repetitions give medians of both.
// Counters: s/step (time per step); x_flexkin (this solver's time per step over flexkin's, the
// medians of 5 paths each, measured in this run before the timed loop); max_err
// (largest end-effector error, link lengths); unreached; motion of the joint nearest the end
// effector (m_ee), at the middle (m_mid) and nearest the base (m_base), total |dtheta| along the
// path (rad), and their sum over all joints (m_sum); iters/step; flexkin's passes over the links
// per step (passes/step).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "arm_metrics.h"
#include "flexkin/arm.h"
#include "kdl_peer.h"
#include "scenes/scenes.h"

namespace {

using flexkin::peers::KdlSolver;
namespace scenes = flexkin::scenes;

// 64 targets on a circle of one link radius through the end effector's start. Planar: in the
// plane; spatial: tilted 45 degrees out of the arc's plane, about the x axis.
flexkin::Points CirclePath(const flexkin::ArmModel& model) {
  return scenes::CircleOfTargets(model, 1.0, 64, scenes::CircleTilt::kTilted45);
}

// The scene of a benchmark: range(0) links, range(1) the dimension.
flexkin::ArmModel Scene(const benchmark::State& state) {
  const int links = static_cast<int>(state.range(0));
  return scenes::ArcArm(static_cast<int>(state.range(1)), links,
                        scenes::ArcTurnForReach(links, 0.7));
}

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// flexkin's seconds per step: the median of 5 runs of TrackPath (wall time).
double FlexkinSecondsPerStep(const flexkin::ArmModel& model, const flexkin::Points& path) {
  std::vector<double> times;
  for (int r = 0; r < 5; ++r) {
    const auto start = std::chrono::steady_clock::now();
    const flexkin::ArmTrajectory t = flexkin::TrackPath(model, path, flexkin::ArmOptions{});
    times.push_back(Seconds(start));
    benchmark::DoNotOptimize(t.steps.back().state.points.data());
  }
  return Median(times) / static_cast<double>(path.rows());
}

// KDL's seconds per step: the median of 5 paths of its own solve time.
double KdlSecondsPerStep(const flexkin::ArmModel& model, const flexkin::Points& path,
                         KdlSolver solver) {
  std::vector<double> times;
  for (int r = 0; r < 5; ++r) {
    times.push_back(flexkin::peers::TrackPathWithKdl(model, path, solver, {}).seconds);
  }
  return Median(times) / static_cast<double>(path.rows());
}

void SetMotionCounters(benchmark::State& state, const Eigen::VectorXd& motion) {
  const Eigen::Index n = motion.size();
  state.counters["m_ee"] = motion[n - 1];
  state.counters["m_mid"] = motion[n / 2];
  state.counters["m_base"] = motion[0];
  state.counters["m_sum"] = motion.sum();
}

// `per_step`: this solver's median seconds per step; `flexkin_per_step`: flexkin's.
void SetStepCounters(benchmark::State& state, double steps, double per_step,
                     double flexkin_per_step) {
  state.SetItemsProcessed(static_cast<int64_t>(steps));  // items = steps
  // Seconds per step of the timed (manual) time (printed with an SI prefix: 34u = 34 us).
  state.counters["s/step"] =
      benchmark::Counter(steps, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  // This solver's time per step over flexkin's.
  state.counters["x_flexkin"] = per_step / flexkin_per_step;
}

void Flexkin(benchmark::State& state) {
  const flexkin::ArmModel model = Scene(state);
  const flexkin::Points path = CirclePath(model);
  const double reference = FlexkinSecondsPerStep(model, path);
  flexkin::ArmTrajectory t;
  double steps = 0, iterations = 0, passes = 0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    t = flexkin::TrackPath(model, path, flexkin::ArmOptions{});
    state.SetIterationTime(Seconds(start));
    benchmark::DoNotOptimize(t.steps.back().state.points.data());
    steps += t.steps.size();
    passes += t.total_passes;
    for (const auto& s : t.steps) iterations += s.iterations;
  }
  SetStepCounters(state, steps, reference, reference);
  state.counters["iters/step"] = iterations / steps;
  state.counters["passes/step"] = passes / steps;  // passes over the links (cost ~ passes * n)
  state.counters["max_err"] = t.max_ee_error;
  state.counters["unreached"] = t.unreached;
  SetMotionCounters(
      state, flexkin::peers::TotalJointMotion(model, model.initial, flexkin::peers::AnglesOf(t)));
}

void Kdl(benchmark::State& state, KdlSolver solver) {
  const flexkin::ArmModel model = Scene(state);
  const flexkin::Points path = CirclePath(model);
  const double reference = FlexkinSecondsPerStep(model, path);
  const double kdl_per_step = KdlSecondsPerStep(model, path, solver);
  flexkin::peers::KdlTrajectory t;
  double steps = 0, iterations = 0;
  for (auto _ : state) {
    t = flexkin::peers::TrackPathWithKdl(model, path, solver, flexkin::peers::KdlOptions{});
    state.SetIterationTime(t.seconds);  // KDL's own solves only
    benchmark::DoNotOptimize(t.steps.back().q.data.data());
    steps += t.steps.size();
    iterations += t.mean_iterations * t.steps.size();
  }
  SetStepCounters(state, steps, kdl_per_step, reference);
  state.counters["iters/step"] = iterations / steps;
  state.counters["max_err"] = t.max_ee_error;
  state.counters["unreached"] = t.unreached;
  std::vector<flexkin::JointAngles> angles;
  for (const auto& s : t.steps) angles.push_back(s.angles);
  SetMotionCounters(state, flexkin::peers::TotalJointMotion(model, model.initial, angles));
}

void KdlNrPinv(benchmark::State& state) { Kdl(state, KdlSolver::kNewtonPinv); }
void KdlLma(benchmark::State& state) { Kdl(state, KdlSolver::kLma); }

// Planar arms of 8 to 512 links; spatial (spherical joints, two KDL joints per link) of 8 to
// 128 (KDL's pseudo-inverse at 512 spatial links takes seconds per step).
void Sizes(benchmark::internal::Benchmark* b) {
  for (int n : {8, 32, 128, 512}) b->Args({n, 2});
  for (int n : {8, 32, 128}) b->Args({n, 3});
  b->ArgNames({"links", "dim"})->Unit(benchmark::kMicrosecond)->UseManualTime();
}
BENCHMARK(Flexkin)->Apply(Sizes);
BENCHMARK(KdlNrPinv)->Apply(Sizes);
BENCHMARK(KdlLma)->Apply(Sizes);

}  // namespace

BENCHMARK_MAIN();
