// Tractrix vs follow-the-leader (FTL), the baseline every hair simulator and FABRIK solver uses.
// Questions answered, each with both methods in the same run:
//   1. cost per link-step of a multi-step move (64 sub-steps), 10 to 100,000 links, on the
//      wavefront engine (both methods) and on the one-pass scalar loop (both methods);
//   2. cost per link-step of single-step moves (one sweep per call);
//   3. cost to reach 1e-6 of the continuous motion: the sub-steps each method needs (found by
//      doubling against a Richardson-extrapolated reference) and the time of that run.
// Run: build/bench/propagation_benchmark --benchmark_repetitions=5
//        --benchmark_report_aggregates_only=true   (docs/BENCHMARKS.md has the figures)

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "flexkin/curves.h"
#include "flexkin/propagate.h"
#include "scenes/scenes.h"
#include "sequential/sweep.h"

namespace flexkin {
namespace {

// The wandering leader of the coil (scenes::Coil): a smooth curve, so every link keeps moving.
Eigen::Vector3d LeaderTarget(const Eigen::Vector3d& from, int j) {
  return from + Eigen::Vector3d(0.2 * std::cos(0.05 * j), 0.2 * std::sin(0.05 * j), 0.05);
}

void SetRate(benchmark::State& state, double link_steps_per_iteration) {
  state.counters["ns_per_link_step"] =
      benchmark::Counter(link_steps_per_iteration * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// A straight chain along -x, links of 0.3, pulled along +x: every link keeps moving, however
// long the chain. (Its leading point is (-0.0, 0, 0), as the chain has always started.)
Chain StraightLine(int n) {
  const LineDef line{Eigen::Vector3d(-0.0, 0.0, 0.0), -Eigen::Vector3d::UnitX(), n, 0.3};
  return MakeChain(MakeLine(line));
}

// Question 1: one move of the leader split into `kSubsteps` sweeps. Two scenes: `wander` (the
// helix, leader on a wandering path: the motion dies out along long chains, and both methods
// skip links whose leading end did not move) and `pull` (every link moves).
constexpr int kSubsteps = 64;

void BM_MultiStep(benchmark::State& state, Method method, bool wavefront, bool wander) {
  const int n = static_cast<int>(state.range(0));
  Chain chain = wander ? scenes::Coil(n) : StraightLine(n);
  const Stepper stepper = MakeStepper(method, chain);
  std::vector<double> heads(3 * kSubsteps);
  int j = 0;
  for (auto _ : state) {
    const Eigen::Vector3d start = chain.points.row(0).transpose();
    const Eigen::Vector3d target =
        wander ? LeaderTarget(start, j++) : Eigen::Vector3d(start + Eigen::Vector3d(0.2, 0, 0));
    for (int s = 1; s <= kSubsteps; ++s) {
      const Eigen::Vector3d h = start + (target - start) * (static_cast<double>(s) / kSubsteps);
      for (int k = 0; k < 3; ++k) heads[3 * (s - 1) + k] = h[k];
    }
    (wavefront ? internal::SweepsWavefront : internal::SweepsScalar)(
        method, 3, heads.data(), kSubsteps, stepper.lengths.data(), stepper.inv_lengths.data(), n,
        chain.points.data());
    benchmark::DoNotOptimize(chain.points.data());
  }
  SetRate(state, static_cast<double>(n) * kSubsteps);
  state.counters["lanes"] = wavefront ? internal::WavefrontLanes() : 1;
}
BENCHMARK_CAPTURE(BM_MultiStep, pull_tractrix_wavefront, Method::kTractrix, true, false)
    ->RangeMultiplier(10)
    ->Range(10, 100000);
BENCHMARK_CAPTURE(BM_MultiStep, pull_ftl_wavefront, Method::kFollowTheLeader, true, false)
    ->RangeMultiplier(10)
    ->Range(10, 100000);
BENCHMARK_CAPTURE(BM_MultiStep, pull_tractrix_one_pass, Method::kTractrix, false, false)
    ->RangeMultiplier(10)
    ->Range(10, 100000);
BENCHMARK_CAPTURE(BM_MultiStep, pull_ftl_one_pass, Method::kFollowTheLeader, false, false)
    ->RangeMultiplier(10)
    ->Range(10, 100000);
BENCHMARK_CAPTURE(BM_MultiStep, wander_tractrix_wavefront, Method::kTractrix, true, true)
    ->RangeMultiplier(10)
    ->Range(10, 100000);
BENCHMARK_CAPTURE(BM_MultiStep, wander_ftl_wavefront, Method::kFollowTheLeader, true, true)
    ->RangeMultiplier(10)
    ->Range(10, 100000);

// Question 2: single-step moves, one MoveLeader call (one sweep) each.
void BM_SingleStep(benchmark::State& state, Method method) {
  const int n = static_cast<int>(state.range(0));
  Chain chain = scenes::Coil(n);
  const Stepper stepper = MakeStepper(method, chain);
  int j = 0;
  for (auto _ : state) {
    const Eigen::Vector3d target = LeaderTarget(chain.points.row(0).transpose(), j++);
    MoveLeader(stepper, target, 1, &chain.points);
    benchmark::DoNotOptimize(chain.points.data());
  }
  SetRate(state, n);
}
BENCHMARK_CAPTURE(BM_SingleStep, tractrix, Method::kTractrix)
    ->RangeMultiplier(10)
    ->Range(10, 100000);
BENCHMARK_CAPTURE(BM_SingleStep, ftl, Method::kFollowTheLeader)
    ->RangeMultiplier(10)
    ->Range(10, 100000);

// Question 3: the coil (scenes::Coil) of 20 and of 100 links, each pulled along a bent path (3
// straight moves of about 1.5 chain lengths in all).
struct AccuracyProblem {
  Chain chain;
  Points moves;
};

AccuracyProblem MakeProblem(int n) {
  AccuracyProblem problem;
  problem.chain = scenes::Coil(n);
  const double scale = problem.chain.lengths.sum() / 3.0;
  const Eigen::Vector3d start = problem.chain.points.row(0).transpose();
  problem.moves.resize(3, 3);
  problem.moves.row(0) = (start + scale * Eigen::Vector3d(1.0, 0.5, 0.0)).transpose();
  problem.moves.row(1) = (start + scale * Eigen::Vector3d(1.5, 1.5, 0.5)).transpose();
  problem.moves.row(2) = (start + scale * Eigen::Vector3d(1.0, 2.0, 1.5)).transpose();
  return problem;
}

Points Solve(const AccuracyProblem& problem, Method method, int substeps) {
  const Stepper stepper = MakeStepper(method, problem.chain);
  Points points = problem.chain.points;
  for (Eigen::Index s = 0; s < problem.moves.rows(); ++s) {
    MoveLeader(stepper, problem.moves.row(s).transpose(), substeps, &points);
  }
  return points;
}

// The continuous motion: tractrix with 2^14 and 2^15 sub-steps, Richardson-extrapolated (order 2).
const Points& Reference(const AccuracyProblem& problem, int n) {
  static std::vector<std::pair<int, Points>> cache;
  for (const auto& [size, points] : cache) {
    if (size == n) return points;
  }
  const Points fine = Solve(problem, Method::kTractrix, 1 << 15);
  const Points coarse = Solve(problem, Method::kTractrix, 1 << 14);
  cache.emplace_back(n, fine + (fine - coarse) / 3.0);
  return cache.back().second;
}

void BM_ToAccuracy(benchmark::State& state, Method method) {
  constexpr double kTolerance = 1e-6;
  const int n = static_cast<int>(state.range(0));
  const AccuracyProblem problem = MakeProblem(n);
  const Points& reference = Reference(problem, n);
  int substeps = 1;
  double error = 0.0;
  for (;; substeps *= 2) {
    error = (Solve(problem, method, substeps) - reference).rowwise().norm().maxCoeff();
    if (error <= kTolerance || substeps >= (1 << 22)) break;
  }
  for (auto _ : state) benchmark::DoNotOptimize(Solve(problem, method, substeps).data());
  state.counters["substeps"] = substeps;
  state.counters["max_error"] = error;
}
BENCHMARK_CAPTURE(BM_ToAccuracy, tractrix, Method::kTractrix)
    ->Arg(20)
    ->Arg(100)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ToAccuracy, ftl, Method::kFollowTheLeader)
    ->Arg(20)
    ->Arg(100)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace flexkin

BENCHMARK_MAIN();
