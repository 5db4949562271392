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
#include "flexkin/tree_overall.h"
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
  const int frames = 120;
  const std::vector<Points> targets = scenes::TipCircles(tree, tips, frames);
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

// The overall method (StepTreeOverall, squared metric) on the same shapes and frames: the exact
// least-motion step, Newton from the tractrix passes. Args: shape.
void BM_Overall(benchmark::State& state) {
  const auto kind = static_cast<scenes::TreeKind>(state.range(0));
  const Tree tree = scenes::TreeShape(kind);
  const std::vector<int> tips = scenes::TreeTips(kind);
  const TreeReacher reacher = MakeTreeReacher(tree, tips, {0});
  const int frames = 120;
  const std::vector<Points> targets = scenes::TipCircles(tree, tips, frames);
  const TreeOverallOptions options;
  Points points = tree.points, before;
  int64_t solves = 0, iterations = 0, converged = 0;
  double motion = 0.0;
  for (auto _ : state) {
    before = points;
    const TreeOverallReport report =
        StepTreeOverall(reacher, targets[solves % frames], options, &points);
    state.PauseTiming();
    iterations += report.iterations;
    converged += report.converged;
    motion += (points - before).squaredNorm();
    ++solves;
    state.ResumeTiming();
  }
  state.counters["newton_iterations"] = static_cast<double>(iterations) / solves;
  state.counters["converged"] = static_cast<double>(converged) / solves;
  state.counters["motion"] = motion / solves;
}
BENCHMARK(BM_Overall)->Arg(0)->Arg(1)->Arg(2)->ArgName("shape")->Unit(benchmark::kMicrosecond);

// The cost of the overall step against the tree's size: random trees (scenes::RandomTree) of
// range(0) points, 4 leaves moved 0.02 each way and back, the root fixed. Reported per link and
// Newton iteration: flat if the elimination along the tree is linear in the links.
void BM_OverallScaling(benchmark::State& state) {
  const int count = static_cast<int>(state.range(0));
  const Tree tree = scenes::RandomTree(count, 3, 11);
  std::vector<char> has_child(count, 0);
  for (int p : tree.parents) {
    if (p >= 0) has_child[p] = 1;
  }
  std::vector<int> tips;
  for (int i = count - 1; i >= 0 && tips.size() < 4; --i) {
    if (!has_child[i]) tips.push_back(i);
  }
  const TreeReacher reacher = MakeTreeReacher(tree, tips, {0});
  Points out(tips.size(), 3), back(tips.size(), 3);
  for (size_t k = 0; k < tips.size(); ++k) {
    back.row(k) = tree.points.row(tips[k]);
    out.row(k) = back.row(k) + Eigen::RowVector3d(0.02, -0.01, 0.015);
  }
  const TreeOverallOptions options;
  Points points = tree.points;
  int64_t solves = 0, iterations = 0;
  for (auto _ : state) {
    const TreeOverallReport report =
        StepTreeOverall(reacher, solves % 2 == 0 ? out : back, options, &points);
    iterations += report.iterations;
    ++solves;
  }
  state.counters["newton_iterations"] = static_cast<double>(iterations) / solves;
  state.counters["ns_per_link_iteration"] =
      benchmark::Counter(static_cast<double>(iterations) * (count - 1),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_OverallScaling)
    ->Arg(128)
    ->Arg(1024)
    ->Arg(8192)
    ->ArgName("points")
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace flexkin

BENCHMARK_MAIN();
