// Several targets and fixed points on a tree (flexkin/tree.h, ReachTargets). The targets are
// reachable by construction (the points of another configuration of the same tree, with the same
// root and lengths), so the passes must reach them to the tolerance; a path with one target and
// nothing fixed must move as MoveTreePoint moves it, bit for bit; a target out of reach is
// reported with its residual, which for a straight pull on a chain is known in closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/tree.h"
#include "flexkin/tree_overall.h"
#include "scenes/scenes.h"
#include "tree_test_util.h"

namespace flexkin {
namespace {

using scenes::RandomTree;
using scenes::TreeKind;

using test_util::Bent;
using test_util::Leaves;

Points Rows(const Points& points, const std::vector<int>& which) {
  Points out(which.size(), points.cols());
  for (size_t k = 0; k < which.size(); ++k) out.row(k) = points.row(which[k]);
  return out;
}

double Residual(const Points& points, const std::vector<int>& which, const Points& targets) {
  return (Rows(points, which) - targets).rowwise().norm().maxCoeff();
}

struct Variant {
  Method method;
  BranchRule rule;
};
const Variant kVariants[] = {{Method::kTractrix, BranchRule::kCentroid},
                             {Method::kTractrix, BranchRule::kKeepLinks},
                             {Method::kFollowTheLeader, BranchRule::kCentroid},
                             {Method::kFollowTheLeader, BranchRule::kKeepLinks}};

ReachOptions OptionsOf(const Variant& v) {
  ReachOptions options;
  options.method = v.method;
  options.branch_rule = v.rule;
  return options;
}

std::string Name(const Variant& v) { return std::string(NameOf(v.method)) + "/" + NameOf(v.rule); }

// The shapes (scenes::TreeShape): a chain of 10 links, two arms on a shoulder, a binary
// tree of depth 10 (2047 points), their tips driven (scenes::TreeTips); a fixed base. The targets
// are the points of a bent configuration (every link turned by up to 0.25 rad): reachable.
Tree TwoArms(int dim = 2);

TEST(TreeReachTest, ReachesReachableTargetsOnTheBenchmarkShapesToTheTolerance) {
  struct Shape {
    const char* name;
    Tree tree;
    std::vector<int> targets;
  };
  int cases = 0;
  for (int dim : {2, 3}) {
    std::vector<Shape> shapes;
    for (TreeKind kind : {TreeKind::kChain10, TreeKind::kTwoArms, TreeKind::kBinary10}) {
      const char* names[] = {"chain", "two arms", "binary"};
      shapes.push_back(
          {names[static_cast<int>(kind)], scenes::TreeShape(kind, dim), scenes::TreeTips(kind)});
    }
    shapes.push_back({"arms on a spine", TwoArms(dim), {5, 8}});
    for (const Shape& shape : shapes) {
      for (unsigned seed = 1; seed <= 3; ++seed) {
        const Points targets = Rows(Bent(shape.tree, 0.25, seed), shape.targets);
        for (const Variant& v : kVariants) {
          const TreeReacher reacher =
              MakeTreeReacher(shape.tree, shape.targets, {0}, {}, OptionsOf(v));
          Points points = shape.tree.points;
          const ReachReport report = ReachTargets(reacher, targets, &points);
          SCOPED_TRACE(Name(v) + " " + shape.name + " dim " + std::to_string(dim) + " seed " +
                       std::to_string(seed));
          EXPECT_TRUE(report.reached) << "residual " << report.residual << " in " << report.passes;
          EXPECT_LE(report.residual, 1e-10);
          // The report's residual is the points' own, scaled by the longest link.
          EXPECT_LE(Residual(points, shape.targets, targets), 1e-10 * reacher.longest_link);
          EXPECT_EQ((points.row(0) - shape.tree.points.row(0)).norm(), 0.0);  // the base, exactly
          EXPECT_LE(MaxTreeLengthError(MakeTreeStepper(Method::kTractrix, shape.tree, 0), points),
                    1e-13);
          ++cases;
        }
      }
    }
  }
  EXPECT_EQ(cases, 96);
}

// One case of the random trees: a tree of 40 points (root 0, fixed), its first five leaves driven
// to a bent configuration of the same tree (reachable), the passes' points after ReachTargets.
struct RandomCase {
  Tree tree;
  std::vector<int> leaves;
  Points targets;
  TreeReacher reacher;
  Points points;
  ReachReport report;
  std::string name;
};

// Calls `check` on each of the 48 cases: 2D and 3D, seeds 1 to 6, every variant.
void ForEachRandomCase(const std::function<void(RandomCase&)>& check) {
  for (int dim : {2, 3}) {
    for (unsigned seed = 1; seed <= 6; ++seed) {
      RandomCase c;
      c.tree = RandomTree(40, dim, seed);
      c.leaves = Leaves(c.tree, 5);
      c.targets = Rows(Bent(c.tree, 0.25, 100 + seed), c.leaves);
      for (const Variant& v : kVariants) {
        c.reacher = MakeTreeReacher(c.tree, c.leaves, {0}, {}, OptionsOf(v));
        c.points = c.tree.points;
        c.report = ReachTargets(c.reacher, c.targets, &c.points);
        c.name = Name(v) + " dim " + std::to_string(dim) + " seed " + std::to_string(seed);
        SCOPED_TRACE(c.name);
        check(c);
      }
    }
  }
}

// Random trees of 40 points with five leaves driven: the passes are not proven to converge on a
// tree (nor are FABRIK's), and on some of these they stall (docs/trees.md gives the count). What
// must hold in every case: the report says which, its residual is the points' own, the lengths
// are kept and the base is exactly fixed.
TEST(TreeReachTest, ReportsTruthfullyOnRandomTrees) {
  int reached = 0, cases = 0;
  ForEachRandomCase([&](RandomCase& c) {
    const double own = Residual(c.points, c.leaves, c.targets) / c.reacher.longest_link;
    EXPECT_NEAR(c.report.residual, own, 1e-15 * (1 + own));
    EXPECT_EQ(c.report.reached, own <= 1e-10);
    EXPECT_EQ((c.points.row(0) - c.tree.points.row(0)).norm(), 0.0);
    EXPECT_LE(MaxTreeLengthError(MakeTreeStepper(Method::kTractrix, c.tree, 0), c.points), 1e-13);
    if (!c.report.reached) {
      std::printf("stalled: %s, residual %.3g after %d passes\n", c.name.c_str(), c.report.residual,
                  c.report.passes);
    }
    reached += c.report.reached;
    ++cases;
  });
  EXPECT_EQ(cases, 48);
  std::printf("random trees: %d of %d reached to 1e-10\n", reached, cases);
  EXPECT_GE(reached, 32);  // 36 of 48 when this was written (docs/trees.md)
}

// The same cases finished (FinishTreeReach, tree_overall.h): a stalled case that Newton's least
// correction completes reaches the tolerance, its lengths kept to Newton's tolerance, the base
// exactly fixed, the correction of the order of the residual it removes; one it does not complete
// is left exactly as the passes left it, and so is a case the passes reached.
TEST(TreeReachTest, StalledPassesAreFinishedByTheLeastCorrection) {
  int reached = 0, finished = 0, cases = 0;
  double largest_ratio = 0.0;
  ForEachRandomCase([&](RandomCase& c) {
    const ReachReport& passes = c.report;
    const Points stalled = c.points;
    const ReachReport report = FinishTreeReach(c.reacher, c.targets, passes, &c.points);
    EXPECT_EQ(report.passes, passes.passes);
    if (!report.finished) {
      EXPECT_TRUE(c.points == stalled);  // untouched
      EXPECT_EQ(report.reached, passes.reached);
      EXPECT_EQ(report.residual, passes.residual);
      if (!passes.reached) {
        std::printf("not finished: %s, residual %.3g\n", c.name.c_str(), passes.residual);
      }
    } else {
      EXPECT_FALSE(passes.reached);
      EXPECT_TRUE(report.reached) << report.residual;
      EXPECT_LE(Residual(c.points, c.leaves, c.targets), 1e-10 * c.reacher.longest_link);
      EXPECT_EQ((c.points.row(0) - c.tree.points.row(0)).norm(), 0.0);
      EXPECT_LE(MaxTreeLengthError(MakeTreeStepper(Method::kTractrix, c.tree, 0), c.points), 1e-12);
      const double moved = (c.points - stalled).rowwise().norm().maxCoeff();
      const double ratio = moved / (passes.residual * c.reacher.longest_link);
      largest_ratio = std::max(largest_ratio, ratio);
      EXPECT_LE(ratio, 50.0);
      ++finished;
    }
    reached += report.reached;
    ++cases;
  });
  EXPECT_EQ(cases, 48);
  std::printf(
      "random trees: %d of %d reached to 1e-10 with the finish (%d finished); the "
      "correction at most %.2f times the residual it removed\n",
      reached, cases, finished, largest_ratio);
  EXPECT_GE(reached, 44);  // 44 of 48 when this was written (docs/trees.md)
}

TEST(TreeReachTest, OneTargetAndNothingFixedMovesAsTheTreeDrivenAtThatPoint) {
  for (int dim : {2, 3}) {
    const Tree tree = RandomTree(30, dim, 7);
    for (Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
      for (int driven : {0, 11, 29}) {
        Eigen::VectorXd target = tree.points.row(driven).transpose();
        target[0] += 0.7;
        target[1] -= 0.4;
        ReachOptions options;
        options.method = method;
        Points reached = tree.points;
        const ReachReport report = ReachTargets(MakeTreeReacher(tree, {driven}, {}, {}, options),
                                                target.transpose(), &reached);
        Points moved = tree.points;
        MoveTreePoint(MakeTreeStepper(method, tree, driven), target, 1, &moved);
        EXPECT_EQ(report.passes, 1);
        EXPECT_TRUE(report.reached);
        EXPECT_EQ(report.residual, 0.0);
        EXPECT_TRUE(reached == moved) << "driven " << driven << ": largest difference "
                                      << (reached - moved).cwiseAbs().maxCoeff();
      }
    }
  }
}

// A straight chain of 10 unit links fixed at point 0, its tip pulled toward a point 13 away: out
// of reach by 3. The passes settle on the chain stretched toward the target; the residual is 3
// (of the longest link, 1) to the accuracy at which they stop.
TEST(TreeReachTest, ReportsTheResidualOfATargetOutOfReach) {
  Tree chain;
  chain.points = Points::Zero(11, 2);
  chain.parents.assign(11, -1);
  for (int i = 1; i <= 10; ++i) {
    chain.parents[i] = i - 1;
    chain.points.row(i) << std::cos(0.2 * i) + chain.points(i - 1, 0),
        std::sin(0.2 * i) + chain.points(i - 1, 1);
  }
  const Eigen::Vector2d target(5.0, 12.0);  // 13 from the base
  for (const Variant& v : kVariants) {
    ReachOptions options = OptionsOf(v);
    Points points = chain.points;
    const ReachReport report =
        ReachTargets(MakeTreeReacher(chain, {10}, {0}, {}, options), target.transpose(), &points);
    SCOPED_TRACE(Name(v));
    EXPECT_FALSE(report.reached);
    EXPECT_LT(report.passes, options.max_passes);  // settled, not run out
    EXPECT_NEAR(report.residual, 3.0, 1e-3);
    EXPECT_NEAR(report.residual, (points.row(10).transpose() - target).norm(), 1e-15);
    // Stretched: the tip 10 from the base, toward the target.
    EXPECT_NEAR(points.row(10).norm(), 10.0, 1e-3);
    EXPECT_LE(MaxTreeLengthError(MakeTreeStepper(Method::kTractrix, chain, 0), points), 1e-14);
  }
}

// Two arms of three links on a shoulder, on a trunk of two from a fixed base (the benchmark's
// shape): a Y. The targets move along circles in steps of 0.01; every frame starts from the last.
Tree TwoArms(int dim) {
  Tree t;
  t.points = Points::Zero(9, dim);
  t.points.leftCols(2) << 0, 0, 0, 1, 0, 2, 0.8, 2.3, 1.6, 2.0, 2.4, 2.2, -0.8, 2.3, -1.6, 2.0,
      -2.4, 2.2;
  if (dim == 3) t.points.col(2) << 0, 0, 0, 0.2, 0.3, 0.1, -0.1, 0.2, 0.3;
  t.parents = {-1, 0, 1, 2, 3, 4, 2, 6, 7};
  return t;
}

TEST(TreeReachTest, TheMotionIsContinuousFromFrameToFrame) {
  const Tree tree = TwoArms();
  const std::vector<int> hands = {5, 8};
  for (const Variant& v : kVariants) {
    const TreeReacher reacher = MakeTreeReacher(tree, hands, {0}, {}, OptionsOf(v));
    Points points = tree.points;
    double largest_jump = 0.0, largest_step = 0.0;
    int reached = 0;
    const int frames = 200;
    Points previous_targets = Rows(tree.points, hands);
    for (int f = 1; f <= frames; ++f) {
      Points targets = Rows(tree.points, hands);
      for (int k = 0; k < 2; ++k) {  // circles of radius 0.3, the hands reach all of them
        const double a = 2 * M_PI * f / frames;
        targets(k, 0) += 0.3 * (std::cos(a + k) - std::cos(double(k)));
        targets(k, 1) += 0.3 * (std::sin(a + k) - std::sin(double(k)));
      }
      const Points before = points;
      reached += ReachTargets(reacher, targets, &points).reached;
      largest_jump = std::max(largest_jump, (points - before).rowwise().norm().maxCoeff());
      largest_step =
          std::max(largest_step, (targets - previous_targets).rowwise().norm().maxCoeff());
      previous_targets = targets;
    }
    SCOPED_TRACE(Name(v));
    EXPECT_EQ(reached, frames);
    // No point jumps: a flip would move a hand's arm by a link's length (about 0.8) in a frame.
    EXPECT_LE(largest_jump, 5 * largest_step) << "targets move " << largest_step;
  }
}

// A Y from a fixed base whose two hands are pulled apart beyond reach: the heavier target is
// reached more nearly.
TEST(TreeReachTest, WeightsDecideBetweenTargetsThatConflict) {
  const Tree tree = TwoArms();
  Points targets(2, 2);
  targets << 4.0, 2.0, -4.0, 2.0;  // each 4 from the shoulder; the arms are about 2.5 long
  for (const Variant& v : kVariants) {
    ReachOptions options = OptionsOf(v);
    Points even = tree.points, heavy = tree.points;
    ReachTargets(MakeTreeReacher(tree, {5, 8}, {0}, {}, options), targets, &even);
    ReachTargets(MakeTreeReacher(tree, {5, 8}, {0}, {4.0, 1.0}, options), targets, &heavy);
    const double even_gap = (even.row(5) - targets.row(0)).norm();
    const double heavy_gap = (heavy.row(5) - targets.row(0)).norm();
    const double light_gap = (heavy.row(8) - targets.row(1)).norm();
    SCOPED_TRACE(Name(v));
    EXPECT_LT(heavy_gap, even_gap - 0.05);
    EXPECT_LT(heavy_gap, light_gap - 0.05);
  }
}

// A fixed sub-base: the shoulder held as well as the base; the hands reach targets of a bent
// configuration with the trunk unchanged.
TEST(TreeReachTest, HoldsFixedPointsBetweenTheTargets) {
  const Tree tree = TwoArms();
  Points goal = Bent(tree, 0.3, 5);
  goal.topRows(3) = tree.points.topRows(3);  // the trunk as it was
  for (int i = 3; i < 9; ++i) {              // the arms rebuilt from it, their links as bent
    const int p = tree.parents[i];
    const Eigen::RowVector2d dir = (Bent(tree, 0.3, 5).row(i) - Bent(tree, 0.3, 5).row(p));
    goal.row(i) = goal.row(p) + dir;
  }
  for (const Variant& v : kVariants) {
    ReachOptions options = OptionsOf(v);
    options.max_passes = 20000;
    const TreeReacher reacher = MakeTreeReacher(tree, {5, 8}, {0, 2}, {}, options);
    Points points = tree.points;
    const ReachReport report = ReachTargets(reacher, Rows(goal, {5, 8}), &points);
    SCOPED_TRACE(Name(v));
    EXPECT_TRUE(report.reached) << report.residual;
    EXPECT_LE((points.row(2) - tree.points.row(2)).norm(), 1e-10);
    EXPECT_LE(Residual(points, {5, 8}, Rows(goal, {5, 8})), 1e-10);
  }
}

std::string RefusalOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(TreeReachTest, RefusesBadInputNamingTheField) {
  const Tree tree = TwoArms();
  auto make = [&](std::vector<int> targets, std::vector<int> fixed, std::vector<double> weights,
                  ReachOptions options) {
    return [=] { MakeTreeReacher(tree, targets, fixed, weights, options); };
  };
  const ReachOptions plain;
  EXPECT_EQ(RefusalOf(make({}, {0}, {}, plain)),
            "targets: none given; at least one point must be driven");
  EXPECT_EQ(RefusalOf(make({5, 9}, {0}, {}, plain)),
            "targets[1]: value 9 is not valid; expected a point of the tree, 0..8");
  EXPECT_EQ(RefusalOf(make({5, 5}, {0}, {}, plain)),
            "targets[1]: is point 5, which targets[0] drives already; a point takes one target "
            "or is fixed");
  EXPECT_EQ(RefusalOf(make({5}, {0, 5}, {}, plain)),
            "fixed[1]: is point 5, which targets[0] drives already; a point takes one target or "
            "is fixed");
  EXPECT_EQ(RefusalOf(make({5, 8}, {0, -1}, {}, plain)),
            "fixed[1]: value -1 is not valid; expected a point of the tree, 0..8");
  EXPECT_NE(RefusalOf(make({5, 8}, {0}, {1.0}, plain)).find("weights: has 1 entries for 2"),
            std::string::npos);
  EXPECT_EQ(RefusalOf(make({5, 8}, {0}, {1.0, 0.0}, plain)),
            "weights[1]: value 0 is not valid; expected a finite number > 0");
  EXPECT_EQ(RefusalOf(make({5, 8}, {0}, {1.0, NAN}, plain)),
            "weights[1]: value nan is not valid; expected a finite number > 0");
  ReachOptions bad = plain;
  bad.method = Method::kOverall;
  EXPECT_EQ(RefusalOf(make({5}, {0}, {}, bad)),
            "method: value \"overall\" is not valid; expected \"tractrix\" or \"ftl\" (the rules "
            "of the passes)");
  bad = plain;
  bad.tolerance = 0.0;
  EXPECT_EQ(RefusalOf(make({5}, {0}, {}, bad)),
            "tolerance: value 0 is not valid; expected a finite number > 0 (of the longest link)");
  bad = plain;
  bad.max_passes = 0;
  EXPECT_EQ(RefusalOf(make({5}, {0}, {}, bad)),
            "max_passes: value 0 is not valid; expected an integer >= 1");
  Tree cycle = tree;
  cycle.parents[1] = 4;
  EXPECT_NE(RefusalOf([&] { MakeTreeReacher(cycle, {5}, {0}); }).find("tree.parents"),
            std::string::npos);

  // The targets at solve time; a refused call leaves the points as they were.
  const TreeReacher reacher = MakeTreeReacher(tree, {5, 8}, {0});
  Points points = tree.points;
  Points wrong(1, 2);
  wrong << 1.0, 2.0;
  EXPECT_EQ(RefusalOf([&] { ReachTargets(reacher, wrong, &points); }),
            "positions: shape 1x2; expected 2x2 (one row per target)");
  Points nan_target(2, 2);
  nan_target << 1.0, 2.0, NAN, 0.0;
  EXPECT_EQ(RefusalOf([&] { ReachTargets(reacher, nan_target, &points); }),
            "positions[1]: has a non-finite coordinate; a target must be finite");
  Points short_points = tree.points.topRows(4);
  EXPECT_NE(RefusalOf([&] {
              ReachTargets(reacher, Rows(tree.points, {5, 8}), &short_points);
            }).find("points: shape 4x2"),
            std::string::npos);
  EXPECT_TRUE(points == tree.points);
}

}  // namespace
}  // namespace flexkin

namespace flexkin {
namespace {

// The arms on a spine with a neck (point 9, on the shoulders, point 2) and a head (point 10).
Tree Torso(int dim) {
  Tree t = TwoArms(dim);
  t.points.conservativeResize(11, dim);
  t.points.bottomRows(2).setZero();
  t.points(9, 1) = 2.4;
  t.points(10, 1) = 2.9;
  if (dim == 3) t.points(10, 2) = 0.1;
  t.parents.push_back(2);
  t.parents.push_back(9);
  return t;
}

// Pointing goals: the torso's hands go round circles while its head (the link from the neck to
// point 10) looks at a point moving round a wide circle in front of it. Every frame reaches the
// hands to 1e-10 of the longest link and turns the head's link onto the point looked at to the
// same, the lengths kept and the base fixed exactly; the motion has no jumps.
TEST(TreeReachTest, PointingGoalsTurnTheirLinksOntoWhatTheyLookAt) {
  for (const int dim : {2, 3}) {
    const Tree tree = Torso(dim);
    const std::vector<int> targets = {5, 8, 10};
    for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
      ReachOptions options;
      options.method = method;
      const TreeReacher reacher =
          MakeTreeReacher(tree, targets, {0}, {}, options, std::vector<char>{0, 0, 1});
      EXPECT_EQ(reacher.root, 0);
      EXPECT_DOUBLE_EQ(reacher.look_length[2], (tree.points.row(10) - tree.points.row(9)).norm());
      Points points = tree.points, previous = tree.points;
      double worst_gaze = 0.0, largest_jump = 0.0;
      const int frames = 120;
      for (int f = 1; f <= frames; ++f) {
        const double a = 2 * M_PI * f / frames;
        Points goal = Rows(tree.points, targets);
        for (int k = 0; k < 2; ++k) {
          goal(k, 0) += 0.3 * (std::cos(a + k) - std::cos(double(k)));
          goal(k, 1) += 0.3 * (std::sin(a + k) - std::sin(double(k)));
        }
        goal.row(2).setZero();
        goal(2, 0) = 3.0 * std::sin(a);  // a point swinging from side to side above the head
        goal(2, 1) = 5.0 + std::cos(a);
        if (dim == 3) goal(2, 2) = 1.5;
        const ReachReport report = ReachTargets(reacher, goal, &points);
        SCOPED_TRACE(std::string(NameOf(method)) + " dim " + std::to_string(dim) + " frame " +
                     std::to_string(f));
        ASSERT_TRUE(report.reached) << report.residual << " after " << report.passes;
        EXPECT_LE(Residual(points, {5, 8}, goal.topRows(2)), 1e-10 * reacher.longest_link);
        const Eigen::RowVectorXd link = points.row(10) - points.row(9);
        const Eigen::RowVectorXd look = goal.row(2) - points.row(9);
        worst_gaze = std::max(worst_gaze, (link.normalized() - look.normalized()).norm());
        EXPECT_EQ((points.row(0) - tree.points.row(0)).norm(), 0.0);
        EXPECT_LE(MaxTreeLengthError(MakeTreeStepper(Method::kTractrix, tree, 0), points), 1e-13);
        largest_jump = std::max(largest_jump, (points - previous).rowwise().norm().maxCoeff());
        previous = points;
      }
      // The gaze to the reach's tolerance (of the longest link, over the head's length 0.5).
      EXPECT_LE(worst_gaze, 1e-10 * reacher.longest_link / 0.5);
      // The goals move at most 3 x 2 pi / 120 = 0.16 a frame: no point jumps much farther.
      EXPECT_LE(largest_jump, 0.5);
      std::printf("  %s, %dD: gaze within %.2g rad, largest jump of a point %.3f\n", NameOf(method),
                  dim, worst_gaze, largest_jump);
    }
  }
}

TEST(TreeReachTest, RefusesPointingGoalsItCannotTake) {
  const Tree tree = Torso(2);
  auto field = [&](const std::vector<int>& targets, const std::vector<int>& fixed,
                   const std::vector<char>& looks) {
    try {
      MakeTreeReacher(tree, targets, fixed, {}, ReachOptions(), looks);
    } catch (const InputError& e) {
      return e.field() + ": " + e.message();
    }
    return std::string("(accepted)");
  };
  // The root has no link from a parent to turn.
  EXPECT_EQ(field({5, 0}, {}, {0, 1}).rfind("targets[1]: is point 0, the tree's root", 0), 0u);
  // Pointing goals alone: nothing says where the body is.
  EXPECT_EQ(field({10}, {}, {1}).rfind("targets: are all pointing goals", 0), 0u);
  EXPECT_EQ(field({10, 5}, {}, {1, 0}), "(accepted)");  // a position target places the body
  EXPECT_EQ(field({10}, {0}, {1}), "(accepted)");       // so does a fixed point
  EXPECT_EQ(field({10, 5}, {0}, {1}).rfind("looks: has 1 entries for 2 targets", 0), 0u);
  // With nothing fixed the passes hang the tree from the first position target.
  EXPECT_EQ(MakeTreeReacher(tree, {10, 5}, {}, {}, ReachOptions(), {1, 0}).root, 5);
}

}  // namespace
}  // namespace flexkin
