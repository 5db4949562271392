// Several targets and fixed points on a tree (flexkin/tree.h, docs/trees.md "Several targets"):
// the iterative natural method, gathering and spreading passes of the link rule between the
// anchors, with the branch rule where several pulled branches meet.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "chain/denormals.h"
#include "flexkin/error.h"
#include "flexkin/tree.h"
#include "sequential/link_rules.h"
#include "sequential/rule_table.h"

namespace flexkin {
namespace {

std::string ReachField(const char* name, size_t i) {
  return std::string(name) + "[" + std::to_string(i) + "]";
}

// The keep_links rule weighs the proposals' centroid as much as all the branches' links together
// (docs/trees.md: less weight converges in fewer passes but moves the body more).
constexpr double kReachCentroidShare = 1.0;

// Passes stop early once this many passes in a row have not brought the residual this fraction
// below the least one yet: a target out of reach, or passes that stall (docs/trees.md). Passes
// that converge take off 5 to 50% a pass in the tests.
constexpr double kReachSettled = 1e-3;
constexpr int kReachSettledPasses = 10;

template <int Dim>
using ReachVec = Eigen::Matrix<double, Dim, 1>;

// Where branch point v goes, given each pulled branch's proposal q[j] (v's position after its
// link to the branch's first point c[j] followed c[j] by the rule), that point's new position
// c[j] and the branch's weight w[j].
template <int Dim>
ReachVec<Dim> ReachBranchPoint(BranchRule rule, const std::vector<ReachVec<Dim>>& q,
                               const std::vector<ReachVec<Dim>>& c, const std::vector<double>& w) {
  double total = 0.0;
  ReachVec<Dim> centroid = ReachVec<Dim>::Zero();
  for (size_t j = 0; j < q.size(); ++j) {
    centroid += w[j] * q[j];
    total += w[j];
  }
  centroid /= total;
  if (rule == BranchRule::kCentroid) return centroid;
  // Least squares: sum_j w_j ((b - q_j) . u_j)^2 + mu |b - centroid|^2, u_j the branch's first
  // link as proposed: the branches' links kept to first order (the linearized constraints of the
  // least-motion problem), the centroid where they leave the point free.
  const double mu = kReachCentroidShare * total;
  Eigen::Matrix<double, Dim, Dim> m = mu * Eigen::Matrix<double, Dim, Dim>::Identity();
  ReachVec<Dim> rhs = mu * centroid;
  for (size_t j = 0; j < q.size(); ++j) {
    const ReachVec<Dim> d = c[j] - q[j];
    const double dd = d.squaredNorm();
    if (!(dd > 0.0)) continue;
    const ReachVec<Dim> u = d / std::sqrt(dd);
    m += w[j] * u * u.transpose();
    rhs += w[j] * u * u.dot(q[j]);
  }
  return m.llt().solve(rhs);
}

// The pointing goals' anchors where the points' parents are in `p`: each on its link's length
// from the parent toward the point looked at (row k of `positions`); where the two coincide, the
// point where it is.
void PlaceLookAnchors(const TreeReacher& r, const Points& positions, const Points& p,
                      Points* anchors) {
  for (size_t k = 0; k < r.looks.size(); ++k) {
    if (!r.looks[k]) continue;
    const int c = r.target_points[k];
    const Eigen::Index row = static_cast<Eigen::Index>(k);
    const Eigen::RowVectorXd parent = p.row(r.parents[c]);
    const Eigen::RowVectorXd toward = positions.row(row) - parent;
    const double distance = toward.norm();
    anchors->row(row) = distance > 0.0
                            ? Eigen::RowVectorXd(parent + (r.look_length[k] / distance) * toward)
                            : Eigen::RowVectorXd(p.row(c));
  }
}

template <class Rule, int Dim>
ReachReport ReachPasses(const TreeReacher& r, Points anchors, const Points& positions,
                        Points* points) {
  const bool looks = std::find(r.looks.begin(), r.looks.end(), 1) != r.looks.end();
  using V = ReachVec<Dim>;
  const int count = static_cast<int>(r.parents.size());
  // Rows of the points as the frame began (the free branches follow from them), as each pass
  // began, and after the gathering; only the pulled points' rows of the last two are used.
  const Points initial = *points;
  Points start = *points, before = *points;
  Points& p = *points;
  std::vector<char> moved(count, 0), broken(count, 0);
  std::vector<V> q, c;
  std::vector<double> w;
  auto row = [](Points& m, int i) { return m.data() + static_cast<size_t>(i) * Dim; };
  auto at = [](const Points& m, int i) {
    return Eigen::Map<const V>(m.data() + static_cast<size_t>(i) * Dim);
  };
  auto anchor = [&](int i) { return anchors.data() + static_cast<size_t>(r.anchor_of[i]) * Dim; };
  const std::vector<int>& pulled = r.pulled_order;
  ReachReport report;
  const double scale = 1.0 / r.longest_link;
  double previous = HUGE_VAL;
  int settled = 0;
  while (report.passes < r.options.max_passes) {
    ++report.passes;
    if (looks) PlaceLookAnchors(r, positions, p, &anchors);
    for (int v : pulled) Eigen::Map<V>(row(start, v)) = at(p, v);
    // Gathering: every anchor but the root to its place, the points between it and the root after
    // it; a point with several pulled branches by the branch rule.
    for (auto it = pulled.rbegin(); it != pulled.rend(); ++it) {
      const int v = *it;
      moved[v] = broken[v] = 0;
      if (r.anchor_of[v] >= 0 && v != r.root) {
        std::copy(anchor(v), anchor(v) + Dim, row(p, v));
        moved[v] = broken[v] = 1;
        continue;
      }
      q.clear();
      c.clear();
      w.clear();
      for (int e = r.down_begin[v]; e < r.down_begin[v + 1]; ++e) {
        const int b = r.down[e];
        if (!r.pulled[b]) continue;
        V tail = at(start, v);
        internal::ApplyScalar<Rule, Dim>(row(start, b), row(p, b), tail.data(), r.up_length[b],
                                         1.0 / r.up_length[b]);
        q.push_back(tail);
        c.push_back(at(p, b));
        w.push_back(r.pull_weight[b]);
      }
      if (q.empty()) continue;
      Eigen::Map<V>(row(p, v)) =
          q.size() == 1 ? q[0] : ReachBranchPoint<Dim>(r.options.branch_rule, q, c, w);
      moved[v] = 1;
      broken[v] = q.size() > 1;
    }
    // Spreading: the root to its anchor, every pulled link outward from it after its leading end,
    // following its leading end's motion in this pass (closing first a link that the gathering
    // left open at an anchor or a branch point).
    for (int v : pulled) Eigen::Map<V>(row(before, v)) = at(p, v);
    std::copy(anchor(r.root), anchor(r.root) + Dim, row(p, r.root));
    for (size_t k = 1; k < pulled.size(); ++k) {
      const int v = pulled[k], u = r.up[v];
      const double length = r.up_length[v];
      const double* lead_old = row(before, u);
      V tail = at(before, v);
      if (broken[u]) {
        const V d = tail - at(before, u);
        const double n = d.norm();
        if (n > 0.0) tail = at(before, u) + (length / n) * d;
      }
      internal::ApplyScalar<Rule, Dim>(lead_old, row(p, u), tail.data(), length, 1.0 / length);
      Eigen::Map<V>(row(p, v)) = tail;
    }
    if (looks) PlaceLookAnchors(r, positions, p, &anchors);  // where the parents ended
    double residual = 0.0;
    for (int v : pulled) {
      if (r.anchor_of[v] >= 0) {
        residual = std::max(residual, (at(p, v) - Eigen::Map<const V>(anchor(v))).norm());
      }
    }
    report.residual = residual * scale;
    if (report.residual <= r.options.tolerance) {
      report.reached = true;
      break;
    }
    if (report.residual < previous * (1.0 - kReachSettled)) {
      previous = report.residual;
      settled = 0;
    } else if (++settled == kReachSettledPasses) {
      break;
    }
  }
  // The branches that nothing pulls follow once, each link its leading end's motion over the
  // whole solve, as a tree driven at the point they hang from.
  for (int v : r.free_order) {
    const int u = r.up[v];
    const double length = r.up_length[v];
    V tail = at(initial, v);
    internal::ApplyScalar<Rule, Dim>(initial.data() + static_cast<size_t>(u) * Dim, row(p, u),
                                     tail.data(), length, 1.0 / length);
    Eigen::Map<V>(row(p, v)) = tail;
  }
  return report;
}

}  // namespace

TreeReacher MakeTreeReacher(const Tree& tree, const std::vector<int>& targets,
                            const std::vector<int>& fixed, const std::vector<double>& weights,
                            const ReachOptions& options, const std::vector<char>& looks) {
  ValidateTree(tree);
  const int count = static_cast<int>(tree.points.rows());
  if (options.method != Method::kTractrix && options.method != Method::kFollowTheLeader) {
    throw InputError(Problem::Invalid("method",
                                      std::string("\"") + MethodName(options.method) + "\"",
                                      "\"tractrix\" or \"ftl\" (the rules of the passes)"));
  }
  if (!(std::isfinite(options.tolerance) && options.tolerance > 0.0)) {
    throw InputError(Problem::Invalid("tolerance", FormatNumber(options.tolerance),
                                      "a finite number > 0 (of the longest link)"));
  }
  if (options.max_passes < 1) {
    throw InputError(
        Problem::Invalid("max_passes", std::to_string(options.max_passes), "an integer >= 1"));
  }
  if (targets.empty()) {
    throw InputError("targets", "none given; at least one point must be driven");
  }
  if (!weights.empty() && weights.size() != targets.size()) {
    throw InputError("weights", "has " + std::to_string(weights.size()) + " entries for " +
                                    std::to_string(targets.size()) +
                                    " targets; give one per target, or none (every weight 1)");
  }
  TreeReacher r;
  r.options = options;
  r.dim = static_cast<int>(tree.points.cols());
  r.parents = tree.parents;
  r.target_points = targets;
  r.fixed_points = fixed;
  if (!looks.empty() && looks.size() != targets.size()) {
    throw InputError("looks", "has " + std::to_string(looks.size()) + " entries for " +
                                  std::to_string(targets.size()) +
                                  " targets; give one per target, or none (every target a "
                                  "position)");
  }
  r.looks.assign(targets.size(), 0);
  r.look_length.assign(targets.size(), 0.0);
  for (size_t k = 0; k < looks.size(); ++k) r.looks[k] = looks[k] ? 1 : 0;
  r.anchor_of.assign(count, -1);
  const std::string range = "a point of the tree, 0.." + std::to_string(count - 1);
  auto claim = [&](int point, const std::string& field) {
    if (point < 0 || point >= count) {
      throw InputError(Problem::Invalid(field, std::to_string(point), range));
    }
    const int other = r.anchor_of[point];
    if (other >= 0) {
      const size_t k = static_cast<size_t>(other);
      const std::string by = k < targets.size()
                                 ? ReachField("targets", k) + " drives"
                                 : ReachField("fixed", k - targets.size()) + " holds";
      throw InputError(Problem(field,
                               "is point " + std::to_string(point) + ", which " + by +
                                   " already; a point takes one target or is fixed",
                               std::to_string(point)));
    }
    r.anchor_of[point] = static_cast<int>(r.weights.size());
  };
  for (size_t k = 0; k < targets.size(); ++k) {
    claim(targets[k], ReachField("targets", k));
    const double weight = weights.empty() ? 1.0 : weights[k];
    if (!(std::isfinite(weight) && weight > 0.0)) {
      throw InputError(
          Problem::Invalid(ReachField("weights", k), FormatNumber(weight), "a finite number > 0"));
    }
    r.weights.push_back(weight);
  }
  r.fixed_positions.resize(static_cast<Eigen::Index>(fixed.size()), r.dim);
  for (size_t k = 0; k < fixed.size(); ++k) {
    claim(fixed[k], ReachField("fixed", k));
    r.weights.push_back(1.0);
    r.fixed_positions.row(static_cast<Eigen::Index>(k)) = tree.points.row(fixed[k]);
  }
  for (size_t k = 0; k < targets.size(); ++k) {
    if (!r.looks[k]) continue;
    const int c = targets[k];
    if (tree.parents[c] < 0) {
      throw InputError(Problem(ReachField("targets", k),
                               "is point " + std::to_string(c) +
                                   ", the tree's root: a pointing goal turns the link from a "
                                   "point's parent, and the root has none",
                               std::to_string(c), "a point other than the root"));
    }
    r.look_length[k] = (tree.points.row(c) - tree.points.row(tree.parents[c])).norm();
  }
  const auto position = std::find(r.looks.begin(), r.looks.end(), 0);
  if (fixed.empty() && position == r.looks.end()) {
    throw InputError("targets",
                     "are all pointing goals and nothing is fixed: the body could be anywhere; "
                     "give a position target or a fixed point");
  }
  r.root = fixed.empty() ? targets[position - r.looks.begin()] : fixed[0];
  // The tree hung from the root: breadth first over the links in both directions.
  std::vector<std::vector<int>> near(count);
  for (int i = 0; i < count; ++i) {
    if (tree.parents[i] < 0) continue;
    near[i].push_back(tree.parents[i]);
    near[tree.parents[i]].push_back(i);
  }
  r.up.assign(count, -1);
  r.up_length.assign(count, 0.0);
  r.order.reserve(count);
  r.order.push_back(r.root);
  std::vector<char> seen(count, 0);
  seen[r.root] = 1;
  for (size_t k = 0; k < r.order.size(); ++k) {
    const int a = r.order[k];
    for (int b : near[a]) {
      if (seen[b]) continue;
      seen[b] = 1;
      r.up[b] = a;
      r.up_length[b] = (tree.points.row(b) - tree.points.row(a)).norm();
      r.longest_link = std::max(r.longest_link, r.up_length[b]);
      r.order.push_back(b);
    }
  }
  r.down_begin.assign(count + 1, 0);
  for (int i = 0; i < count; ++i) {
    if (r.up[i] >= 0) ++r.down_begin[r.up[i] + 1];
  }
  for (int i = 0; i < count; ++i) r.down_begin[i + 1] += r.down_begin[i];
  r.down.resize(r.down_begin[count]);
  std::vector<int> fill(r.down_begin.begin(), r.down_begin.end() - 1);
  for (int k = 1; k < count; ++k) {
    const int b = r.order[k];
    r.down[fill[r.up[b]]++] = b;
  }
  r.pulled.assign(count, 0);
  r.pull_weight.assign(count, 0.0);
  for (int k = count - 1; k >= 0; --k) {
    const int v = r.order[k];
    if (r.anchor_of[v] >= 0) {
      r.pulled[v] = 1;
      r.pull_weight[v] += r.weights[r.anchor_of[v]];
    }
    if (r.up[v] >= 0 && r.pulled[v]) {
      r.pulled[r.up[v]] = 1;
      r.pull_weight[r.up[v]] += r.pull_weight[v];
    }
  }
  for (int v : r.order) (r.pulled[v] ? r.pulled_order : r.free_order).push_back(v);
  if (!(r.longest_link > 0.0)) r.longest_link = 1.0;  // one point: nothing to scale by
  return r;
}

ReachReport ReachTargets(const TreeReacher& reacher, const Points& positions, Points* points) {
  const int dim = reacher.dim;
  const Eigen::Index count = static_cast<Eigen::Index>(reacher.parents.size());
  const Eigen::Index driven = static_cast<Eigen::Index>(reacher.target_points.size());
  if (positions.rows() != driven || positions.cols() != dim) {
    throw InputError("positions", "shape " + std::to_string(positions.rows()) + "x" +
                                      std::to_string(positions.cols()) + "; expected " +
                                      std::to_string(driven) + "x" + std::to_string(dim) +
                                      " (one row per target)");
  }
  for (Eigen::Index k = 0; k < driven; ++k) {
    if (!positions.row(k).allFinite()) {
      throw InputError(ReachField("positions", static_cast<size_t>(k)),
                       "has a non-finite coordinate; a target must be finite");
    }
  }
  if (points->rows() != count || points->cols() != dim || !points->allFinite()) {
    throw InputError("points", "shape " + std::to_string(points->rows()) + "x" +
                                   std::to_string(points->cols()) +
                                   (points->allFinite() ? "" : " with a non-finite value") +
                                   "; expected the reacher's tree, " + std::to_string(count) + "x" +
                                   std::to_string(dim) + ", finite");
  }
  Points anchors(driven + reacher.fixed_positions.rows(), dim);
  anchors.topRows(driven) = positions;
  anchors.bottomRows(reacher.fixed_positions.rows()) = reacher.fixed_positions;
  const internal::SubnormalsAsZero subnormals;
  ReachReport report;
  internal::DispatchRule<internal::kTreeEngine>(reacher.options.method, [&](auto rule) {
    using Rule = decltype(rule);
    report =
        dim == 2
            ? ReachPasses<typename Rule::template Step<2>, 2>(reacher, anchors, positions, points)
            : ReachPasses<typename Rule::template Step<3>, 3>(reacher, anchors, positions, points);
  });
  return report;
}

}  // namespace flexkin
