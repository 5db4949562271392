// Tractrix against follow-the-leader (FTL) on the scenes users meet, not only the cheapest: the
// cost per link-step of one move of the leading end split into 2,000 sub-steps (MoveLeader, the
// engine it picks), every scene at 20 to 100,000 links, both methods in the same run.
//
//   axial     a straight chain pulled along its own axis: every link translates along itself and
//             the motion never dies out (the scene of the propagation benchmark's `pull`)
//   oblique   the same chain pulled at 45 degrees to its axis
//   sideways  pulled at 90 degrees
//   push      pushed into itself (180 degrees)
//   arc       a chain bent into a quarter circle per 100 links, pulled along +x
//   random    a random smooth chain (scenes::RandomSmoothChain) pulled along a random polyline of
//             20 legs of 100 sub-steps each
//   wander    the coil (scenes::Coil) with its leading end on a wandering curve, 20 legs
//
// In every scene but `axial` the motion dies out along a long chain: the far links' moves fall
// below 1e-50 of their length and then to exactly 0. Every iteration starts from the same
// configuration. The counter ns_per_link_step is the figure docs/BENCHMARKS.md quotes; the
// ratio tractrix / ftl is taken from the medians of the same run.
//
// Run: build/bench/scenes_benchmark --benchmark_repetitions=3
//        --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "flexkin/curves.h"
#include "flexkin/propagate.h"
#include "scenes/scenes.h"

namespace flexkin {
namespace {

constexpr int kSubsteps = 2000;
constexpr int kLegs = 20;  // the random and wander scenes: 20 moves of 100 sub-steps

enum class Scene { kAxial, kOblique, kSideways, kPush, kArc, kRandom, kWander };

Chain StraightChain(int n) {
  return MakeChain(MakeLine(LineDef{Eigen::Vector3d::Zero(), -Eigen::Vector3d::UnitX(), n, 0.3}));
}

// A chain bent into a quarter circle every 100 links (radius 0.3 * 200 / pi), in the x-y plane.
Chain ArcChain(int n) { return scenes::CurvedChain(3, n, 0.3 / (M_PI / 200.0), M_PI / 200.0); }

Chain SceneChain(Scene scene, int n) {
  switch (scene) {
    case Scene::kArc:
      return ArcChain(n);
    case Scene::kRandom: {
      std::mt19937 rng(7);
      Chain c = scenes::RandomSmoothChain(3, n, 0.3, &rng);
      return c;
    }
    case Scene::kWander:
      return scenes::Coil(n);
    default:
      return StraightChain(n);
  }
}

// The leading end's targets: one for the single-move scenes (a move of 1, about 3 links of the
// straight chain), kLegs for the polyline scenes.
std::vector<Eigen::Vector3d> SceneTargets(Scene scene, const Eigen::Vector3d& start) {
  const double c = std::sqrt(0.5);
  switch (scene) {
    case Scene::kAxial:
      return {start + Eigen::Vector3d(1, 0, 0)};
    case Scene::kOblique:
      return {start + Eigen::Vector3d(c, c, 0)};
    case Scene::kSideways:
      return {start + Eigen::Vector3d(0, 1, 0)};
    case Scene::kPush:
      return {start + Eigen::Vector3d(-1, 0, 0)};
    case Scene::kArc:
      return {start + Eigen::Vector3d(1, 0, 0)};
    case Scene::kRandom: {
      std::mt19937 rng(11);
      std::uniform_real_distribution<double> u(-1.0, 1.0);
      std::vector<Eigen::Vector3d> targets;
      Eigen::Vector3d at = start;
      for (int leg = 0; leg < kLegs; ++leg) {
        at += 0.2 * Eigen::Vector3d(u(rng), u(rng), u(rng));
        targets.push_back(at);
      }
      return targets;
    }
    case Scene::kWander: {
      std::vector<Eigen::Vector3d> targets;
      Eigen::Vector3d at = start;
      for (int leg = 0; leg < kLegs; ++leg) {
        at += Eigen::Vector3d(0.2 * std::cos(0.5 * leg), 0.2 * std::sin(0.5 * leg), 0.05);
        targets.push_back(at);
      }
      return targets;
    }
  }
  return {};
}

void BM_Scene(benchmark::State& state, Scene scene, Method method) {
  const int n = static_cast<int>(state.range(0));
  const Chain initial = SceneChain(scene, n);
  const Stepper stepper = MakeStepper(method, initial);
  const std::vector<Eigen::Vector3d> targets =
      SceneTargets(scene, initial.points.row(0).transpose());
  const int substeps = kSubsteps / static_cast<int>(targets.size());
  Points points = initial.points;
  for (auto _ : state) {
    state.PauseTiming();
    points = initial.points;
    state.ResumeTiming();
    for (const Eigen::Vector3d& target : targets) MoveLeader(stepper, target, substeps, &points);
    benchmark::DoNotOptimize(points.data());
  }
  state.counters["ns_per_link_step"] = benchmark::Counter(
      static_cast<double>(n) * kSubsteps * static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void Sizes(benchmark::internal::Benchmark* b) {
  for (int n : {20, 200, 1000, 10000, 100000}) b->Arg(n);
  b->Unit(benchmark::kMillisecond);
}

#define FLEXKIN_SCENE(name, scene)                                                      \
  BENCHMARK_CAPTURE(BM_Scene, name##_tractrix, scene, Method::kTractrix)->Apply(Sizes); \
  BENCHMARK_CAPTURE(BM_Scene, name##_ftl, scene, Method::kFollowTheLeader)->Apply(Sizes)

FLEXKIN_SCENE(axial, Scene::kAxial);
FLEXKIN_SCENE(oblique, Scene::kOblique);
FLEXKIN_SCENE(sideways, Scene::kSideways);
FLEXKIN_SCENE(push, Scene::kPush);
FLEXKIN_SCENE(arc, Scene::kArc);
FLEXKIN_SCENE(random, Scene::kRandom);
FLEXKIN_SCENE(wander, Scene::kWander);

}  // namespace
}  // namespace flexkin

BENCHMARK_MAIN();
