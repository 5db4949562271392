// OverallStep against general-purpose solvers on the same problems: NLopt's SLSQP and IPOPT
// (testing/peer_solvers.h), from the same starting point, with the same objective function.
// Where a peer reports convergence, OverallStep must reach the same minimum (objective to 1e-8
// relative, configuration to 1e-6). A peer that does not converge is recorded as a test property
// (--gtest_output=xml shows it), not a failure: the peers are the reference, not the subject.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "flexkin/overall.h"
#include "peer_solvers.h"
#include "scenes/scenes.h"

namespace flexkin {
namespace {

using peers::PeerOptions;
using peers::PeerReport;

struct Case {
  std::string name;
  Chain chain;
  Eigen::VectorXd head;
  ObjectiveWeights weights;
};

ObjectiveWeights Weights(double squared, double squared_weighted, double rotation,
                         double joint_angle) {
  ObjectiveWeights w;
  w.squared = squared;
  w.squared_weighted = squared_weighted;
  w.rotation = rotation;
  w.joint_angle = joint_angle;
  return w;
}

// The objectives tried on every chain: each term alone, and mixes (the joint angle is planar).
std::vector<std::pair<std::string, ObjectiveWeights>> Objectives(int dim) {
  std::vector<std::pair<std::string, ObjectiveWeights>> list = {
      {"squared", Weights(1, 0, 0, 0)},
      {"squared_weighted", Weights(0, 1, 0, 0)},
      {"rotation", Weights(0, 0, 1, 0)},
      {"squared_rotation", Weights(1, 0, 0.5, 0)},
  };
  if (dim == 2) list.push_back({"squared_rotation_joint", Weights(1, 0, 0.5, 0.3)});
  return list;
}

// A random chain: link lengths in [0.5, 1.5], each link turned from the previous one by at most
// atan(0.6 sqrt(dim)) (40 degrees in 2D, 46 in 3D), so that the chain is curved but never folds
// back on itself.
Chain RandomChain(int dim, int links, std::mt19937* rng) {
  return scenes::RandomSmoothChain(dim, links, 0.6, rng);
}

std::vector<Case> Cases() {
  std::vector<Case> cases;
  // Paper Sec. 5.1: y = x^2 in 20 links of 0.25, vertex leading, pulled 0.7 at 45 degrees.
  const Chain paper = scenes::PaperParabola();
  const Eigen::Vector2d pull = scenes::PaperPull();
  for (const auto& [objective, weights] : Objectives(2)) {
    cases.push_back(
        {"parabola_" + objective, paper, paper.points.row(0).transpose() + pull, weights});
  }
  // Random chains of 5 to 50 links, moved by 0.1 to 1 mean link length in a random direction.
  std::mt19937 rng(20240611);
  std::uniform_int_distribution<int> links(5, 50);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), size(0.1, 1.0);
  for (int dim : {2, 3}) {
    for (int seed = 0; seed < 5; ++seed) {
      const Chain chain = RandomChain(dim, links(rng), &rng);
      Eigen::VectorXd move(dim);
      for (int k = 0; k < dim; ++k) move[k] = unit(rng);
      move *= size(rng) * chain.lengths.mean() / move.norm();
      const Eigen::VectorXd head = chain.points.row(0).transpose() + move;
      for (const auto& [objective, weights] : Objectives(dim)) {
        cases.push_back({"random" + std::to_string(dim) + "d_" + std::to_string(seed) + "_" +
                             std::to_string(chain.num_links()) + "links_" + objective,
                         chain, head, weights});
      }
    }
  }
  return cases;
}

// |a - b| within 1e-8 relative; minima of exactly 0 (the rotation term alone: a translation)
// compare to 1e-14 absolute.
void ExpectSameObjective(double overall, double peer, const std::string& who) {
  EXPECT_LE(std::fabs(overall - peer),
            1e-8 * std::fmax(std::fabs(overall), std::fabs(peer)) + 1e-14)
      << who << ": OverallStep " << overall << " vs " << peer;
}

// For gtest's messages: the case's name rather than its bytes.
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

class OverallPeersTest : public testing::TestWithParam<Case> {};

TEST_P(OverallPeersTest, SameMinimumAsSlsqpAndIpopt) {
  const Case& c = GetParam();
  // The peers first, so that their outcome is recorded (and shown below) whatever OverallStep does.
  PeerOptions peer_options;
  peer_options.weights = c.weights;
  std::vector<PeerReport> peers;
  std::string peer_results;
  for (auto solve : {peers::SolveWithSlsqp, peers::SolveWithIpopt}) {
    peers.push_back(solve(c.chain.lengths, c.head, peer_options, c.chain.points));
    RecordProperty(peers.back().solver, peers.back().BriefReport());
    peer_results += "\n  " + peers.back().BriefReport();
  }

  OverallOptions options;
  options.weights = c.weights;
  Chain moved = c.chain;
  const Points& overall = moved.points;
  const OverallReport report = OverallStep(c.head, options, &moved);
  ASSERT_TRUE(report.converged()) << report.BriefReport() << peer_results;
  EXPECT_LT(report.constraint_violation, 1e-12) << report.BriefReport();
  EXPECT_NEAR(report.objective,
              OverallObjective(c.weights, c.chain.lengths, c.chain.points, overall),
              1e-12 * (1.0 + std::fabs(report.objective)));

  int compared = 0;
  for (const PeerReport& peer : peers) {
    if (!peer.converged) continue;  // recorded above; the peer's failure is not OverallStep's
    ++compared;
    ExpectSameObjective(report.objective, peer.objective, peer.BriefReport());
    EXPECT_LT(peer.constraint_violation, 1e-10) << peer.BriefReport();
    EXPECT_LT((overall - peer.points).cwiseAbs().maxCoeff(), 1e-6) << peer.BriefReport();
  }
  // A problem no peer solved compares nothing: at least one must have.
  EXPECT_GE(compared, 1) << "no peer converged on " << c.name << peer_results;
}

// The whole list, counted: every one of its 50 problems (5 objectives on the paper's parabola, 4
// or 5 on each of 10 random chains) is solved by both peers and matched by OverallStep (measured:
// 50 of 50 for each), so a peer that stops converging, or a list that shrinks, fails here.
TEST(OverallPeers, EnoughProblemsAreCompared) {
  const std::vector<Case> cases = Cases();
  ASSERT_EQ(cases.size(), 50u);
  int slsqp = 0, ipopt = 0;
  for (const Case& c : cases) {
    PeerOptions peer_options;
    peer_options.weights = c.weights;
    OverallOptions options;
    options.weights = c.weights;
    Chain moved = c.chain;
    const OverallReport report = OverallStep(c.head, options, &moved);
    if (!report.converged()) continue;
    const auto same = [&](const PeerReport& peer) {
      return peer.converged &&
             std::fabs(report.objective - peer.objective) <=
                 1e-8 * std::fmax(std::fabs(report.objective), std::fabs(peer.objective)) + 1e-14 &&
             (moved.points - peer.points).cwiseAbs().maxCoeff() < 1e-6;
    };
    slsqp += same(peers::SolveWithSlsqp(c.chain.lengths, c.head, peer_options, c.chain.points));
    ipopt += same(peers::SolveWithIpopt(c.chain.lengths, c.head, peer_options, c.chain.points));
  }
  RecordProperty("slsqp_compared", slsqp);
  RecordProperty("ipopt_compared", ipopt);
  std::printf("compared with SLSQP: %d of %zu; with IPOPT: %d of %zu\n", slsqp, cases.size(), ipopt,
              cases.size());
  EXPECT_EQ(slsqp, 50);
  EXPECT_EQ(ipopt, 50);
}

INSTANTIATE_TEST_SUITE_P(Problems, OverallPeersTest, testing::ValuesIn(Cases()),
                         [](const testing::TestParamInfo<Case>& info) { return info.param.name; });

// A peer made once and reused for a sequence of steps (as the benchmark uses it, and as its users
// would) gives each step the answer a peer made for that step alone gives.
TEST(OverallPeers, PeersMadeOnceSolveEveryStepAsFreshOnes) {
  const Chain chain = scenes::PaperParabola();
  PeerOptions options;
  peers::SlsqpPeer slsqp(chain.lengths, 2, options);
  peers::IpoptPeer ipopt(chain.lengths, 2, options);
  int compared = 0;
  for (const Eigen::Vector2d& move :
       {Eigen::Vector2d(0.49, 0.49), Eigen::Vector2d(-0.3, 0.2), Eigen::Vector2d(0.1, -0.6)}) {
    const Eigen::Vector2d head = chain.points.row(0).transpose() + move;
    const PeerReport reused[] = {slsqp.Solve(head, chain.points), ipopt.Solve(head, chain.points)};
    const PeerReport fresh[] = {peers::SolveWithSlsqp(chain.lengths, head, options, chain.points),
                                peers::SolveWithIpopt(chain.lengths, head, options, chain.points)};
    for (int k = 0; k < 2; ++k) {
      ASSERT_TRUE(reused[k].converged) << reused[k].BriefReport();
      ASSERT_TRUE(fresh[k].converged) << fresh[k].BriefReport();
      EXPECT_NEAR(reused[k].objective, fresh[k].objective, 1e-12 * fresh[k].objective);
      EXPECT_LT((reused[k].points - fresh[k].points).cwiseAbs().maxCoeff(), 1e-12);
      EXPECT_GT(reused[k].seconds, 0.0);
      ++compared;
    }
  }
  EXPECT_EQ(compared, 6);
  // A peer refuses a chain of another shape.
  const Chain other = scenes::Helix(5);
  EXPECT_THROW(slsqp.Solve(other.points.row(0).transpose(), other.points), InputError);
}

// IPOPT with its quasi-Newton Hessian instead of the exact one reaches the same minimum.
TEST(OverallPeers, IpoptLimitedMemoryAgrees) {
  const Chain chain = scenes::PaperParabola();
  const Eigen::Vector2d head = chain.points.row(0).transpose() + Eigen::Vector2d(0.49, 0.49);
  PeerOptions options;
  options.exact_hessian = false;
  const PeerReport exact = peers::SolveWithIpopt(chain.lengths, head, PeerOptions(), chain.points);
  const PeerReport quasi = peers::SolveWithIpopt(chain.lengths, head, options, chain.points);
  ASSERT_TRUE(exact.converged) << exact.BriefReport();
  RecordProperty("ipopt_limited_memory", quasi.BriefReport());
  if (quasi.converged) EXPECT_NEAR(quasi.objective, exact.objective, 1e-8 * exact.objective);
}

// The peers start where OverallStep starts (the tractrix step) and stop where their own test says
// so; the report carries the solver's verdict and the same measures as OverallReport.
TEST(OverallPeers, ReportsAreComplete) {
  std::mt19937 rng(7);
  const Chain chain = RandomChain(3, 12, &rng);
  const Eigen::Vector3d head = chain.points.row(0).transpose() + Eigen::Vector3d(0.3, -0.2, 0.1);
  PeerOptions options;
  options.max_evaluations = 2;  // SLSQP stops long before convergence
  options.max_iterations = 1;
  const PeerReport slsqp = peers::SolveWithSlsqp(chain.lengths, head, options, chain.points);
  EXPECT_FALSE(slsqp.converged);
  EXPECT_EQ(slsqp.status, "MAXEVAL_REACHED") << slsqp.BriefReport();
  const PeerReport ipopt = peers::SolveWithIpopt(chain.lengths, head, options, chain.points);
  EXPECT_FALSE(ipopt.converged);
  EXPECT_EQ(ipopt.status, "Maximum_Iterations_Exceeded") << ipopt.BriefReport();
  for (const PeerReport* r : {&slsqp, &ipopt}) {
    ASSERT_EQ(r->points.rows(), chain.points.rows());
    EXPECT_EQ(r->points.row(0), head.transpose());
    EXPECT_GT(r->evaluations, 0);
    EXPECT_GT(r->seconds, 0.0);
    EXPECT_NEAR(r->objective,
                OverallObjective(ObjectiveWeights(), chain.lengths, chain.points, r->points),
                1e-15);
  }
  EXPECT_THROW(peers::SolveWithIpopt(chain.lengths, head, PeerOptions(), chain.points.leftCols(2)),
               InputError);
  options.weights.joint_angle = 1.0;  // planar only
  EXPECT_THROW(peers::SolveWithSlsqp(chain.lengths, head, options, chain.points), InputError);
}

// IPOPT stays silent: no banner, no iteration log.
TEST(OverallPeers, IpoptPrintsNothing) {
  std::mt19937 rng(3);
  const Chain chain = RandomChain(2, 8, &rng);
  const Eigen::Vector2d head = chain.points.row(0).transpose() + Eigen::Vector2d(0.2, 0.3);
  testing::internal::CaptureStdout();
  const PeerReport report = peers::SolveWithIpopt(chain.lengths, head, PeerOptions(), chain.points);
  EXPECT_EQ(testing::internal::GetCapturedStdout(), "");
  EXPECT_TRUE(report.converged) << report.BriefReport();
}

// The banded Hessian handed to IPOPT, assembled from OverallObjective's Hessian on windows, equals
// OverallObjective's Hessian of the whole chain: one window (short chains) and many (long ones).
TEST(OverallPeers, BandedHessianEqualsDense) {
  std::mt19937 rng(11);
  for (int dim : {2, 3}) {
    for (int links : {1, 3, 23, 24, 25, 90}) {
      const Chain chain = RandomChain(dim, links, &rng);
      const Chain moved = RandomChain(dim, links, &rng);  // any configuration will do
      for (const auto& [objective, weights] : Objectives(dim)) {
        SCOPED_TRACE(std::to_string(dim) + "D, " + std::to_string(links) + " links, " + objective);
        Eigen::MatrixXd dense;
        OverallObjective(weights, chain.lengths, chain.points, moved.points, nullptr, &dense);
        peers::BandedHessian banded;
        peers::ObjectiveHessianBands(weights, chain.lengths, chain.points, moved.points, &banded);
        EXPECT_EQ(banded.band, peers::HessianBand(weights, dim));
        EXPECT_LE((banded.ToDense() - dense).cwiseAbs().maxCoeff(), 1e-12 * (1.0 + dense.norm()));
      }
    }
  }
}

}  // namespace
}  // namespace flexkin
