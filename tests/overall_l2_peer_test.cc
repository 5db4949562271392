// OverallStep's exact sparse minimizer of the paper's L2 metric against IPOPT on the smooth
// epigraph (second-order-cone) form of the same problem (testing/l2_peer.h): same objective,
// same constraints, IPOPT from the sequential tractrix step (OverallStep's own path is a
// continuation with an active set of moving points). On Section 5.1's parabola, straight chains
// pulled at several angles and random smooth 2D and 3D chains, for the weights l2 alone,
// l2_weighted alone and l2 + squared. Where IPOPT reports convergence the two must agree: the
// same minimum value (OverallStep never above IPOPT's), the same points held still, the same
// configuration. IPOPT's failures are counted, printed and bounded, never hidden.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "flexkin/curves.h"
#include "flexkin/error.h"
#include "flexkin/overall.h"
#include "l2_peer.h"
#include "scenes/scenes.h"
#include "test_util.h"

namespace flexkin {
namespace {

using peers::PeerOptions;
using peers::PeerReport;

struct Case {
  std::string name;
  Chain chain;
  Eigen::VectorXd head;
};

ObjectiveWeights L2Weights(double l2, double l2_weighted, double squared) {
  ObjectiveWeights w;
  w.l2 = l2;
  w.l2_weighted = l2_weighted;
  w.squared = squared;
  return w;
}

const std::vector<std::pair<std::string, ObjectiveWeights>>& Objectives() {
  static const std::vector<std::pair<std::string, ObjectiveWeights>> list = {
      {"l2", L2Weights(1, 0, 0)},
      {"l2_weighted", L2Weights(0, 1, 0)},
      {"l2_squared", L2Weights(1, 0, 1)},
  };
  return list;
}

std::vector<Case> Cases() {
  std::vector<Case> cases;
  // Paper Sec. 5.1: y = x^2 in 20 links of 0.25, vertex leading, pulled 0.7 at 45 degrees.
  const Chain paper = scenes::PaperParabola();
  cases.push_back({"parabola", paper, paper.points.row(0).transpose() + scenes::PaperPull()});
  // A straight chain of 12 links of 0.5 along +x from the origin, its head pulled by 0.6 at
  // `angle` from the -x axis (0: straight away from the chain, all points translate; 90: across;
  // 170: nearly into the chain, which is singular at exactly 180).
  const Chain straight = MakeEqualLinkChain(
      MakeLine({Eigen::Vector2d::Zero(), Eigen::Vector2d::UnitX(), 12, 0.5}), 0.5);
  for (const int degrees : {0, 20, 45, 70, 90, 120, 150, 170}) {
    const double a = degrees * M_PI / 180.0;
    cases.push_back({"straight_" + std::to_string(degrees) + "deg", straight,
                     Eigen::Vector2d(-0.6 * std::cos(a), 0.6 * std::sin(a))});
  }
  // Random smooth chains of 2 to 30 links (link lengths in [0.5, 1.5], each link turned from the
  // previous one by at most atan(0.5 sqrt(dim)): 35 degrees in 2D, 41 in 3D), the head moved by
  // 0.05 to 1 mean link in a random direction.
  std::mt19937 rng(20240817);
  std::uniform_int_distribution<int> links(2, 30);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), size(0.05, 1.0);
  for (const int dim : {2, 3}) {
    for (int k = 0; k < 12; ++k) {
      Chain chain = scenes::RandomSmoothChain(dim, links(rng), 0.5, &rng);
      Eigen::VectorXd move(dim);
      for (int c = 0; c < dim; ++c) move[c] = unit(rng);
      move *= size(rng) * chain.lengths.mean() / move.norm();
      const Eigen::VectorXd head = chain.points.row(0).transpose() + move;
      cases.push_back({"random" + std::to_string(dim) + "d_" + std::to_string(k) + "_" +
                           std::to_string(chain.num_links()) + "links",
                       std::move(chain), head});
    }
  }
  return cases;
}

// Objective agreement, relative to the larger value. IPOPT's "converged" (tol 1e-12 on its
// scaled KKT error, s_max = 100) is looser than it looks on this problem: the cone multipliers of
// still points grow like 1 / mu and scale the dual infeasibility down, so IPOPT stops while its
// still points still creep by ~1e-7 of a link. Measured on these cases: its objective is above
// OverallStep's by up to 4.6e-6 relative (never below, except at the other local minimizer
// below), and with that scaling off (StrictStopAgreesToRounding) the two agree to 1e-14. So:
constexpr double kObjectiveTolerance = 1e-5;  // |difference| where IPOPT converged
constexpr double kLowerTolerance = 1e-8;      // IPOPT below OverallStep by more: another minimum
// A point is still for IPOPT when it moved less than this fraction of its link. Measured: IPOPT's
// still points creep by up to 1.3e-6 of a link under its default stop, 0 under the strict one.
constexpr double kStill = 1e-5;
constexpr double kStrictStill = 1e-9;

std::string Describe(const Case& c, const std::string& objective) {
  std::string s = c.name + " / " + objective + ": head (";
  for (Eigen::Index k = 0; k < c.head.size(); ++k) s += (k ? ", " : "") + std::to_string(c.head[k]);
  return s + ")";
}

// Points 1..k moved by `still` of their link or more; the last such k (0: none).
int MovingPoints(const Chain& chain, const Points& x, double still) {
  int moving = 0;
  for (int j = 1; j < static_cast<int>(x.rows()); ++j) {
    if ((x.row(j) - chain.points.row(j)).norm() >= still * chain.lengths[j - 1]) moving = j;
  }
  return moving;
}

struct Tally {
  int total = 0, converged = 0, lower = 0, overall_failed = 0;
  double worst_objective = 0.0, worst_position = 0.0, worst_still = 0.0;
  std::vector<std::string> lower_cases;  // "name / objective" where IPOPT found a lower value
};

// One case: OverallStep and IPOPT; the comparison where both converged.
void Compare(const Case& c, const std::string& objective, const ObjectiveWeights& weights,
             const peers::EpigraphOptions& epigraph, int max_iterations, double objective_tolerance,
             double still, Tally* tally) {
  SCOPED_TRACE(Describe(c, objective));
  const int n = c.chain.num_links();
  OverallOptions options;
  options.weights = weights;
  Chain moved = c.chain;
  const Points& overall = moved.points;
  const OverallReport report = OverallStep(c.head, options, &moved);
  PeerOptions peer_options;
  peer_options.weights = weights;
  peer_options.max_iterations = max_iterations;
  const PeerReport peer =
      peers::SolveL2WithIpopt(c.chain.lengths, c.head, peer_options, c.chain.points, epigraph);
  ++tally->total;
  if (!report.converged()) {
    ++tally->overall_failed;
    std::printf("OverallStep did not converge: %s: %s\n  %s\n", Describe(c, objective).c_str(),
                report.BriefReport().c_str(), peer.BriefReport().c_str());
    return;
  }
  if (!peer.converged) {
    std::printf("IPOPT did not converge: %s: %s\n", Describe(c, objective).c_str(),
                peer.BriefReport().c_str());
    return;
  }
  ++tally->converged;
  EXPECT_LT(peer.constraint_violation, 1e-10) << peer.BriefReport();
  // The epigraph's value closes on the metric (t_j = |x_j - a_j| at the minimum), to IPOPT's
  // accuracy on its cones: measured, up to 1.2e-5 relative under the default stop (cones slightly
  // violated) and 1e-11 under the strict one (an interior point stays off its bounds).
  EXPECT_NEAR(peer.solver_objective, peer.objective,
              std::fmax(10 * objective_tolerance, 1e-10) * peer.objective)
      << peer.BriefReport();
  const double scale = std::fmax(report.objective, peer.objective);
  const double gap = report.objective - peer.objective;  // > 0: IPOPT found a lower value
  if (gap > kLowerTolerance * scale) {  // printed, counted, bounded below; never hidden
    ++tally->lower;
    tally->lower_cases.push_back(c.name + " / " + objective);
    std::printf(
        "IPOPT found a LOWER value: %s: OverallStep %.15g (points 1..%d of %d move; %s) vs IPOPT "
        "%.15g (points 1..%d move; %s)\n",
        Describe(c, objective).c_str(), report.objective, report.moving_points, n,
        report.BriefReport().c_str(), peer.objective, MovingPoints(c.chain, peer.points, still),
        peer.BriefReport().c_str());
    return;
  }
  tally->worst_objective = std::fmax(tally->worst_objective, std::fabs(gap) / scale);
  EXPECT_LE(std::fabs(gap), objective_tolerance * scale)
      << "OverallStep " << report.objective << " vs " << peer.BriefReport();
  // The points OverallStep holds still (after moving_points) are still for IPOPT, and those it
  // moves by more than 10 times the threshold (to stay clear of it) move for IPOPT.
  for (int j = 1; j <= n; ++j) {
    const double moved =
        (peer.points.row(j) - c.chain.points.row(j)).norm() / c.chain.lengths[j - 1];
    if (j > report.moving_points) {
      tally->worst_still = std::fmax(tally->worst_still, moved);
      EXPECT_LT(moved, still) << "point " << j << " still for OverallStep, not for IPOPT";
    } else if ((overall.row(j) - c.chain.points.row(j)).norm() >
               10 * still * c.chain.lengths[j - 1]) {
      EXPECT_GE(moved, still) << "point " << j << " moves for OverallStep, not for IPOPT";
    }
  }
  const double position = (overall - peer.points).cwiseAbs().maxCoeff();
  tally->worst_position = std::fmax(tally->worst_position, position);
  // Measured: 1.3e-6 under the default stop (the creeping still points), 1.2e-12 when strict.
  EXPECT_LT(position, std::fmax(objective_tolerance, 1e-10) * c.chain.lengths.maxCoeff())
      << "moving points: OverallStep " << report.moving_points << ", IPOPT "
      << MovingPoints(c.chain, peer.points, still) << "; " << peer.BriefReport();
}

void Summarize(const char* what, const Tally& t, double seconds) {
  std::printf(
      "%s: IPOPT converged in %d of %d cases; worst relative objective difference %.3g, worst "
      "position difference %.3g, worst motion of a still point %.3g links; IPOPT lower %d, "
      "OverallStep not converged %d; %.2f s\n",
      what, t.converged, t.total, t.worst_objective, t.worst_position, t.worst_still, t.lower,
      t.overall_failed, seconds);
}

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TEST(OverallL2PeerTest, SameMinimumAsIpoptOnTheEpigraphForm) {
  const auto started = std::chrono::steady_clock::now();
  Tally tally;
  for (const Case& c : Cases()) {
    for (const auto& [objective, weights] : Objectives()) {
      Compare(c, objective, weights, peers::EpigraphOptions(), 3000, kObjectiveTolerance, kStill,
              &tally);
    }
  }
  Summarize("default stop", tally, SecondsSince(started));
  RecordProperty("ipopt_converged",
                 std::to_string(tally.converged) + " of " + std::to_string(tally.total));
  // Measured: 78 of 99 (the others: Solved_To_Acceptable_Level, Search_Direction_Becomes_Too_Small,
  // restoration failures, all printed).
  EXPECT_GE(tally.converged, 0.75 * tally.total);
  // Known and reported, not hidden (see the printed lines):
  // - random3d_0_25links / l2 (head moved by 0.063, a twentieth of a link): OverallStep moves
  //   point 1 only (by 0.128), objective 0.127699437876; IPOPT moves points 1 and 2 (0.056 and
  //   0.067), 0.123272916725, 3.5% lower, also when started from OverallStep's answer. Along the
  //   feasible path from OverallStep's answer towards IPOPT's the metric first rises (by 3e-7 at
  //   a hundredth of the way) and falls only past a third of it: OverallStep's answer is a local
  //   minimizer, IPOPT's another, lower one.
  for (const std::string& name : tally.lower_cases) {
    EXPECT_EQ(name, "random3d_0_25links / l2") << "IPOPT found a lower value in a new case";
  }
  // OverallStep converges in every case. (random3d_8_10links / l2 used to stall at optimality
  // 5.8e-12, the rounding level of a point that moved by little, whose direction of motion is
  // known only to eps |x| / r; the optimality measure now counts that level as 0 (see
  // src/overall/newton.cc), and OverallStep returns IPOPT's minimizer there, 2.54804198313.)
  EXPECT_EQ(tally.overall_failed, 0);
}

// With IPOPT's error scaling off (s_max 1e20) its stopping test is absolute: where it converges
// (measured: 15 of the 24 straight-chain cases, the others stop at max_iter or with a too small
// search direction), the two answers agree to rounding.
TEST(OverallL2PeerTest, StrictStopAgreesToRounding) {
  const auto started = std::chrono::steady_clock::now();
  peers::EpigraphOptions strict;
  strict.error_scaling_limit = 1e20;
  Tally tally;
  for (const Case& c : Cases()) {
    if (c.name.rfind("straight", 0) != 0) continue;
    for (const auto& [objective, weights] : Objectives()) {
      Compare(c, objective, weights, strict, 200, 1e-12, kStrictStill, &tally);
    }
  }
  Summarize("strict stop", tally, SecondsSince(started));
  EXPECT_LT(tally.worst_position, 1e-9);
  EXPECT_GE(tally.converged, 12);
  EXPECT_EQ(tally.lower, 0);
  EXPECT_EQ(tally.overall_failed, 0);
}

// The caller's start is used (from OverallStep's own answer IPOPT stays there), the report is
// complete, and bad input throws InputError naming the field.
TEST(OverallL2PeerTest, StartsWhereToldAndRejectsBadInput) {
  const Chain chain = scenes::PaperParabola();
  const Eigen::Vector2d head = chain.points.row(0).transpose() + Eigen::Vector2d(0.3, 0.4);
  PeerOptions options;
  options.weights = L2Weights(1, 0, 0);
  OverallOptions overall_options;
  overall_options.weights = options.weights;
  Chain moved = chain;
  const Points& overall = moved.points;
  const OverallReport report = OverallStep(head, overall_options, &moved);
  ASSERT_TRUE(report.converged()) << report.BriefReport();

  peers::EpigraphOptions start;
  start.start = overall;
  start.margin = 1e-3;
  const PeerReport peer =
      peers::SolveL2WithIpopt(chain.lengths, head, options, chain.points, start);
  EXPECT_EQ(peer.solver, "ipopt_l2");
  ASSERT_TRUE(peer.converged) << peer.BriefReport();
  EXPECT_EQ(peer.points.row(0), head.transpose());
  EXPECT_GT(peer.iterations, 0);
  EXPECT_GT(peer.evaluations, 0);
  EXPECT_NEAR(peer.objective, report.objective, kObjectiveTolerance * report.objective);
  EXPECT_LT((peer.points - overall).cwiseAbs().maxCoeff(), 1e-6) << peer.BriefReport();

  // One iteration from there: not converged, and said so.
  options.max_iterations = 1;
  const PeerReport stopped = peers::SolveL2WithIpopt(chain.lengths, head, options, chain.points);
  EXPECT_FALSE(stopped.converged);
  EXPECT_EQ(stopped.status, "Maximum_Iterations_Exceeded") << stopped.BriefReport();

  options.max_iterations = 3000;
  start.margin = 0.0;
  test_util::ExpectInputError(
      [&] { peers::SolveL2WithIpopt(chain.lengths, head, options, chain.points, start); },
      "epigraph.margin");
  start.margin = 1e-2;
  start.start = chain.points.topRows(3);
  test_util::ExpectInputError(
      [&] { peers::SolveL2WithIpopt(chain.lengths, head, options, chain.points, start); },
      "epigraph.start");
  options.weights = L2Weights(0, 0, 1);  // no L2 term
  test_util::ExpectInputError(
      [&] { peers::SolveL2WithIpopt(chain.lengths, head, options, chain.points); },
      "options.weights");
}

}  // namespace
}  // namespace flexkin
