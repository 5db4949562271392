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

// Where the motion has died out completely (the head of a link did not move) both paths leave
// the rest of the chain exactly where it was.
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
