// The tree's overall step posed to IPOPT (tree_overall_peer.h).
#include "tree_overall_peer.h"

#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>
#include <IpTNLP.hpp>
#include <chrono>
#include <stdexcept>

namespace flexkin::peers {
namespace {

class TreeStepNlp : public Ipopt::TNLP {
 public:
  TreeStepNlp(const Tree& tree, const Points& anchors_at, const std::vector<char>& anchored,
              const ObjectiveWeights& weights, const Points& old, const Points& start)
      : tree_(tree),
        at_(anchors_at),
        anchored_(anchored),
        weights_(weights),
        old_(old),
        start_(start),
        dim_(static_cast<int>(old.cols())) {
    const int count = static_cast<int>(tree.parents.size());
    index_.assign(count, -1);
    for (int i = 0; i < count; ++i) {
      if (!anchored_[i]) index_[i] = unknowns_++;
    }
    w_.assign(count, weights.squared);
    for (int i = 0; i < count; ++i) {
      const int p = tree.parents[i];
      if (p < 0) continue;
      const double length = (tree.points.row(i) - tree.points.row(p)).norm();
      w_[i] += 0.5 * weights.squared_weighted * length;
      w_[p] += 0.5 * weights.squared_weighted * length;
      if (index_[i] >= 0 || index_[p] >= 0) {
        links_.push_back(i);
        lengths_.push_back(length);
      }
    }
    result_ = start;
  }

  const Points& result() const { return result_; }
  double objective() const { return objective_; }

  bool get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac, Ipopt::Index& nnz_h,
                    IndexStyleEnum& style) override {
    n = unknowns_ * dim_;
    m = static_cast<Ipopt::Index>(links_.size());
    nnz_jac = 0;
    nnz_h = unknowns_ * dim_;
    for (int i : links_) {
      const int p = tree_.parents[i];
      nnz_jac += ((index_[i] >= 0) + (index_[p] >= 0)) * dim_;
      if (index_[i] >= 0 && index_[p] >= 0) nnz_h += dim_;
    }
    style = C_STYLE;
    return true;
  }
  bool get_bounds_info(Ipopt::Index n, Ipopt::Number* xl, Ipopt::Number* xu, Ipopt::Index m,
                       Ipopt::Number* gl, Ipopt::Number* gu) override {
    for (int k = 0; k < n; ++k) {
      xl[k] = -2e19;
      xu[k] = 2e19;
    }
    for (int k = 0; k < m; ++k) gl[k] = gu[k] = 0.0;
    return true;
  }
  bool get_starting_point(Ipopt::Index, bool init_x, Ipopt::Number* x, bool, Ipopt::Number*,
                          Ipopt::Number*, Ipopt::Index, bool, Ipopt::Number*) override {
    if (init_x) {
      for (size_t i = 0; i < index_.size(); ++i) {
        if (index_[i] < 0) continue;
        for (int k = 0; k < dim_; ++k) x[index_[i] * dim_ + k] = start_(i, k);
      }
    }
    return true;
  }
  // The point i at x (or its anchor), coordinate k.
  double P(const Ipopt::Number* x, int i, int k) const {
    return index_[i] >= 0 ? x[index_[i] * dim_ + k] : at_(i, k);
  }
  bool eval_f(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Number& f) override {
    f = 0.0;
    for (size_t i = 0; i < index_.size(); ++i) {
      if (index_[i] < 0) continue;
      for (int k = 0; k < dim_; ++k) {
        const double d = P(x, static_cast<int>(i), k) - old_(i, k);
        f += w_[i] * d * d;
      }
    }
    for (size_t l = 0; l < links_.size(); ++l) {
      const int i = links_[l], p = tree_.parents[i];
      for (int k = 0; k < dim_; ++k) {
        const double d = P(x, i, k) - P(x, p, k) - (old_(i, k) - old_(p, k));
        f += weights_.rotation * d * d / lengths_[l];
      }
    }
    return true;
  }
  bool eval_grad_f(Ipopt::Index n, const Ipopt::Number* x, bool, Ipopt::Number* g) override {
    for (int k = 0; k < n; ++k) g[k] = 0.0;
    for (size_t i = 0; i < index_.size(); ++i) {
      if (index_[i] < 0) continue;
      for (int k = 0; k < dim_; ++k) {
        g[index_[i] * dim_ + k] += 2.0 * w_[i] * (P(x, static_cast<int>(i), k) - old_(i, k));
      }
    }
    for (size_t l = 0; l < links_.size(); ++l) {
      const int i = links_[l], p = tree_.parents[i];
      for (int k = 0; k < dim_; ++k) {
        const double d = 2.0 * weights_.rotation *
                         (P(x, i, k) - P(x, p, k) - (old_(i, k) - old_(p, k))) / lengths_[l];
        if (index_[i] >= 0) g[index_[i] * dim_ + k] += d;
        if (index_[p] >= 0) g[index_[p] * dim_ + k] -= d;
      }
    }
    return true;
  }
  bool eval_g(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Index, Ipopt::Number* c) override {
    for (size_t l = 0; l < links_.size(); ++l) {
      const int i = links_[l], p = tree_.parents[i];
      double dd = 0.0;
      for (int k = 0; k < dim_; ++k) dd += (P(x, i, k) - P(x, p, k)) * (P(x, i, k) - P(x, p, k));
      c[l] = (dd - lengths_[l] * lengths_[l]) / (2.0 * lengths_[l]);
    }
    return true;
  }
  bool eval_jac_g(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Index, Ipopt::Index,
                  Ipopt::Index* row, Ipopt::Index* col, Ipopt::Number* v) override {
    int e = 0;
    for (size_t l = 0; l < links_.size(); ++l) {
      const int i = links_[l], p = tree_.parents[i];
      for (const int end : {i, p}) {
        if (index_[end] < 0) continue;
        for (int k = 0; k < dim_; ++k, ++e) {
          if (v == nullptr) {
            row[e] = static_cast<Ipopt::Index>(l);
            col[e] = index_[end] * dim_ + k;
          } else {
            const double d = (P(x, i, k) - P(x, p, k)) / lengths_[l];
            v[e] = end == i ? d : -d;
          }
        }
      }
    }
    return true;
  }
  bool eval_h(Ipopt::Index, const Ipopt::Number*, bool, Ipopt::Number sigma, Ipopt::Index,
              const Ipopt::Number* lambda, bool, Ipopt::Index, Ipopt::Index* row, Ipopt::Index* col,
              Ipopt::Number* v) override {
    // The diagonal entries first (one per unknown coordinate), then one off-diagonal entry per
    // coordinate of each link between two unknowns (the lower triangle).
    std::vector<double> diag(static_cast<size_t>(unknowns_), 0.0);
    int e = 0;
    for (size_t i = 0; i < index_.size(); ++i) {
      if (index_[i] < 0) continue;
      if (v != nullptr) diag[index_[i]] = sigma * 2.0 * w_[i];
    }
    for (size_t l = 0; l < links_.size() && v != nullptr; ++l) {
      const int i = links_[l], p = tree_.parents[i];
      const double kappa = (sigma * 2.0 * weights_.rotation + lambda[l]) / lengths_[l];
      if (index_[i] >= 0) diag[index_[i]] += kappa;
      if (index_[p] >= 0) diag[index_[p]] += kappa;
    }
    for (int u = 0; u < unknowns_; ++u) {
      for (int k = 0; k < dim_; ++k, ++e) {
        if (v == nullptr) {
          row[e] = col[e] = u * dim_ + k;
        } else {
          v[e] = diag[u];
        }
      }
    }
    for (size_t l = 0; l < links_.size(); ++l) {
      const int i = links_[l], p = tree_.parents[i];
      if (index_[i] < 0 || index_[p] < 0) continue;
      const int hi = std::max(index_[i], index_[p]), lo = std::min(index_[i], index_[p]);
      for (int k = 0; k < dim_; ++k, ++e) {
        if (v == nullptr) {
          row[e] = hi * dim_ + k;
          col[e] = lo * dim_ + k;
        } else {
          v[e] = -(sigma * 2.0 * weights_.rotation + lambda[l]) / lengths_[l];
        }
      }
    }
    return true;
  }
  void finalize_solution(Ipopt::SolverReturn, Ipopt::Index, const Ipopt::Number* x,
                         const Ipopt::Number*, const Ipopt::Number*, Ipopt::Index,
                         const Ipopt::Number*, const Ipopt::Number*, Ipopt::Number f,
                         const Ipopt::IpoptData*, Ipopt::IpoptCalculatedQuantities*) override {
    for (size_t i = 0; i < index_.size(); ++i) {
      for (int k = 0; k < dim_; ++k) result_(i, k) = P(x, static_cast<int>(i), k);
    }
    objective_ = f;
  }

 private:
  const Tree& tree_;
  const Points& at_;
  const std::vector<char>& anchored_;
  ObjectiveWeights weights_;
  const Points& old_;
  const Points& start_;
  int dim_;
  int unknowns_ = 0;
  std::vector<int> index_, links_;
  std::vector<double> w_, lengths_;
  Points result_;
  double objective_ = 0.0;
};

}  // namespace

TreeIpoptReport SolveTreeWithIpopt(const Tree& tree, const std::vector<int>& target_points,
                                   const Points& targets, const std::vector<int>& fixed,
                                   const ObjectiveWeights& weights, const Points& old,
                                   const Points& start, double tolerance, Points* points) {
  const int count = static_cast<int>(tree.parents.size());
  std::vector<char> anchored(count, 0);
  Points at = old;
  for (size_t k = 0; k < target_points.size(); ++k) {
    anchored[target_points[k]] = 1;
    at.row(target_points[k]) = targets.row(static_cast<Eigen::Index>(k));
  }
  for (int f : fixed) anchored[f] = 1;
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = new Ipopt::IpoptApplication(false);
  app->Options()->SetIntegerValue("print_level", 0);
  app->Options()->SetStringValue("sb", "yes");
  app->Options()->SetNumericValue("tol", tolerance);
  app->Options()->SetIntegerValue("max_iter", 500);
  app->Options()->SetStringValue("linear_solver", "mumps");
  if (app->Initialize("") != Ipopt::Solve_Succeeded) {
    throw std::runtime_error("IPOPT did not initialize");
  }
  Ipopt::SmartPtr<TreeStepNlp> nlp = new TreeStepNlp(tree, at, anchored, weights, old, start);
  const auto started = std::chrono::steady_clock::now();
  const Ipopt::ApplicationReturnStatus status = app->OptimizeTNLP(GetRawPtr(nlp));
  TreeIpoptReport report;
  report.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  report.converged = status == Ipopt::Solve_Succeeded;
  if (Ipopt::SmartPtr<Ipopt::SolveStatistics> stats = app->Statistics(); Ipopt::IsValid(stats)) {
    report.iterations = stats->IterationCount();
  }
  report.objective = nlp->objective();
  *points = nlp->result();
  return report;
}

}  // namespace flexkin::peers
