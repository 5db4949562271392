// Trees driven at one point (flexkin/tree.h, docs/trees.md): the links in the order a move visits
// them, and the sweep that moves them, each link by the rule's scalar step with its fallback as
// the chain's one-pass sweep (propagate.cc) applies it.
#include "flexkin/tree.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "chain/denormals.h"
#include "chain/simd.h"
#include "chain/substep.h"
#include "flexkin/error.h"
#include "sequential/joint_rotation.h"
#include "sequential/link_rules.h"
#include "sequential/move_checks.h"
#include "sequential/rule_table.h"
#include "sequential/tree_sweep.h"

namespace flexkin {
namespace {

// "tree.parents[3]"; "parents[3]" where `field` is empty.
std::string At(const std::string& field, const char* member, int i) {
  return (field.empty() ? "" : field + ".") + member + "[" + std::to_string(i) + "]";
}

// The points of a cycle of `parents` through which point `start` (one not reached from the root)
// leads: parents followed from `start` until a point repeats, then that loop, as "3 -> 5 -> 3".
std::string CycleThrough(const std::vector<int>& parents, int start) {
  std::vector<char> seen(parents.size(), 0);
  int p = start;
  while (!seen[p]) {
    seen[p] = 1;
    p = parents[p];
  }
  std::string text = std::to_string(p);
  for (int q = parents[p]; q != p; q = parents[q]) text += " -> " + std::to_string(q);
  return text + " -> " + std::to_string(p);
}

template <class Rule, int Dim>
void TreeSweeps(const TreeStepper& t, const double* heads, int substeps, double* pts, double* old) {
  const int d = t.driven;
  const size_t links = t.lead.size();
  for (int s = 0; s < substeps; ++s) {
    for (int k = 0; k < Dim; ++k) {
      old[d * Dim + k] = pts[d * Dim + k];
      pts[d * Dim + k] = heads[s * Dim + k];
    }
    // Link j's leading end has moved from old[lead] to pts[lead]; its trailing end moves now.
    for (size_t j = 0; j < links; ++j) {
      const int a = t.lead[j], b = t.tail[j];
      double* tail = pts + b * Dim;
      for (int k = 0; k < Dim; ++k) old[b * Dim + k] = tail[k];
      internal::ApplyScalar<Rule, Dim>(old + a * Dim, pts + a * Dim, tail, t.lengths[j],
                                       t.inv_lengths[j]);
    }
  }
}

}  // namespace

void ValidateTree(const Tree& tree, const char* field, const std::vector<char>* sliding) {
  const std::string f = field;
  const std::string points_field = f.empty() ? "points" : f + ".points";
  const std::string parents_field = f.empty() ? "parents" : f + ".parents";
  const Points& points = tree.points;
  if (points.cols() != 2 && points.cols() != 3) {
    throw InputError(points_field, "points have " + std::to_string(points.cols()) +
                                       " coordinates; expected 2 (planar) or 3 (spatial)");
  }
  if (points.rows() < 2) {
    throw InputError(points_field, "a tree needs at least 2 points (1 link); got " +
                                       std::to_string(points.rows()));
  }
  const int count = static_cast<int>(points.rows());
  for (int i = 0; i < count; ++i) {
    for (Eigen::Index k = 0; k < points.cols(); ++k) {
      if (!std::isfinite(points(i, k))) {
        throw InputError(At(f, "points", i) + "[" + std::to_string(k) + "]",
                         "value " + FormatNumber(points(i, k)) + " is not a finite number");
      }
    }
  }
  const std::vector<int>& parents = tree.parents;
  if (static_cast<int>(parents.size()) != count) {
    throw InputError(parents_field, "has " + std::to_string(parents.size()) + " entries for " +
                                        std::to_string(count) +
                                        " points; expected one per point (-1 for the root)");
  }
  int root = -1;
  for (int i = 0; i < count; ++i) {
    const int p = parents[i];
    if (p == -1) {
      if (root >= 0) {
        throw InputError(At(f, "parents", i),
                         "is -1, but point " + std::to_string(root) +
                             " is the root already; a tree has one root (every other point "
                             "hangs from a point of the tree)");
      }
      root = i;
      continue;
    }
    if (p < 0 || p >= count || p == i) {
      throw InputError(At(f, "parents", i),
                       "is " + std::to_string(p) + "; expected -1 (the root) or a point 0.." +
                           std::to_string(count - 1) + " other than " + std::to_string(i));
    }
  }
  if (root < 0) {
    throw InputError(parents_field,
                     "has no root (no entry -1); a tree has exactly one, the "
                     "point that hangs from no other: the parents form a cycle " +
                         CycleThrough(parents, 0));
  }
  // Every point reached from the root, else it lies on (or hangs from) a cycle.
  const std::vector<std::vector<int>> children = TreeChildren(parents);
  std::vector<char> reached(count, 0);
  std::vector<int> stack{root};
  reached[root] = 1;
  while (!stack.empty()) {
    const int p = stack.back();
    stack.pop_back();
    for (int c : children[p]) {
      reached[c] = 1;
      stack.push_back(c);
    }
  }
  for (int i = 0; i < count; ++i) {
    if (!reached[i]) {
      throw InputError(At(f, "parents", i),
                       "is " + std::to_string(parents[i]) + ": point " + std::to_string(i) +
                           " does not lead to the root " + std::to_string(root) +
                           "; its parents form the cycle " + CycleThrough(parents, i));
    }
  }
  for (int i = 0; i < count; ++i) {
    if (i == root) continue;
    const double length = (points.row(i) - points.row(parents[i])).norm();
    const bool slides =
        sliding != nullptr && static_cast<size_t>(i) < sliding->size() && (*sliding)[i] != 0;
    if (!std::isfinite(length) || (!slides && !(length > 0.0))) {
      throw InputError(At(f, "points", i), "lies at distance " + FormatNumber(length) +
                                               " from its parent point " +
                                               std::to_string(parents[i]) +
                                               "; every link needs a positive, finite length");
    }
  }
}

std::vector<std::vector<int>> TreeChildren(const std::vector<int>& parents) {
  std::vector<std::vector<int>> children(parents.size());
  for (size_t i = 0; i < parents.size(); ++i) {
    if (parents[i] >= 0) children[parents[i]].push_back(static_cast<int>(i));
  }
  return children;
}

int TreeRoot(const std::vector<int>& parents) {
  const auto root = std::find(parents.begin(), parents.end(), -1);
  return root == parents.end() ? 0 : static_cast<int>(root - parents.begin());
}

Tree TreeOfChain(const Chain& chain) {
  Tree tree;
  tree.points = chain.points;
  tree.parents.resize(chain.points.rows());
  for (size_t i = 0; i < tree.parents.size(); ++i) tree.parents[i] = static_cast<int>(i) - 1;
  return tree;
}

TreeStepper MakeTreeStepper(Method method, const Tree& tree, int driven) {
  ValidateTree(tree);
  const int count = static_cast<int>(tree.points.rows());
  if (driven < 0 || driven >= count) {
    throw InputError("driven", "is point " + std::to_string(driven) + "; the tree has points 0.." +
                                   std::to_string(count - 1));
  }
  constexpr unsigned kTreeEngines = internal::kTreeEngine | internal::kWholeTreeEngine;
  if (!internal::RuleRunsOn(method, kTreeEngines)) {
    throw InputError(Problem::Invalid(
        "method", std::string("\"") + MethodName(method) + "\"",
        QuotedList(internal::RuleNamesOn(kTreeEngines)) + " (the methods of trees)"));
  }
  TreeStepper t;
  t.method = method;
  t.dim = static_cast<int>(tree.points.cols());
  t.driven = driven;
  t.parents = tree.parents;
  // Depth first from the driven point over the links in both directions (to a child, and to the
  // parent), children in increasing order: a path driven at point 0 visits its links in order.
  const std::vector<std::vector<int>> children = TreeChildren(tree.parents);
  std::vector<char> visited(count, 0);
  std::vector<int> placed_by(count, -1);  // the link whose trailing end a point is
  std::vector<int> stack{driven};
  visited[driven] = 1;
  while (!stack.empty()) {
    const int a = stack.back();
    stack.pop_back();
    std::vector<int> next;
    if (tree.parents[a] >= 0 && !visited[tree.parents[a]]) next.push_back(tree.parents[a]);
    for (int c : children[a]) {
      if (!visited[c]) next.push_back(c);
    }
    for (auto it = next.rbegin(); it != next.rend(); ++it) {
      visited[*it] = 1;
      stack.push_back(*it);
    }
    for (int b : next) {
      placed_by[b] = static_cast<int>(t.lead.size());
      t.source.push_back(placed_by[a]);
      t.lead.push_back(a);
      t.tail.push_back(b);
      const double length = (tree.points.row(b) - tree.points.row(a)).norm();
      t.lengths.push_back(length);
      t.inv_lengths.push_back(1.0 / length);
    }
  }
  return t;
}

void MoveTreePoint(const TreeStepper& stepper, const Eigen::Ref<const Eigen::VectorXd>& target,
                   int substeps, Points* points) {
  const int dim = stepper.dim;
  internal::CheckMove(target, dim, substeps, "tree");
  const size_t count = stepper.parents.size();
  if (points->rows() != static_cast<Eigen::Index>(count) || points->cols() != dim) {
    throw InputError("points", "shape " + std::to_string(points->rows()) + "x" +
                                   std::to_string(points->cols()) +
                                   " does not match the stepper's tree (" + std::to_string(count) +
                                   "x" + std::to_string(dim) + ")");
  }
  std::vector<double> heads(static_cast<size_t>(substeps) * dim);
  for (int j = 1; j <= substeps; ++j) {
    for (int k = 0; k < dim; ++k) {
      heads[(j - 1) * dim + k] =
          internal::SubstepHead((*points)(stepper.driven, k), target[k], j, substeps);
    }
  }
  const internal::SubnormalsAsZero subnormals;
  if (internal::RuleRunsOn(stepper.method, internal::kWholeTreeEngine)) {
    internal::DispatchRule<internal::kWholeTreeEngine>(stepper.method, [&](auto rule) {
      decltype(rule)::WholeTreeSweeps(dim, heads.data(), substeps, internal::LinksOf(stepper),
                                      points->data());
    });
    return;
  }
  // The SIMD wavefront takes groups of as many sub-steps as it has lanes (tree_wavefront.h), the
  // one-pass sweep the rest.
  int64_t done = 0;
  const internal::TreeWavefrontFn wavefront = internal::ChosenTreeWavefront();
  if (wavefront != nullptr && !stepper.lead.empty()) {
    done = wavefront(stepper.method, dim, heads.data(), substeps, internal::LinksOf(stepper),
                     points->data());
  }
  if (done == substeps) return;
  thread_local std::vector<double> old;
  old.resize(count * dim);
  const double* rest = heads.data() + done * dim;
  const int left = substeps - static_cast<int>(done);
  internal::DispatchRule<internal::kTreeEngine>(stepper.method, [&](auto rule) {
    using Rule = decltype(rule);
    dim == 2 ? TreeSweeps<typename Rule::template Step<2>, 2>(stepper, rest, left, points->data(),
                                                              old.data())
             : TreeSweeps<typename Rule::template Step<3>, 3>(stepper, rest, left, points->data(),
                                                              old.data());
  });
}

namespace internal {

std::vector<TreeWavefrontEngine> AvailableTreeWavefronts() {
  std::vector<TreeWavefrontEngine> engines;
#if FLEXKIN_HAVE_WAVEFRONT
  if (CpuSimd().avx2_fma) engines.push_back({"avx2", TreeWavefrontAvx2, 4});
  if (CpuSimd().avx512) engines.push_back({"avx512", TreeWavefrontAvx512, 8});
#endif
  return engines;
}

TreeWavefrontFn ChosenTreeWavefront() {
#if FLEXKIN_HAVE_WAVEFRONT
  if (AllowedSimd().avx512) return TreeWavefrontAvx512;
  if (AllowedSimd().avx2_fma) return TreeWavefrontAvx2;
#endif
  return nullptr;
}

TreeLinks LinksOf(const TreeStepper& stepper) {
  TreeLinks links;
  links.driven = stepper.driven;
  links.num_points = static_cast<int>(stepper.parents.size());
  links.num_links = static_cast<int>(stepper.lead.size());
  links.lead = stepper.lead.data();
  links.tail = stepper.tail.data();
  links.source = stepper.source.data();
  links.lengths = stepper.lengths.data();
  links.inv_lengths = stepper.inv_lengths.data();
  return links;
}

void TreeSweepsMinRotation(int dim, const double* heads, int64_t num_sweeps, const TreeLinks& tree,
                           double* points) {
  const int d = tree.driven;
  for (int64_t s = 0; s < num_sweeps; ++s) {
    for (int k = 0; k < dim; ++k) {
      const double shift = heads[s * dim + k] - points[d * dim + k];
      for (int i = 0; i < tree.num_points; ++i) points[i * dim + k] += shift;
    }
  }
}

namespace {

template <int Dim>
void TreeMinJointAngle(const double* heads, int64_t num_sweeps, const TreeLinks& tree,
                       double* points) {
  using Vec = Eigen::Matrix<double, Dim, 1>;
  using Mat = Eigen::Matrix<double, Dim, Dim>;
  Eigen::Map<Eigen::Matrix<double, Dim, Eigen::Dynamic>> p(points, Dim, tree.num_points);
  // The link from the driven point that each link hangs behind (itself for those links).
  std::vector<int> first_of(tree.num_links);
  for (int j = 0; j < tree.num_links; ++j) {
    first_of[j] = tree.source[j] < 0 ? j : first_of[tree.source[j]];
  }
  std::vector<Vec> first_old(tree.num_links), first_new(tree.num_links);
  std::vector<Mat> rotation(tree.num_links);
  const int d = tree.driven;
  for (int64_t s = 0; s < num_sweeps; ++s) {
    const Vec head_old = p.col(d);
    const Vec head_new = Eigen::Map<const Vec>(heads + s * Dim);
    for (int j = 0; j < tree.num_links; ++j) {
      if (tree.source[j] >= 0) continue;
      first_old[j] = p.col(tree.tail[j]);
      first_new[j] = first_old[j];
      TractrixStep<Dim>(head_old.data(), head_new.data(), first_new[j].data(), tree.lengths[j],
                        tree.inv_lengths[j]);
      rotation[j] =
          RotationBetween<Dim>(Vec(first_old[j] - head_old), Vec(first_new[j] - head_new));
    }
    for (int j = 0; j < tree.num_links; ++j) {
      if (tree.source[j] < 0) continue;
      const int f = first_of[j];
      p.col(tree.tail[j]) = first_new[f] + rotation[f] * (p.col(tree.tail[j]) - first_old[f]);
    }
    p.col(d) = head_new;
    for (int j = 0; j < tree.num_links; ++j) {
      if (tree.source[j] < 0) p.col(tree.tail[j]) = first_new[j];
    }
  }
}

}  // namespace

void TreeSweepsMinJointAngle(int dim, const double* heads, int64_t num_sweeps,
                             const TreeLinks& tree, double* points) {
  dim == 2 ? TreeMinJointAngle<2>(heads, num_sweeps, tree, points)
           : TreeMinJointAngle<3>(heads, num_sweeps, tree, points);
}

}  // namespace internal

double MaxTreeLengthError(const TreeStepper& stepper, const Points& points) {
  double worst = 0.0;
  for (size_t j = 0; j < stepper.lead.size(); ++j) {
    const double length = (points.row(stepper.tail[j]) - points.row(stepper.lead[j])).norm();
    worst = std::fmax(worst, std::fabs(length - stepper.lengths[j]) / stepper.lengths[j]);
  }
  return worst;
}

}  // namespace flexkin
