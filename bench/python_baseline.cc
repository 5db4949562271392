// The C++ side of bench/python_benchmark.py: the same four calls as the Python benchmark, timed
// here through the library directly, so that the Python script compares the two in one run.
//   link_step   one 2D TractrixStep (the function flexkin.tractrix_step calls)
//   move10      one MoveLeader of a 10-link 2D chain in place, 8 sub-steps, tractrix (the call
//               flexkin.Chain.move_leader makes)
//   fig12       LoadScenarioFile + Run of examples/fig12_spatial_curve.json (flexkin.run_scenario)
//   chain10k    Run of a 10,000-link 3D chain, 200 leader steps, 4 sub-steps, every 10th frame
//               recorded (flexkin.run); the chain and the steps are the formulas of
//               python_benchmark.py's chain10k, evaluated with the same libm
// The runs record their frames as the module does: through Run's plain form, into dense frames
// (flexkin/frames.h) that the module's Result wraps without a copy. fig12_sink and chain10k_sink
// are the same runs streamed to a FrameSink that copies each frame into arrays allocated for the
// run (frames, steps, link angles): the module's way before the frames were dense.
// Usage: python_baseline SCENARIO_DIR SAMPLES; prints one JSON object: case -> list of seconds per
// call, one per sample (each sample repeats the call enough times to last about 0.2 s).

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/link_step.h"
#include "flexkin/propagate.h"
#include "flexkin/result_io.h"
#include "flexkin/run.h"
#include "flexkin/scenario.h"

namespace flexkin {
namespace {

using Clock = std::chrono::steady_clock;

// Seconds per call of `call`, one value per sample; each sample runs `call` `reps` times, `reps`
// chosen once so that a sample lasts about 0.2 s.
std::vector<double> Time(const std::function<void()>& call, int samples) {
  int64_t reps = 1;
  for (;;) {
    const auto start = Clock::now();
    for (int64_t i = 0; i < reps; ++i) call();
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    if (seconds > 0.05) {
      reps = std::max<int64_t>(1, static_cast<int64_t>(reps * 0.2 / seconds));
      break;
    }
    reps *= 4;
  }
  std::vector<double> result;
  for (int s = 0; s < samples; ++s) {
    const auto start = Clock::now();
    for (int64_t i = 0; i < reps; ++i) call();
    result.push_back(std::chrono::duration<double>(Clock::now() - start).count() / reps);
  }
  return result;
}

// The 10,000-link chain of python_benchmark.py: along -x with links of 0.01, the leading end
// pulled along a smooth 3D curve.
constexpr int kChainLinks = 10'000;
constexpr int kChainSteps = 200;

Chain LongChain() {
  Points points(kChainLinks + 1, 3);
  for (int i = 0; i <= kChainLinks; ++i) points.row(i) << -0.01 * i, 0.0, 0.0;
  return MakeChain(points);
}

Points LongChainSteps() {
  Points steps(kChainSteps, 3);
  for (int k = 1; k <= kChainSteps; ++k) {
    steps.row(k - 1) << 0.05 * k, 0.5 * std::sin(0.05 * k), 0.2 * (1.0 - std::cos(0.03 * k));
  }
  return steps;
}

// Every frame copied into the next row of arrays allocated for the run, uninitialized as
// numpy.empty's are (the module's way of recording before the frames were dense).
class ArraySink : public FrameSink {
 public:
  ArraySink(int64_t frames, int64_t links, int dim)
      : frame_size_((links + 1) * dim),
        links_(links),
        points_(new double[frames * frame_size_]),
        angles_(new double[frames * links]),
        steps_(new int64_t[frames]) {}
  void Add(int64_t step, const PointsRef& points, const VectorRef& link_angles) override {
    std::memcpy(points_.get() + count_ * frame_size_, points.data(), sizeof(double) * frame_size_);
    std::memcpy(angles_.get() + count_ * links_, link_angles.data(), sizeof(double) * links_);
    steps_[count_++] = step;
  }

 private:
  int64_t frame_size_, links_, count_ = 0;
  std::unique_ptr<double[]> points_, angles_;
  std::unique_ptr<int64_t[]> steps_;
};

// The run streamed to arrays: the frames counted, arrays allocated, the frames copied in.
RunResult RunToArrays(const Chain& chain, const Points& steps, const RunOptions& options) {
  ArraySink sink(CountRecordedFrames(steps.rows(), options.record_every), chain.num_links(),
                 chain.dim());
  return Run(chain, steps, options, &sink);
}

void Print(const char* name, const std::vector<double>& seconds, bool last) {
  std::printf("  \"%s\": [", name);
  for (size_t i = 0; i < seconds.size(); ++i) {
    std::printf("%s%.6e", i ? ", " : "", seconds[i]);
  }
  std::printf("]%s\n", last ? "" : ",");
}

int Main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: python_baseline SCENARIO_DIR SAMPLES\n");
    return 2;
  }
  const std::string dir = argv[1];
  const int samples = std::atoi(argv[2]);
  if (samples < 1) {
    std::fprintf(stderr, "python_baseline: SAMPLES must be an integer >= 1, got '%s'\n", argv[2]);
    return 2;
  }

  const Eigen::Vector2d head_old(0.0, 0.0), head_new(0.1, 0.05), tail(-1.0, 0.2);
  const auto link_step = Time(
      [&] {
        Eigen::Vector2d a = head_old, b = head_new, t = tail;
        benchmark::DoNotOptimize(a);
        benchmark::DoNotOptimize(b);
        benchmark::DoNotOptimize(t);
        Eigen::Vector2d out = TractrixStep(a, b, t, 1.0);
        benchmark::DoNotOptimize(out);
      },
      samples);

  Points line(11, 2);
  for (int i = 0; i <= 10; ++i) line.row(i) << -0.25 * i, 0.0;
  Chain chain = MakeChain(line);
  const Eigen::Vector2d targets[2] = {Eigen::Vector2d(0.2, 0.1), Eigen::Vector2d(0.0, 0.0)};
  int which = 0;
  const auto move10 = Time(
      [&] {
        MoveLeader(Method::kTractrix, targets[which], 8, &chain);
        which ^= 1;
        benchmark::DoNotOptimize(chain.points.data());
      },
      samples);

  const std::string fig12_path = dir + "/fig12_spatial_curve.json";
  const auto fig12 = Time(
      [&] {
        const Scenario scenario = LoadScenarioFile(fig12_path);
        RunResult result = Run(scenario.chain, scenario.leader_steps, scenario.options);
        benchmark::DoNotOptimize(result.metrics.l2_total);
      },
      samples);
  const auto fig12_sink = Time(
      [&] {
        const Scenario scenario = LoadScenarioFile(fig12_path);
        RunResult result = RunToArrays(scenario.chain, scenario.leader_steps, scenario.options);
        benchmark::DoNotOptimize(result.frames.points_data().data());
      },
      samples);

  const Chain long_chain = LongChain();
  const Points long_steps = LongChainSteps();
  RunOptions options;
  options.substeps = 4;
  options.record_every = 10;
  const auto chain10k = Time(
      [&] {
        RunResult result = Run(long_chain, long_steps, options);
        benchmark::DoNotOptimize(result.metrics.l2_total);
      },
      samples);
  const auto chain10k_sink = Time(
      [&] {
        RunResult result = RunToArrays(long_chain, long_steps, options);
        benchmark::DoNotOptimize(result.frames.points_data().data());
      },
      samples);

  std::printf("{\n");
  Print("link_step", link_step, false);
  Print("move10", move10, false);
  Print("fig12", fig12, false);
  Print("chain10k", chain10k, false);
  Print("fig12_sink", fig12_sink, false);
  Print("chain10k_sink", chain10k_sink, true);
  std::printf("}\n");
  return 0;
}

}  // namespace
}  // namespace flexkin

int main(int argc, char** argv) {
  try {
    return flexkin::Main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "python_baseline: %s\n", e.what());
    return 1;
  }
}
