// Several targets on a tree (flexkin/tree.h, ReachTargets; docs/trees.md "Several targets"):
// the natural passes (tractrix) with either branch rule against FABRIK on trees (follow-the-leader
// passes with the centroid at branch points, the baseline written here as the same engine with the
// ftl rule), in the same run.
//
// Shapes (scenes::TreeShape, TheComet/ik's; 3D, unit links, the base fixed): a chain of 10 links
// driven at its tip; two arms of 5 links on a shoulder driven at both hands; a binary tree of depth
// 10 (2,047 points) driven at 4 leaves. Each tip's target moves round a circle of radius 0.3
// (120 frames a turn, a step of 0.016 a frame); every solve starts where the last one ended, as
// an animation's frames do. Reported per solve: the time, the passes, the share of solves that
// reached the tolerance (1e-6 or 1e-10 of a link), and the body's motion (the sum over points of
// the squared displacement, per frame): how much less the body moves.
// Run: build/bench/tree_reach_benchmark --benchmark_repetitions=5
//      --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "flexkin/tree.h"
#include "scenes/scenes.h"

namespace flexkin {
namespace {

// Args: shape (scenes::TreeKind), variant (0 FABRIK: ftl + centroid; 1 tractrix + centroid;
// 2 tractrix + keep_links; 3 ftl + keep_links), -log10 of the tolerance.
void BM_Reach(benchmark::State& state) {
  const auto kind = static_cast<scenes::TreeKind>(state.range(0));
  const Tree tree = scenes::TreeShape(kind);
  const std::vector<int> tips = scenes::TreeTips(kind);
  ReachOptions options;
  const int variant = static_cast<int>(state.range(1));
  options.method = variant == 1 || variant == 2 ? Method::kTractrix : Method::kFollowTheLeader;
  options.branch_rule = variant >= 2 ? BranchRule::kKeepLinks : BranchRule::kCentroid;
  options.tolerance = std::pow(10.0, -static_cast<double>(state.range(2)));
  const TreeReacher reacher = MakeTreeReacher(tree, tips, {0}, {}, options);
  // The frames' targets, computed before the timing.
  const int frames = 120;
  std::vector<Points> targets(frames, Points(tips.size(), 3));
  for (int f = 0; f < frames; ++f) {
    for (size_t k = 0; k < tips.size(); ++k) {
      const double a = 2 * M_PI * (f + 1) / frames, phase = static_cast<double>(k);
      targets[f].row(k) = tree.points.row(tips[k]) +
                          0.3 * Eigen::RowVector3d(std::cos(a + phase) - std::cos(phase),
                                                   std::sin(a + phase) - std::sin(phase), 0.0);
    }
  }
  Points points = tree.points, before;
  int64_t solves = 0, passes = 0, reached = 0;
  double motion = 0.0;
  for (auto _ : state) {
    before = points;
    const ReachReport report = ReachTargets(reacher, targets[solves % frames], &points);
    state.PauseTiming();
    passes += report.passes;
    reached += report.reached;
    motion += (points - before).squaredNorm();
    ++solves;
    state.ResumeTiming();
  }
  state.counters["passes"] = static_cast<double>(passes) / static_cast<double>(solves);
  state.counters["reached"] = static_cast<double>(reached) / static_cast<double>(solves);
  state.counters["motion"] = motion / static_cast<double>(solves);
  state.counters["us_per_solve"] = benchmark::Counter(
      static_cast<double>(solves), benchmark::Counter::kIsRate | benchmark::Counter::kInvert,
      benchmark::Counter::kIs1000);
}

void Cases(benchmark::internal::Benchmark* b) {
  for (const int shape : {0, 1, 2}) {
    for (const int variant : {0, 1, 2, 3}) {
      for (const int digits : {6, 10}) b->Args({shape, variant, digits});
    }
  }
  b->ArgNames({"shape", "variant", "digits"});
}
BENCHMARK(BM_Reach)->Apply(Cases)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace flexkin

BENCHMARK_MAIN();
