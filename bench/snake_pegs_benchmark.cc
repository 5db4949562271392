// Snake robots and fixed-base arms among pegs (issue 26; docs/BENCHMARKS.md section 19).
//
// Chain: the snake of examples/snake_robot_16.urdf (16 links of 0.1, link radius 0.03) led along
// the slalom y = 0.5 sin(pi (x - 0.5)) of examples/snake_pegs.json (x from 0 to 21 in steps of
// 1/160: 3360 leader steps) through 20 pegs (discs of radius 0.3 at x = 1..20, y = 0), method
// tractrix: time per leader step with the 20 pegs (grown by the link radius) against without.
// Target: at most 2x.
//
// Arm: a planar fixed-base arm of 12 unit links (link radius 0.05) tracking a circle of 60
// targets, as tests/arm_colliders_test.cc: free; with a collider nothing reaches (the cost of
// measuring the clearance after each step); with a disc that the free motion cuts 0.1 into
// (steps solved again with contact steps).
//   build/bench/snake_pegs_benchmark --benchmark_repetitions=5
//   --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "flexkin/arm.h"
#include "flexkin/colliders.h"
#include "flexkin/run.h"
#include "scenes/scenes.h"

namespace {

using flexkin::Collider;
using flexkin::Points;

constexpr double kPi = 3.14159265358979323846;

// The snake: 16 links of 0.1, the head at the slalom's start, the body trailing along -x.
flexkin::Chain Snake() {
  Points p(17, 2);
  for (int i = 0; i <= 16; ++i) p.row(i) << -0.1 * i, -0.5;
  return flexkin::MakeChain(p);
}

Points Slalom() {
  const int steps = 21 * 160;
  Points path(steps, 2);
  for (int i = 0; i < steps; ++i) {
    const double x = (i + 1) / 160.0;
    path.row(i) << x, 0.5 * std::sin(kPi * (x - 0.5));
  }
  return path;
}

std::vector<Collider> Pegs() {
  std::vector<Collider> pegs(20);
  for (int k = 0; k < 20; ++k) {
    pegs[k].radius = 0.3;
    pegs[k].pose.translation() = Eigen::Vector3d(k + 1.0, 0.0, 0.0);
  }
  return pegs;
}

void SnakeSlalom(benchmark::State& state) {
  // range(0): 0 no pegs, 1 the 20 pegs, 2 the 20 pegs 100 away (nothing reached: the cost of the
  // contact sweep's loop and broad phase without a contact).
  const bool with_pegs = state.range(0) != 0;
  const flexkin::Chain chain = Snake();
  const Points path = Slalom();
  flexkin::RunOptions options;
  options.method = flexkin::Method::kTractrix;
  options.record_every = static_cast<int>(path.rows());  // the first and last frames
  if (with_pegs) {
    options.colliders = Pegs();
    if (state.range(0) == 2) {
      for (Collider& c : options.colliders) c.pose.translation().y() = 100.0;
    }
    options.link_radius = 0.03;
  }
  long long contacts = 0;
  double clearance = 0.0;
  for (auto _ : state) {
    const flexkin::RunResult r = flexkin::Run(chain, path, options);
    benchmark::DoNotOptimize(r.frames.back().points.data());
    contacts = r.contacts.contact_link_steps;
    clearance = r.contacts.least_clearance;
  }
  state.counters["us_per_step"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * path.rows(),
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert, benchmark::Counter::kIs1000);
  state.counters["contact_link_steps"] = static_cast<double>(contacts);
  if (with_pegs) state.counters["least_clearance_rel"] = clearance;
}
BENCHMARK(SnakeSlalom)->Arg(0)->Arg(1)->Arg(2)->ArgName("pegs")->Unit(benchmark::kMillisecond);

// The disc beside a middle link of the free run at some step, cutting 0.1 into it, clear of the
// start and of every target (the test's placement).
Collider Obstacle(const flexkin::ArmModel& model, const Points& path) {
  const flexkin::ArmTrajectory free = flexkin::TrackPath(model, path, flexkin::ArmOptions());
  const Points start = flexkin::ForwardKinematics(model, model.initial);
  const int n = model.num_links();
  const double reach = 0.35;
  auto segment = [](const Eigen::Vector2d& x, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    const Eigen::Vector2d d = b - a;
    const double t = std::fmax(0.0, std::fmin(1.0, (x - a).dot(d) / d.squaredNorm()));
    return (x - (a + t * d)).norm();
  };
  Collider disc;
  disc.radius = 0.3;
  for (size_t s = free.steps.size() / 3; s < free.steps.size(); ++s) {
    for (int k = n / 3; k < 2 * n / 3; ++k) {
      const Points& p = free.steps[s].state.points;
      const Eigen::Vector2d a = p.row(k).transpose(), b = p.row(k + 1).transpose();
      const Eigen::Vector2d along = (b - a).normalized(), across(along.y(), -along.x());
      const Eigen::Vector2d c = 0.5 * (a + b) + (reach - 0.1) * across;
      bool clear = true;
      for (int i = 0; i < n && clear; ++i) {
        clear = segment(c, start.row(i).transpose(), start.row(i + 1).transpose()) > reach + 0.3;
      }
      for (int i = 0; i < path.rows() && clear; ++i) {
        clear = (path.row(i).transpose() - c).norm() > reach + 0.3;
      }
      if (clear) {
        disc.pose.translation() = Eigen::Vector3d(c.x(), c.y(), 0.0);
        return disc;
      }
    }
  }
  disc.pose.translation() = Eigen::Vector3d(100.0, 100.0, 0.0);
  return disc;
}

// range(0): 0 free, 1 a collider nothing reaches, 2 a disc in the way.
void ArmAmongPegs(benchmark::State& state) {
  flexkin::ArmModel model = flexkin::scenes::CurledArm(2, 12, 0.15);
  model.link_radii = Eigen::VectorXd::Constant(12, 0.05);
  const Points path = flexkin::scenes::CircleOfTargets(model, 2.0, 60);
  flexkin::ArmOptions options;
  if (state.range(0) == 1) {
    Collider far;
    far.radius = 0.3;
    far.pose.translation() = Eigen::Vector3d(100.0, 100.0, 0.0);
    options.colliders = {far};
  } else if (state.range(0) == 2) {
    options.colliders = {Obstacle(model, path)};
  }
  flexkin::ArmTrajectory t;
  for (auto _ : state) {
    t = flexkin::TrackPath(model, path, options);
    benchmark::DoNotOptimize(t.steps.back().state.points.data());
  }
  state.counters["us_per_step"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * path.rows(),
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert, benchmark::Counter::kIs1000);
  state.counters["contact_steps"] = t.contact_steps;
  state.counters["unreached"] = t.unreached;
  state.counters["blocked"] = t.blocked_steps;
  state.counters["passes"] = static_cast<double>(t.total_passes);
}
BENCHMARK(ArmAmongPegs)
    ->Arg(0)
    ->Arg(1)
    ->Arg(2)
    ->ArgName("colliders")
    ->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
