#include "contact_peer.h"

#include <algorithm>
#include <cmath>

#include "ipopt_contact.h"

namespace flexkin::peers {
namespace {

using Ipopt::Index;
using Ipopt::Number;

// Unknowns x (3); constraints g_0 = |x - h|^2 (= L^2) and g_k = |p_k - c_k| (>= r_k), p_k the
// point of the segment [h, x] nearest to c_k, at parameter s_k = clamp((c_k - h).(x - h) /
// |x - h|^2, 0, 1). By the envelope theorem the gradient of g_k in x is s_k (p_k - c_k) / |p_k -
// c_k|. The Hessian is left to IPOPT's limited-memory approximation.
class ContactNlp : public Ipopt::TNLP {
 public:
  ContactNlp(const Eigen::Vector3d& head, const Eigen::Vector3d& tail, double length,
             const std::vector<SphereObstacle>& spheres, const Eigen::Vector3d& start)
      : head_(head), tail_(tail), length_(length), spheres_(spheres), start_(start) {}

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac_g, Index& nnz_h_lag,
                    IndexStyleEnum& index_style) override {
    n = 3;
    m = 1 + static_cast<Index>(spheres_.size());
    nnz_jac_g = 3 * m;
    nnz_h_lag = 0;
    index_style = C_STYLE;
    return true;
  }
  bool get_bounds_info(Index n, Number* x_l, Number* x_u, Index m, Number* g_l,
                       Number* g_u) override {
    for (Index i = 0; i < n; ++i) x_l[i] = -1e19, x_u[i] = 1e19;
    g_l[0] = g_u[0] = length_ * length_;
    for (Index k = 1; k < m; ++k) g_l[k] = spheres_[k - 1].radius, g_u[k] = 1e19;
    return true;
  }
  bool get_starting_point(Index, bool, Number* x, bool, Number*, Number*, Index, bool,
                          Number*) override {
    for (int i = 0; i < 3; ++i) x[i] = start_[i];
    return true;
  }
  bool eval_f(Index, const Number* x, bool, Number& f) override {
    f = (Eigen::Map<const Eigen::Vector3d>(x) - tail_).squaredNorm();
    return true;
  }
  bool eval_grad_f(Index, const Number* x, bool, Number* g) override {
    for (int i = 0; i < 3; ++i) g[i] = 2.0 * (x[i] - tail_[i]);
    return true;
  }
  bool eval_g(Index, const Number* x, bool, Index m, Number* g) override {
    const Eigen::Vector3d p(x[0], x[1], x[2]);
    g[0] = (p - head_).squaredNorm();
    for (Index k = 1; k < m; ++k) g[k] = Nearest(p, spheres_[k - 1].center).norm();
    return true;
  }
  bool eval_jac_g(Index, const Number* x, bool, Index m, Index, Index* rows, Index* cols,
                  Number* values) override {
    if (values == nullptr) {
      for (Index k = 0; k < m; ++k) {
        for (Index i = 0; i < 3; ++i) rows[3 * k + i] = k, cols[3 * k + i] = i;
      }
      return true;
    }
    const Eigen::Vector3d p(x[0], x[1], x[2]);
    for (int i = 0; i < 3; ++i) values[i] = 2.0 * (p[i] - head_[i]);
    for (Index k = 1; k < m; ++k) {
      double s = 0.0;
      const Eigen::Vector3d away = Nearest(p, spheres_[k - 1].center, &s);
      const double d = away.norm();
      for (int i = 0; i < 3; ++i) values[3 * k + i] = d > 0.0 ? s * away[i] / d : 0.0;
    }
    return true;
  }
  void finalize_solution(Ipopt::SolverReturn, Index, const Number* x, const Number*, const Number*,
                         Index, const Number*, const Number*, Number, const Ipopt::IpoptData*,
                         Ipopt::IpoptCalculatedQuantities*) override {
    solution = Eigen::Vector3d(x[0], x[1], x[2]);
  }

  Eigen::Vector3d solution;

 private:
  // p_k - c for the segment [head, x].
  Eigen::Vector3d Nearest(const Eigen::Vector3d& x, const Eigen::Vector3d& c,
                          double* s_out = nullptr) const {
    const Eigen::Vector3d ab = x - head_;
    const double ab2 = ab.squaredNorm();
    const double s = ab2 > 0.0 ? std::clamp((c - head_).dot(ab) / ab2, 0.0, 1.0) : 0.0;
    if (s_out != nullptr) *s_out = s;
    return head_ + s * ab - c;
  }

  const Eigen::Vector3d head_, tail_;
  const double length_;
  const std::vector<SphereObstacle> spheres_;
  const Eigen::Vector3d start_;
};

}  // namespace

bool IpoptContactTail(const Eigen::Vector3d& head, const Eigen::Vector3d& tail, double length,
                      const std::vector<SphereObstacle>& spheres, const Eigen::Vector3d& start,
                      Eigen::Vector3d* x) {
  Ipopt::SmartPtr<ContactNlp> nlp = new ContactNlp(head, tail, length, spheres, start);
  const bool solved = SolveTightly(nlp, 3000);
  *x = nlp->solution;
  return solved;
}

}  // namespace flexkin::peers
