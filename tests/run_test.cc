// Tests of a whole run (Run): input checking, the recorded frames, the metrics against an
// independent computation from the frames, and the accuracy control against the continuous
// motion computed by an independent ODE solver (reference_ode.h).
#include "flexkin/run.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/error.h"
#include "flexkin/propagate.h"
#include "reference_ode.h"
#include "run/sweep_pipeline.h"
#include "scenes/scenes.h"
#include "sequential/whole_chain.h"
#include "test_util.h"

namespace flexkin {
namespace {

using scenes::CurvedChain;
using test_util::ExpectInputError;
using test_util::Str;

// `count` leader targets along a smooth curve starting at the chain's leading end, about
// `step` apart.
Points CurvedLeaderPath(const Chain& chain, int count, double step) {
  Points targets(count, chain.dim());
  const Eigen::VectorXd start = chain.points.row(0).transpose();
  for (int s = 1; s <= count; ++s) {
    const double t = step * s;
    Eigen::VectorXd x = start;
    x[0] += t;
    x[1] += 0.5 * std::sin(2.0 * t);
    if (chain.dim() == 3) x[2] += 0.3 * (1.0 - std::cos(t));
    targets.row(s - 1) = x.transpose();
  }
  return targets;
}

// The configurations after each leader step, computed directly with MoveLeader.
std::vector<Points> DirectRun(const Chain& chain, const Points& targets, Method method,
                              int substeps) {
  const Stepper stepper = MakeStepper(method, chain);
  std::vector<Points> states = {chain.points};
  Points points = chain.points;
  for (Eigen::Index s = 0; s < targets.rows(); ++s) {
    MoveLeader(stepper, targets.row(s).transpose(), substeps, &points);
    states.push_back(points);
  }
  return states;
}

// ----- Input checking -----------------------------------------------------------------------

TEST(RunTest, RejectsInvalidInputNamingTheField) {
  const Chain chain = CurvedChain(2, 4, 1.0, 0.3);
  const Points targets = CurvedLeaderPath(chain, 5, 0.1);
  EXPECT_TRUE(RunOptions().Validate().empty());
  const auto with = [](auto change) {
    RunOptions o;
    change(o);
    return o;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    RunOptions options;
    std::string field;
  };
  for (const Case& c :
       {Case{with([](RunOptions& o) { o.substeps = 0; }), "substeps"},
        Case{with([](RunOptions& o) { o.record_every = 0; }), "record_every"},
        Case{with([](RunOptions& o) { o.tolerance = -1e-6; }), "tolerance"},
        Case{with([&](RunOptions& o) { o.tolerance = nan; }), "tolerance"},
        Case{with([](RunOptions& o) { o.tolerance = std::numeric_limits<double>::infinity(); }),
             "tolerance"},
        Case{with([](RunOptions& o) {
               o.substeps = 8;
               o.max_substeps = 4;
             }),
             "max_substeps"}}) {
    const Problems problems = c.options.Validate();
    ASSERT_FALSE(problems.empty()) << c.field;
    EXPECT_EQ(problems.front().field, c.field) << problems.front().Text();
    EXPECT_NE(problems.front().Text().find(c.field), std::string::npos) << problems.front().Text();
    ExpectInputError([&] { flexkin::Run(chain, targets, c.options); }, c.field);
  }
  ExpectInputError([&] { flexkin::Run(chain, Points(0, 2), RunOptions()); }, "leader_steps");
  ExpectInputError([&] { flexkin::Run(chain, Points::Zero(3, 3), RunOptions()); }, "leader_steps");
  Points bad = targets;
  bad(2, 1) = nan;
  ExpectInputError([&] { flexkin::Run(chain, bad, RunOptions()); }, "leader_steps[2][1]");
  Chain broken = chain;
  broken.lengths[1] = 0.0;
  ExpectInputError([&] { flexkin::Run(broken, targets, RunOptions()); }, "chain.lengths[1]");
}

// ----- Frames ---------------------------------------------------------------------------------

// record_every keeps frame 0, every N-th leader step and the last one (once), and the frames
// are exactly the configurations of a direct MoveLeader run.
TEST(RunTest, RecordEveryKeepsTheFirstEveryNthAndTheLastFrame) {
  const Chain chain = CurvedChain(3, 6, 1.0, 0.4);
  for (const int num_steps : {30, 28, 1, 6}) {
    const Points targets = CurvedLeaderPath(chain, num_steps, 0.05);
    const std::vector<Points> direct = DirectRun(chain, targets, Method::kTractrix, 3);
    RunOptions options;
    options.substeps = 3;
    options.record_every = 7;
    const RunResult result = flexkin::Run(chain, targets, options);
    std::vector<int64_t> expected_steps = {0};
    for (int s = 1; s <= num_steps; ++s) {
      if (s % 7 == 0 || s == num_steps) expected_steps.push_back(s);
    }
    ASSERT_EQ(result.frames.size(), expected_steps.size()) << num_steps << " steps";
    for (size_t f = 0; f < expected_steps.size(); ++f) {
      EXPECT_EQ(result.frames[f].step, expected_steps[f]);
      EXPECT_EQ(result.frames[f].points, direct[expected_steps[f]]) << "frame " << f;
      EXPECT_EQ(result.frames[f].link_angles.size(), chain.num_links());
    }
    EXPECT_EQ(result.num_steps, num_steps);
    EXPECT_EQ(result.lengths, chain.lengths);
    EXPECT_EQ(result.metrics.l2_per_step.size(), num_steps);
  }
}

// The same scenario gives bit-identical results twice.
TEST(RunTest, IsDeterministic) {
  const Chain chain = CurvedChain(3, 20, 1.0, 0.3);
  const Points targets = CurvedLeaderPath(chain, 50, 0.1);
  RunOptions options;
  options.substeps = 4;
  const RunResult a = flexkin::Run(chain, targets, options);
  const RunResult b = flexkin::Run(chain, targets, options);
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (size_t f = 0; f < a.frames.size(); ++f) EXPECT_EQ(a.frames[f].points, b.frames[f].points);
  EXPECT_EQ(a.metrics.l2_per_step, b.metrics.l2_per_step);
  EXPECT_EQ(a.metrics.path_length, b.metrics.path_length);
}

// ----- Metrics --------------------------------------------------------------------------------

// With record_every = 1 and substeps = 1 the per-step metrics can be recomputed from the
// frames: l2 sums |x_j(after) - x_j(before)| over all points, the weighted form uses the
// trapezoid weights, and the length error is the worst over all frames.
TEST(RunTest, MetricsMatchAnIndependentComputationFromTheFrames) {
  for (const int dim : {2, 3}) {
    for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
      const Chain chain = CurvedChain(dim, 8, 1.0, 0.35);
      const Points targets = CurvedLeaderPath(chain, 40, 0.08);
      RunOptions options;
      options.method = method;
      const RunResult result = flexkin::Run(chain, targets, options);
      ASSERT_EQ(result.frames.size(), 41u);
      const int n = chain.num_links();
      Eigen::VectorXd weights = Eigen::VectorXd::Zero(n + 1);
      for (int j = 0; j <= n; ++j) {
        if (j > 0) weights[j] += 0.5 * chain.lengths[j - 1];
        if (j < n) weights[j] += 0.5 * chain.lengths[j];
      }
      double total = 0.0, weighted_total = 0.0, worst_length = 0.0;
      Eigen::VectorXd path = Eigen::VectorXd::Zero(n + 1);
      for (int s = 0; s < 40; ++s) {
        const Points& before = result.frames[s].points;
        const Points& after = result.frames[s + 1].points;
        double l2 = 0.0, l2_weighted = 0.0;
        for (int j = 0; j <= n; ++j) {
          const double moved = (after.row(j) - before.row(j)).norm();
          l2 += moved;
          l2_weighted += weights[j] * moved;
          path[j] += moved;
        }
        EXPECT_NEAR(result.metrics.l2_per_step[s], l2, 1e-14 * l2) << "step " << s;
        EXPECT_NEAR(result.metrics.l2_weighted_per_step[s], l2_weighted, 1e-14 * l2_weighted);
        total += l2;
        weighted_total += l2_weighted;
        Chain c = chain;
        c.points = after;
        worst_length = std::fmax(worst_length, MaxRelativeLengthError(c));
      }
      EXPECT_NEAR(result.metrics.l2_total, total, 1e-13 * total);
      EXPECT_NEAR(result.metrics.l2_weighted_total, weighted_total, 1e-13 * weighted_total);
      // The wavefront measures each link in its lane (fused multiply-adds, a multiplication by
      // 1/L), which may round the length one ulp otherwise: within 2 ulps of the relative error.
      EXPECT_NEAR(result.metrics.max_relative_length_error, worst_length, 4.5e-16);
      EXPECT_LT(result.metrics.max_relative_length_error, 1e-14);
      for (int j = 0; j <= n; ++j) {
        EXPECT_NEAR(result.metrics.path_length[j], path[j], 1e-13 * path[j]);
      }
    }
  }
}

// path_length is the distance travelled "sub-steps included": with several sub-steps per
// leader step it is the sum over sub-steps, which is longer than the sum of the chords between
// recorded configurations for every point that moves on a curve.
TEST(RunTest, PathLengthIncludesSubsteps) {
  const Chain chain = CurvedChain(2, 6, 1.0, 0.5);
  const Points targets = CurvedLeaderPath(chain, 10, 0.3);
  constexpr int kSubsteps = 8;
  RunOptions options;
  options.substeps = kSubsteps;
  const RunResult result = flexkin::Run(chain, targets, options);
  // Independently: one sub-step at a time, to the same equally spaced intermediate targets.
  const Stepper stepper = MakeStepper(Method::kTractrix, chain);
  Points points = chain.points;
  Eigen::VectorXd path = Eigen::VectorXd::Zero(chain.num_links() + 1);
  for (Eigen::Index s = 0; s < targets.rows(); ++s) {
    const Eigen::VectorXd start = points.row(0).transpose();
    const Eigen::VectorXd target = targets.row(s).transpose();
    for (int j = 1; j <= kSubsteps; ++j) {
      const Eigen::VectorXd head =
          j == kSubsteps ? target
                         : Eigen::VectorXd(start + (double(j) / kSubsteps) * (target - start));
      const Points before = points;
      MoveLeader(stepper, head, 1, &points);
      path += (points - before).rowwise().norm();
    }
  }
  EXPECT_EQ(points, result.frames.back().points);
  for (int j = 0; j <= chain.num_links(); ++j) {
    EXPECT_NEAR(result.metrics.path_length[j], path[j], 1e-12 * path[j]) << "point " << j;
  }
}

// The motion dies out along the chain: pulled straight from a curved start, every point
// travels no farther than the point ahead of it, and the final frame is aligned with the pull.
TEST(RunTest, PathLengthDoesNotIncreaseAlongAChainPulledStraight) {
  for (const int dim : {2, 3}) {
    const Chain chain = CurvedChain(dim, 15, 1.0, 0.4);
    const double chain_length = chain.lengths.sum();
    Eigen::VectorXd dir = Eigen::VectorXd::Zero(dim);
    dir[0] = 0.6;
    dir[1] = -0.8;
    const Points targets =
        scenes::StraightPull(chain.points.row(0).transpose(), dir, 20.0 * chain_length, 400);
    RunOptions options;
    options.substeps = 2;
    options.record_every = 100;
    const RunResult result = flexkin::Run(chain, targets, options);
    const Eigen::VectorXd& path = result.metrics.path_length;
    ASSERT_EQ(path.size(), chain.num_links() + 1);
    EXPECT_NEAR(path[0], 20.0 * chain_length, 1e-12 * path[0]);
    for (int j = 1; j <= chain.num_links(); ++j) {
      EXPECT_LE(path[j], path[j - 1] * (1 + 1e-13)) << dim << "D, point " << j;
    }
    EXPECT_LT(path[chain.num_links()], path[0]);
    const Eigen::VectorXd& angles = result.frames.back().link_angles;
    ASSERT_EQ(angles.size(), chain.num_links());
    EXPECT_LT(angles.maxCoeff(), 1e-6) << dim << "D";
    EXPECT_GE(angles.minCoeff(), 0.0);
    // Frame 0's angles are taken against the first move's direction.
    const Eigen::VectorXd link0 = (chain.points.row(0) - chain.points.row(1)).transpose();
    const double along = link0.dot(dir);
    EXPECT_NEAR(result.frames[0].link_angles[0], std::atan2((link0 - along * dir).norm(), along),
                1e-14);
  }
}

// ----- Accuracy control -----------------------------------------------------------------------

// The maximum, over all leader steps, of the largest point distance between a run's frames and
// the continuous motion.
double ErrorAgainstOde(const Chain& chain, const Points& targets, const RunResult& result) {
  std::vector<Points> exact;
  reference::ReferenceChainMotion(chain.points, targets, &exact);
  double worst = 0.0;
  for (size_t f = 1; f < result.frames.size(); ++f) {
    const Points& got = result.frames[f].points;
    worst = std::fmax(worst, (got - exact[result.frames[f].step - 1]).rowwise().norm().maxCoeff());
  }
  return worst;
}

// With a tolerance the run picks its sub-steps so that the estimated distance to the continuous
// motion is at most the tolerance; the actual distance, measured against the ODE reference, is
// of the same order. Follow-the-leader (order 1) needs many more sub-steps than the tractrix
// (order 2) for the same tolerance.
TEST(RunTest, AccuracyControlMeetsTheToleranceAgainstTheOdeReference) {
  constexpr double kTolerance = 1e-6;
  for (const int dim : {2, 3}) {
    const Chain chain = CurvedChain(dim, 6, 0.6, 0.4);
    const Points targets = CurvedLeaderPath(chain, 8, 0.08);
    int substeps[2] = {0, 0};
    for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
      RunOptions options;
      options.method = method;
      options.tolerance = kTolerance;
      const RunResult result = flexkin::Run(chain, targets, options);
      const AccuracyReport& a = result.accuracy;
      EXPECT_TRUE(a.enabled);
      EXPECT_EQ(a.order, MethodOrder(method));
      EXPECT_TRUE(a.met) << MethodName(method) << ": " << result.BriefReport();
      EXPECT_LE(a.estimated_error, kTolerance);
      EXPECT_LE(a.substeps, options.max_substeps);
      const double actual = ErrorAgainstOde(chain, targets, result);
      EXPECT_LE(actual, 10 * kTolerance) << MethodName(method);
      substeps[method == Method::kTractrix ? 0 : 1] = a.substeps;
      std::cout << "[ measured ] " << dim << "D " << MethodName(method) << ", tolerance "
                << kTolerance << ": " << a.substeps << " sub-steps, estimated error "
                << Str(a.estimated_error) << ", actual error vs ODE " << Str(actual) << "\n";
      ::testing::Test::RecordProperty(
          std::to_string(dim) + "D_" + MethodName(method) + "_substeps_actual_error",
          std::to_string(a.substeps) + " " + Str(actual));
    }
    EXPECT_GE(substeps[1], 16 * substeps[0])
        << dim << "D: ftl " << substeps[1] << " vs tractrix " << substeps[0];
  }
}

// Without a tolerance the given sub-steps are used and nothing is estimated.
TEST(RunTest, AccuracyControlOffUsesTheGivenSubsteps) {
  const Chain chain = CurvedChain(2, 4, 1.0, 0.3);
  RunOptions options;
  options.substeps = 5;
  const RunResult result = flexkin::Run(chain, CurvedLeaderPath(chain, 3, 0.1), options);
  EXPECT_FALSE(result.accuracy.enabled);
  EXPECT_EQ(result.accuracy.substeps, 5);
  EXPECT_TRUE(result.accuracy.met);
}

// max_substeps bounds the automatic choice; a tolerance that cannot be met is reported as not
// met, not silently exceeded.
TEST(RunTest, AccuracyControlNeverExceedsMaxSubsteps) {
  const Chain chain = CurvedChain(2, 4, 1.0, 0.3);
  const Points targets = CurvedLeaderPath(chain, 3, 0.2);
  struct Case {
    int substeps, max_substeps;
  };
  for (const Case c : {Case{1, 64}, Case{3, 100}, Case{5, 8}, Case{4, 4}}) {
    RunOptions options;
    options.method = Method::kFollowTheLeader;
    options.tolerance = 1e-15;
    options.substeps = c.substeps;
    options.max_substeps = c.max_substeps;
    const RunResult result = flexkin::Run(chain, targets, options);
    EXPECT_LE(result.accuracy.substeps, c.max_substeps)
        << "substeps " << c.substeps << ", max_substeps " << c.max_substeps;
    EXPECT_FALSE(result.accuracy.met);
    EXPECT_NE(result.BriefReport().find("NOT MET"), std::string::npos) << result.BriefReport();
  }
}

TEST(RunTest, ReportsAndProgress) {
  const Chain chain = CurvedChain(3, 30, 1.0, 0.3);
  const Points targets = CurvedLeaderPath(chain, 20, 0.1);
  RunOptions options;
  options.tolerance = 1e-4;
  int64_t last_done = -1, last_total = -1;
  options.progress = [&](int64_t done, int64_t total) {
    EXPECT_GE(done, last_done);
    last_done = done;
    last_total = total;
  };
  const auto before = std::chrono::steady_clock::now();
  const RunResult result = flexkin::Run(chain, targets, options);
  const double outside =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - before).count();
  EXPECT_EQ(last_done, 20);
  EXPECT_EQ(last_total, 20);
  const std::string brief = result.BriefReport();
  EXPECT_NE(brief.find("tractrix"), std::string::npos) << brief;
  EXPECT_NE(brief.find("tolerance met"), std::string::npos) << brief;
  EXPECT_EQ(brief.find('\n'), std::string::npos) << "one line";
  const std::string full = result.FullReport();
  EXPECT_EQ(full.rfind(brief, 0), 0u) << "the full report starts with the brief one";
  EXPECT_NE(full.find("[30]"), std::string::npos) << "the last point is in the profile:\n" << full;
  // The run's own clock: some time passed (a run of 20 steps with its accuracy control is not
  // instantaneous), and no more than the caller saw.
  EXPECT_GT(result.seconds, 0.0);
  EXPECT_LE(result.seconds, outside);
}

// A progress callback that throws stops the run: the exception comes out of Run, during the
// accuracy control and during the run itself.
TEST(RunTest, ProgressThatThrowsStopsTheRun) {
  const Chain chain = CurvedChain(3, 400, 0.2, 0.3);
  const Points targets = CurvedLeaderPath(chain, 2000, 0.05);
  for (const bool accuracy : {true, false}) {
    RunOptions options;
    // Work of seconds either way, stopped at the first report (about 0.1 s in).
    options.tolerance = accuracy ? 1e-12 : 0.0;
    options.substeps = accuracy ? 1 : 4096;
    int64_t calls = 0, first_done = -1;
    options.progress = [&](int64_t done, int64_t) {
      if (calls++ == 0) first_done = done;
      throw std::runtime_error("stop");
    };
    EXPECT_THROW(flexkin::Run(chain, targets, options), std::runtime_error);
    EXPECT_EQ(calls, 1);
    // Stopped at its first report: while the sub-steps were chosen (0 done), or part way.
    if (accuracy) EXPECT_EQ(first_done, 0);
    if (!accuracy) EXPECT_LT(first_done, 2000);
  }
}

// The whole-chain rules on the SIMD engine (sequential/whole_chain.h) give the run of the
// sub-step by sub-step loop to rounding: every frame's points and link angles, every metric, on
// chains of 1 to 203 links (the kernel's batches full, partial and empty), in 2D and 3D, with
// sub-steps and sparse recording.
TEST(RunTest, WholeChainRulesOnTheSimdEngineGiveTheSubstepBySubstepRun) {
  if (!internal::WholeChainOnSimd()) {
    GTEST_SKIP() << "this CPU (or FLEXKIN_SIMD) gives no SIMD engine: Run takes the loop itself";
  }
  const auto near = [](double a, double b) {
    return std::fabs(a - b) <= 1e-14 * std::fmax(1.0, std::fmax(std::fabs(a), std::fabs(b)));
  };
  int compared = 0;
  for (const Method method : {Method::kMinRotation, Method::kMinJointAngle}) {
    ASSERT_TRUE(internal::Pipelined(method));
    for (int dim : {2, 3}) {
      for (int n : {1, 2, 3, 7, 8, 9, 20, 203}) {
        for (int substeps : {1, 3}) {
          for (int every : {1, 5}) {
            SCOPED_TRACE(std::string(NameOf(method)) + " dim " + std::to_string(dim) + " links " +
                         std::to_string(n) + " substeps " + std::to_string(substeps) + " every " +
                         std::to_string(every));
            const Chain chain = CurvedChain(dim, n, 2.0, 1.5);
            const Points path = CurvedLeaderPath(chain, 23, 0.07);
            RunOptions options;
            options.method = method;
            options.substeps = substeps;
            options.record_every = every;
            const RunResult simd = flexkin::Run(chain, path, options);
            FrameRecorder recorder;
            const RunResult loop = internal::RunSubstepBySubstep(chain, path, options, &recorder);
            ASSERT_EQ(simd.frames.size(), recorder.frames.size());
            for (size_t f = 0; f < simd.frames.size(); ++f) {
              const Frame a = simd.frames[f], b = recorder.frames[f];
              ASSERT_EQ(a.step, b.step);
              for (Eigen::Index i = 0; i < a.points.size(); ++i) {
                ASSERT_PRED2(near, a.points.data()[i], b.points.data()[i]) << "frame " << f;
              }
              for (Eigen::Index i = 0; i < a.link_angles.size(); ++i) {
                ASSERT_NEAR(a.link_angles[i], b.link_angles[i], 1e-12) << "frame " << f;
              }
            }
            const Metrics &m = simd.metrics, &r = loop.metrics;
            for (Eigen::Index s = 0; s < path.rows(); ++s) {
              ASSERT_PRED2(near, m.l2_per_step[s], r.l2_per_step[s]) << "step " << s;
              ASSERT_PRED2(near, m.l2_weighted_per_step[s], r.l2_weighted_per_step[s]);
            }
            for (Eigen::Index i = 0; i <= n; ++i) {
              ASSERT_PRED2(near, m.path_length[i], r.path_length[i]) << "point " << i;
            }
            ASSERT_PRED2(near, m.l2_total, r.l2_total);
            ASSERT_PRED2(near, m.l2_weighted_total, r.l2_weighted_total);
            // Rigid motions keep the lengths to rounding in both; the error is measured the same.
            EXPECT_LE(m.max_relative_length_error, 1e-13);
            EXPECT_NEAR(m.max_relative_length_error, r.max_relative_length_error, 1e-14);
            ++compared;
          }
        }
      }
    }
  }
  EXPECT_EQ(compared, 2 * 2 * 8 * 2 * 2);
}

}  // namespace
}  // namespace flexkin
