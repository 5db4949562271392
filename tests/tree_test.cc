// Trees driven at one point (flexkin/tree.h). The references are the chain's own sweep
// (internal::SweepsScalar, which MoveLeader runs): a link's step depends only on how its leading
// end moved, so a path driven at point 0 must move as the chain, and every branch of any tree as
// the chain from the driven point along it, bit for bit.
#include "flexkin/tree.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "chain/substep.h"
#include "flexkin/error.h"
#include "flexkin/link_step.h"
#include "scenes/scenes.h"
#include "sequential/sweep.h"
#include "sequential/tree_sweep.h"

namespace flexkin {
namespace {

using scenes::RandomTree;

// The points from `from` to `to` along the tree (the unique path between them).
std::vector<int> PathBetween(const std::vector<int>& parents, int from, int to) {
  std::vector<int> up_from{from}, up_to{to};
  for (int p = from; parents[p] >= 0; p = parents[p]) up_from.push_back(parents[p]);
  for (int p = to; parents[p] >= 0; p = parents[p]) up_to.push_back(parents[p]);
  // Drop the common ancestors but the lowest one.
  while (up_from.size() > 1 && up_to.size() > 1 &&
         up_from[up_from.size() - 2] == up_to[up_to.size() - 2]) {
    up_from.pop_back();
    up_to.pop_back();
  }
  std::vector<int> path(up_from.begin(), up_from.end());
  for (auto it = up_to.rbegin() + 1; it != up_to.rend(); ++it) path.push_back(*it);
  return path;
}

// The chain sweep's motion of the points `path` (path[0] the driven point) under the same
// sub-step points of the driven point: the reference.
Points ChainAlong(const Points& start, const std::vector<int>& path, Method method,
                  const Eigen::VectorXd& target, int substeps) {
  const int dim = static_cast<int>(start.cols());
  Points pts(path.size(), dim);
  for (size_t i = 0; i < path.size(); ++i) pts.row(i) = start.row(path[i]);
  std::vector<double> lengths, inv;
  for (size_t i = 1; i < path.size(); ++i) {
    lengths.push_back((pts.row(i) - pts.row(i - 1)).norm());
    inv.push_back(1.0 / lengths.back());
  }
  std::vector<double> heads;
  for (int j = 1; j <= substeps; ++j) {
    for (int k = 0; k < dim; ++k) {
      heads.push_back(internal::SubstepHead(start(path[0], k), target[k], j, substeps));
    }
  }
  internal::SweepsScalar(method, dim, heads.data(), substeps, lengths.data(), inv.data(),
                         static_cast<int>(lengths.size()), pts.data());
  return pts;
}

TEST(TreeTest, APathDrivenAtItsFirstPointMovesAsTheChain) {
  for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
    for (const int dim : {2, 3}) {
      std::mt19937 rng(3);
      std::normal_distribution<double> normal;
      Points points(41, dim);
      points.row(0).setZero();
      for (int i = 1; i <= 40; ++i) {
        Eigen::VectorXd d(dim);
        for (int k = 0; k < dim; ++k) d[k] = normal(rng);
        points.row(i) = points.row(i - 1) + 0.3 * d.transpose();
      }
      const Chain chain = MakeChain(points);
      const TreeStepper stepper = MakeTreeStepper(method, TreeOfChain(chain), 0);
      Points tree_points = chain.points;
      Chain moved = chain;
      const Stepper chain_stepper = MakeStepper(method, chain);
      for (int step = 0; step < 50; ++step) {
        Eigen::VectorXd target(dim);
        for (int k = 0; k < dim; ++k) target[k] = tree_points(0, k) + 0.2 * normal(rng);
        const int substeps = 1 + step % 3;  // few sub-steps: MoveLeader's one-pass sweep
        MoveTreePoint(stepper, target, substeps, &tree_points);
        MoveLeader(chain_stepper, target, substeps, &moved.points);
        ASSERT_TRUE(tree_points == moved.points)
            << MethodName(method) << " " << dim << "D, step " << step;
      }
    }
  }
}

TEST(TreeTest, EveryBranchMovesAsTheChainFromTheDrivenPointAlongIt) {
  for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
    for (unsigned seed = 1; seed <= 6; ++seed) {
      const int dim = seed % 2 ? 3 : 2;
      const Tree tree = RandomTree(60, dim, seed);
      std::mt19937 rng(seed);
      const int driven = std::uniform_int_distribution<int>(0, 59)(rng);
      const TreeStepper stepper = MakeTreeStepper(method, tree, driven);
      ASSERT_EQ(stepper.lead.size(), 59u);
      Eigen::VectorXd target = tree.points.row(driven).transpose();
      target[0] += 1.3;
      target[1] -= 0.4;
      Points moved = tree.points;
      // 3 sub-steps, fewer than the lanes of any SIMD wavefront (4 with AVX2, 8 with AVX-512),
      // which takes groups of that many and agrees with the one-pass sweep to rounding (tested
      // below): here every machine runs the one-pass sweep, the scalar chain's bit for bit.
      MoveTreePoint(stepper, target, 3, &moved);
      // Every point is on the path to some leaf: checking each leaf's path checks every point.
      std::vector<int> degree(60, 0);
      for (int i = 0; i < 60; ++i) {
        if (tree.parents[i] >= 0) ++degree[i], ++degree[tree.parents[i]];
      }
      int leaves = 0;
      for (int leaf = 0; leaf < 60; ++leaf) {
        if (degree[leaf] != 1 || leaf == driven) continue;
        ++leaves;
        const std::vector<int> path = PathBetween(tree.parents, driven, leaf);
        const Points reference = ChainAlong(tree.points, path, method, target, 3);
        for (size_t i = 0; i < path.size(); ++i) {
          ASSERT_TRUE(moved.row(path[i]) == reference.row(i))
              << MethodName(method) << " seed " << seed << ": point " << path[i]
              << " on the way to leaf " << leaf;
        }
      }
      EXPECT_GT(leaves, 10);
    }
  }
}

// The SIMD wavefront (every instruction set this CPU has) against the branches' one-pass chain
// sweeps: the same motion up to the rounding of the vector exp (as the chain's wavefront), on
// random trees driven at random points, with the sub-steps of a move split into the wavefront's
// groups and the one-pass sweep's rest (MoveTreePoint), and through the engines' entry points.
TEST(TreeTest, TheWavefrontMovesAsTheOnePassSweep) {
  const std::vector<internal::TreeWavefrontEngine> engines = internal::AvailableTreeWavefronts();
  if (engines.empty()) GTEST_SKIP() << "no SIMD wavefront on this CPU (it has no AVX2 and FMA)";
  for (const internal::TreeWavefrontEngine& engine : engines) {
    for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
      for (unsigned seed = 1; seed <= 4; ++seed) {
        const int dim = seed % 2 ? 3 : 2;
        const Tree tree = RandomTree(50, dim, 100 + seed);
        const int driven = static_cast<int>(seed * 7 % 50);
        const TreeStepper stepper = MakeTreeStepper(method, tree, driven);
        Eigen::VectorXd target = tree.points.row(driven).transpose();
        target[0] -= 2.1;
        target[1] += 0.7;
        // 24 sub-steps: 3 groups of 8 lanes (AVX-512) or 6 of 4 (AVX2), none left over.
        constexpr int kSubsteps = 24;
        std::vector<double> heads;
        for (int j = 1; j <= kSubsteps; ++j) {
          for (int k = 0; k < dim; ++k) {
            heads.push_back(internal::SubstepHead(tree.points(driven, k), target[k], j, kSubsteps));
          }
        }
        const internal::TreeLinks links = internal::LinksOf(stepper);
        Points simd = tree.points;
        // Every sub-step by the engine itself (its count of sweeps done).
        ASSERT_EQ(engine.fn(method, dim, heads.data(), kSubsteps, links, simd.data()), kSubsteps);
        Points moved = tree.points;  // MoveTreePoint: groups, then the one-pass rest
        MoveTreePoint(stepper, target, kSubsteps + 3, &moved);
        std::vector<int> degree(50, 0);
        for (int i = 0; i < 50; ++i) {
          if (tree.parents[i] >= 0) ++degree[i], ++degree[tree.parents[i]];
        }
        double worst = 0.0, worst_move = 0.0;
        for (int leaf = 0; leaf < 50; ++leaf) {
          if (degree[leaf] != 1 || leaf == driven) continue;
          const std::vector<int> path = PathBetween(tree.parents, driven, leaf);
          const Points reference = ChainAlong(tree.points, path, method, target, kSubsteps);
          const Points reference_move =
              ChainAlong(tree.points, path, method, target, kSubsteps + 3);
          for (size_t i = 0; i < path.size(); ++i) {
            worst = std::fmax(worst, (simd.row(path[i]) - reference.row(i)).cwiseAbs().maxCoeff());
            worst_move = std::fmax(
                worst_move, (moved.row(path[i]) - reference_move.row(i)).cwiseAbs().maxCoeff());
          }
        }
        const std::string what =
            std::string(engine.name) + " " + MethodName(method) + " seed " + std::to_string(seed);
        EXPECT_LE(worst, 1e-12) << what;  // the tree spans a few units
        EXPECT_LE(worst_move, 1e-12) << what;
        EXPECT_LT(MaxTreeLengthError(stepper, simd), 1e-13) << what;
      }
    }
  }
}

// The whole-tree rules: a path driven at point 0 moves as MoveLeader moves the chain, bit for bit;
// on a tree, min_rotation translates it with the driven point, and min_joint_angle steps each link
// from the driven point by the tractrix and carries the subtree behind it rigidly.
TEST(TreeTest, TheWholeTreeRulesMoveAPathAsTheChainAndATreeRigidlyBehindItsFirstLinks) {
  for (const Method method : {Method::kMinRotation, Method::kMinJointAngle}) {
    for (const int dim : {2, 3}) {
      Points pts = Points::Zero(12, dim);
      for (int i = 1; i < 12; ++i) {
        pts.row(i) = pts.row(i - 1);
        pts(i, 0) += 0.3;
        pts(i, 1) += 0.1 * std::sin(i);
      }
      const Chain chain = MakeChain(pts);
      const TreeStepper stepper = MakeTreeStepper(method, TreeOfChain(chain), 0);
      Chain moved = chain;
      Points tree_points = chain.points;
      const Stepper chain_stepper = MakeStepper(method, chain);
      for (int step = 0; step < 20; ++step) {
        Eigen::VectorXd target = tree_points.row(0).transpose();
        target[0] += 0.05 * std::cos(step);
        target[1] += 0.07;
        MoveTreePoint(stepper, target, 3, &tree_points);
        MoveLeader(chain_stepper, target, 3, &moved.points);
        ASSERT_TRUE(tree_points == moved.points) << MethodName(method) << " " << dim << "D";
      }
    }
  }
  const Tree tree = RandomTree(40, 3, 21);
  const int driven = 6;
  Eigen::VectorXd target = tree.points.row(driven).transpose();
  target += Eigen::Vector3d(0.4, -0.3, 0.2);
  {
    const TreeStepper stepper = MakeTreeStepper(Method::kMinRotation, tree, driven);
    Points moved = tree.points;
    MoveTreePoint(stepper, target, 5, &moved);
    const Eigen::RowVectorXd shift = moved.row(0) - tree.points.row(0);
    EXPECT_LT(((moved - tree.points).rowwise() - shift).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_LT((shift.transpose() - Eigen::Vector3d(0.4, -0.3, 0.2)).norm(), 1e-15);
  }
  const TreeStepper stepper = MakeTreeStepper(Method::kMinJointAngle, tree, driven);
  Points moved = tree.points;
  MoveTreePoint(stepper, target, 1, &moved);
  // The first links' trailing ends by the tractrix step; every point behind one of them at the
  // same distances from the others behind it and from that trailing end (a rigid motion).
  std::vector<int> first_of(stepper.lead.size());
  for (size_t j = 0; j < stepper.lead.size(); ++j) {
    first_of[j] = stepper.source[j] < 0 ? static_cast<int>(j) : first_of[stepper.source[j]];
  }
  int checked = 0;
  for (size_t j = 0; j < stepper.lead.size(); ++j) {
    const int b = stepper.tail[j], f = stepper.tail[first_of[j]];
    if (stepper.source[j] < 0) {
      const Eigen::Vector3d expected = TractrixStep(
          Eigen::Vector3d(tree.points.row(driven).transpose()), Eigen::Vector3d(target),
          Eigen::Vector3d(tree.points.row(b).transpose()), stepper.lengths[j]);
      EXPECT_LT((moved.row(b).transpose() - expected).norm(), 1e-14);
      continue;
    }
    const double before = (tree.points.row(b) - tree.points.row(f)).norm();
    EXPECT_NEAR((moved.row(b) - moved.row(f)).norm(), before, 1e-14);
    ++checked;
  }
  EXPECT_GT(checked, 20);
  EXPECT_LT(MaxTreeLengthError(stepper, moved), 1e-14);
}

// Moves near the largest doubles: every engine's result finite.
TEST(TreeTest, MovesNearTheLargestDoublesStayFinite) {
  const Tree tree = RandomTree(30, 2, 4);
  for (const internal::TreeWavefrontEngine& engine : internal::AvailableTreeWavefronts()) {
    for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
      for (const double far : {1e300, 1e155, -1e308}) {
        const TreeStepper stepper = MakeTreeStepper(method, tree, 3);
        std::vector<double> heads;
        for (int s = 1; s <= 32; ++s)
          heads.push_back(far * (s / 32.0)), heads.push_back(-far * (s / 32.0));
        Points pts = tree.points;
        engine.fn(method, 2, heads.data(), 32, internal::LinksOf(stepper), pts.data());
        EXPECT_TRUE(pts.allFinite()) << engine.name << " " << MethodName(method) << " " << far;
      }
    }
  }
  for (const Method method : {Method::kTractrix, Method::kFollowTheLeader, Method::kMinRotation,
                              Method::kMinJointAngle}) {
    const TreeStepper stepper = MakeTreeStepper(method, tree, 3);
    Points pts = tree.points;
    MoveTreePoint(stepper, Eigen::Vector2d(1e300, -1e300), 19, &pts);
    EXPECT_TRUE(pts.allFinite()) << MethodName(method);
  }
}

TEST(TreeTest, AStillDrivenPointLeavesTheTreeExactlyInPlace) {
  const Tree tree = RandomTree(30, 3, 9);
  for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
    const TreeStepper stepper = MakeTreeStepper(method, tree, 7);
    Points moved = tree.points;
    MoveTreePoint(stepper, tree.points.row(7).transpose(), 3, &moved);
    EXPECT_TRUE(moved == tree.points) << MethodName(method);
  }
}

// A binary tree of depth 7 (255 points) driven at an interior point along a wandering path,
// 4,000 moves of 254 links (about a million link steps): every length to rounding.
TEST(TreeTest, LengthsStayToRoundingOverAMillionLinkSteps) {
  Tree tree;
  const int count = 255;
  tree.points = Points::Zero(count, 3);
  tree.parents.assign(count, -1);
  for (int i = 1; i < count; ++i) {
    const int p = (i - 1) / 2;
    const int depth = static_cast<int>(std::log2(i + 1));
    const double side = (i % 2 ? 1.0 : -1.0) * std::pow(0.7, depth);
    tree.parents[i] = p;
    tree.points.row(i) =
        tree.points.row(p) + Eigen::RowVector3d(side, 0.3, 0.1 * depth).normalized() * 0.5;
  }
  for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
    const TreeStepper stepper = MakeTreeStepper(method, tree, 5);
    Points pts = tree.points;
    const Eigen::Vector3d origin = pts.row(5).transpose();
    double worst = 0.0;
    for (int s = 1; s <= 4000; ++s) {
      const double t = 2e-3 * s;
      const Eigen::Vector3d target =
          origin + 2.0 * Eigen::Vector3d(std::sin(1.3 * t) + 0.5 * std::sin(3.7 * t),
                                         std::cos(1.1 * t) - 1.0, 0.6 * std::sin(0.7 * t));
      MoveTreePoint(stepper, target, 1, &pts);
      if (s % 500 == 0) worst = std::fmax(worst, MaxTreeLengthError(stepper, pts));
    }
    EXPECT_TRUE(pts.allFinite());
    EXPECT_LT(worst, 1e-12) << MethodName(method);
    EXPECT_GT(MaxTreeLengthError(stepper, pts), 0.0);  // measured, not a copy of the lengths
  }
}

// What each bad tree is told: the field, and a part of the message.
TEST(TreeTest, BadTreesAreRefusedNamingTheField) {
  const auto refused = [](const Tree& tree, const std::string& field, const std::string& part) {
    try {
      ValidateTree(tree);
      ADD_FAILURE() << "accepted; expected " << field;
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), field) << e.what();
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  Tree good = RandomTree(6, 2, 1);  // parents -1, then earlier points
  ValidateTree(good);
  Tree t = good;
  t.parents.pop_back();
  refused(t, "tree.parents", "5 entries for 6 points");
  t = good;
  t.parents[3] = -1;
  refused(t, "tree.parents[3]", "point 0 is the root already");
  t = good;
  t.parents[4] = 6;
  refused(t, "tree.parents[4]", "expected -1 (the root) or a point 0..5 other than 4");
  t = good;
  t.parents[2] = 2;
  refused(t, "tree.parents[2]", "other than 2");
  t = good;
  t.parents[0] = 5;  // no root: 0 -> 5 -> ... -> 0
  refused(t, "tree.parents", "has no root");
  t.parents = {-1, 0, 3, 2, 1, 4};  // 2 and 3 hang from each other
  refused(t, "tree.parents[2]", "the cycle 2 -> 3 -> 2");
  t = good;
  t.points.row(4) = t.points.row(t.parents[4]);
  refused(t, "tree.points[4]", "from its parent point");
  t = good;
  t.points(3, 1) = std::nan("");
  refused(t, "tree.points[3][1]", "not a finite number");
  t = good;
  t.points = Points::Zero(6, 4);
  refused(t, "tree.points", "expected 2 (planar) or 3 (spatial)");
}

TEST(TreeTest, BadStepperAndMoveArgumentsAreRefused) {
  const Tree tree = RandomTree(8, 3, 2);
  try {
    MakeTreeStepper(Method::kTractrix, tree, 8);
    ADD_FAILURE() << "driven point 8 accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "driven");
  }
  for (const Method method : {Method::kOverall, Method::kFollowPath}) {
    try {
      MakeTreeStepper(method, tree, 0);
      ADD_FAILURE() << MethodName(method) << " accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), "method");
      EXPECT_NE(std::string(e.what()).find("\"tractrix\""), std::string::npos) << e.what();
    }
  }
  const TreeStepper stepper = MakeTreeStepper(Method::kTractrix, tree, 3);
  Points pts = tree.points;
  EXPECT_THROW(MoveTreePoint(stepper, Eigen::Vector2d(0, 0), 1, &pts), InputError);
  EXPECT_THROW(MoveTreePoint(stepper, Eigen::Vector3d(0, NAN, 0), 1, &pts), InputError);
  EXPECT_THROW(MoveTreePoint(stepper, Eigen::Vector3d(0, 0, 0), 0, &pts), InputError);
  Points wrong = Points::Zero(7, 3);
  EXPECT_THROW(MoveTreePoint(stepper, Eigen::Vector3d(0, 0, 0), 1, &wrong), InputError);
  EXPECT_TRUE(pts == tree.points);  // nothing moved by a refused call
}

}  // namespace
}  // namespace flexkin
