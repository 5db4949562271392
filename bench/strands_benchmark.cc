// Many strands at once (flexkin/strands.h, docs/strands.md): 10,000 hair strands of 32 links on
// a wobbling head, one sub-step per frame, 3D. Time per frame of
//   1. the tractrix on the strand engine, 1 and 2 threads;
//   2. follow-the-leader on the same engine, 1 and 2 threads;
//   3. a loop of the single-chain MoveLeader over the strands (one thread);
//   4. the conventional one-pass follow-the-leader loop hair simulators run (one thread);
// and the strand engine's tractrix over 100 to 100,000 strands and 8 to 64 links (linear cost);
// and, with colliders (docs/colliders.md), hair draped over a turning head with the scalp and 4
// capsules (a neck, two shoulders, a torso), against the same hair without colliders and against
// the baseline hair simulators use: follow-the-leader, then each point pushed out of the
// colliders (BM_Draped*; the counters give the deepest link inside a collider after the frame and
// the worst relative link-length error, over the run); and the hair of 1 and 2 on the upper half
// of the scalp with and without the same colliders (BM_Grown*: a groom as the head demo's).
// ns_per_link_step is the time per link per strand per frame (printed in seconds: "3.3n").
// Run: build/bench/strands_benchmark --benchmark_repetitions=5
//        --benchmark_report_aggregates_only=true ; FLEXKIN_SIMD=avx2 caps the engine at AVX2.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "flexkin/propagate.h"
#include "flexkin/strands.h"

namespace flexkin {
namespace {

// Strands on the unit sphere, growing outward with small random bends, links of 0.01 to 0.02.
// `upper`: rooted on the upper half only (a root below the equator mirrored in it), each link kept
// at least 0.3 of its length away from the sphere's centre (no strand curls back into it).
std::vector<Points> Hair(int count, int links, bool upper = false) {
  std::mt19937 rng(42);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(0.01, 0.02);
  std::vector<Points> strands;
  strands.reserve(count);
  for (int s = 0; s < count; ++s) {
    Points p(links + 1, 3);
    Eigen::Vector3d dir(normal(rng), normal(rng), normal(rng));
    dir.normalize();
    if (upper) dir.z() = std::fabs(dir.z());
    p.row(0) = dir.transpose();
    for (int i = 1; i <= links; ++i) {
      dir = (dir + 0.2 * Eigen::Vector3d(normal(rng), normal(rng), normal(rng))).normalized();
      const Eigen::Vector3d out = p.row(i - 1).transpose().normalized();
      if (upper && dir.dot(out) < 0.3) dir = (dir + (0.3 - dir.dot(out)) * out).normalized();
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
// 6. Colliders. Hair draped over the unit-sphere scalp: roots on the upper half, each link turned a
// little off the surface (radial part 0.1 to 0.25), so that every point starts outside and a
// turning head drags the strands through the scalp where nothing stops them.
std::vector<Points> Draped(int count, int links) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> radial(0.1, 0.25), length(0.01, 0.02);
  std::vector<Points> strands;
  for (int s = 0; s < count; ++s) {
    Points p(links + 1, 3);
    Eigen::Vector3d root(normal(rng), normal(rng), normal(rng));
    root.normalize();
    root.z() = std::fabs(root.z());
    Eigen::Vector3d tangent(normal(rng), normal(rng), normal(rng));
    p.row(0) = root.transpose();
    for (int i = 1; i <= links; ++i) {
      const Eigen::Vector3d out = p.row(i - 1).transpose().normalized();
      const Eigen::Vector3d t = (tangent - tangent.dot(out) * out).normalized();
      const double a = radial(rng);
      p.row(i) = p.row(i - 1) + length(rng) * (a * out + std::sqrt(1 - a * a) * t).transpose();
      tangent = t;
    }
    strands.push_back(p);
  }
  return strands;
}

Collider Capsule(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double radius) {
  Collider c;
  c.shape = ColliderShape::kCapsule;
  c.pose.translation() = 0.5 * (from + to);
  c.pose.linear() =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), to - from).matrix();
  c.half_length = 0.5 * (to - from).norm();
  c.radius = radius;
  return c;
}

// The scalp and 4 capsules, in body coordinates.
std::vector<Collider> Body() {
  Collider scalp;
  scalp.shape = ColliderShape::kSphere;
  scalp.radius = 1.0;
  return {scalp, Capsule({0, 0, -1.1}, {0, 0, -2.4}, 0.45),
          Capsule({0.5, 0, -2.0}, {1.8, 0, -2.2}, 0.35),
          Capsule({-0.5, 0, -2.0}, {-1.8, 0, -2.2}, 0.35),
          Capsule({0, 0, -2.6}, {0, 0, -4.0}, 0.9)};
}

// A faster turn than HeadPose, as a head shaken left and right (about z) while nodding: the
// draped strands lag and are pulled across the scalp.
BodyPose ShakePose(int64_t frame) {
  const double t = frame / 60.0;
  const double yaw = 0.9 * std::sin(3.0 * t), pitch = 0.25 * std::sin(2.0 * t);
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()))
                                .toRotationMatrix();
  BodyPose pose;
  pose.rotation = r;
  return pose;
}

// The strands on a head moved by `pose`, with or without the scalp and 4 capsules, by threads.
void BodyEngine(benchmark::State& state, const std::vector<Points>& strands,
                BodyPose (*pose)(int64_t), bool colliders) {
  StrandOptions options;
  options.threads = static_cast<int>(state.range(0));
  if (colliders) options.body_colliders = Body();
  StrandBatch batch(strands, options);
  int64_t frame = 0;
  for (auto _ : state) {
    StepStrands(&batch, pose(++frame));
    benchmark::ClobberMemory();
  }
  state.SetLabel(batch.engine());
  SetRate(state, 10000.0 * 32);
  if (colliders) {
    state.counters["contact_steps_per_frame"] =
        static_cast<double>(batch.contacts().contact_link_steps) / static_cast<double>(frame);
    state.counters["least_clearance"] = batch.contacts().least_clearance;
  }
}
void DrapedEngine(benchmark::State& state, bool colliders) {
  BodyEngine(state, Draped(10000, 32), ShakePose, colliders);
}
void BM_DrapedFree(benchmark::State& state) { DrapedEngine(state, false); }
void BM_DrapedColliders(benchmark::State& state) { DrapedEngine(state, true); }
BENCHMARK(BM_DrapedFree)
    ->Arg(1)
    ->Arg(2)
    ->Iterations(120)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_DrapedColliders)
    ->Arg(1)
    ->Arg(2)
    ->Iterations(120)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Hair grown outward as in 1 and 2 (the head nodding and turning as there), rooted on the upper
// half of the scalp (the neck capsule would hold roots at the bottom), with and without the scalp
// and 4 capsules: a groom as the head demo's, where the strands the turning head lays against the
// scalp touch it.
void GrownEngine(benchmark::State& state, bool colliders) {
  BodyEngine(state, Hair(10000, 32, true), HeadPose, colliders);
}
void BM_GrownFree(benchmark::State& state) { GrownEngine(state, false); }
void BM_GrownColliders(benchmark::State& state) { GrownEngine(state, true); }
BENCHMARK(BM_GrownFree)
    ->Arg(1)
    ->Arg(2)
    ->Iterations(120)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_GrownColliders)
    ->Arg(1)
    ->Arg(2)
    ->Iterations(120)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The baseline: one follow-the-leader pass per strand, then every point inside a collider moved to
// its nearest surface point (sphere: radially; capsule: radially from its axis), on plain arrays
// of points, one thread (as hair simulators write it). Its deepest link inside a collider and its
// length error are measured after the frame, outside the timer.
void BM_DrapedFtlPushOut(benchmark::State& state) {
  const std::vector<Points> strands = Draped(10000, 32);
  const std::vector<Collider> body = Body();
  std::vector<double> pts, rest, body_pts;
  std::vector<int> first;
  for (const Points& p : strands) {
    first.push_back(static_cast<int>(pts.size() / 3));
    for (int i = 0; i < p.rows(); ++i) {
      for (int k = 0; k < 3; ++k) pts.push_back(p(i, k));
      if (i > 0) rest.push_back((p.row(i) - p.row(i - 1)).norm());
    }
  }
  first.push_back(static_cast<int>(pts.size() / 3));
  std::vector<Eigen::Vector3d> roots;
  for (const Points& p : strands) roots.emplace_back(p(0, 0), p(0, 1), p(0, 2));
  // Placed colliders of the frame: centre, axis end points, radius.
  struct Placed {
    bool sphere;
    Eigen::Vector3d a, b;
    double r;
  };
  std::vector<Placed> placed(body.size());
  double deepest = 0.0, worst_length = 0.0;
  int64_t frame = 0;
  auto step = [&](const BodyPose& pose) {
    for (size_t c = 0; c < body.size(); ++c) {
      const Eigen::Vector3d center = pose.rotation * body[c].pose.translation() + pose.translation;
      const Eigen::Vector3d axis =
          pose.rotation * body[c].pose.linear().col(2) * body[c].half_length;
      placed[c] = {body[c].shape == ColliderShape::kSphere, center - axis, center + axis,
                   body[c].radius};
    }
    int link = 0;
    for (size_t s = 0; s + 1 < first.size(); ++s) {
      double* p = pts.data() + 3 * first[s];
      const Eigen::Vector3d root = pose.rotation * roots[s] + pose.translation;
      for (int k = 0; k < 3; ++k) p[k] = root[k];
      const int n = first[s + 1] - first[s] - 1;
      for (int i = 1; i <= n; ++i, ++link) {
        double* q = p + 3 * i;
        const double d[3] = {q[0] - q[-3], q[1] - q[-2], q[2] - q[-1]};
        const double scale = rest[link] / std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int k = 0; k < 3; ++k) q[k] = q[k - 3] + d[k] * scale;
        Eigen::Map<Eigen::Vector3d> x(q);
        for (const Placed& c : placed) {
          Eigen::Vector3d nearest = c.a;
          if (!c.sphere) {
            const Eigen::Vector3d ab = c.b - c.a;
            nearest = c.a + std::clamp((x - c.a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) * ab;
          }
          const Eigen::Vector3d off = x - nearest;
          const double dist = off.norm();
          if (dist < c.r && dist > 0.0) x = nearest + off * (c.r / dist);
        }
      }
    }
  };
  for (auto _ : state) {
    const BodyPose pose = ShakePose(++frame);
    step(pose);
    benchmark::ClobberMemory();
    state.PauseTiming();
    // How far the links reach into the colliders, and how far the pushing moved the lengths.
    int link = 0;
    for (size_t s = 0; s + 1 < first.size(); ++s) {
      for (int i = first[s] + 1; i < first[s + 1]; ++i, ++link) {
        const Eigen::Vector3d a(&pts[3 * (i - 1)]), b(&pts[3 * i]);
        worst_length = std::max(worst_length, std::fabs((b - a).norm() - rest[link]) / rest[link]);
        for (const Placed& c : placed) {
          // Deepest point of the link inside: sampled at 9 points along it.
          for (int k = 0; k <= 8; ++k) {
            const Eigen::Vector3d x = a + (k / 8.0) * (b - a);
            Eigen::Vector3d nearest = c.a;
            if (!c.sphere) {
              const Eigen::Vector3d ab = c.b - c.a;
              nearest = c.a + std::clamp((x - c.a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) * ab;
            }
            deepest = std::min(deepest, ((x - nearest).norm() - c.r) / rest[link]);
          }
        }
      }
    }
    state.ResumeTiming();
  }
  SetRate(state, 10000.0 * 32);
  state.counters["deepest_link_inside"] = deepest;
  state.counters["max_length_error"] = worst_length;
}
BENCHMARK(BM_DrapedFtlPushOut)->Iterations(120)->Unit(benchmark::kMillisecond)->UseRealTime();

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
