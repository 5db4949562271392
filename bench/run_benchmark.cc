// The path every user takes, Run (and so `flexkin run`), against the engine's bare cost for the
// same sweeps, in one run. Scene: a straight 3D chain along -x, links of 0.3, whose leading end is
// pulled along +x in equal steps of 0.01 (every link keeps moving, however long the chain), one
// sub-step per leader step, tractrix. Cost per link-step (ns), for 20, 200, 2,000 and 100,000
// links:
//   engine        the wavefront engine over all the sweeps in one call (no metrics, no frames)
//   one_pass      the one-pass loop (SweepsScalar) over the same sweeps
//   single_calls  one MoveLeader call per leader step (the loop a user would write by hand)
//   run_*         Run with the frames copied into one buffer by the sink: recording every step
//                 (with and without link angles), every 100th step, and first and last (also
//                 with a progress callback, whose hidden cost is the difference)
//   whole_chain   min_rotation and min_joint_angle through Run (on the SIMD engine where the CPU
//                 has one) against the sub-step by sub-step loop they took before
//                 (internal::RunSubstepBySubstep), first and last frames recorded, the leading
//                 end pulled obliquely, (1, 0.5, 0.25) / |.|, so the joint-angle rule turns
//   cli_json, cli_npz  `flexkin run -q` end to end (reading the scenario, the run, the file
//                 written), one sub-process per iteration
// Run: build/bench/run_benchmark --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//   (docs/BENCHMARKS.md has the figures; FLEXKIN_SIMD=scalar gives the portable engine's.)

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "flexkin/curves.h"
#include "flexkin/propagate.h"
#include "flexkin/run.h"
#include "run/sweep_pipeline.h"
#include "sequential/sweep.h"

namespace flexkin {
namespace {

constexpr double kLinkLength = 0.3;
constexpr double kStep = 0.01;

// About 2e7 link-steps per iteration, whatever the chain.
int64_t StepsFor(int n) { return std::max<int64_t>(200, 20'000'000 / n); }

Chain StraightLine(int n) {
  const LineDef line{Eigen::Vector3d(-0.0, 0.0, 0.0), -Eigen::Vector3d::UnitX(), n, kLinkLength};
  return MakeChain(MakeLine(line));
}

Points Targets(const Chain& chain, int64_t steps) {
  Points targets(steps, 3);
  for (int64_t s = 0; s < steps; ++s) {
    targets.row(s) = chain.points.row(0) + Eigen::RowVector3d(kStep * (s + 1), 0.0, 0.0);
  }
  return targets;
}

void SetRate(benchmark::State& state, double link_steps_per_iteration) {
  state.counters["ns_per_link_step"] =
      benchmark::Counter(link_steps_per_iteration * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

enum class Bare { kEngine, kOnePass, kSingleCalls };

void BM_Bare(benchmark::State& state, Bare kind) {
  const int n = static_cast<int>(state.range(0));
  const Chain chain = StraightLine(n);
  const int64_t steps = StepsFor(n);
  const Points targets = Targets(chain, steps);
  const Stepper stepper = MakeStepper(Method::kTractrix, chain);
  Points points;
  for (auto _ : state) {
    points = chain.points;
    if (kind == Bare::kSingleCalls) {
      for (int64_t s = 0; s < steps; ++s) {
        MoveLeader(stepper, targets.row(s).transpose(), 1, &points);
      }
    } else {
      (kind == Bare::kEngine ? internal::SweepsWavefront : internal::SweepsScalar)(
          Method::kTractrix, 3, targets.data(), steps, stepper.lengths.data(),
          stepper.inv_lengths.data(), n, points.data());
    }
    benchmark::DoNotOptimize(points.data());
  }
  SetRate(state, static_cast<double>(n) * steps);
  state.counters["lanes"] = kind == Bare::kEngine ? internal::WavefrontLanes() : 1;
}

// Copies each frame into one buffer: the least a caller that keeps or writes frames does.
class CopySink : public FrameSink {
 public:
  void Add(int64_t, const PointsRef& points, const VectorRef& angles) override {
    last = points;
    last_angles = angles;
    ++frames;
  }
  Points last;
  Eigen::VectorXd last_angles;
  int64_t frames = 0;
};

void BM_Run(benchmark::State& state, int record_every, bool link_angles, bool progress = false) {
  const int n = static_cast<int>(state.range(0));
  const Chain chain = StraightLine(n);
  const int64_t steps = StepsFor(n);
  const Points targets = Targets(chain, steps);
  RunOptions options;
  options.record_every = record_every;
  options.link_angles = link_angles;
  int64_t reports = 0;
  if (progress) options.progress = [&reports](int64_t, int64_t) { ++reports; };
  CopySink sink;
  double length_error = 0.0;
  for (auto _ : state) {
    const RunResult result = Run(chain, targets, options, &sink);
    length_error = result.metrics.max_relative_length_error;
    benchmark::DoNotOptimize(result.metrics.l2_total);
  }
  SetRate(state, static_cast<double>(n) * steps);
  state.counters["frames"] = static_cast<double>(sink.frames) / state.iterations();
  state.counters["length_error"] = length_error;
}

void BM_WholeChain(benchmark::State& state, Method method, bool engine) {
  const int n = static_cast<int>(state.range(0));
  const Chain chain = StraightLine(n);
  const int64_t steps = StepsFor(n) / 4;
  const Eigen::RowVector3d direction = Eigen::RowVector3d(1.0, 0.5, 0.25).normalized();
  Points targets(steps, 3);
  for (int64_t s = 0; s < steps; ++s) {
    targets.row(s) = chain.points.row(0) + kStep * static_cast<double>(s + 1) * direction;
  }
  RunOptions options;
  options.method = method;
  options.record_every = 1 << 30;
  CopySink sink;
  double length_error = 0.0;
  for (auto _ : state) {
    const RunResult result = engine ? Run(chain, targets, options, &sink)
                                    : internal::RunSubstepBySubstep(chain, targets, options, &sink);
    length_error = result.metrics.max_relative_length_error;
    benchmark::DoNotOptimize(result.metrics.l2_total);
  }
  SetRate(state, static_cast<double>(n) * steps);
  state.counters["length_error"] = length_error;
}

// `flexkin run` end to end on the same scene, written as a scenario file.
void BM_Cli(benchmark::State& state, const char* extension) {
  const int n = static_cast<int>(state.range(0));
  const int64_t steps = StepsFor(n);
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("flexkin_run_bench_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string scenario = (dir / "scenario.json").string();
  const std::string output = (dir / (std::string("result.") + extension)).string();
  std::ofstream(scenario) << "{\"curve\": {\"shape\": \"line\", \"start\": [0, 0, 0], "
                          << "\"direction\": [-1, 0, 0], \"links\": " << n
                          << ", \"link_length\": " << kLinkLength << "},\n\"leader\": {\"pull\": ["
                          << kStep * steps << ", 0, 0], \"steps\": " << steps
                          << "},\n\"record\": {\"every\": " << state.range(1) << "}}\n";
  const std::string command = std::string(FLEXKIN_CLI) + " run -q --max-output-size 0 '" +
                              scenario + "' -o '" + output + "'";
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const int status = std::system(command.c_str());
    const auto end = std::chrono::steady_clock::now();
    if (status != 0) {
      state.SkipWithError(("exit status " + std::to_string(status) + ": " + command).c_str());
      break;
    }
    state.SetIterationTime(std::chrono::duration<double>(end - start).count());
  }
  state.counters["output_MB"] =
      std::filesystem::exists(output) ? std::filesystem::file_size(output) / 1e6 : 0.0;
  std::filesystem::remove_all(dir);
  SetRate(state, static_cast<double>(n) * steps);
}

void Sizes(benchmark::internal::Benchmark* b) {
  for (int n : {20, 200, 2000, 100000}) b->Arg(n);
  b->Unit(benchmark::kMillisecond);
}
void CliSizes(benchmark::internal::Benchmark* b) {
  for (int n : {20, 200, 2000, 100000}) {
    for (int every : {1, 100, 1 << 30}) b->Args({n, every});
  }
  b->Unit(benchmark::kMillisecond)->UseManualTime()->Iterations(3);
}

BENCHMARK_CAPTURE(BM_Bare, engine, Bare::kEngine)->Apply(Sizes);
BENCHMARK_CAPTURE(BM_Bare, one_pass, Bare::kOnePass)->Apply(Sizes);
BENCHMARK_CAPTURE(BM_Bare, single_calls, Bare::kSingleCalls)->Apply(Sizes);
BENCHMARK_CAPTURE(BM_Run, every_step, 1, true)->Apply(Sizes);
BENCHMARK_CAPTURE(BM_Run, every_step_no_angles, 1, false)->Apply(Sizes);
BENCHMARK_CAPTURE(BM_Run, every_100, 100, true)->Apply(Sizes);
BENCHMARK_CAPTURE(BM_Run, first_last, 1 << 30, true)->Apply(Sizes);
BENCHMARK_CAPTURE(BM_Run, first_last_with_progress, 1 << 30, true, true)->Apply(Sizes);
BENCHMARK_CAPTURE(BM_WholeChain, min_rotation_engine, Method::kMinRotation, true)->Apply(Sizes);
BENCHMARK_CAPTURE(BM_WholeChain, min_rotation_loop, Method::kMinRotation, false)->Apply(Sizes);
BENCHMARK_CAPTURE(BM_WholeChain, min_joint_angle_engine, Method::kMinJointAngle, true)
    ->Apply(Sizes);
BENCHMARK_CAPTURE(BM_WholeChain, min_joint_angle_loop, Method::kMinJointAngle, false)->Apply(Sizes);
BENCHMARK_CAPTURE(BM_Cli, json, "json")->Apply(CliSizes);
BENCHMARK_CAPTURE(BM_Cli, npz, "npz")->Apply(CliSizes);

}  // namespace
}  // namespace flexkin

BENCHMARK_MAIN();
