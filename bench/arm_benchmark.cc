// Fixed-base arm step: Newton on the base residual against the predecessors' fixed-point
// iteration, per step, for 8 to 512 links and for end-effector positions nearer and nearer the
// edge of the workspace. Counters: iterations, sweeps and passes over the links per step (a pass
// costs ~n link steps; the sweeps of a finite-difference Jacobian share one pass).
//   build/bench/arm_benchmark --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include "flexkin/arm.h"
#include "scenes/scenes.h"

namespace {

namespace scenes = flexkin::scenes;

void Track(benchmark::State& state, flexkin::FixedBaseMethod method) {
  const int links = static_cast<int>(state.range(0));
  const double fraction = state.range(1) / 1000.0;
  const flexkin::ArmModel model =
      scenes::ArcArm(2, links, scenes::ArcTurnForReach(links, fraction));
  // A small circle (radius: one link) traced by the end effector in 64 steps.
  const flexkin::Points path = scenes::CircleOfTargets(model, 1.0, 64);
  flexkin::ArmOptions options;
  options.method = method;
  long long steps = 0, iterations = 0, sweeps = 0, passes = 0, unreached = 0;
  for (auto _ : state) {
    const flexkin::ArmTrajectory t = flexkin::TrackPath(model, path, options);
    benchmark::DoNotOptimize(t.steps.back().state.points.data());
    for (const auto& s : t.steps)
      iterations += s.iterations, sweeps += s.sweeps, passes += s.passes;
    steps += t.steps.size();
    unreached += t.unreached;
  }
  state.SetItemsProcessed(steps);  // items = steps: items_per_second is steps per second
  state.counters["iters/step"] = double(iterations) / steps;
  state.counters["sweeps/step"] = double(sweeps) / steps;
  state.counters["passes/step"] = double(passes) / steps;
  state.counters["unreached"] = double(unreached) / state.iterations();
  // Seconds per step (printed with an SI prefix: 34u = 34 microseconds).
  state.counters["s/step"] =
      benchmark::Counter(double(steps), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void Newton(benchmark::State& state) { Track(state, flexkin::FixedBaseMethod::kNewton); }
void FixedPoint(benchmark::State& state) { Track(state, flexkin::FixedBaseMethod::kFixedPoint); }

// Links 8..512 at 70% of the reach; then 128 links at 30%..99% of the reach.
void Sizes(benchmark::internal::Benchmark* b) {
  for (int n : {8, 32, 128, 512}) b->Args({n, 700});
  for (int f : {300, 900, 970, 990}) b->Args({128, f});
  b->ArgNames({"links", "reach_permille"})->Unit(benchmark::kMicrosecond);
}
BENCHMARK(Newton)->Apply(Sizes);
BENCHMARK(FixedPoint)->Apply(Sizes);

}  // namespace

BENCHMARK_MAIN();
