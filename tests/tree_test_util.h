#pragma once
// Trees for the tests of several targets (tree_reach_test, tree_overall_test): a tree's leaves,
// and another configuration of the same tree (its targets are then reachable by construction).

#include <Eigen/Core>
#include <cmath>
#include <random>
#include <vector>

#include "flexkin/tree.h"

namespace flexkin::test_util {

// The first `most` leaves of `tree` (points no other point hangs from), in index order.
inline std::vector<int> Leaves(const Tree& tree, size_t most) {
  std::vector<char> has_child(tree.parents.size(), 0);
  for (int p : tree.parents) {
    if (p >= 0) has_child[p] = 1;
  }
  std::vector<int> leaves;
  for (size_t i = 0; i < has_child.size() && leaves.size() < most; ++i) {
    if (!has_child[i]) leaves.push_back(static_cast<int>(i));
  }
  return leaves;
}

// Another configuration of `tree`, whose parents come before their children: the root where it
// is, every link turned by a random small rotation of its direction (at most `angle` off), its
// length kept.
inline Points Bent(const Tree& tree, double angle, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  const int dim = static_cast<int>(tree.points.cols());
  Points out = tree.points;
  for (int i = 0; i < tree.points.rows(); ++i) {
    const int p = tree.parents[i];
    if (p < 0) continue;
    const Eigen::VectorXd link = (tree.points.row(i) - tree.points.row(p)).transpose();
    Eigen::VectorXd nudge(dim);
    for (int k = 0; k < dim; ++k) nudge[k] = normal(rng);
    nudge -= nudge.dot(link) / link.squaredNorm() * link;
    const Eigen::VectorXd dir =
        (link.normalized() + std::tan(angle) * 0.5 * nudge.normalized()).normalized();
    out.row(i) = out.row(p) + link.norm() * dir.transpose();
  }
  return out;
}

}  // namespace flexkin::test_util
