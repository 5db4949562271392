#pragma once
// Bodies that branch (docs/trees.md): points joined by rigid links in a tree, every point but the
// root hanging from its parent point. A path, the shape of a Chain, is the tree whose point i
// hangs from point i - 1.
//
// Driven at any one point (the root, a leaf or one between), the motion spreads outward from it
// along every branch: each link's trailing end (its end farther from the driven point) follows
// its leading end by the chosen link rule, in closed form, as the links of a chain do. A link's
// step depends only on how its leading end moved, so every branch moves as the chain from the
// driven point along it would, bit for bit, and a path driven at point 0 moves as a Chain moved
// by MoveLeader's one-pass sweep.

#include <Eigen/Core>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/propagate.h"
#include "flexkin/vocabulary.h"

namespace flexkin {

struct Tree {
  Points points;             // (n+1) by dim, dim 2 or 3
  std::vector<int> parents;  // n+1 entries: the point each point hangs from; -1 for the one root
};

// Checks that `tree` is usable: points of 2 or 3 finite coordinates, one parent entry per point,
// exactly one root (-1), every other parent a point of the tree other than itself, no cycle, and
// no point on its parent (a link of length 0). Throws InputError naming `field` ("tree.parents[4]",
// "tree.points[7]"; "parents[4]" where `field` is empty) with the value and what would be valid.
// `sliding` (per point, or null): 1 where the link into the point slides (a robot tree's prismatic
// joint, flexkin/robot_tree.h), which may be of length 0.
void ValidateTree(const Tree& tree, const char* field = "tree",
                  const std::vector<char>* sliding = nullptr);

// The path of `chain` as a tree (point i hangs from point i - 1).
Tree TreeOfChain(const Chain& chain);

// Each point's children (the points that hang from it), in increasing order; `parents` as a
// Tree's (-1 for the root).
std::vector<std::vector<int>> TreeChildren(const std::vector<int>& parents);
// The root of `parents` (the one entry -1); 0 if there is none.
int TreeRoot(const std::vector<int>& parents);

// A tree prepared for moves driven at one point: its links in the order a move visits them (each
// link's leading end placed before its trailing end; depth first from the driven point), their
// lengths as the tree's points give them, and the rule.
struct TreeStepper {
  Method method = Method::kTractrix;
  int dim = 0;
  int driven = 0;               // the point moves drive
  std::vector<int> parents;     // the tree's
  std::vector<int> lead, tail;  // link j joins point lead[j] (leading) to tail[j]
  std::vector<int> source;      // the link whose trailing end is lead[j]; -1 for the driven point
  std::vector<double> lengths, inv_lengths;  // of link j, and 1 / that
};

// Throws InputError if `tree` is not valid (ValidateTree), `driven` is not one of its points, or
// `method` is not a rule that runs on trees (tractrix, ftl, min_rotation, min_joint_angle).
TreeStepper MakeTreeStepper(Method method, const Tree& tree, int driven);

// The driven point moves in a straight line from where it is to `target` in `substeps` equal
// sub-steps (MoveLeader's sub-step points); after each sub-step every link, outward from the
// driven point, applies the rule with its leading end moving along the straight segment between
// its old and new positions. `points` ((n+1) by dim) is updated in place. Throws InputError on a
// target of the wrong size or with non-finite values, substeps < 1, or points of the wrong shape.
void MoveTreePoint(const TreeStepper& stepper, const Eigen::Ref<const Eigen::VectorXd>& target,
                   int substeps, Points* points);

// Largest |(|p_tail - p_lead| - L)| / L over the stepper's links (a Chain's is
// MaxRelativeLengthError).
double MaxTreeLengthError(const TreeStepper& stepper, const Points& points);

}  // namespace flexkin

namespace flexkin {

// ---- Several targets and fixed points (docs/trees.md, "Several targets") ----
//
// Several points of a tree driven to their own targets at once, any points held where they are
// (bases, sub-bases). The iterative natural method: passes of the link rule (tractrix or ftl)
// between the targets and the fixed points, as FABRIK's passes are with follow-the-leader. The
// tree is taken as hanging from one anchor, the root of the passes (the first fixed point, else
// the first target's point). A gathering pass moves every other anchor to its target, each in a
// straight line, with the links between it and the root following it by the rule; a branch point
// that several such branches pull is placed by the branch rule. A spreading pass then moves the
// root to its anchor and every link, outward from it, follows its leading end by the rule; the
// points that nothing pulls (branches without a target) move only here, as a body driven at the
// root would. Passes repeat until every target and fixed point lies within `tolerance` of where it
// should be; they stop short of it after `max_passes`, or once a pass moves no point by more than
// a hundredth of the tolerance (a target out of reach: the report gives the residual).
// Every link keeps its length to rounding after every pass.

enum class BranchRule {
  // FABRIK's rule: the weighted centroid of what the branches propose.
  kCentroid,
  // The rule derived from the least-motion problem (docs/trees.md): its linearized constraints
  // keep every branch's first link, so the point matches each branch's proposal along that link
  // (weighted least squares), blended with the proposals' centroid, which alone places it in the
  // directions no branch constrains. About half the passes of the centroid; the body moves more.
  kKeepLinks,
};
template <>
struct Vocabulary<BranchRule> {
  static constexpr const char* kKind = "branch rule";
  static constexpr NamedValue<BranchRule> kEntries[] = {
      {BranchRule::kCentroid, "centroid", "the weighted centroid of the proposals (FABRIK's)"},
      {BranchRule::kKeepLinks, "keep_links",
       "each branch's first link kept to first order, blended with the centroid (derived from "
       "the least-motion problem's linearized constraints)"},
  };
};

struct ReachOptions {
  Method method = Method::kTractrix;  // the rule of the passes: tractrix or ftl
  BranchRule branch_rule = BranchRule::kCentroid;
  double tolerance = 1e-10;  // the largest distance allowed from a target, as a fraction of the
                             // tree's longest link
  int max_passes = 1000;
};

// A tree prepared for several targets: its anchors (the targets' points, then the fixed points),
// the root of the passes and the orders the passes take.
struct TreeReacher {
  ReachOptions options;
  int dim = 0;
  std::vector<int> parents;         // the tree's
  std::vector<int> target_points;   // as given
  std::vector<char> looks;          // per target: a pointing goal (see MakeTreeReacher)
  std::vector<double> look_length;  // per target: a pointing goal's link length (else 0)
  std::vector<double> weights;      // per target, then 1 per fixed point
  std::vector<int> fixed_points;    // as given
  Points fixed_positions;           // where the fixed points are held (one row each)
  int root = 0;                     // the anchor the passes hang the tree from
  std::vector<int> anchor_of;       // per point: its index among the anchors, or -1
  std::vector<int> up;              // per point: its neighbour toward the root (-1: the root)
  std::vector<double> up_length;    // the length of the link to it
  std::vector<int> order;           // the points, the root first, each after its `up`
  std::vector<int> down_begin;      // the points whose `up` is v: down[down_begin[v]] up to
  std::vector<int> down;            // (not including) down[down_begin[v + 1]]
  std::vector<char> pulled;         // per point: an anchor lies beyond it (or it is one)
  std::vector<double> pull_weight;  // the weights of the anchors beyond it (itself included)
  std::vector<int> pulled_order;    // the pulled points in `order`'s order (the passes' points)
  std::vector<int> free_order;      // the others (the branches that follow once, at the end)
  double longest_link = 0.0;
};

struct ReachReport {
  int passes = 0;         // pairs of passes done
  double residual = 0.0;  // the largest distance of a target or fixed point from where it
                          // should be, after the last pass, as a fraction of the longest link
  bool reached = false;   // residual <= options.tolerance
  bool finished = false;  // passes that stalled, completed by FinishTreeReach (tree_overall.h)
};

// Throws InputError naming the field ("targets[2]", "fixed[0]", "weights[1]", "method",
// "tolerance", "max_passes") on a tree that ValidateTree refuses, a point that the tree does not
// have, a point driven twice or both driven and fixed, no target, a weight that is not positive
// and finite, a method other than tractrix and ftl, or a tolerance or max_passes out of range.
// `weights` is empty (every target 1) or one per target. The fixed points are held where `tree`
// has them.
//
// Pointing goals (docs/trees.md, "Pointing goals"): `looks` is empty (every target a position) or
// one flag per target; a flagged target's row of ReachTargets's positions is a point that its
// point's link from its parent must point at (a head looking at something, a tool aimed), not
// where the point goes. Its point is then placed, at the start of every pass, on the link's
// length from where its parent is, toward the point looked at: a position goal that moves with
// the parent, reached when the passes settle, the residual the point's distance from it. Also
// refused: a pointing goal on the tree's root ("targets[k]": it has no link from a parent), and
// pointing goals with neither a position target nor a fixed point ("targets": the body could be
// anywhere). The root of the passes is then the first fixed point, else the first position target.
TreeReacher MakeTreeReacher(const Tree& tree, const std::vector<int>& targets,
                            const std::vector<int>& fixed, const std::vector<double>& weights = {},
                            const ReachOptions& options = ReachOptions(),
                            const std::vector<char>& looks = {});

// Moves `points` (the tree's shape: (n+1) by dim, each link at its length) so that target k's
// point reaches row k of `positions` (one row per target, dim columns, finite), or, for a pointing
// goal, its link from its parent points at it. Throws
// InputError on positions or points of the wrong shape or with non-finite values; a refused call
// changes nothing.
ReachReport ReachTargets(const TreeReacher& reacher, const Points& positions, Points* points);

}  // namespace flexkin
