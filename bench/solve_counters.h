#pragma once
// The counters of the benchmarks that time one solve per iteration against a peer's (the tree
// solvers against KDL's): the time a solve, the share of solves that failed, and the largest
// error left after a solve.
#include <benchmark/benchmark.h>

#include <cstdint>

namespace flexkin {

inline void SetSolveCounters(benchmark::State& state, int64_t solves, int64_t failed,
                             double worst) {
  state.counters["worst_error"] = worst;
  state.counters["failed"] = static_cast<double>(failed) / static_cast<double>(solves);
  state.counters["us_per_solve"] = benchmark::Counter(
      static_cast<double>(solves), benchmark::Counter::kIsRate | benchmark::Counter::kInvert,
      benchmark::Counter::kIs1000);
}

}  // namespace flexkin
