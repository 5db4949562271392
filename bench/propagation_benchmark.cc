#include <benchmark/benchmark.h>
#include <cmath>
#include "flexkin/propagate.h"
using namespace flexkin;
static Chain Helix(int n) {
  Points p(n + 1, 3);
  for (int i = 0; i <= n; ++i) p.row(i) << std::cos(0.3 * i), std::sin(0.3 * i), 0.05 * i;
  return MakeChain(p);
}
static void BM_Move(benchmark::State& st, Method m) {
  const int n = st.range(0);
  Chain c = Helix(n);
  Stepper s = MakeStepper(m, c);
  Eigen::Vector3d t = c.points.row(0).transpose();
  int j = 0;
  for (auto _ : st) {
    t += Eigen::Vector3d(0.01 * std::cos(0.01 * j), 0.01 * std::sin(0.01 * j), 0.003);
    ++j;
    MoveLeader(s, t, 16, &c.points);
    benchmark::DoNotOptimize(c.points.data());
  }
  st.counters["ns_per_link_step"] = benchmark::Counter(double(n) * 16 * st.iterations(), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK_CAPTURE(BM_Move, tractrix, Method::kTractrix)->RangeMultiplier(10)->Range(10, 100000);
BENCHMARK_CAPTURE(BM_Move, ftl, Method::kFollowTheLeader)->RangeMultiplier(10)->Range(10, 100000);
BENCHMARK_MAIN();
