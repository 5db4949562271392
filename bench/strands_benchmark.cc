// Many strands at once (flexkin/strands.h, docs/strands.md): 10,000 hair strands of 32 links on
// a wobbling head, one sub-step per frame, 3D. Time per frame of
//   1. the tractrix on the strand engine, 1 and 2 threads;
//   2. follow-the-leader on the same engine, 1 and 2 threads;
//   3. a loop of the single-chain MoveLeader over the strands (one thread);
//   4. the conventional one-pass follow-the-leader loop hair simulators run (one thread);
// and the strand engine's tractrix over 100 to 100,000 strands and 8 to 64 links (linear cost).
// ns_per_link_step is the time per link per strand per frame (printed in seconds: "3.3n").
// Run: build/bench/strands_benchmark --benchmark_repetitions=5
//        --benchmark_report_aggregates_only=true ; FLEXKIN_SIMD=avx2 caps the engine at AVX2.

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "flexkin/propagate.h"
#include "flexkin/strands.h"

namespace flexkin {
namespace {

// Strands on the unit sphere, growing outward with small random bends, links of 0.01 to 0.02.
std::vector<Points> Hair(int count, int links) {
  std::mt19937 rng(42);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(0.01, 0.02);
  std::vector<Points> strands;
  strands.reserve(count);
  for (int s = 0; s < count; ++s) {
    Points p(links + 1, 3);
    Eigen::Vector3d dir(normal(rng), normal(rng), normal(rng));
    dir.normalize();
    p.row(0) = dir.transpose();
    for (int i = 1; i <= links; ++i) {
      dir = (dir + 0.2 * Eigen::Vector3d(normal(rng), normal(rng), normal(rng))).normalized();
      p.row(i) = p.row(i - 1) + uniform(rng) * dir.transpose();
    }
    strands.push_back(p);
  }
  return strands;
}

// The head nodding and turning, a frame at 60 Hz.
BodyPose HeadPose(int64_t frame) {
  const double t = frame / 60.0;
  const double angle = 0.4 * std::sin(2.0 * t);
  Eigen::Vector3d axis(std::sin(0.7 * t), 1.0, 0.3 * std::cos(t));
  axis.normalize();
  const double s = std::sin(angle / 2);
  return BodyPose::FromQuaternion(std::cos(angle / 2), s * axis[0], s * axis[1], s * axis[2],
                                  Eigen::Vector3d(0.1 * std::sin(3.0 * t), 0.05 * std::sin(t), 0));
}

void SetRate(benchmark::State& state, double link_steps_per_iteration) {
  state.counters["ns_per_link_step"] =
      benchmark::Counter(link_steps_per_iteration * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void StrandEngine(benchmark::State& state, Method method, int count, int links, int threads) {
  StrandOptions options;
  options.method = method;
  options.threads = threads;
  StrandBatch batch(Hair(count, links), options);
  int64_t frame = 0;
  for (auto _ : state) {
    StepStrands(&batch, HeadPose(++frame));
    benchmark::ClobberMemory();
  }
  state.SetLabel(batch.engine());
  SetRate(state, static_cast<double>(count) * links);
}

// 1, 2. The strand engine, 10,000 x 32, by threads.
void BM_StrandsTractrix(benchmark::State& state) {
  StrandEngine(state, Method::kTractrix, 10000, 32, static_cast<int>(state.range(0)));
}
void BM_StrandsFtl(benchmark::State& state) {
  StrandEngine(state, Method::kFollowTheLeader, 10000, 32, static_cast<int>(state.range(0)));
}
BENCHMARK(BM_StrandsTractrix)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_StrandsFtl)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// The roots of a frame as the engine computes them from the pose.
Eigen::Vector3d Root(const BodyPose& pose, const Points& rest) {
  return pose.rotation * rest.row(0).transpose() + pose.translation;
}

// 3. The single-chain path: MoveLeader on each strand in turn (steppers made once).
void BM_MoveLeaderLoop(benchmark::State& state) {
  const Method method = state.range(0) == 0 ? Method::kTractrix : Method::kFollowTheLeader;
  const std::vector<Points> rest = Hair(10000, 32);
  std::vector<Points> points = rest;
  std::vector<Stepper> steppers;
  for (const Points& p : rest) steppers.push_back(MakeStepper(method, MakeChain(p)));
  int64_t frame = 0;
  for (auto _ : state) {
    const BodyPose pose = HeadPose(++frame);
    for (size_t s = 0; s < points.size(); ++s) {
      MoveLeader(steppers[s], Root(pose, rest[s]), 1, &points[s]);
    }
    benchmark::ClobberMemory();
  }
  state.SetLabel(MethodName(method));
  SetRate(state, 10000.0 * 32);
}
BENCHMARK(BM_MoveLeaderLoop)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// 4. The one-pass follow-the-leader loop of hair simulators: each point put back at its link's
// length from the point before, along the line to its old position; points as arrays of xyz.
void BM_OnePassFtlLoop(benchmark::State& state) {
  const std::vector<Points> rest = Hair(10000, 32);
  std::vector<double> xyz, lengths;
  for (const Points& p : rest) {
    for (int i = 0; i <= 32; ++i) {
      for (int k = 0; k < 3; ++k) xyz.push_back(p(i, k));
      if (i > 0) lengths.push_back((p.row(i) - p.row(i - 1)).norm());
    }
  }
  int64_t frame = 0;
  for (auto _ : state) {
    const BodyPose pose = HeadPose(++frame);
    for (size_t s = 0; s < rest.size(); ++s) {
      double* p = xyz.data() + s * 33 * 3;
      const double* len = lengths.data() + s * 32;
      const Eigen::Vector3d root = Root(pose, rest[s]);
      p[0] = root[0], p[1] = root[1], p[2] = root[2];
      for (int i = 1; i <= 32; ++i) {
        double* a = p + (i - 1) * 3;
        double* b = p + i * 3;
        const double dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
        const double f = len[i - 1] / std::sqrt(dx * dx + dy * dy + dz * dz);
        b[0] = a[0] + f * dx, b[1] = a[1] + f * dy, b[2] = a[2] + f * dz;
      }
    }
    benchmark::ClobberMemory();
  }
  SetRate(state, 10000.0 * 32);
}
BENCHMARK(BM_OnePassFtlLoop)->Unit(benchmark::kMillisecond)->UseRealTime();

// 5. Linear cost: strands (100 to 100,000, 32 links) and links (8 to 64, 10,000 strands), the
// tractrix on one thread.
void BM_StrandsSweep(benchmark::State& state) {
  StrandEngine(state, Method::kTractrix, static_cast<int>(state.range(0)),
               static_cast<int>(state.range(1)), 1);
}
BENCHMARK(BM_StrandsSweep)
    ->Args({100, 32})
    ->Args({1000, 32})
    ->Args({10000, 32})
    ->Args({100000, 32})
    ->Args({10000, 8})
    ->Args({10000, 16})
    ->Args({10000, 64})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace flexkin

BENCHMARK_MAIN();
