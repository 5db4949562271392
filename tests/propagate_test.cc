// Tests of chains and sequential propagation (MoveLeader): input checking, agreement with the
// one-link rules, the invariants of the paper (lengths kept, trailing end never faster, motion
// dying out, alignment with a long pull) and convergence of the multi-step methods to the
// continuous motion computed by an independent ODE solver (reference_ode.h).
#include "flexkin/propagate.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/error.h"
#include "flexkin/link_step.h"
#include "reference_ode.h"
#include "scenes/scenes.h"
#include "test_util.h"

namespace flexkin {
namespace {

using scenes::CurvedChain;
using scenes::CurvedPoints;
using test_util::ExpectInputError;
using test_util::Str;

constexpr double kEps = std::numeric_limits<double>::epsilon();

// Largest distance between corresponding points.
double MaxDistance(const Points& a, const Points& b) { return (a - b).rowwise().norm().maxCoeff(); }

// Observed orders log2(e_k / e_2k) from errors at k, 2k, 4k, ...
std::vector<double> ObservedOrders(const std::vector<double>& errors) {
  std::vector<double> orders;
  for (size_t j = 1; j < errors.size(); ++j) orders.push_back(std::log2(errors[j - 1] / errors[j]));
  return orders;
}

std::string Join(const std::vector<double>& v) {
  std::string s;
  for (const double x : v) s += (s.empty() ? "" : " ") + Str(x);
  return s;
}

// ----- Chains and input checking ----------------------------------------------------------

TEST(MakeChainTest, LengthsAreTheDistancesBetweenConsecutivePoints) {
  Points p(4, 3);
  p << 0, 0, 0, 3, 4, 0, 3, 4, 12, 3, 4, 13;
  const Chain chain = MakeChain(p);
  EXPECT_EQ(chain.dim(), 3);
  EXPECT_EQ(chain.num_links(), 3);
  EXPECT_EQ(chain.points, p);
  EXPECT_EQ(chain.lengths, Eigen::Vector3d(5, 12, 1));
  EXPECT_EQ(MaxRelativeLengthError(chain), 0.0);
}

TEST(MakeChainTest, RejectsDegenerateInputNamingTheField) {
  ExpectInputError([] { MakeChain(Points(0, 3)); }, "points");
  ExpectInputError([] { MakeChain(Points::Zero(1, 2)); }, "points");
  ExpectInputError([] { MakeChain(Points::Ones(3, 4)); }, "points");
  ExpectInputError([] { MakeChain(Points::Ones(3, 1)); }, "points");
  const Points good = CurvedPoints(3, 5, 1.0, 0.3);
  for (const double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
        -std::numeric_limits<double>::infinity()}) {
    Points p = good;
    p(3, 1) = bad;
    ExpectInputError([&] { MakeChain(p); }, "points[3][1]");
  }
  Points p = good;
  p.row(3) = p.row(2);  // link 3 (points 2 and 3) has zero length
  ExpectInputError([&] { MakeChain(p); }, "points[3]");
  try {
    MakeChain(p);
  } catch (const InputError& e) {
    // The message says which link and which points, and what would be valid.
    EXPECT_NE(std::string(e.what()).find("link 3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("points 2 and 3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("positive"), std::string::npos) << e.what();
  }
  // A link whose length overflows is not finite either.
  Points huge(2, 2);
  huge << -1e308, 0, 1e308, 0;
  ExpectInputError([&] { MakeChain(huge); }, "points[1]");
}

TEST(MakeChainTest, ValidateChainNamesTheField) {
  Chain chain = CurvedChain(2, 4, 1.0, 0.3);
  EXPECT_NO_THROW(ValidateChain(chain));
  Chain short_lengths = chain;
  short_lengths.lengths.conservativeResize(3);
  ExpectInputError([&] { ValidateChain(short_lengths); }, "chain.lengths");
  Chain negative = chain;
  negative.lengths[2] = -1.0;
  ExpectInputError([&] { ValidateChain(negative); }, "chain.lengths[2]");
  Chain nan = chain;
  nan.points(1, 0) = std::numeric_limits<double>::quiet_NaN();
  ExpectInputError([&] { ValidateChain(nan); }, "chain.points[1][0]");
}

TEST(MoveLeaderTest, RejectsInvalidInputNamingTheField) {
  const Chain chain = CurvedChain(3, 4, 1.0, 0.3);
  const Stepper stepper = MakeStepper(Method::kTractrix, chain);
  Points points = chain.points;
  ExpectInputError([&] { MoveLeader(stepper, Eigen::Vector2d(1, 2), 1, &points); }, "target");
  ExpectInputError([&] { MoveLeader(stepper, Eigen::Vector4d(1, 2, 3, 4), 1, &points); }, "target");
  ExpectInputError(
      [&] {
        MoveLeader(stepper, Eigen::Vector3d(1, std::numeric_limits<double>::quiet_NaN(), 0), 1,
                   &points);
      },
      "target[1]");
  ExpectInputError(
      [&] {
        MoveLeader(stepper, Eigen::Vector3d(std::numeric_limits<double>::infinity(), 0, 0), 1,
                   &points);
      },
      "target[0]");
  ExpectInputError([&] { MoveLeader(stepper, Eigen::Vector3d(1, 2, 3), 0, &points); }, "substeps");
  ExpectInputError([&] { MoveLeader(stepper, Eigen::Vector3d(1, 2, 3), -3, &points); }, "substeps");
  Points wrong_shape = Points::Zero(3, 3);
  ExpectInputError([&] { MoveLeader(stepper, Eigen::Vector3d(1, 2, 3), 1, &wrong_shape); },
                   "points");
  // Nothing moved on a rejected call.
  EXPECT_EQ(points, chain.points);
  // The convenience overload checks the chain too.
  Chain bad = chain;
  bad.lengths[0] = 0.0;
  ExpectInputError([&] { MoveLeader(Method::kTractrix, Eigen::Vector3d(1, 2, 3), 1, &bad); },
                   "chain.lengths[0]");
}

TEST(MoveLeaderTest, MethodNamesRoundTrip) {
  for (const Method m : {Method::kTractrix, Method::kFollowTheLeader}) {
    EXPECT_EQ(ParseMethod(MethodName(m)), m);
  }
  EXPECT_EQ(MethodOrder(Method::kTractrix), 2);
  EXPECT_EQ(MethodOrder(Method::kFollowTheLeader), 1);
  ExpectInputError([] { ParseMethod("fabrik", "/method"); }, "/method");
}

// ----- Propagation agrees with the one-link rules -------------------------------------------

// The motion of MoveLeader computed independently: k sweeps to equally spaced targets, each
// applying the public one-link rule from the leading end down, each link's leading end moving
// from its old to its new position.
Points LinkRuleSweeps(Method method, const Chain& chain, const Eigen::Vector3d& target,
                      int substeps) {
  const Eigen::Vector3d start = chain.points.row(0).transpose();
  Points points = chain.points;
  for (int j = 1; j <= substeps; ++j) {
    const Eigen::Vector3d head =
        j == substeps ? target : Eigen::Vector3d(start + (double(j) / substeps) * (target - start));
    Eigen::Vector3d lead_old = points.row(0).transpose(), lead_new = head;
    points.row(0) = head.transpose();
    for (int i = 1; i <= chain.num_links(); ++i) {
      const Eigen::Vector3d tail = points.row(i).transpose();
      const Eigen::Vector3d moved =
          method == Method::kTractrix
              ? TractrixStep(lead_old, lead_new, tail, chain.lengths[i - 1])
              : FollowTheLeaderStep(lead_old, lead_new, tail, chain.lengths[i - 1]);
      points.row(i) = moved.transpose();
      lead_old = tail;
      lead_new = moved;
    }
  }
  return points;
}

// Short chains and few sub-steps take the scalar sweep: bit-identical to the link rules.
TEST(MoveLeaderTest, SweepAppliesTheLinkRuleDownTheChain) {
  for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
    const Chain chain = CurvedChain(3, 6, 1.0, 0.4);
    const Eigen::Vector3d target(0.3, 1.7, -0.4);
    Chain moved = chain;
    MoveLeader(method, target, 5, &moved);
    EXPECT_EQ(moved.points, LinkRuleSweeps(method, chain, target, 5)) << MethodName(method);
    EXPECT_EQ(moved.points.row(0), target.transpose()) << "the leader lands exactly on target";
  }
}

// Long chains with many sub-steps may take the vectorized (wavefront) sweep, whose exp (a
// vector exp, or a short Taylor series for sub-steps below L/32, as with 1024 sub-steps here)
// may differ from std::exp by about an ulp: the same motion to rounding.
TEST(MoveLeaderTest, ManySubstepsOnALongChainAgreeWithTheLinkRules) {
  double worst = 0.0;
  for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
    for (const int substeps : {16, 64, 67, 1024}) {
      const Chain chain = CurvedChain(3, 40, 1.0, 0.2);
      const Eigen::Vector3d target(-0.4, 2.2, 0.5);
      Chain moved = chain;
      MoveLeader(method, target, substeps, &moved);
      const double diff =
          MaxDistance(moved.points, LinkRuleSweeps(method, chain, target, substeps));
      EXPECT_LT(diff, 1e-13) << MethodName(method) << ", " << substeps << " sub-steps";
      worst = std::fmax(worst, diff);
      EXPECT_LT(MaxRelativeLengthError(moved), 1e-14);
    }
  }
  std::cout << "[ measured ] vectorized vs scalar link-rule sweeps: max point distance " << worst
            << "\n";
}

// ----- Invariants ---------------------------------------------------------------------------

// (a) Lengths are kept to rounding and rounding does not accumulate: a 100-link 3D chain whose
// leading end wanders along a smooth 3D path in ONE MILLION small steps.
// EXPENSIVE: about 1e8 link steps, a few seconds in an optimized build (much longer under
// sanitizers); the most expensive test of the suite.
TEST(MoveLeaderInvariantTest, ExpensiveOneMillionStepsKeepEveryLinkLength) {
  constexpr int kLinks = 100;
  constexpr int kSteps = 1000000;
  Chain chain = CurvedChain(3, kLinks, 1.0, 0.15);
  const Stepper stepper = MakeStepper(Method::kTractrix, chain);
  const Eigen::Vector3d origin = chain.points.row(0).transpose();
  const auto start = std::chrono::steady_clock::now();
  double worst = 0.0;
  for (int s = 1; s <= kSteps; ++s) {
    // Sum of incommensurate sines: a bounded, smooth, non-repeating path; steps of ~1e-2 L.
    const double t = 1e-3 * s;
    const Eigen::Vector3d target =
        origin + 3.0 * Eigen::Vector3d(std::sin(1.3 * t) + 0.5 * std::sin(3.7 * t),
                                       std::cos(1.1 * t) - 1.0 + 0.4 * std::sin(2.9 * t),
                                       0.6 * std::sin(0.7 * t) * std::cos(1.9 * t));
    MoveLeader(stepper, target, 1, &chain.points);
    if (s % 100000 == 0) {
      const double error = MaxRelativeLengthError(chain);
      worst = std::fmax(worst, error);
      EXPECT_LT(error, 1e-12) << "after " << s << " steps";
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(chain.points.allFinite());
  std::cout << "[ measured ] " << kSteps << " steps of a " << kLinks
            << "-link 3D chain: max relative length error " << worst
            << " (checked every 1e5 steps), " << seconds << " s\n";
  ::testing::Test::RecordProperty("million_step_length_error", Str(worst));
}

// The same with many sub-steps per leader step (the vectorized sweep): 100 links, 2000 leader
// steps of 32 sub-steps.
TEST(MoveLeaderInvariantTest, ManySubstepsKeepEveryLinkLength) {
  for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
    Chain chain = CurvedChain(3, 100, 1.0, 0.15);
    const Stepper stepper = MakeStepper(method, chain);
    const Eigen::Vector3d origin = chain.points.row(0).transpose();
    for (int s = 1; s <= 2000; ++s) {
      const double t = 5e-3 * s;
      const Eigen::Vector3d target =
          origin + 3.0 * Eigen::Vector3d(std::sin(1.3 * t), std::cos(1.1 * t) - 1.0,
                                         0.6 * std::sin(0.7 * t));
      MoveLeader(stepper, target, 32, &chain.points);
    }
    EXPECT_LT(MaxRelativeLengthError(chain), 1e-12) << MethodName(method);
  }
}

// A link pulled straight and then pushed straight back with large steps: the link lies within
// rounding of the line of motion, the unstable configuration. Its length must still be kept.
TEST(MoveLeaderInvariantTest, PushedBackAfterAStraightPullLengthsStayKept) {
  for (const int dim : {2, 3}) {
    for (const double step_over_length : {1.0, 10.0, 20.0, 30.0}) {
      for (const int links : {1, 5}) {
        Points p = Points::Zero(links + 1, dim);
        Eigen::VectorXd dir = Eigen::VectorXd::Zero(dim);
        dir[0] = 0.6;
        dir[1] = 0.8;
        const double length = 0.01;
        for (int i = 1; i <= links; ++i) p.row(i) = p.row(i - 1) - length * dir.transpose();
        Chain chain = MakeChain(p);
        const Stepper stepper = MakeStepper(Method::kTractrix, chain);
        double worst = 0.0;
        for (const double sign : {1.0, -1.0}) {
          for (int s = 0; s < 40; ++s) {
            const Eigen::VectorXd target =
                chain.points.row(0).transpose() + sign * step_over_length * length * dir;
            MoveLeader(stepper, target, 1, &chain.points);
            worst = std::fmax(worst, MaxRelativeLengthError(chain));
          }
        }
        EXPECT_LT(worst, 1e-12) << dim << "D, " << links << " links, steps of " << step_over_length
                                << " L";
      }
    }
  }
}

// (b) The trailing end is never faster than the leading end: in every step, point i moves no
// farther than point i-1. Random curved chains, random steps up to 2 link lengths.
TEST(MoveLeaderInvariantTest, NoPointMovesFartherThanThePointAheadOfIt) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (const int dim : {2, 3}) {
    for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
      Chain chain = CurvedChain(dim, 20, 1.0, 0.35);
      const Stepper stepper = MakeStepper(method, chain);
      int violations = 0;
      std::string example;
      for (int s = 0; s < 2000; ++s) {
        Eigen::VectorXd d(dim);
        for (int k = 0; k < dim; ++k) d[k] = uniform(rng);
        // Mostly small steps, some up to 2 link lengths (link length ~0.35).
        d *= (s % 10 == 0 ? 0.7 : 0.05);
        const Points before = chain.points;
        MoveLeader(stepper, before.row(0).transpose() + d, 1, &chain.points);
        const Eigen::VectorXd moved = (chain.points - before).rowwise().norm();
        const double scale = before.cwiseAbs().maxCoeff() + chain.points.cwiseAbs().maxCoeff();
        for (int i = 1; i <= chain.num_links(); ++i) {
          const double slack = 4 * kEps * (moved[i - 1] + chain.lengths[i - 1] + scale);
          if (moved[i] > moved[i - 1] + slack) {
            if (violations++ == 0) {
              example = "step " + std::to_string(s) + ", point " + std::to_string(i) + ": " +
                        Str(moved[i]) + " > " + Str(moved[i - 1]);
            }
          }
        }
      }
      EXPECT_EQ(violations, 0) << dim << "D " << MethodName(method) << "; first: " << example;
    }
  }
}

// (c) The motion dies out along the chain: the distance travelled by each point, summed over
// many small steps of a curved leader path, does not increase from the leading to the
// trailing end.
TEST(MoveLeaderInvariantTest, PathLengthDoesNotIncreaseAlongTheChain) {
  for (const int dim : {2, 3}) {
    for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
      Chain chain = CurvedChain(dim, 30, 1.0, 0.2);
      const Stepper stepper = MakeStepper(method, chain);
      const Eigen::VectorXd start = chain.points.row(0).transpose();
      Eigen::VectorXd path = Eigen::VectorXd::Zero(chain.num_links() + 1);
      for (int s = 1; s <= 3000; ++s) {
        const double t = 1e-3 * s;
        Eigen::VectorXd target = start;
        target[0] += 2.0 * std::sin(2.0 * t);
        target[1] += 1.5 * (1.0 - std::cos(3.0 * t));
        if (dim == 3) target[2] += 0.5 * t;
        const Points before = chain.points;
        MoveLeader(stepper, target, 1, &chain.points);
        path += (chain.points - before).rowwise().norm();
      }
      for (int i = 1; i <= chain.num_links(); ++i) {
        EXPECT_LE(path[i], path[i - 1] * (1 + 1e-12))
            << dim << "D " << MethodName(method) << ", point " << i;
      }
      // It really dies out, not merely stays level.
      EXPECT_LT(path[chain.num_links()], 0.9 * path[0]) << dim << "D " << MethodName(method);
      std::cout << "[ measured ] " << dim << "D " << MethodName(method)
                << ": path length of point 0, 10, 20, 30: " << Str(path[0]) << " " << Str(path[10])
                << " " << Str(path[20]) << " " << Str(path[30]) << "\n";
    }
  }
}

// (d) A long straight pull (50 chain lengths) aligns every link with the pull (paper eq. 24).
TEST(MoveLeaderInvariantTest, LongStraightPullAlignsEveryLink) {
  for (const int dim : {2, 3}) {
    for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
      Chain chain = CurvedChain(dim, 12, 1.0, 0.45);
      const double chain_length = chain.lengths.sum();
      const Stepper stepper = MakeStepper(method, chain);
      Eigen::VectorXd dir(dim);
      dir.setConstant(1.0);
      dir[0] = -2.0;  // a pull direction that is not along the chain's start
      dir.normalize();
      const Points pull =
          scenes::StraightPull(chain.points.row(0).transpose(), dir, 50.0 * chain_length, 1000);
      for (Eigen::Index s = 0; s < pull.rows(); ++s) {
        MoveLeader(stepper, pull.row(s).transpose(), 1, &chain.points);
      }
      for (int i = 1; i <= chain.num_links(); ++i) {
        const Eigen::VectorXd link = (chain.points.row(i - 1) - chain.points.row(i)).transpose();
        const double along = link.dot(dir);
        const double angle = std::atan2((link - along * dir).norm(), along);
        EXPECT_LT(angle, 1e-6) << dim << "D " << MethodName(method) << ", link " << i;
      }
      EXPECT_LT(MaxRelativeLengthError(chain), 1e-13);
    }
  }
}

// ----- Convergence --------------------------------------------------------------------------

// (a) One link: follow-the-leader with k sub-steps converges to the exact tractrix step with
// order 1.
TEST(ConvergenceTest, FollowTheLeaderSubstepsConvergeToTheTractrixStepWithOrderOne) {
  for (const int dim : {2, 3}) {
    // Pulling, sideways and pushing moves of one link length.
    for (const double angle : {2.5, 1.6, 0.7}) {
      Points p = Points::Zero(2, dim);
      p(1, 0) = std::cos(angle);
      p(1, 1) = std::sin(angle);
      if (dim == 3) p(1, 2) = 0.3;
      const Chain chain = MakeChain(p);
      Eigen::VectorXd target = Eigen::VectorXd::Zero(dim);
      target[0] = chain.lengths[0];
      Eigen::VectorXd exact;
      if (dim == 2) {
        exact = TractrixStep(Eigen::Vector2d(p.row(0).transpose()), Eigen::Vector2d(target),
                             Eigen::Vector2d(p.row(1).transpose()), chain.lengths[0]);
      } else {
        exact = TractrixStep(Eigen::Vector3d(p.row(0).transpose()), Eigen::Vector3d(target),
                             Eigen::Vector3d(p.row(1).transpose()), chain.lengths[0]);
      }
      std::vector<double> errors;
      for (int k = 16; k <= 4096; k *= 2) {
        Chain ftl = chain;
        MoveLeader(Method::kFollowTheLeader, target, k, &ftl);
        errors.push_back((ftl.points.row(1).transpose() - exact).norm());
      }
      const std::vector<double> orders = ObservedOrders(errors);
      for (const double q : orders) {
        EXPECT_GE(q, 0.9) << dim << "D, angle " << angle << ": orders " << Join(orders);
        EXPECT_LE(q, 1.1) << dim << "D, angle " << angle << ": orders " << Join(orders);
      }
      std::cout << "[ measured ] one link, " << dim << "D, angle " << angle
                << ": FTL error at k = 16 .. 4096: " << Join(errors) << "; orders " << Join(orders)
                << "\n";
    }
  }
}

// (b) A curved 10-link chain whose leading end follows a polyline of about one chain length:
// multi-step tractrix and multi-step follow-the-leader both converge to the continuous motion
// (the ODE reference of the whole chain); tractrix with order 2, follow-the-leader with order 1.
TEST(ConvergenceTest, ChainConvergesToTheContinuousMotion) {
  for (const int dim : {2, 3}) {
    const Chain chain = CurvedChain(dim, 10, 0.5, 0.3);
    const double chain_length = chain.lengths.sum();
    // Three straight pieces, total ~1.1 chain lengths, turning left then right.
    Points targets(3, dim);
    const Eigen::VectorXd start = chain.points.row(0).transpose();
    targets.row(0) = start.transpose();
    targets(0, 0) += 0.5 * chain_length;
    targets.row(1) = targets.row(0);
    targets(1, 1) += 0.4 * chain_length;
    targets.row(2) = targets.row(1);
    targets(2, 0) += 0.2 * chain_length;
    targets(2, 1) -= 0.1 * chain_length;
    if (dim == 3) {
      targets(1, 2) += 0.2 * chain_length;
      targets(2, 2) += 0.1 * chain_length;
    }
    const Points exact = reference::ReferenceChainMotion(chain.points, targets);
    ASSERT_LT(std::fabs((exact.row(9) - exact.row(10)).norm() - chain.lengths[9]), 1e-11)
        << "the ODE reference keeps lengths";
    for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
      std::vector<double> errors;
      std::vector<int> ks;
      for (int k = 4; k <= 512; k *= 2) {
        const Stepper stepper = MakeStepper(method, chain);
        Points points = chain.points;
        for (Eigen::Index s = 0; s < targets.rows(); ++s) {
          MoveLeader(stepper, targets.row(s).transpose(), k, &points);
        }
        errors.push_back(MaxDistance(points, exact));
        ks.push_back(k);
      }
      const std::vector<double> orders = ObservedOrders(errors);
      // The first doublings are pre-asymptotic; judge the orders from k >= 16.
      const double expected = MethodOrder(method);
      for (size_t j = 2; j < orders.size(); ++j) {
        EXPECT_GE(orders[j], expected - 0.15) << dim << "D " << MethodName(method)
                                              << ", k = " << ks[j] << ": orders " << Join(orders);
        EXPECT_LE(orders[j], expected + 0.15) << dim << "D " << MethodName(method)
                                              << ", k = " << ks[j] << ": orders " << Join(orders);
      }
      // And they do converge to the continuous motion, not to something else.
      EXPECT_LT(errors.back(), method == Method::kTractrix ? 3e-6 : 3e-3);
      std::cout << "[ measured ] 10-link chain, " << dim << "D " << MethodName(method)
                << ": max point error vs ODE at k = 4 .. 512 sub-steps per piece: " << Join(errors)
                << "; observed orders " << Join(orders) << "\n";
      ::testing::Test::RecordProperty(std::to_string(dim) + "D_" + MethodName(method) + "_orders",
                                      Join(orders));
    }
  }
}

}  // namespace
}  // namespace flexkin
