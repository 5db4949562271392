// The overall method on trees with several targets (flexkin/tree_overall.h, docs/trees.md):
// Newton's method on the KKT system of the least-motion problem, its linear algebra eliminated
// along the tree.
//
// Unknowns: the motion dx_v of every point v that is neither a target nor fixed (a "free" point),
// and the change of the multiplier of every link that has a free end. Each link is named by its
// end farther from the root of the passes (TreeReacher::root, always an anchor), v, joining v to
// u = up[v]: D_v = p_v - p_u, c_v = (|D_v|^2 - L_v^2) / (2 L_v). A free point's block holds dx_v,
// its own link's multiplier, and the multipliers of the links to its anchored children; it is
// coupled only to its parent's dx (through its own link) and to its free children's blocks. So
// eliminating the blocks from the leaves to the root (each child's Schur complement added to its
// parent's dx rows) and substituting back from the root is an exact solve of the whole KKT system
// whose cost is linear in the links: one small dense solve (dim + 1 + anchored children) a point.
#include "flexkin/tree_overall.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "flexkin/error.h"

namespace flexkin {
namespace {

// Each point's weight in the squared terms: squared + squared_weighted * (half the lengths of
// the links at the point); 0 for an anchor, whose motion is given and not part of the metric.
std::vector<double> TreePointWeights(const TreeReacher& r, const ObjectiveWeights& weights) {
  const int count = static_cast<int>(r.parents.size());
  std::vector<double> w(count, weights.squared);
  for (int v = 0; v < count; ++v) {
    const int u = r.up[v];
    if (u < 0) continue;
    const double half = 0.5 * weights.squared_weighted * r.up_length[v];
    w[v] += half;
    w[u] += half;
  }
  for (int v = 0; v < count; ++v) {
    if (r.anchor_of[v] >= 0) w[v] = 0.0;
  }
  return w;
}

// The solver of one call of StepTreeOverall for a tree of `Dim` dimensions: the problem's
// constants and every buffer of its iterations, allocated once.
template <int Dim>
class TreeKkt {
 public:
  using Vec = Eigen::Matrix<double, Dim, 1>;
  using Mat = Eigen::Matrix<double, Dim, Dim>;
  using VecList = std::vector<Vec, Eigen::aligned_allocator<Vec>>;

  TreeKkt(const TreeReacher& r, const ObjectiveWeights& weights, const Points& old)
      : r_(r), count_(static_cast<int>(r.parents.size())), rotation_(weights.rotation), old_(old) {
    w_ = TreePointWeights(r, weights);
    anchored_.resize(count_);
    for (int v = 0; v < count_; ++v) {
      const int u = r.up[v];
      if (u >= 0 && !Free(v) && Free(u)) anchored_[u].push_back(v);
    }
    lambda_.setZero(count_);
    d_.resize(count_);
    c_.setZero(count_);
    kappa_.setZero(count_);
    grad_.resize(count_);
    objective_gradient_.resize(count_);
    a_.resize(count_);
    rx_.resize(count_);
    blocks_.resize(count_);
    for (int v = 0; v < count_; ++v) {
      if (!Free(v)) continue;
      const int m = Dim + 1 + static_cast<int>(anchored_[v].size());
      blocks_[v].kkt.resize(m, m);
      blocks_[v].rb.resize(m, Dim + 1);
      blocks_[v].x.resize(m, Dim + 1);
      blocks_[v].lu = Eigen::PartialPivLU<Eigen::MatrixXd>(m);
    }
  }

  bool Free(int v) const { return r_.anchor_of[v] < 0; }
  // A link with a free end (the others, between two anchors, cannot move).
  bool Moves(int v) const { return r_.up[v] >= 0 && (Free(v) || Free(r_.up[v])); }

  // D_v, c_v and the coupling kappa_v = (2 rotation + lambda_v) / L_v of every link, and, unless
  // `constraints_only`, the gradients at the free points and the metric.
  void Evaluate(const Points& p, bool constraints_only) {
    objective_ = 0.0;
    length_error_ = 0.0;
    for (int v = 0; v < count_; ++v) {
      grad_[v].setZero();
      objective_gradient_[v].setZero();
    }
    for (int v = 0; v < count_; ++v) {
      const Vec pv = At(p, v), ov = At(old_, v);
      if (!constraints_only && Free(v)) {
        objective_ += w_[v] * (pv - ov).squaredNorm();
        objective_gradient_[v] += 2.0 * w_[v] * (pv - ov);
      }
      const int u = r_.up[v];
      if (u < 0) continue;
      const double length = r_.up_length[v];
      d_[v] = pv - At(p, u);
      if (!constraints_only && rotation_ != 0.0) {
        const Vec change = d_[v] - (ov - At(old_, u));
        objective_ += rotation_ * change.squaredNorm() / length;
        const Vec g = (2.0 * rotation_ / length) * change;
        if (Free(v)) objective_gradient_[v] += g;
        if (Free(u)) objective_gradient_[u] -= g;
      }
      if (!Moves(v)) continue;
      c_[v] = (d_[v].squaredNorm() - length * length) / (2.0 * length);
      length_error_ = std::max(length_error_, std::abs(c_[v]) / length);
      if (constraints_only) continue;
      kappa_[v] = (2.0 * rotation_ + lambda_[v]) / length;
      const Vec g = (lambda_[v] / length) * d_[v];
      if (Free(v)) grad_[v] += g;
      if (Free(u)) grad_[u] -= g;
    }
    gradient_norm_ = 0.0;
    for (int v = 0; v < count_; ++v) {
      if (!Free(v)) continue;
      grad_[v] += objective_gradient_[v];
      gradient_norm_ = std::max(gradient_norm_, grad_[v].cwiseAbs().maxCoeff());
    }
  }

  // Newton's step (dx per point, dlambda per link) from the last Evaluate, by elimination along
  // the tree, with `extra` added to the Hessian's diagonal; with `unit`, the least correction of
  // the constraints instead (identity Hessian, no gradient: the retraction's Gauss-Newton step).
  // False where a block is singular. `inertia_ok` (if not null) says whether the KKT matrix has
  // as many positive eigenvalues as there are unknown coordinates (the Hessian positive definite
  // on the links' tangent space: a step toward a minimum, not a saddle), by Haynsworth's theorem
  // the sum of the eliminated blocks' inertias.
  bool Step(double extra, bool unit, bool* inertia_ok) {
    return StepInto(extra, unit, inertia_ok, &dx_, &dlambda_own_);
  }
  bool StepInto(double extra, bool unit, bool* inertia_ok, VecList* dx_out,
                Eigen::VectorXd* dlambda_out) {
    VecList& dx = *dx_out;
    Eigen::VectorXd& dlambda = *dlambda_out;
    int positive = 0, unknowns = 0;
    for (int v = 0; v < count_; ++v) {
      if (!Free(v)) continue;
      double diag = unit ? 1.0 : 2.0 * w_[v] + extra;
      if (!unit) {
        if (Moves(v)) diag += kappa_[v];
        for (int e = r_.down_begin[v]; e < r_.down_begin[v + 1]; ++e) diag += kappa_[r_.down[e]];
      }
      a_[v] = diag * Mat::Identity();
      rx_[v] = unit ? Vec::Zero() : Vec(-grad_[v]);
    }
    for (auto it = r_.order.rbegin(); it != r_.order.rend(); ++it) {
      const int v = *it;
      if (!Free(v)) continue;
      Block& b = blocks_[v];
      const std::vector<int>& kids = anchored_[v];
      const double length = r_.up_length[v];
      const double kappa = unit ? 0.0 : kappa_[v];
      const Vec own = d_[v] / length;
      // The fast form: no anchored child and A (the block's dx rows, after its children's Schur
      // complements) positive definite, so K = [A own; own^T 0] is solved through A's Cholesky
      // factor and the scalar S = own^T A^-1 own > 0; and K has exactly Dim positive eigenvalues
      // (A's; the Schur complement -S is negative).
      const Eigen::LLT<Mat> llt(a_[v]);
      b.fast = kids.empty() && llt.info() == Eigen::Success;
      if (b.fast) {
        const Mat ainv = llt.solve(Mat::Identity());
        const Vec g = ainv * own;
        const double schur = own.dot(g);
        if (!(schur > 0.0)) return false;
        const Vec af = ainv * rx_[v];
        b.y0 = (own.dot(af) + c_[v]) / schur;
        b.x0 = af - g * b.y0;
        b.y = (kappa * own.transpose() * ainv - own.transpose()) / schur;
        b.xb = kappa * ainv - g * b.y;
        if (inertia_ok != nullptr) {
          positive += Dim;
          unknowns += Dim;
        }
      } else {
        b.kkt.setZero();
        b.kkt.template topLeftCorner<Dim, Dim>() = a_[v];
        b.kkt.template block<Dim, 1>(0, Dim) = own;
        b.kkt.template block<1, Dim>(Dim, 0) = own.transpose();
        b.rb.setZero();
        b.rb.template block<Dim, 1>(0, 0) = rx_[v];
        b.rb(Dim, 0) = -c_[v];
        for (size_t j = 0; j < kids.size(); ++j) {
          const int c = kids[j];
          const Vec g = -d_[c] / r_.up_length[c];
          b.kkt.template block<Dim, 1>(0, Dim + 1 + j) = g;
          b.kkt.template block<1, Dim>(Dim + 1 + j, 0) = g.transpose();
          b.rb(Dim + 1 + j, 0) = -c_[c];
        }
        // The coupling B to the parent's dx: kappa I in the dx rows, own^T in the link's row.
        b.rb.template block<Dim, Dim>(0, 1) = kappa * Mat::Identity();
        b.rb.template block<1, Dim>(Dim, 1) = own.transpose();
        b.lu.compute(b.kkt);
        if (!(std::abs(b.lu.determinant()) > 0.0)) return false;
        b.x = b.lu.solve(b.rb);  // column 0: K^-1 r; columns 1..Dim: K^-1 B
        b.x0 = b.x.template block<Dim, 1>(0, 0);
        b.y0 = b.x(Dim, 0);
        b.xb = b.x.template block<Dim, Dim>(0, 1);
        b.y = b.x.template block<1, Dim>(Dim, 1);
        if (inertia_ok != nullptr) {
          if (llt.info() == Eigen::Success) {  // as above: A's Dim positive eigenvalues
            positive += Dim;
          } else {
            eigen_.compute(b.kkt, Eigen::EigenvaluesOnly);
            positive += static_cast<int>((eigen_.eigenvalues().array() > 0.0).count());
          }
          unknowns += Dim;
        }
      }
      const int u = r_.up[v];
      if (Free(u)) {
        // B^T rows: kappa I over the dx rows, own over the link's row (the anchored children's
        // rows of B are zero).
        a_[u] -= kappa * b.xb + own * b.y;
        rx_[u] += kappa * b.x0 + own * b.y0;
      }
    }
    dx.resize(count_);
    dlambda.resize(count_);
    for (const int v : r_.order) {
      dx[v].setZero();
      if (!Free(v)) continue;
      const Block& b = blocks_[v];
      const int u = r_.up[v];
      const Vec du = Free(u) ? dx[u] : Vec::Zero();
      dx[v] = b.x0 + b.xb * du;
      dlambda[v] = b.y0 + b.y.dot(du);
      if (!b.fast) {
        z_ = b.x.col(0);
        if (Free(u)) z_.noalias() += b.x.rightCols(Dim) * du;
        for (size_t j = 0; j < anchored_[v].size(); ++j) {
          dlambda[anchored_[v][j]] = z_[Dim + 1 + j];
        }
      }
      if (!dx[v].allFinite()) return false;
    }
    if (inertia_ok != nullptr) *inertia_ok = positive == unknowns;
    return true;
  }

  // p + alpha dx (the free points), and lambda0 + alpha dlambda.
  void Advance(const Points& p, double alpha, Points* out) const {
    *out = p;
    for (int v = 0; v < count_; ++v) {
      if (Free(v)) Row(out, v) += alpha * dx_[v];
    }
  }
  void SetLambda(const Eigen::VectorXd& base, double alpha) {
    for (int v = 0; v < count_; ++v) {
      lambda_[v] = Moves(v) ? base[v] + alpha * dlambda_own_[v] : 0.0;
    }
  }
  double StepSize() const {
    double m = 0.0;
    for (int v = 0; v < count_; ++v) {
      if (Free(v)) m = std::max(m, dx_[v].cwiseAbs().maxCoeff());
    }
    return m;
  }
  double Slope() const {  // of the metric along dx
    double slope = 0.0;
    for (int v = 0; v < count_; ++v) {
      if (Free(v)) slope += objective_gradient_[v].dot(dx_[v]);
    }
    return slope;
  }

  // Puts `p` back on the links (the anchors where they are): Gauss-Newton on the constraints,
  // each correction the least one that makes them hold to first order. False if it does not
  // reach `tolerance`.
  bool Retract(double tolerance, Points* p) {
    double previous = HUGE_VAL;
    for (int it = 0; it < 20; ++it) {
      Evaluate(*p, true);
      if (length_error_ <= tolerance) return true;
      // Gauss-Newton converges quadratically; once it stops halving the error it is at the
      // rounding of the points (which grows with the tree's size).
      if (length_error_ > 0.5 * previous) return length_error_ <= 64.0 * tolerance;
      previous = length_error_;
      if (!StepInto(0.0, true, nullptr, &retract_dx_, &retract_dlambda_)) return false;
      for (int v = 0; v < count_; ++v) {
        if (Free(v)) Row(p, v) += retract_dx_[v];
      }
    }
    return false;
  }

  // Newton's iterations from `p` (on the links, the anchors in place), as the chain's overall
  // solver iterates: every trial put back on the links by the retraction, so the line search is
  // on the metric itself; a full step is taken where it halves the Lagrangian's gradient without
  // raising the metric beyond rounding, else the step is halved until the metric falls (Armijo);
  // where the Hessian is not positive on the tangent space, or no step length lowers the metric,
  // its diagonal is raised and the step solved again. Returns the iterations used, negated where
  // they did not converge.
  int Solve(const TreeOverallOptions& options, Points* p) {
    const double length_tolerance = 1e-15;
    if (!Retract(length_tolerance, p)) return -1;
    Evaluate(*p, false);
    const double step_tolerance = options.tolerance * r_.longest_link;
    double scale = 0.0;  // of the Hessian's diagonal, for the regularization
    for (int v = 0; v < count_; ++v) scale = std::max(scale, 2.0 * w_[v]);
    if (!(scale > 0.0)) scale = 1.0;
    for (int it = 1; it <= options.max_iterations; ++it) {
      bool moved = false;
      double step = 0.0;
      const double objective = objective_, gradient_norm = gradient_norm_;
      const Eigen::VectorXd lambda = lambda_;
      const Points at = *p;
      for (double extra = 0.0; extra <= 1e8 * scale && !moved;
           extra = extra == 0.0 ? 1e-8 * scale : 10.0 * extra) {
        // The state at `at` (a failed line search evaluated trials).
        lambda_ = lambda;
        Evaluate(at, false);
        bool inertia_ok = false;
        if (!Step(extra, false, &inertia_ok) || !inertia_ok) continue;
        if (extra == 0.0 && StepSize() <= step_tolerance) {  // converged: the last small step
          Advance(at, 1.0, &trial_);
          if (Retract(length_tolerance, &trial_)) {
            SetLambda(lambda, 1.0);
            *p = trial_;
            return it;
          }
        }
        const double slope = Slope();
        const double allowance = 64.0 * 2.2e-16 * (std::abs(objective) + 1.0);
        for (double alpha = 1.0; alpha > 1e-6; alpha *= 0.5) {
          Advance(at, alpha, &trial_);
          if (!Retract(length_tolerance, &trial_)) continue;
          SetLambda(lambda, alpha);
          Evaluate(trial_, false);
          const bool full = alpha == 1.0 && objective_ <= objective + allowance &&
                            gradient_norm_ <= 0.5 * gradient_norm;
          const bool armijo = objective_ <= objective + 1e-4 * alpha * std::min(slope, 0.0) &&
                              objective_ < objective;
          if (full || armijo) {
            moved = true;
            step = alpha * StepSize();
            break;
          }
        }
      }
      if (!moved) {
        *p = at;
        lambda_ = lambda;
        Evaluate(at, false);
        return gradient_norm_ <= 1e3 * step_tolerance * scale ? it : -it;
      }
      *p = trial_;
      if (step <= step_tolerance) return it;
    }
    return -options.max_iterations;
  }

 private:
  struct Block {
    bool fast = false;
    // z = K^-1 (r + B du): dx = x0 + xb du, the own link's dlambda = y0 + y du.
    Vec x0;
    double y0 = 0.0;
    Mat xb;
    Eigen::Matrix<double, 1, Dim> y;
    // The general form (anchored children, or A not positive definite).
    Eigen::MatrixXd kkt, rb, x;
    Eigen::PartialPivLU<Eigen::MatrixXd> lu;
  };
  static Vec At(const Points& p, int v) { return Eigen::Map<const Vec>(p.data() + v * Dim); }
  static Eigen::Map<Vec> Row(Points* p, int v) { return Eigen::Map<Vec>(p->data() + v * Dim); }

  const TreeReacher& r_;
  int count_;
  double rotation_;
  const Points& old_;
  std::vector<double> w_;
  std::vector<std::vector<int>> anchored_;
  Eigen::VectorXd lambda_, c_, kappa_, dlambda_own_;
  VecList d_, grad_, objective_gradient_, rx_, dx_, retract_dx_;
  Eigen::VectorXd retract_dlambda_, z_;
  std::vector<Mat, Eigen::aligned_allocator<Mat>> a_;
  std::vector<Block> blocks_;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen_;
  Points trial_;
  double objective_ = 0.0, length_error_ = 0.0, gradient_norm_ = 0.0;
};

// The metric of the step from `old` to `p`, over the points that are not anchors.
double TreeObjective(const TreeReacher& r, const TreeOverallOptions& options, const Points& old,
                     const Points& p) {
  const std::vector<double> w = TreePointWeights(r, options.weights);
  double sum = 0.0;
  for (size_t v = 0; v < w.size(); ++v) {
    sum += w[v] * (p.row(v) - old.row(v)).squaredNorm();
    const int u = r.up[v];
    if (u >= 0) {
      sum += options.weights.rotation *
             ((p.row(v) - p.row(u)) - (old.row(v) - old.row(u))).squaredNorm() / r.up_length[v];
    }
  }
  return sum;
}

// The largest |(|D|^2 - L^2)| / (2 L^2) over the links.
double TreeConstraintError(const TreeReacher& r, const Points& p) {
  double worst = 0.0;
  for (size_t v = 0; v < r.parents.size(); ++v) {
    const int u = r.up[v];
    if (u < 0) continue;
    const double length = r.up_length[v];
    worst = std::max(worst, std::abs((p.row(v) - p.row(u)).squaredNorm() - length * length) /
                                (2.0 * length * length));
  }
  return worst;
}

// Passes that stall this near their targets (of the longest link) still start Newton, which puts
// the anchors on their targets and the links back (the retraction) and then minimizes: on random
// trees where the passes stall at 7e-5 to 7e-3 it reaches the targets exactly (tests).
constexpr double kNewtonAfterStall = 0.05;

// Where anchor `a` (an index of TreeReacher::anchor_of) belongs: its target's row of `positions`,
// or its fixed point's place.
Eigen::RowVectorXd AnchorPlace(const TreeReacher& r, const Points& positions, int a) {
  const int driven = static_cast<int>(r.target_points.size());
  return a < driven ? Eigen::RowVectorXd(positions.row(a))
                    : Eigen::RowVectorXd(r.fixed_positions.row(a - driven));
}

// StepTreeOverall's continuation, its input checked and reachable.
template <int Dim>
TreeOverallReport TreeContinuation(const TreeReacher& reacher, const Points& positions,
                                   const TreeOverallOptions& options, Points* points,
                                   TreeOverallReport report, bool one_step) {
  const int count = static_cast<int>(reacher.parents.size());
  double shortest = HUGE_VAL;
  for (int v = 0; v < count; ++v) {
    if (reacher.up[v] >= 0) shortest = std::min(shortest, reacher.up_length[v]);
  }
  const Points old = *points;
  TreeKkt<Dim> kkt(reacher, options.weights, old);
  // Continuation: the targets advance in sub-steps of at most half the shortest link, each
  // solved by Newton from the passes' motion of the last solution, so that the minimizer
  // returned is the one continuously connected to the points before the step.
  const Eigen::Index driven = static_cast<Eigen::Index>(reacher.target_points.size());
  Points from(driven, reacher.dim);
  double move = 0.0;
  for (Eigen::Index t = 0; t < driven; ++t) {
    from.row(t) = points->row(reacher.target_points[t]);
    move = std::max(move, (positions.row(t) - from.row(t)).norm());
  }
  report.substeps =
      one_step ? 1 : std::max(1, static_cast<int>(std::ceil(move / (0.5 * shortest))));
  Points p = *points, goal(driven, reacher.dim);
  for (int j = 1; j <= report.substeps; ++j) {
    const double f = static_cast<double>(j) / report.substeps;
    goal = j == report.substeps ? positions : Points(from + f * (positions - from));
    report.start = ReachTargets(reacher, goal, &p);
    if (!report.start.reached && report.start.residual > kNewtonAfterStall) break;
    for (int v = 0; v < count; ++v) {  // the anchors exactly where they should be
      const int a = reacher.anchor_of[v];
      if (a >= 0) p.row(v) = AnchorPlace(reacher, goal, a);
    }
    const int used = kkt.Solve(options, &p);
    report.iterations += std::abs(used);
    if (used < 0) break;
    report.converged = j == report.substeps;
  }
  if (!report.converged) {  // the passes' points for the whole move, reported
    p = *points;
    report.start = ReachTargets(reacher, positions, &p);
  }
  report.objective = TreeObjective(reacher, options, *points, p);
  report.length_error = TreeConstraintError(reacher, p);
  *points = p;
  return report;
}

}  // namespace

TreeOverallReport StepTreeOverall(const TreeReacher& reacher, const Points& positions,
                                  const TreeOverallOptions& options, Points* points) {
  Problems problems = options.weights.Validate();
  if (!problems.empty()) {
    Problem p = problems.front();
    p.field = "weights." + p.field;
    throw InputError(p);
  }
  for (const ObjectiveTerm t :
       {ObjectiveTerm::kL2, ObjectiveTerm::kL2Weighted, ObjectiveTerm::kJointAngle}) {
    if (options.weights[t] != 0.0) {
      throw InputError(Problem::Invalid(std::string("weights.") + NameOf(t),
                                        FormatNumber(options.weights[t]),
                                        "0: trees take the squared, squared_weighted and rotation "
                                        "terms"));
    }
  }
  if (!(std::isfinite(options.tolerance) && options.tolerance > 0.0)) {
    throw InputError(
        Problem::Invalid("tolerance", FormatNumber(options.tolerance), "a finite number > 0"));
  }
  if (options.max_iterations < 1) {
    throw InputError(Problem::Invalid("max_iterations", std::to_string(options.max_iterations),
                                      "an integer >= 1"));
  }
  for (size_t k = 0; k < reacher.looks.size(); ++k) {
    if (reacher.looks[k]) {
      throw InputError(Problem("targets[" + std::to_string(k) + "]",
                               "is a pointing goal; the overall step takes position targets "
                               "only (the passes, tractrix or ftl, take pointing goals)"));
    }
  }
  TreeOverallReport report;
  {  // the positions' and points' checks, before anything changes
    Points probe = *points;
    report.start = ReachTargets(reacher, positions, &probe);
    if (!report.start.reached && report.start.residual > kNewtonAfterStall) {
      // Out of reach: the passes' points, reported.
      *points = probe;
      report.objective = TreeObjective(reacher, options, *points, probe);
      report.length_error = TreeConstraintError(reacher, probe);
      return report;
    }
  }
  const auto continuation = [&](bool one_step) {
    return reacher.dim == 2
               ? TreeContinuation<2>(reacher, positions, options, points, report, one_step)
               : TreeContinuation<3>(reacher, positions, options, points, report, one_step);
  };
  const Points before = *points;
  TreeOverallReport result = continuation(false);
  if (!result.converged && report.start.reached != true && result.substeps > 1) {
    // The sub-steps' targets, on straight lines between the old and the new ones, need not be
    // reachable where the new ones are (a target a link away from a fixed point): from the
    // passes' points for the whole move in one step.
    *points = before;
    const int tried = result.iterations;
    result = continuation(true);
    result.iterations += tried;
  }
  return result;
}

// FinishTreeReach's sub-steps and Newton iterations a sub-step.
constexpr int kFinishSubsteps = 8;
constexpr int kFinishIterations = 100;

ReachReport FinishTreeReach(const TreeReacher& reacher, const Points& positions,
                            const ReachReport& passes, Points* points) {
  const Eigen::Index driven = static_cast<Eigen::Index>(reacher.target_points.size());
  const int count = static_cast<int>(reacher.parents.size());
  if (positions.rows() != driven || positions.cols() != reacher.dim || !positions.allFinite() ||
      points->rows() != count || points->cols() != reacher.dim || !points->allFinite()) {
    Points probe = *points;  // ReachTargets names the problem
    ReachTargets(reacher, positions, &probe);
  }
  const bool looks =
      std::find(reacher.looks.begin(), reacher.looks.end(), 1) != reacher.looks.end();
  if (passes.reached || looks || !(passes.residual <= kNewtonAfterStall)) return passes;
  TreeOverallOptions options;
  options.weights = ObjectiveWeights();
  options.weights.squared = 1.0;
  options.max_iterations = kFinishIterations;
  // The anchors move from where the passes left them to where they should be in sub-steps, each
  // solved by Newton from the last solution, the metric measured from the passes' points.
  Points p = *points;
  const Points stalled = *points;
  for (int j = 1; j <= kFinishSubsteps; ++j) {
    const double f = static_cast<double>(j) / kFinishSubsteps;
    for (int v = 0; v < count; ++v) {
      const int a = reacher.anchor_of[v];
      if (a < 0) continue;
      const Eigen::RowVectorXd goal = AnchorPlace(reacher, positions, a);
      p.row(v) = j == kFinishSubsteps
                     ? goal
                     : Eigen::RowVectorXd(stalled.row(v) + f * (goal - stalled.row(v)));
    }
    const int used = reacher.dim == 2
                         ? TreeKkt<2>(reacher, options.weights, stalled).Solve(options, &p)
                         : TreeKkt<3>(reacher, options.weights, stalled).Solve(options, &p);
    if (used < 0) return passes;
  }
  ReachReport report = passes;
  double residual = 0.0;
  for (int v = 0; v < count; ++v) {
    const int a = reacher.anchor_of[v];
    if (a >= 0)
      residual = std::max(residual, (p.row(v) - AnchorPlace(reacher, positions, a)).norm());
  }
  report.residual = residual / reacher.longest_link;
  report.reached = report.residual <= reacher.options.tolerance;
  report.finished = true;
  *points = p;
  return report;
}

}  // namespace flexkin
