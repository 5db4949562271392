// Fixed-base arms with joint limits that saturate (docs/robots.md "Joint limits"): the cost of
// reaching every target when the sweep finds no root and the step goes to joint space, against
// the predecessors' fixed-point scheme (method fixed_point, no fallback) on the same paths.
// Planar and spherical arms of 16 and 64 unit links, limits 0.2 rad (16) and 0.08 rad (64),
// 5 paths of 100 steps whose joints swing beyond the limits (scenes/scenes.h,
// SaturatingPath). Counters per step: CPU time (s/step), passes over the links, the share of
// steps solved in joint space, and the steps not reached (of 500).
//   build/bench/arm_limits_benchmark --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "flexkin/arm.h"
#include "scenes/scenes.h"

namespace {

void Track(benchmark::State& state, flexkin::FixedBaseMethod method) {
  const int links = static_cast<int>(state.range(0)), dim = static_cast<int>(state.range(1));
  const double limit = links <= 16 ? 0.2 : 0.08;
  const flexkin::ArmModel model = flexkin::scenes::LimitedArm(dim, links, limit, 0.0);
  std::mt19937 rng(3);
  std::vector<flexkin::Points> paths;
  for (int p = 0; p < 5; ++p) {
    paths.push_back(flexkin::scenes::SaturatingPath(model, limit, 100, &rng));
  }
  flexkin::ArmOptions options;
  options.method = method;
  double steps = 0, passes = 0, joint_space = 0, unreached = 0;
  for (auto _ : state) {
    unreached = 0;
    for (const flexkin::Points& path : paths) {
      const flexkin::ArmTrajectory t = flexkin::TrackPath(model, path, options);
      benchmark::DoNotOptimize(t.steps.back().state.points.data());
      steps += t.steps.size();
      passes += t.total_passes;
      for (const auto& s : t.steps) joint_space += s.joint_space ? 1 : 0;
      unreached += t.unreached;
    }
  }
  state.counters["s/step"] =
      benchmark::Counter(steps, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["passes/step"] = passes / steps;
  state.counters["joint_space"] = joint_space / steps;  // share of the steps
  state.counters["unreached"] = unreached;              // of the 500 steps of one iteration
}

void Newton(benchmark::State& state) { Track(state, flexkin::FixedBaseMethod::kNewton); }
void FixedPoint(benchmark::State& state) { Track(state, flexkin::FixedBaseMethod::kFixedPoint); }

void Arms(benchmark::internal::Benchmark* b) {
  for (int dim : {2, 3}) {
    for (int n : {16, 64}) b->Args({n, dim});
  }
  b->ArgNames({"links", "dim"})->Unit(benchmark::kMillisecond);
}
BENCHMARK(Newton)->Apply(Arms);
BENCHMARK(FixedPoint)->Apply(Arms);

}  // namespace

BENCHMARK_MAIN();
