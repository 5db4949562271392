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

namespace flexkin {

struct Tree {
  Points points;             // (n+1) by dim, dim 2 or 3
  std::vector<int> parents;  // n+1 entries: the point each point hangs from; -1 for the one root
};

// Checks that `tree` is usable: points of 2 or 3 finite coordinates, one parent entry per point,
// exactly one root (-1), every other parent a point of the tree other than itself, no cycle, and
// no point on its parent (a link of length 0). Throws InputError naming `field` ("tree.parents[4]",
// "tree.points[7]"; "parents[4]" where `field` is empty) with the value and what would be valid.
void ValidateTree(const Tree& tree, const char* field = "tree");

// The path of `chain` as a tree (point i hangs from point i - 1).
Tree TreeOfChain(const Chain& chain);

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
