// flexkin's TrackPath on snakes read from URDF (ArmFromUrdf, issue 15) against Orocos KDL reading
// the same URDF text with kdl_parser (testing/kdl_urdf_peer.h): the Jacobian pseudo-inverse
// (ChainIkSolverPos_NR + ChainIkSolverVel_pinv) and Levenberg-Marquardt (ChainIkSolverPos_LMA),
// each step warm-started from the last. Snakes of 16, 32 and 64 modules (testing/snake_urdfs.h):
// universal-joint modules (2 joints per module, at one point) and roll modules (pitch, yaw and a
// twist joint along the link: 3 per module), bent into an arc (2.4 rad of pitch and 0.6 rad of
// yaw spread over the modules) so that the start is not the straight, singular pose; the end
// effector traces a circle of one module radius through its start, tilted out of the arc's
// plane, in 64 steps. Position only, and position + pointing (the tool's x axis held along a
// world direction 0.1 rad from where it starts; KDL gets the full frame flexkin reached at each
// step, see kdl_urdf_peer.h). Tolerance 1e-10 of the mean link length for all three.
//   build/bench/urdf_kdl_benchmark --benchmark_counters_tabular=true
// Counters (all times CPU time of this thread; the machine may be shared):
//   s/step       this benchmark's time per step (timed loop)
//   x_nr, x_lma  (Flexkin rows) KDL NR's / LMA's time per step over flexkin's: the medians of 5
//                runs of each KDL solver and 25 of flexkin, each after a run not timed, measured
//                once per scene in this process
//   x_flexkin    (KDL rows) this solver's median time per step over flexkin's
//   us/module    the median time per step over the number of modules (linearity: constant if
//                the cost grows linearly with the snake's length)
//   max_err      largest end-effector error (mean link lengths); max_angle (rad): pointing error
//                (flexkin) or angle to the target frame (KDL)
//   unreached    steps not reached; off_limits (KDL): steps that left a joint limit
//   iters/step   solver iterations per step
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <tuple>
#include <vector>

#include "flexkin/arm.h"
#include "flexkin/urdf.h"
#include "kdl_urdf_peer.h"
#include "snake_urdfs.h"

namespace {

using flexkin::peers::KdlUrdfSolver;
namespace peers = flexkin::peers;
namespace snakes = flexkin::snakes;

constexpr int kSteps = 64;
constexpr int kRuns = 5;          // runs per KDL solver for the reference medians
constexpr int kFlexkinRuns = 25;  // flexkin's (each run a hundred times shorter)

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double Median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// One benchmark scene: range(0) modules, range(1) design (0 universal, 1 roll), range(2)
// pointing (0 position only, 1 position + pointing).
struct Scene {
  int modules = 0;
  flexkin::ArmModel model;
  peers::KdlUrdfChain kdl;
  flexkin::Points path;
  flexkin::ArmOptions options;
  peers::KdlUrdfOptions kdl_options;
  std::vector<Eigen::Matrix3d> target_rotations;  // pointing: flexkin's reached tool rotations
  double mean_link = 0.0;
  // Median seconds per step of each solver's own work: flexkin, KDL NR and KDL LMA.
  double flexkin_per_step = 0.0, nr_per_step = 0.0, lma_per_step = 0.0;
};

flexkin::ArmTrajectory RunFlexkin(const Scene& s) {
  return flexkin::TrackPath(s.model, s.path, s.options);
}

peers::KdlUrdfTrajectory RunKdl(const Scene& s, KdlUrdfSolver solver) {
  return peers::TrackUrdfPathWithKdl(s.kdl, s.model.initial.angle, s.path, solver, s.kdl_options,
                                     s.target_rotations);
}

// After one run not timed (first calls: lazy symbol binding, first allocations, cold caches), the
// median of `runs` timed runs: flexkin's runs (64 steps) last a few hundred microseconds, a hundred
// times less than KDL's, so they take more runs for the same shelter from the machine's noise.
// `run` returns the seconds of the solver's own work: flexkin's TrackPath call (wall time), KDL's
// CartToJnt calls summed (its goal frames and the end effector read back are outside them).
template <typename Run>
double MedianPerStep(const Run& run, int runs = kRuns) {
  run();
  std::vector<double> times;
  for (int r = 0; r < runs; ++r) times.push_back(run());
  return Median(times) / kSteps;
}

std::unique_ptr<Scene> MakeScene(int modules, int design, bool pointing) {
  auto s = std::make_unique<Scene>();
  s->modules = modules;
  const std::string urdf =
      design == 0 ? snakes::UniversalSnakeUrdf(modules) : snakes::RollSnakeUrdf(modules);
  flexkin::UrdfChain chain;
  chain.base_link = "base_link";
  chain.tip_link = "tip_link";
  s->model = flexkin::ArmFromUrdf(urdf, chain);
  s->kdl = peers::KdlChainFromUrdf(urdf, "base_link", "tip_link");
  snakes::BendInitial(&s->model, 2.4 / modules, 0.6 / modules, design == 1 ? 0.05 : 0.0);
  s->mean_link = s->model.link_lengths.mean();

  // The circle: through the end effector, in the plane across the base-to-end direction tilted
  // 45 degrees toward it.
  const flexkin::ToolPose tool = flexkin::ToolPoseAt(s->model, s->model.initial);
  const Eigen::Vector3d along = (tool.position - s->model.base.head<3>()).normalized();
  const Eigen::Vector3d u0 = along.cross(Eigen::Vector3d(0.2, 0.3, 1.0)).normalized();
  const Eigen::Vector3d v = along.cross(u0).normalized();
  const Eigen::Vector3d u = (u0 + along).normalized();
  s->path = snakes::CircleThrough(tool.position, u, v, snakes::kSnakeModuleLength, kSteps);

  if (pointing) {
    s->options.pointing.enabled = true;
    s->options.pointing.axis = Eigen::Vector3d::UnitX();
    const Eigen::Vector3d axis0 = tool.rotation.col(0);
    const Eigen::Vector3d across = axis0.cross(Eigen::Vector3d(0.2, 0.3, 1.0)).normalized();
    s->options.pointing.direction = Eigen::AngleAxisd(0.1, across) * axis0;
  }
  s->kdl_options.tolerance = s->options.tolerance * s->mean_link;
  s->kdl_options.angle_tolerance = 1e-6;  // KDL's resolution of rotations (kdl_urdf_peer.h)
  s->kdl_options.rotation_weight = s->options.pointing.weight * s->mean_link;
  if (pointing) {
    // KDL's target frames: the tool frames flexkin reached.
    const flexkin::ArmTrajectory t = RunFlexkin(*s);
    for (const flexkin::ArmStepReport& step : t.steps) {
      s->target_rotations.push_back(flexkin::ToolPoseAt(s->model, step.state.angles).rotation);
    }
  }
  s->flexkin_per_step = MedianPerStep(
      [&] {
        const auto start = std::chrono::steady_clock::now();
        const flexkin::ArmTrajectory t = RunFlexkin(*s);
        const double seconds = Seconds(start);
        benchmark::DoNotOptimize(t.steps.back().state.points.data());
        return seconds;
      },
      kFlexkinRuns);
  s->nr_per_step = MedianPerStep([&] { return RunKdl(*s, KdlUrdfSolver::kNewtonPinv).seconds; });
  s->lma_per_step = MedianPerStep([&] { return RunKdl(*s, KdlUrdfSolver::kLma).seconds; });
  return s;
}

// The scenes, made once per process (the repetitions share them and their medians).
const Scene& SceneOf(const benchmark::State& state) {
  static std::map<std::tuple<int64_t, int64_t, int64_t>, std::unique_ptr<Scene>> scenes;
  const auto key = std::make_tuple(state.range(0), state.range(1), state.range(2));
  std::unique_ptr<Scene>& scene = scenes[key];
  if (!scene) {
    scene = MakeScene(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)),
                      state.range(2) != 0);
  }
  return *scene;
}

void SetTimeCounters(benchmark::State& state, double steps, double median_per_step,
                     const Scene& s) {
  state.SetItemsProcessed(static_cast<int64_t>(steps));  // items = steps
  state.counters["s/step"] =
      benchmark::Counter(steps, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["us/module"] = 1e6 * median_per_step / s.modules;
}

void Flexkin(benchmark::State& state) {
  const Scene& s = SceneOf(state);
  flexkin::ArmTrajectory t;
  double steps = 0, iterations = 0;
  for (auto _ : state) {
    t = RunFlexkin(s);
    benchmark::DoNotOptimize(t.steps.back().state.points.data());
    steps += t.steps.size();
    for (const auto& step : t.steps) iterations += step.iterations;
  }
  SetTimeCounters(state, steps, s.flexkin_per_step, s);
  state.counters["x_nr"] = s.nr_per_step / s.flexkin_per_step;
  state.counters["x_lma"] = s.lma_per_step / s.flexkin_per_step;
  state.counters["iters/step"] = iterations / steps;
  state.counters["max_err"] = t.max_ee_error / s.mean_link;
  state.counters["max_angle"] = t.max_pointing_error;
  state.counters["unreached"] = t.unreached;
}

void Kdl(benchmark::State& state, KdlUrdfSolver solver) {
  const Scene& s = SceneOf(state);
  peers::KdlUrdfTrajectory t;
  double steps = 0, iterations = 0;
  for (auto _ : state) {
    t = RunKdl(s, solver);
    benchmark::DoNotOptimize(t.steps.back().angles.data());
    steps += t.steps.size();
    iterations += t.mean_iterations * t.steps.size();
  }
  const double median = solver == KdlUrdfSolver::kNewtonPinv ? s.nr_per_step : s.lma_per_step;
  SetTimeCounters(state, steps, median, s);
  state.counters["x_flexkin"] = median / s.flexkin_per_step;
  state.counters["iters/step"] = iterations / steps;
  state.counters["max_err"] = t.max_ee_error / s.mean_link;
  state.counters["max_angle"] = t.max_angle_error;
  state.counters["unreached"] = t.unreached;
  int off_limits = 0;
  for (const auto& step : t.steps) {
    flexkin::JointAngles q;
    q.angle = step.angles;
    off_limits += flexkin::WithinLimits(s.model, q, 1e-12) ? 0 : 1;
  }
  state.counters["off_limits"] = off_limits;
}

void KdlNrPinv(benchmark::State& state) { Kdl(state, KdlUrdfSolver::kNewtonPinv); }
void KdlLma(benchmark::State& state) { Kdl(state, KdlUrdfSolver::kLma); }

void Scenes(benchmark::internal::Benchmark* b) {
  for (int pointing : {0, 1}) {
    for (int design : {0, 1}) {
      for (int modules : {16, 32, 64}) b->Args({modules, design, pointing});
    }
  }
  b->ArgNames({"modules", "roll", "pointing"})->Unit(benchmark::kMicrosecond);
}
BENCHMARK(Flexkin)->Apply(Scenes);
BENCHMARK(KdlNrPinv)->Apply(Scenes);
BENCHMARK(KdlLma)->Apply(Scenes);

}  // namespace

BENCHMARK_MAIN();
