#include "overall/retract.h"

#include <cassert>
#include <cmath>
#include <limits>

namespace flexkin::internal {
namespace {

// The follow-the-leader projection from the (fixed) head down: exact lengths in one pass.
// (Plain loops on the row-major storage, of the dimension `Dim` known at compile time: this runs
// for every trial point of the line search, a chain of a square root and a division per link.)
template <int Dim>
void RetractFollowTheLeader(const Eigen::VectorXd& lengths, Points* x) {
  assert(x->cols() == Dim && lengths.size() == x->rows() - 1);
  double* p = x->data();
  const double* const length = lengths.data();
  for (Eigen::Index i = 1; i < x->rows(); ++i) {
    double* point = p + i * Dim;
    const double* previous = point - Dim;
    double sq = 0.0;
    for (int k = 0; k < Dim; ++k) sq += (point[k] - previous[k]) * (point[k] - previous[k]);
    const double norm = std::sqrt(sq);
    if (!(norm > 0.0)) continue;
    const double f = length[i - 1] / norm;
    for (int k = 0; k < Dim; ++k) point[k] = previous[k] + f * (point[k] - previous[k]);
  }
}

// Least-change projection of points 1..moving onto the chain of links 1..moving+1 between the
// head and the fixed point moving+1: Gauss-Newton steps x -= J^T (J J^T)^-1 c(x) with
// c_i = (|D_i|^2 - L_i^2) / (2 L_i). J J^T is tridiagonal, so each step is linear.
bool RetractBetweenEnds(const Eigen::VectorXd& lengths, int moving, ChainSystem* system,
                        Points* x) {
  const int m = moving + 1;  // constraints
  const int dim = static_cast<int>(x->cols());
  MatrixView e = LeadingMatrix(&system->e, m, dim);  // rows: D_i / L_i
  VectorView c = Leading(&system->c, m), y = Leading(&system->y, m);
  double last_violation = std::numeric_limits<double>::infinity();
  for (int iteration = 0; iteration < 30; ++iteration) {
    double violation = 0.0;
    for (int i = 1; i <= m; ++i) {
      const double l = lengths[i - 1];
      e.row(i - 1) = (x->row(i) - x->row(i - 1)) / l;
      c[i - 1] = 0.5 * l * (e.row(i - 1).squaredNorm() - 1.0);
      violation = std::fmax(violation, std::fabs(c[i - 1]) / l);
    }
    if (!std::isfinite(violation)) return false;
    // Done at the rounding level, or when Gauss-Newton stops gaining (rounding reached).
    if (violation <= 4.0 * std::numeric_limits<double>::epsilon() ||
        (violation <= 1e-14 && violation >= 0.5 * last_violation)) {
      return true;
    }
    if (iteration > 0 && violation > 0.9 * last_violation && violation > 1e-8) return false;
    last_violation = violation;
    y = c;
    if (!SolveChainNormalEquations(e, moving, 1e-14, system, &y)) return false;
    // x -= J^T y.
    for (int i = 1; i <= m; ++i) {
      if (i <= moving) x->row(i) -= y[i - 1] * e.row(i - 1);
      if (i >= 2) x->row(i - 1) += y[i - 1] * e.row(i - 1);
    }
  }
  return false;
}

}  // namespace

void ChainSystem::Reserve(int m, int dim) {
  internal::Reserve(&e, static_cast<Eigen::Index>(m) * dim);
  for (Eigen::VectorXd* v : {&c, &y, &diag, &off}) internal::Reserve(v, m);
}

bool SolveChainNormalEquations(const MatrixView& e, int moving, double tiny, ChainSystem* system,
                               VectorView* rhs) {
  const int m = static_cast<int>(e.rows());
  VectorView diag = Leading(&system->diag, m), off = Leading(&system->off, m);
  VectorView& y = *rhs;
  for (int i = 1; i <= m; ++i) {
    diag[i - 1] = e.row(i - 1).squaredNorm() * ((i <= moving ? 1.0 : 0.0) + (i >= 2 ? 1.0 : 0.0));
    off[i - 1] = i < m ? -e.row(i - 1).dot(e.row(i)) : 0.0;  // (i, i+1), shared point x_i
  }
  for (int i = 1; i < m; ++i) {
    if (!(diag[i - 1] > 0.0)) return false;
    const double f = off[i - 1] / diag[i - 1];
    diag[i] -= f * off[i - 1];
    y[i] -= f * y[i - 1];
  }
  if (!(diag[m - 1] > tiny * diag.cwiseAbs().maxCoeff())) return false;
  y[m - 1] /= diag[m - 1];
  for (int i = m - 2; i >= 0; --i) y[i] = (y[i] - off[i] * y[i + 1]) / diag[i];
  return y.allFinite();
}

// (Plain loops: |D_i|^2 summed by coordinate in order, as Eigen's squaredNorm of a row sums 2 or 3
// entries; `worst` only grows where |c| is larger, as with std::fmax: worst is never NaN, and a
// NaN |c| is passed over.)
double ConstraintViolation(const Eigen::VectorXd& lengths, const Points& x) {
  assert(lengths.size() == x.rows() - 1);
  const int dim = static_cast<int>(x.cols());
  const double* const points = x.data();
  const double* const length = lengths.data();
  double worst = 0.0;
  for (Eigen::Index i = 1; i < x.rows(); ++i) {
    const double* const a = points + (i - 1) * dim;  // x_{i-1}, then x_i
    double sq = 0.0;
    for (int q = 0; q < dim; ++q) sq += (a[dim + q] - a[q]) * (a[dim + q] - a[q]);
    const double l = length[i - 1];
    const double c = std::fabs((sq - l * l) / (2.0 * l * l));
    if (c > worst) worst = c;
  }
  return worst;
}

bool Retract(const Eigen::VectorXd& lengths, int moving, ChainSystem* system, Points* x) {
  if (moving == lengths.size()) {
    if (x->cols() == 2) {
      RetractFollowTheLeader<2>(lengths, x);
    } else {
      RetractFollowTheLeader<3>(lengths, x);
    }
    return true;
  }
  return RetractBetweenEnds(lengths, moving, system, x);
}

}  // namespace flexkin::internal
