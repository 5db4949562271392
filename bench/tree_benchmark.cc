// Trees driven at one point (flexkin/tree.h, docs/trees.md) against a path of the same number of
// links on the chain engine (MoveLeader), in the same run: the cost per link step.
//
// Shapes (TheComet/ik's): a 10-bone chain; two arms of 5 bones on a shared sub-base (a spine of
// 2 links from the root); a binary tree of depth 10 (2,047 points, 2,046 links). 3D, the tractrix,
// driven at the root along a circle, one move per iteration of 1 sub-step (the one-pass sweep on
// both) or of 16 sub-steps (the chain engine then takes its SIMD wavefront; the tree does not
// have one). The path of the same size: a chain with the shape's number of links, moved by the
// same targets.
// Run: build/bench/tree_benchmark --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "flexkin/propagate.h"
#include "flexkin/tree.h"
#include "scenes/scenes.h"

namespace flexkin {
namespace {

enum Shape { kChain10 = 0, kTwoArms = 1, kBinary10 = 2 };

Tree MakeShape(int shape) { return scenes::TreeShape(static_cast<scenes::TreeKind>(shape)); }

Eigen::Vector3d Target(const Eigen::Vector3d& origin, int64_t step) {
  const double t = 0.01 * static_cast<double>(step);
  return origin + Eigen::Vector3d(std::cos(t) - 1.0, std::sin(t), 0.3 * std::sin(0.7 * t));
}

void SetRate(benchmark::State& state, double links_per_move, int substeps) {
  state.counters["ns_per_link_step"] =
      benchmark::Counter(links_per_move * substeps * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// Args: shape, sub-steps per move.
void BM_Tree(benchmark::State& state) {
  const Tree tree = MakeShape(static_cast<int>(state.range(0)));
  const int substeps = static_cast<int>(state.range(1));
  const TreeStepper stepper = MakeTreeStepper(Method::kTractrix, tree, 0);
  Points points = tree.points;
  const Eigen::Vector3d origin = points.row(0).transpose();
  int64_t step = 0;
  for (auto _ : state) {
    MoveTreePoint(stepper, Target(origin, ++step), substeps, &points);
    benchmark::DoNotOptimize(points.data());
  }
  SetRate(state, static_cast<double>(stepper.lead.size()), substeps);
  state.counters["length_error"] = MaxTreeLengthError(stepper, points);
}

// The same number of links as a path, on the chain engine.
void BM_PathOfTheSameSize(benchmark::State& state) {
  const Tree tree = MakeShape(static_cast<int>(state.range(0)));
  const int substeps = static_cast<int>(state.range(1));
  const int links = static_cast<int>(tree.parents.size()) - 1;
  Points path(links + 1, 3);
  for (int i = 0; i <= links; ++i) path.row(i) = Eigen::RowVector3d(i, 0.2 * std::sin(i), 0);
  Chain chain = MakeChain(path);
  const Stepper stepper = MakeStepper(Method::kTractrix, chain);
  const Eigen::Vector3d origin = chain.points.row(0).transpose();
  int64_t step = 0;
  for (auto _ : state) {
    MoveLeader(stepper, Target(origin, ++step), substeps, &chain.points);
    benchmark::DoNotOptimize(chain.points.data());
  }
  SetRate(state, links, substeps);
  state.counters["length_error"] = MaxRelativeLengthError(chain);
}

void Shapes(benchmark::internal::Benchmark* b) {
  for (const int shape : {kChain10, kTwoArms, kBinary10}) {
    for (const int substeps : {1, 16}) b->Args({shape, substeps});
  }
}
BENCHMARK(BM_Tree)->Apply(Shapes);
BENCHMARK(BM_PathOfTheSameSize)->Apply(Shapes);

}  // namespace
}  // namespace flexkin

BENCHMARK_MAIN();
