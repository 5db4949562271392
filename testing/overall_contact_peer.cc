#include "overall_contact_peer.h"

#include <algorithm>
#include <cmath>

#include "ipopt_contact.h"

namespace flexkin::peers {
namespace {

using Ipopt::Index;
using Ipopt::Number;

// The objective's terms other than the L2 term.
double SmoothObjective(const OverallContactProblem& problem, const Eigen::MatrixXd& x) {
  double f = 0.0;
  const Eigen::Index n = problem.lengths.size();
  for (Eigen::Index j = 1; j <= n; ++j) {
    f += problem.squared * (x.row(j) - problem.old_points.row(j)).squaredNorm();
    const Eigen::RowVectorXd d =
        (x.row(j) - x.row(j - 1)) - (problem.old_points.row(j) - problem.old_points.row(j - 1));
    f += problem.rotation * d.squaredNorm() / problem.lengths[j - 1];
  }
  return f;
}

// Unknowns: points 1..n, dim coordinates each. Constraints: n lengths |D_i|^2 (= L_i^2), then
// for link i and sphere k the distance |p - c| (>= r), p the point of the segment nearest to c
// at s = clamp((c - a).(b - a) / |b - a|^2, 0, 1); its gradient by the envelope theorem:
// (1 - s) u in a, s u in b, u = (p - c) / |p - c|. The Hessian is IPOPT's limited-memory
// approximation.
class OverallContactNlp : public Ipopt::TNLP {
 public:
  OverallContactNlp(const OverallContactProblem& problem, const Eigen::MatrixXd& start)
      : p_(problem),
        start_(start),
        n_(static_cast<int>(problem.lengths.size())),
        dim_(static_cast<int>(problem.old_points.cols())) {}

  // The epigraph's unknowns t_j (after the points' n dim) and rows (after the links' and the
  // spheres'), with an L2 term.
  bool Cones() const { return p_.l2 > 0.0; }
  Index PointRows() const { return n_ + n_ * static_cast<Index>(p_.spheres.size()); }

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac_g, Index& nnz_h_lag,
                    IndexStyleEnum& index_style) override {
    n = n_ * dim_ + (Cones() ? n_ : 0);
    m = PointRows() + (Cones() ? n_ : 0);
    // Every link or sphere row: both ends of its link (link 1: entries 0); a cone: x_j and t_j.
    nnz_jac_g = PointRows() * 2 * dim_ + (Cones() ? n_ * (dim_ + 1) : 0);
    nnz_h_lag = 0;
    index_style = C_STYLE;
    return true;
  }
  bool get_bounds_info(Index n, Number* x_l, Number* x_u, Index m, Number* g_l,
                       Number* g_u) override {
    for (Index i = 0; i < n; ++i) x_l[i] = -1e19, x_u[i] = 1e19;
    for (Index i = n_ * dim_; i < n; ++i) x_l[i] = 0.0;  // t_j >= 0
    for (int i = 0; i < n_; ++i) g_l[i] = g_u[i] = p_.lengths[i] * p_.lengths[i];
    for (Index r = n_; r < PointRows(); ++r) {
      g_l[r] = p_.spheres[(r - n_) % p_.spheres.size()].radius;
      g_u[r] = 1e19;
    }
    for (Index r = PointRows(); r < m; ++r) g_l[r] = 0.0, g_u[r] = 1e19;
    return true;
  }
  bool get_starting_point(Index, bool, Number* x, bool, Number*, Number*, Index, bool,
                          Number*) override {
    for (int j = 1; j <= n_; ++j) {
      for (int q = 0; q < dim_; ++q) x[(j - 1) * dim_ + q] = start_(j, q);
      // t_j strictly inside its cone, by 1e-2 of the link.
      if (Cones()) {
        x[n_ * dim_ + j - 1] =
            (start_.row(j) - p_.old_points.row(j)).norm() + 1e-2 * p_.lengths[j - 1];
      }
    }
    return true;
  }
  bool eval_f(Index, const Number* x, bool, Number& f) override {
    f = SmoothObjective(p_, Points(x));
    for (int j = 0; Cones() && j < n_; ++j) f += p_.l2 * x[n_ * dim_ + j];
    return true;
  }
  bool eval_grad_f(Index, const Number* x, bool, Number* g) override {
    const Eigen::MatrixXd pts = Points(x);
    std::fill(g, g + n_ * dim_, 0.0);
    for (int j = 0; Cones() && j < n_; ++j) g[n_ * dim_ + j] = p_.l2;
    for (int j = 1; j <= n_; ++j) {
      for (int q = 0; q < dim_; ++q) {
        g[(j - 1) * dim_ + q] += 2.0 * p_.squared * (pts(j, q) - p_.old_points(j, q));
      }
    }
    for (int i = 1; i <= n_; ++i) {
      for (int q = 0; q < dim_; ++q) {
        const double d =
            (pts(i, q) - pts(i - 1, q)) - (p_.old_points(i, q) - p_.old_points(i - 1, q));
        const double w = 2.0 * p_.rotation * d / p_.lengths[i - 1];
        g[(i - 1) * dim_ + q] += w;
        if (i >= 2) g[(i - 2) * dim_ + q] -= w;
      }
    }
    return true;
  }
  bool eval_g(Index, const Number* x, bool, Index, Number* g) override {
    const Eigen::MatrixXd pts = Points(x);
    for (int i = 1; i <= n_; ++i) g[i - 1] = (pts.row(i) - pts.row(i - 1)).squaredNorm();
    for (int i = 1; i <= n_; ++i) {
      for (size_t k = 0; k < p_.spheres.size(); ++k) {
        double s = 0.0;
        g[n_ + (i - 1) * p_.spheres.size() + k] = Away(pts, i, p_.spheres[k].center, &s).norm();
      }
    }
    for (int j = 1; Cones() && j <= n_; ++j) {
      const double t = x[n_ * dim_ + j - 1];
      g[PointRows() + j - 1] = t * t - (pts.row(j) - p_.old_points.row(j)).squaredNorm();
    }
    return true;
  }
  bool eval_jac_g(Index, const Number* x, bool, Index, Index, Index* rows, Index* cols,
                  Number* values) override {
    // Row r's entries: point i-1's coordinates (link 1: the head, not an unknown: given the
    // column of point 1 and the value 0), then point i's.
    const auto link_of = [&](Index r) {
      return r < n_ ? static_cast<int>(r) + 1 : static_cast<int>((r - n_) / p_.spheres.size()) + 1;
    };
    const Index cones = PointRows() * 2 * dim_;  // the cones' first entry
    if (values == nullptr) {
      for (int j = 1; Cones() && j <= n_; ++j) {
        const Index at = cones + (j - 1) * (dim_ + 1);
        for (int q = 0; q < dim_; ++q) {
          rows[at + q] = PointRows() + j - 1;
          cols[at + q] = (j - 1) * dim_ + q;
        }
        rows[at + dim_] = PointRows() + j - 1;
        cols[at + dim_] = n_ * dim_ + j - 1;
      }
      for (Index r = 0; r < PointRows(); ++r) {
        const int i = link_of(r);
        for (int q = 0; q < dim_; ++q) {
          rows[r * 2 * dim_ + q] = r;
          cols[r * 2 * dim_ + q] = (i >= 2 ? i - 2 : i - 1) * dim_ + q;
          rows[r * 2 * dim_ + dim_ + q] = r;
          cols[r * 2 * dim_ + dim_ + q] = (i - 1) * dim_ + q;
        }
      }
      return true;
    }
    const Eigen::MatrixXd pts = Points(x);
    for (int j = 1; Cones() && j <= n_; ++j) {
      const Index at = cones + (j - 1) * (dim_ + 1);
      for (int q = 0; q < dim_; ++q) values[at + q] = -2.0 * (pts(j, q) - p_.old_points(j, q));
      values[at + dim_] = 2.0 * x[n_ * dim_ + j - 1];
    }
    for (Index r = 0; r < PointRows(); ++r) {
      const int i = link_of(r);
      Eigen::VectorXd ga(dim_), gb(dim_);
      if (r < n_) {
        for (int q = 0; q < dim_; ++q) {
          gb[q] = 2.0 * (pts(i, q) - pts(i - 1, q));
          ga[q] = -gb[q];
        }
      } else {
        double s = 0.0;
        const Eigen::Vector3d away =
            Away(pts, i, p_.spheres[(r - n_) % p_.spheres.size()].center, &s);
        const double d = away.norm();
        for (int q = 0; q < dim_; ++q) {
          const double u = d > 0.0 ? away[q] / d : 0.0;
          ga[q] = (1.0 - s) * u;
          gb[q] = s * u;
        }
      }
      for (int q = 0; q < dim_; ++q) {
        values[r * 2 * dim_ + q] = i >= 2 ? ga[q] : 0.0;
        values[r * 2 * dim_ + dim_ + q] = gb[q];
      }
    }
    return true;
  }
  void finalize_solution(Ipopt::SolverReturn, Index, const Number* x, const Number*, const Number*,
                         Index, const Number*, const Number*, Number, const Ipopt::IpoptData*,
                         Ipopt::IpoptCalculatedQuantities*) override {
    solution = Points(x);
  }

  Eigen::MatrixXd solution;

 private:
  Eigen::MatrixXd Points(const Number* x) const {
    Eigen::MatrixXd pts(n_ + 1, dim_);
    pts.row(0) = p_.head.transpose();
    for (int j = 1; j <= n_; ++j) {
      for (int q = 0; q < dim_; ++q) pts(j, q) = x[(j - 1) * dim_ + q];
    }
    return pts;
  }
  // p - c for link i's segment and the sphere center c (3D; z = 0 for a 2D chain).
  Eigen::Vector3d Away(const Eigen::MatrixXd& pts, int i, const Eigen::Vector3d& c,
                       double* s_out) const {
    Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
    for (int q = 0; q < dim_; ++q) a[q] = pts(i - 1, q), b[q] = pts(i, q);
    const Eigen::Vector3d ab = b - a;
    const double ab2 = ab.squaredNorm();
    const double s = ab2 > 0.0 ? std::clamp((c - a).dot(ab) / ab2, 0.0, 1.0) : 0.0;
    *s_out = s;
    return a + s * ab - c;
  }

  const OverallContactProblem p_;
  const Eigen::MatrixXd start_;
  const int n_, dim_;
};

}  // namespace

double OverallContactObjective(const OverallContactProblem& problem, const Eigen::MatrixXd& x) {
  double f = SmoothObjective(problem, x);
  for (Eigen::Index j = 1; j <= problem.lengths.size(); ++j) {
    f += problem.l2 * (x.row(j) - problem.old_points.row(j)).norm();
  }
  return f;
}

bool IpoptOverallContact(const OverallContactProblem& problem, const Eigen::MatrixXd& start,
                         Eigen::MatrixXd* x) {
  Ipopt::SmartPtr<OverallContactNlp> nlp = new OverallContactNlp(problem, start);
  const bool solved = SolveTightly(nlp, 5000);
  *x = nlp->solution;
  return solved;
}

}  // namespace flexkin::peers
