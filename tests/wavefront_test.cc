// The SIMD wavefront engines (every one this CPU can run) against the one-pass scalar loop, the
// reference order of operations: same configuration to within rounding, for both methods, 2D and
// 3D, chain lengths around the lane counts, pulling and pushing moves, links whose motion has died
// out, and moves in the reference form's range. Also: a run is deterministic.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "flexkin/propagate.h"
#include "flexkin/run.h"
#include "sequential/sweep.h"

namespace flexkin {
namespace {

// A random chain with link lengths between 0.5 and 1.5 and a random-walk shape.
Chain RandomChain(int dim, int links, std::mt19937& rng) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0), length(0.5, 1.5);
  Points p(links + 1, dim);
  p.row(0).setZero();
  for (int i = 1; i <= links; ++i) {
    Eigen::VectorXd step(dim);
    for (int k = 0; k < dim; ++k) step[k] = uniform(rng);
    p.row(i) = p.row(i - 1) + length(rng) * step.normalized().transpose();
  }
  return MakeChain(p);
}

// `sweeps` leader positions of a random walk with steps of length `step` (pulling, sideways and
// pushing moves), or, if `back_and_forth`, straight out and straight back past the start.
std::vector<double> Heads(const Chain& chain, int sweeps, double step, bool back_and_forth,
                          std::mt19937& rng) {
  const int dim = chain.dim();
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  auto random_direction = [&] {
    Eigen::VectorXd direction(dim);
    for (int k = 0; k < dim; ++k) direction[k] = uniform(rng);
    return Eigen::VectorXd(direction.normalized());
  };
  const Eigen::VectorXd line = random_direction();
  std::vector<double> heads;
  Eigen::VectorXd head = chain.points.row(0).transpose();
  for (int s = 0; s < sweeps; ++s) {
    head += back_and_forth ? Eigen::VectorXd((s < sweeps / 2 ? step : -step) * line)
                           : Eigen::VectorXd(step * random_direction());
    for (int k = 0; k < dim; ++k) heads.push_back(head[k]);
  }
  return heads;
}

double MaxDifference(const Points& a, const Points& b) {
  return (a - b).rowwise().norm().maxCoeff();
}

TEST(WavefrontTest, EveryEngineMatchesTheOnePassLoop) {
  const std::vector<internal::WavefrontEngine> engines = internal::AvailableWavefronts();
  if (engines.empty()) {
    GTEST_SKIP() << "this CPU has no AVX2+FMA: no wavefront engine to compare (the library then "
                    "uses the one-pass loop everywhere)";
  }
  std::mt19937 rng(7);
  double worst = 0.0;
  for (const internal::WavefrontEngine& engine : engines) {
    for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
      for (const int dim : {2, 3}) {
        for (const int links : {1, 2, 3, 7, 8, 9, 16, 17, 100}) {
          for (const int sweeps : {1, 3, 4, 8, 9, 12, 16, 24, 33}) {
            // Small steps (the exp fast path), steps of about a link, and huge ones (the
            // reference form's range).
            for (const double step : {1e-3, 0.7, 1e55}) {
              for (const bool back_and_forth : {false, true}) {
                const Chain chain = RandomChain(dim, links, rng);
                const std::vector<double> heads = Heads(chain, sweeps, step, back_and_forth, rng);
                const Stepper stepper = MakeStepper(method, chain);
                Points scalar = chain.points, simd = chain.points;
                internal::SweepsScalar(method, dim, heads.data(), sweeps, stepper.lengths.data(),
                                       stepper.inv_lengths.data(), links, scalar.data());
                engine.fn(method, dim, heads.data(), sweeps, stepper.lengths.data(),
                          stepper.inv_lengths.data(), links, simd.data());
                const std::string what = std::string(engine.name) + " " + MethodName(method) + " " +
                                         std::to_string(dim) + "D, " + std::to_string(links) +
                                         " links, " + std::to_string(sweeps) + " sweeps of " +
                                         std::to_string(step);
                ASSERT_TRUE(simd.allFinite()) << what;
                const double scale = scalar.cwiseAbs().maxCoeff() + 1.0;
                Chain moved = chain;
                moved.points = simd;
                EXPECT_LE(MaxRelativeLengthError(moved), 1e-13 * scale) << what;
                // Pushed straight back after a pull, a chain is on its unstable equilibrium and
                // amplifies the last-bit differences of the vector exp by about exp(p/L) per
                // step; there only the invariants above are compared.
                if (back_and_forth && step > 0.1) continue;
                const double difference = MaxDifference(scalar, simd) / scale;
                worst = std::fmax(worst, difference);
                EXPECT_LE(difference, 1e-12) << what;
              }
            }
          }
        }
      }
    }
  }
  std::cout << "[ measured ] engines vs one-pass loop: largest difference / (|coords| + 1) = "
            << worst << "\n";
}

// What the traced engines record of a call: the trace's outputs and every captured
// configuration, in the order captured.
struct Traced {
  Points points;
  std::vector<double> sweep_l2, sweep_l2w;
  Eigen::VectorXd path_length;
  double max_length_error = 0.0;
  std::vector<int64_t> captured_sweeps;
  std::vector<Points> captured;
};

Traced RunTraced(internal::TracedSweepsFn fn, Method method, const Chain& chain,
                 const std::vector<double>& heads, const std::vector<uint8_t>& flags) {
  const int n = chain.num_links(), dim = chain.dim();
  const int64_t sweeps = static_cast<int64_t>(flags.size());
  const Stepper stepper = MakeStepper(method, chain);
  Traced out;
  out.points = chain.points;
  out.sweep_l2.assign(sweeps, -1.0);
  out.sweep_l2w.assign(sweeps, -1.0);
  out.path_length = Eigen::VectorXd::Zero(n + 1);
  Eigen::VectorXd weights = Eigen::VectorXd::LinSpaced(n + 1, 1.0, 2.0);
  std::vector<Points> slots(internal::SweepTrace::kMaxSlots, Points(n + 1, dim));
  std::vector<double*> slot_ptrs;
  for (Points& slot : slots) slot_ptrs.push_back(slot.data());
  internal::SweepTrace trace;
  trace.Prepare(stepper.lengths.data(), stepper.inv_lengths.data(), weights.data(), n);
  trace.flags = flags.data();
  trace.sweep_l2 = out.sweep_l2.data();
  trace.sweep_l2w = out.sweep_l2w.data();
  trace.path_length = out.path_length.data();
  trace.slots = slot_ptrs.data();
  struct Context {
    Traced* out;
    std::vector<Points>* slots;
  } context{&out, &slots};
  trace.context = &context;
  trace.capture = [](void* c, int64_t sweep, int slot) {
    auto* ctx = static_cast<Context*>(c);
    ctx->out->captured_sweeps.push_back(sweep);
    ctx->out->captured.push_back(slot < 0 ? ctx->out->points : (*ctx->slots)[slot]);
  };
  fn(method, dim, heads.data(), sweeps, stepper.lengths.data(), stepper.inv_lengths.data(), n,
     out.points.data(), &trace);
  out.max_length_error = trace.max_length_error;
  return out;
}

// The traced engines (what Run uses) move the chain exactly as the plain ones, and what they
// measure in the lanes (per-sweep L2 sums, path lengths, link lengths at step ends) and capture
// (the configuration after chosen sweeps, slot by slot) is what the one-pass loop measures and
// sees, to rounding.
TEST(WavefrontTest, TracedEnginesMoveAsThePlainOnesAndMeasureAsTheOnePassLoop) {
  const std::vector<internal::WavefrontEngine> engines = internal::AvailableWavefronts();
  if (engines.empty()) GTEST_SKIP() << "this CPU has no AVX2+FMA: no wavefront engine";
  std::mt19937 rng(19);
  std::bernoulli_distribution coin(0.3);
  int64_t captures = 0;
  for (const internal::WavefrontEngine& engine : engines) {
    for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
      for (const int dim : {2, 3}) {
        for (const int links : {1, 8, 9, 17, 100}) {
          for (const int sweeps : {1, 9, 16, 33, 50}) {
            for (const double step : {1e-3, 0.7}) {
              const Chain chain = RandomChain(dim, links, rng);
              const std::vector<double> heads = Heads(chain, sweeps, step, false, rng);
              std::vector<uint8_t> flags(sweeps);
              int captured = 0;
              for (uint8_t& flag : flags) {
                flag = coin(rng) ? internal::SweepTrace::kStepEnd : 0;
                // No call captures more than the slots hold (the run cuts its chunks so).
                if (coin(rng) && captured < internal::SweepTrace::kMaxSlots) {
                  flag |= internal::SweepTrace::kCapture;
                  ++captured;
                }
              }
              const std::string what = std::string(engine.name) + " " + MethodName(method) + " " +
                                       std::to_string(dim) + "D, " + std::to_string(links) +
                                       " links, " + std::to_string(sweeps) + " sweeps of " +
                                       std::to_string(step);
              Points plain = chain.points;
              const Stepper stepper = MakeStepper(method, chain);
              engine.fn(method, dim, heads.data(), sweeps, stepper.lengths.data(),
                        stepper.inv_lengths.data(), links, plain.data());
              const Traced simd = RunTraced(engine.traced, method, chain, heads, flags);
              const Traced scalar =
                  RunTraced(internal::TracedSweepsScalar, method, chain, heads, flags);
              EXPECT_EQ(simd.points, plain) << what;
              const double scale = scalar.points.cwiseAbs().maxCoeff() + 1.0;
              EXPECT_LE(MaxDifference(simd.points, scalar.points) / scale, 1e-12) << what;
              for (int s = 0; s < sweeps; ++s) {
                EXPECT_NEAR(simd.sweep_l2[s], scalar.sweep_l2[s], 1e-12 * scale * (links + 1))
                    << what << ", sweep " << s;
                EXPECT_NEAR(simd.sweep_l2w[s], scalar.sweep_l2w[s], 2e-12 * scale * (links + 1))
                    << what << ", sweep " << s;
              }
              for (int j = 0; j <= links; ++j) {
                EXPECT_NEAR(simd.path_length[j], scalar.path_length[j], 1e-12 * scale * sweeps)
                    << what << ", point " << j;
              }
              EXPECT_NEAR(simd.max_length_error, scalar.max_length_error, 1e-13 * scale) << what;
              ASSERT_EQ(simd.captured_sweeps, scalar.captured_sweeps) << what;
              for (size_t c = 0; c < simd.captured.size(); ++c) {
                EXPECT_LE(MaxDifference(simd.captured[c], scalar.captured[c]) / scale, 1e-12)
                    << what << ", capture " << c;
              }
              // The last sweep's capture is the chain the call leaves, bit for bit.
              if (!simd.captured.empty() && simd.captured_sweeps.back() == sweeps - 1) {
                EXPECT_EQ(simd.captured.back(), simd.points) << what;
              }
              captures += static_cast<int64_t>(simd.captured.size());
            }
          }
        }
      }
    }
  }
  EXPECT_GT(captures, 1000);  // the captures were exercised
}

// Run's pipeline against the plain definition: each leader step a MoveLeader call with the
// sub-steps, the frames the configurations after the recorded steps. Sub-step counts that do not
// divide the lanes, recording that does not divide the steps, and a chain long enough (200,000
// links) that a call holds fewer than 16 captured configurations.
TEST(WavefrontTest, RunFramesAreTheConfigurationsOfSuccessiveMoves) {
  std::mt19937 rng(23);
  struct Case {
    int links, steps, substeps, record_every;
  };
  for (const Case c :
       {Case{9, 37, 3, 2}, Case{40, 25, 5, 1}, Case{100, 20, 1, 3}, Case{200000, 20, 1, 1}}) {
    for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
      const Chain chain = RandomChain(3, c.links, rng);
      const std::vector<double> heads = Heads(chain, c.steps, 0.3, false, rng);
      const Points targets = Eigen::Map<const Points>(heads.data(), c.steps, 3);
      RunOptions options;
      options.method = method;
      options.substeps = c.substeps;
      options.record_every = c.record_every;
      const RunResult result = flexkin::Run(chain, targets, options);
      const Stepper stepper = MakeStepper(method, chain);
      Points points = chain.points;
      size_t frame = 1;
      ASSERT_EQ(result.frames[0].points, chain.points);
      for (int s = 0; s < c.steps; ++s) {
        MoveLeader(stepper, targets.row(s).transpose(), c.substeps, &points);
        if ((s + 1) % c.record_every != 0 && s + 1 != c.steps) continue;
        ASSERT_LT(frame, result.frames.size());
        EXPECT_EQ(result.frames[frame].step, s + 1);
        const double scale = points.cwiseAbs().maxCoeff() + 1.0;
        EXPECT_LE(MaxDifference(result.frames[frame].points, points) / scale, 1e-12)
            << MethodName(method) << ", " << c.links << " links, frame " << frame;
        ++frame;
      }
      EXPECT_EQ(frame, result.frames.size());
      EXPECT_LT(result.metrics.max_relative_length_error, 1e-12);
      EXPECT_TRUE(result.metrics.l2_per_step.allFinite());
    }
  }
}

// Where the motion has died out completely (the head of a link did not move) both paths leave
// the rest of the chain exactly where it was.
// Moves near the largest doubles: the vector step overflows where the one-pass loop's does not;
// those lanes take the scalar reference, and nothing non-finite comes out of any engine.
TEST(WavefrontTest, MovesNearTheLargestDoublesStayFinite) {
  const std::vector<internal::WavefrontEngine> engines = internal::AvailableWavefronts();
  if (engines.empty()) GTEST_SKIP() << "no SIMD wavefront on this CPU (it has no AVX2 and FMA)";
  for (const internal::WavefrontEngine& engine : engines) {
    for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
      for (const double far : {1e300, 1e155, -1e308}) {
        const int n = 12, sweeps = 32;
        std::vector<double> points, lengths(n, 0.5), inv(n, 2.0), heads;
        for (int i = 0; i <= n; ++i) points.push_back(0.5 * i), points.push_back(0.0);
        for (int s = 1; s <= sweeps; ++s) {
          heads.push_back(far * (static_cast<double>(s) / sweeps));
          heads.push_back(-far * (static_cast<double>(s) / sweeps));
        }
        engine.fn(method, 2, heads.data(), sweeps, lengths.data(), inv.data(), n, points.data());
        for (double x : points) {
          ASSERT_TRUE(std::isfinite(x)) << engine.name << " " << MethodName(method) << " " << far;
        }
      }
    }
  }
}

TEST(WavefrontTest, StillHeadLeavesTheChainExactlyInPlace) {
  std::mt19937 rng(11);
  for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
    const Chain chain = RandomChain(3, 40, rng);
    std::vector<double> heads;
    for (int s = 0; s < 32; ++s) {
      for (int k = 0; k < 3; ++k) heads.push_back(chain.points(0, k));
    }
    const Stepper stepper = MakeStepper(method, chain);
    Points scalar = chain.points;
    internal::SweepsScalar(method, 3, heads.data(), 32, stepper.lengths.data(),
                           stepper.inv_lengths.data(), 40, scalar.data());
    EXPECT_EQ(scalar, chain.points);
    for (const internal::WavefrontEngine& engine : internal::AvailableWavefronts()) {
      Points simd = chain.points;
      engine.fn(method, 3, heads.data(), 32, stepper.lengths.data(), stepper.inv_lengths.data(), 40,
                simd.data());
      EXPECT_EQ(simd, chain.points) << engine.name;
    }
  }
}

// The same moves twice give bit-identical results: MoveLeader with many sub-steps (the wavefront
// engine) and a whole Run with frames and metrics.
TEST(WavefrontTest, MovesAndRunsAreDeterministic) {
  std::mt19937 rng(3);
  const Chain chain = RandomChain(3, 50, rng);
  Points targets(20, 3);
  for (int s = 0; s < 20; ++s) {
    targets.row(s) << 0.3 * s, std::sin(0.5 * s), 0.1 * s;
  }
  const Stepper stepper = MakeStepper(Method::kTractrix, chain);
  Points first = chain.points, second = chain.points;
  for (int s = 0; s < 20; ++s) {
    MoveLeader(stepper, targets.row(s).transpose(), 64, &first);
    MoveLeader(stepper, targets.row(s).transpose(), 64, &second);
  }
  EXPECT_EQ(first, second);
  RunOptions options;
  options.substeps = 4;
  const RunResult a = flexkin::Run(chain, targets, options);
  const RunResult b = flexkin::Run(chain, targets, options);
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (size_t f = 0; f < a.frames.size(); ++f) EXPECT_EQ(a.frames[f].points, b.frames[f].points);
  EXPECT_EQ(a.metrics.path_length, b.metrics.path_length);
}

}  // namespace
}  // namespace flexkin
