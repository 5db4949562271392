// Dynamic strands (flexkin/strands.h `dynamics`, docs/dynamics.md): 10,000 hair strands of 32
// links (0.01 to 0.02 each) grown out of a unit-sphere scalp, gravity, air drag 1/s, the scalp as
// a body collider, one sub-step at 60 frames per second, the head shaken left and right while
// nodding. Each projection (overall, shake, tractrix, dftl) is timed per frame; the baseline in the
// same run is the kinematic strand engine (tractrix) on the same strands, scalp and motion. Before
// the timer the hair falls for 60 frames, so that it lies on the scalp as it does in use (most
// strands touch it). Counters: contact link steps per frame, the overall projection's
// non-converged strand sub-steps per frame (SHAKE's: the sub-steps that took the overall
// projection). *NoScalp: the same without the scalp collider.
// BM_EqualTime/projection/substeps: the same scene (2 threads) with 1 to 8 sub-steps a frame, and
// beside the time (outside the timer) the accuracy those sub-steps give each projection: the
// hanging chain's first mode (32 links, 10 s at 60 Hz, SimulateChain: each strand's operations)
// against the discrete chain's own, and the energy drift per second of an 8-link rope released
// from horizontal without damping (10 s at 60 Hz; the free points' mass 1, g 9.81, length 1).
// Run: build/bench/dynamic_strands_benchmark --benchmark_repetitions=5
//        --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "chain_physics.h"
#include "flexkin/dynamics.h"
#include "flexkin/strands.h"

namespace flexkin {
namespace {

std::vector<Points> Hair(int count, int links) {
  std::mt19937 rng(42);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(0.01, 0.02);
  std::vector<Points> strands;
  for (int s = 0; s < count; ++s) {
    Points p(links + 1, 3);
    Eigen::Vector3d dir(normal(rng), normal(rng), normal(rng));
    dir.normalize();
    dir.z() = std::fabs(dir.z());  // the upper half of the head
    p.row(0) = dir.transpose();
    for (int i = 1; i <= links; ++i) {
      dir = (dir + 0.2 * Eigen::Vector3d(normal(rng), normal(rng), normal(rng))).normalized();
      // Out of the scalp: the direction turned outward where it points in.
      const Eigen::Vector3d out = p.row(i - 1).transpose().normalized();
      if (dir.dot(out) < 0.2) dir = (dir + (0.2 - dir.dot(out)) * out).normalized();
      p.row(i) = p.row(i - 1) + uniform(rng) * dir.transpose();
    }
    strands.push_back(p);
  }
  return strands;
}

BodyPose ShakePose(int64_t frame) {
  const double t = frame / 60.0;
  const double yaw = 0.9 * std::sin(3.0 * t), pitch = 0.25 * std::sin(2.0 * t);
  BodyPose pose;
  pose.rotation = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()))
                      .toRotationMatrix();
  return pose;
}

StrandOptions Options(int threads, std::optional<Projection> projection, bool scalp_collider,
                      int substeps = 1) {
  StrandOptions options;
  options.threads = threads;
  Collider scalp;
  scalp.shape = ColliderShape::kSphere;
  scalp.radius = 1.0;
  if (scalp_collider) options.body_colliders = {scalp};
  if (projection) {
    DynamicOptions d;
    d.projection = *projection;
    d.gravity = Eigen::Vector3d(0.0, 0.0, -9.81);
    d.damping = 1.0;
    d.frame_rate = 60.0;
    options.dynamics = d;
    options.substeps = substeps;
  }
  return options;
}

void Run(benchmark::State& state, std::optional<Projection> projection, bool scalp_collider = true,
         int threads = 0, int substeps = 1) {
  StrandBatch batch(Hair(10000, 32),
                    Options(threads > 0 ? threads : static_cast<int>(state.range(0)), projection,
                            scalp_collider, substeps));
  int64_t frame = 0;
  // The hair falls onto the scalp before the timer (the kinematic strands just follow the head).
  for (; frame < 60; ++frame) StepStrands(&batch, ShakePose(frame + 1), (frame + 1) / 60.0);
  const int64_t contacts_before = batch.contacts().contact_link_steps;
  const int64_t failures_before = batch.dynamics().failures;
  const int64_t start = frame;
  for (auto _ : state) {
    ++frame;
    StepStrands(&batch, ShakePose(frame), frame / 60.0);
    benchmark::ClobberMemory();
  }
  const double frames = static_cast<double>(frame - start);
  state.SetLabel(batch.engine());
  state.counters["contact_steps_per_frame"] =
      static_cast<double>(batch.contacts().contact_link_steps - contacts_before) / frames;
  state.counters["failures_per_frame"] =
      static_cast<double>(batch.dynamics().failures - failures_before) / frames;
  state.counters["least_clearance"] = batch.contacts().least_clearance;
}

void BM_KinematicHair(benchmark::State& state) { Run(state, std::nullopt); }
void BM_DynamicHairTractrix(benchmark::State& state) { Run(state, Projection::kTractrix); }
void BM_DynamicHairDftl(benchmark::State& state) { Run(state, Projection::kDftl); }
void BM_DynamicHairOverall(benchmark::State& state) { Run(state, Projection::kOverall); }
void BM_DynamicHairShake(benchmark::State& state) { Run(state, Projection::kShake); }
// Without the scalp (the hair falls through where the head is): the projections' own cost.
void BM_DynamicHairTractrixNoScalp(benchmark::State& state) {
  Run(state, Projection::kTractrix, false);
}
void BM_DynamicHairDftlNoScalp(benchmark::State& state) { Run(state, Projection::kDftl, false); }
void BM_DynamicHairOverallNoScalp(benchmark::State& state) {
  Run(state, Projection::kOverall, false);
}
void BM_DynamicHairShakeNoScalp(benchmark::State& state) { Run(state, Projection::kShake, false); }

// The accuracy of `projection` with `substeps` a frame (see the top): the hanging chain's first
// mode's relative error, and the rope's energy drift per second.
void Accuracy(Projection projection, int substeps, double* mode_error, double* drift) {
  namespace phys = testing_physics;
  const int n = 32;
  Eigen::MatrixXd modes;
  const Eigen::VectorXd omega = phys::DiscreteModes(n, 1.0, &modes);
  const DynamicResult hanging =
      SimulateChain(phys::ChainInMode(n, 1.0, modes, 0), Points::Zero(600, 2),
                    phys::Options(projection, substeps));
  *mode_error = std::fabs(phys::SwingOmega(hanging, n) - omega[0]) / omega[0];
  const DynamicResult fall =
      SimulateChain(phys::Horizontal(8), Points::Zero(600, 2), phys::Options(projection, substeps));
  *drift = (fall.energy[fall.energy.size() - 1] - fall.energy[0]) / 10.0;
}

void BM_EqualTime(benchmark::State& state) {
  const auto projection = static_cast<Projection>(state.range(0));
  const int substeps = static_cast<int>(state.range(1));
  Run(state, projection, true, 2, substeps);
  double mode_error = 0.0, drift = 0.0;
  Accuracy(projection, substeps, &mode_error, &drift);
  state.counters["hanging_mode_error"] = mode_error;
  state.counters["energy_drift_per_s"] = drift;
  state.SetLabel(std::string(ProjectionName(projection)) + " " + std::to_string(substeps) +
                 " sub-steps");
}

#define FLEXKIN_HAIR_BENCHMARK(name) \
  BENCHMARK(name)->Arg(1)->Arg(2)->Iterations(60)->Unit(benchmark::kMillisecond)->UseRealTime()
FLEXKIN_HAIR_BENCHMARK(BM_KinematicHair);
FLEXKIN_HAIR_BENCHMARK(BM_DynamicHairTractrix);
FLEXKIN_HAIR_BENCHMARK(BM_DynamicHairDftl);
FLEXKIN_HAIR_BENCHMARK(BM_DynamicHairOverall);
FLEXKIN_HAIR_BENCHMARK(BM_DynamicHairShake);
FLEXKIN_HAIR_BENCHMARK(BM_DynamicHairTractrixNoScalp);
FLEXKIN_HAIR_BENCHMARK(BM_DynamicHairDftlNoScalp);
FLEXKIN_HAIR_BENCHMARK(BM_DynamicHairOverallNoScalp);
FLEXKIN_HAIR_BENCHMARK(BM_DynamicHairShakeNoScalp);
BENCHMARK(BM_EqualTime)
    ->Args({static_cast<int>(Projection::kOverall), 1})
    ->Args({static_cast<int>(Projection::kOverall), 2})
    ->Args({static_cast<int>(Projection::kShake), 1})
    ->Args({static_cast<int>(Projection::kShake), 2})
    ->Args({static_cast<int>(Projection::kTractrix), 1})
    ->Args({static_cast<int>(Projection::kTractrix), 2})
    ->Args({static_cast<int>(Projection::kTractrix), 4})
    ->Args({static_cast<int>(Projection::kTractrix), 8})
    ->Args({static_cast<int>(Projection::kDftl), 1})
    ->Args({static_cast<int>(Projection::kDftl), 2})
    ->Args({static_cast<int>(Projection::kDftl), 4})
    ->Args({static_cast<int>(Projection::kDftl), 8})
    ->Iterations(60)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace flexkin

BENCHMARK_MAIN();
