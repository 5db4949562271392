// Trees (scenes/scenes.h): TheComet/ik's shapes and random trees.
#include <cmath>
#include <random>

#include "scenes/scenes.h"

namespace flexkin::scenes {
namespace {

// A point hanging from `parent` one unit away in the direction `d` (in 2D, its x and z).
void Hang(Tree* tree, int parent, const Eigen::RowVector3d& d) {
  const int i = static_cast<int>(tree->parents.size());
  const Eigen::Index dim = tree->points.cols();
  tree->parents.push_back(parent);
  tree->points.conservativeResize(i + 1, dim);
  const Eigen::RowVectorXd step =
      dim == 3 ? Eigen::RowVectorXd(d) : Eigen::RowVectorXd(Eigen::RowVector2d(d.x(), d.z()));
  tree->points.row(i) = tree->points.row(parent) + step.normalized();
}

}  // namespace

Tree TreeShape(TreeKind kind, int dim) {
  Tree tree;
  tree.points = Points::Zero(1, dim);
  tree.parents = {-1};
  if (kind == TreeKind::kChain10) {
    for (int i = 0; i < 10; ++i) Hang(&tree, i, {1.0, 0.2 * std::sin(i), 0.1 * i});
  } else if (kind == TreeKind::kTwoArms) {
    Hang(&tree, 0, {0, 0, 1});
    Hang(&tree, 1, {0, 0.1, 1});
    for (const double side : {-1.0, 1.0}) {
      int at = 2;
      for (int i = 0; i < 5; ++i) {
        Hang(&tree, at, {side, 0.1 * i, -0.2 * i});
        at = static_cast<int>(tree.parents.size()) - 1;
      }
    }
  } else {
    for (int i = 1; i < 2047; ++i) {
      const int depth = static_cast<int>(std::log2(i + 1));
      Hang(&tree, (i - 1) / 2, {(i % 2 ? 1.0 : -1.0) * std::pow(0.8, depth), 0.5, 0.1 * depth});
    }
  }
  return tree;
}

std::vector<int> TreeTips(TreeKind kind) {
  switch (kind) {
    case TreeKind::kChain10:
      return {10};
    case TreeKind::kTwoArms:
      return {7, 12};
    case TreeKind::kBinary10:
      return {1023, 1400, 1700, 2046};
  }
  return {};
}

std::vector<Points> TipCircles(const Tree& tree, const std::vector<int>& tips, int frames) {
  const int dim = static_cast<int>(tree.points.cols());
  std::vector<Points> targets(frames, Points(tips.size(), dim));
  for (int f = 0; f < frames; ++f) {
    for (size_t k = 0; k < tips.size(); ++k) {
      const double a = 2 * M_PI * (f + 1) / frames, phase = static_cast<double>(k);
      targets[f].row(k) = tree.points.row(tips[k]);
      targets[f](k, 0) += 0.3 * (std::cos(a + phase) - std::cos(phase));
      targets[f](k, 1) += 0.3 * (std::sin(a + phase) - std::sin(phase));
    }
  }
  return targets;
}

Tree RandomTree(int count, int dim, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> length(0.5, 1.5);
  Tree tree;
  tree.points = Points::Zero(count, dim);
  tree.parents.assign(count, -1);
  for (int i = 1; i < count; ++i) {
    const int p = std::uniform_int_distribution<int>(0, i - 1)(rng);
    tree.parents[i] = p;
    Eigen::VectorXd d(dim);
    for (int k = 0; k < dim; ++k) d[k] = normal(rng);
    tree.points.row(i) = tree.points.row(p) + length(rng) * d.normalized().transpose();
  }
  return tree;
}

}  // namespace flexkin::scenes
