#pragma once
// Banded matrices for the overall solver, whose KKT matrix is banded in the interleaved order:
// storage that the solver assembles into directly, an LU factorization with partial pivoting,
// and the inertia of a symmetric banded matrix.
//
// The LU is LAPACK's dgbtf2/dgbtrs algorithm (same storage, same pivoting, so the same factors),
// written out here because the systems are small and solved thousands of times: the reference
// LAPACK spends most of its time in per-column BLAS calls at these sizes. tests/banded_lu_test.cc
// checks it against LAPACK's dgbtrf/dgbtrs.

#include <Eigen/Core>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <vector>

namespace flexkin::internal {

// A square matrix of half-bandwidth `band` (entries with |i - j| > band are 0), stored by
// columns in LAPACK's band layout: A(i, j) = ab[j * ldab + offset + i - j], with ldab = 2 band + 1
// and offset = band; or, with `room_for_fill`, ldab = 3 band + 1 and offset = 2 band, the extra
// rows above holding the fill-in of partial pivoting (BandedLu's own copy).
class BandMatrix {
 public:
  BandMatrix(int size, int band, bool room_for_fill = false)
      : size_(size),
        band_(band),
        ldab_((room_for_fill ? 3 : 2) * band + 1),
        offset_((room_for_fill ? 2 : 1) * band),
        ab_(static_cast<size_t>(ldab_) * size) {}

  int size() const { return size_; }
  int band() const { return band_; }
  void SetZero() { std::fill(ab_.begin(), ab_.end(), 0.0); }
  // Adds v to A(i, j); (i, j) must lie in the band.
  void Add(int i, int j, double v) {
    assert(i >= 0 && j >= 0 && i < size_ && j < size_ && std::abs(i - j) <= band_);
    ab_[Index(i, j)] += v;
  }
  double operator()(int i, int j) const {
    return std::abs(i - j) <= band_ ? ab_[Index(i, j)] : 0.0;
  }
  // y = A x for a symmetric A, from its lower band: y_i = (column i) . x over the band, since
  // A(i, j) = A(j, i). (Dot products: no chain of updates to the same y_i.)
  Eigen::VectorXd MultiplySymmetric(const Eigen::VectorXd& x) const {
    Eigen::VectorXd y(size_);
    const double* in = x.data();
    for (int i = 0; i < size_; ++i) {
      const int first = std::max(0, i - band_), last = std::min(size_ - 1, i + band_);
      const double* column = &ab_[Index(0, i)];  // column[j] = A(j, i) = A(i, j)
      double sum = 0.0;
      for (int j = first; j <= last; ++j) sum += column[j] * in[j];
      y[i] = sum;
    }
    return y;
  }
  // y = A x.
  Eigen::VectorXd Multiply(const Eigen::VectorXd& x) const {
    Eigen::VectorXd y = Eigen::VectorXd::Zero(size_);
    double* out = y.data();
    for (int j = 0; j < size_; ++j) {
      const double xj = x[j];
      if (xj == 0.0) continue;
      const int first = std::max(0, j - band_), last = std::min(size_ - 1, j + band_);
      const double* column = &ab_[Index(0, j)];
      for (int i = first; i <= last; ++i) out[i] += column[i] * xj;
    }
    return y;
  }

 private:
  friend class BandedLu;
  friend class BandedLdlt;
  size_t Index(int i, int j) const {
    return static_cast<size_t>(j) * ldab_ + (offset_ + i - j);
  }

  int size_, band_, ldab_, offset_;
  std::vector<double> ab_;
};

// LU factorization with partial pivoting of a BandMatrix. Cost O(size band^2).
class BandedLu {
 public:
  explicit BandedLu(const BandMatrix& shape)
      : lu_(shape.size(), shape.band(), /*room_for_fill=*/true), ipiv_(shape.size()) {}

  // Factors a copy of `a` (of the shape given at construction). False if it is singular.
  bool Factorize(const BandMatrix& a) {
    assert(a.size() == lu_.size_ && a.band() == lu_.band_);
    lu_.SetZero();
    for (int j = 0; j < a.size_; ++j) {
      const int first = std::max(0, j - a.band_), last = std::min(a.size_ - 1, j + a.band_);
      for (int i = first; i <= last; ++i) lu_.ab_[lu_.Index(i, j)] = a.ab_[a.Index(i, j)];
    }
    return FactorizeStorage();
  }

 private:
  bool FactorizeStorage() {
    const int n = lu_.size_, kl = lu_.band_, ku = lu_.band_;
    factorized_ = false;
    int ju = 0;  // the last column that the pivot rows so far reach
    for (int j = 0; j < n; ++j) {
      const int km = std::min(kl, n - 1 - j);
      double* column = &lu_.ab_[lu_.Index(j, j)];  // column[r] = A(j + r, j)
      int jp = 0;
      double largest = std::fabs(column[0]);
      for (int r = 1; r <= km; ++r) {
        const double v = std::fabs(column[r]);
        if (v > largest) {
          largest = v;
          jp = r;
        }
      }
      ipiv_[j] = j + jp;
      if (column[jp] == 0.0 || !std::isfinite(column[jp])) return false;
      ju = std::max(ju, std::min(j + ku + jp, n - 1));
      if (jp != 0) {
        for (int c = j; c <= ju; ++c) std::swap(lu_.ab_[lu_.Index(j, c)], lu_.ab_[lu_.Index(j + jp, c)]);
      }
      const double inverse = 1.0 / column[0];
      for (int r = 1; r <= km; ++r) column[r] *= inverse;
      for (int c = j + 1; c <= ju; ++c) {
        const double u = lu_.ab_[lu_.Index(j, c)];
        if (u == 0.0) continue;
        double* target = &lu_.ab_[lu_.Index(j, c)];  // target[r] = A(j + r, c)
        for (int r = 1; r <= km; ++r) target[r] -= column[r] * u;
      }
    }
    factorized_ = true;
    return true;
  }


 public:
  // Solves A x = rhs with the last factorization.
  Eigen::VectorXd Solve(const Eigen::VectorXd& rhs) const {
    assert(factorized_);
    const int n = lu_.size_, kl = lu_.band_, kv = 2 * lu_.band_;
    Eigen::VectorXd solution = rhs;
    double* b = solution.data();
    for (int j = 0; j < n; ++j) {  // L, with the row interchanges in order
      if (ipiv_[j] != j) std::swap(b[j], b[ipiv_[j]]);
      const int km = std::min(kl, n - 1 - j);
      const double* column = &lu_.ab_[lu_.Index(j, j)];
      const double bj = b[j];
      for (int r = 1; r <= km; ++r) b[j + r] -= column[r] * bj;
    }
    for (int j = n - 1; j >= 0; --j) {  // U, of half-bandwidth 2 band above the diagonal
      const double* column = &lu_.ab_[lu_.Index(j, j)];
      const double bj = b[j] / column[0];
      b[j] = bj;
      for (int i = std::max(0, j - kv); i < j; ++i) b[i] -= column[i - j] * bj;
    }
    return solution;
  }
  bool factorized() const { return factorized_; }

 private:
  BandMatrix lu_;
  std::vector<int> ipiv_;
  bool factorized_ = false;
};

// LDL^T factorization without pivoting of a symmetric BandMatrix (its lower band is read): a
// quarter of the LU's work, and the inertia comes with it (by Sylvester's law, the signs of the
// pivots). Without pivoting it can fail: Factorize returns false when a pivot is tiny, below
// `tiny` times the largest entry, and the caller then uses BandedLu (or decides another way).
class BandedLdlt {
 public:
  explicit BandedLdlt(const BandMatrix& shape)
      : size_(shape.size()),
        band_(shape.band()),
        l_(static_cast<size_t>(size_) * (band_ + 1)),
        inverse_pivot_(size_) {}

  bool Factorize(const BandMatrix& a, double tiny) {
    const int n = size_, band = band_, width = band + 1;
    double scale = 0.0;
    for (int j = 0; j < n; ++j) {
      double* column = &l_[static_cast<size_t>(j) * width];
      const double* source = &a.ab_[a.Index(j, j)];  // source[r] = A(j + r, j)
      const int last = std::min(n - 1 - j, band);
      double largest = 0.0;  // (per column: one long chain of max through `scale` is slow)
      for (int r = 0; r <= last; ++r) {
        column[r] = source[r];
        largest = std::max(largest, std::fabs(source[r]));
      }
      for (int r = last + 1; r <= band; ++r) column[r] = 0.0;
      scale = std::max(scale, largest);
    }
    negative_ = 0;
    factorized_ = false;
    for (int j = 0; j < n; ++j) {
      double* column = &l_[static_cast<size_t>(j) * width];
      const double pivot = column[0];
      if (!(std::fabs(pivot) > tiny * scale)) return false;
      if (pivot < 0.0) ++negative_;
      // A(i, k) -= A(i, j) A(k, j) / pivot for j < k <= i <= j + band, then L(i, j) = A(i, j) / pivot.
      const int last = std::min(n - 1, j + band);
      const double inverse = 1.0 / pivot;
      for (int k = j + 1; k <= last; ++k) {
        const double f = column[k - j] * inverse;
        if (f == 0.0) continue;
        double* target = &l_[static_cast<size_t>(k) * width];
        for (int i = k; i <= last; ++i) target[i - k] -= f * column[i - j];
      }
      for (int r = 1; r <= last - j; ++r) column[r] *= inverse;
      inverse_pivot_[j] = inverse;
    }
    factorized_ = true;
    return true;
  }
  // The number of negative pivots, i.e. of negative eigenvalues, of the last factorization.
  int negative() const { return negative_; }
  bool factorized() const { return factorized_; }

  Eigen::VectorXd Solve(const Eigen::VectorXd& rhs) const {
    assert(factorized_);
    const int n = size_, band = band_, width = band + 1;
    Eigen::VectorXd solution = rhs;
    double* y = solution.data();
    // L y = rhs by rows, y_i -= L(i, j) y_j, L(i, j) at l_[j width + i - j] (dot products: no
    // chain of updates to the same y_i), then D.
    for (int i = 1; i < n; ++i) {
      const int first = std::max(0, i - band);
      double yi = y[i];
      for (int j = first; j < i; ++j) yi -= l_[static_cast<size_t>(j) * width + (i - j)] * y[j];
      y[i] = yi;
    }
    for (int j = 0; j < n; ++j) y[j] *= inverse_pivot_[j];
    for (int j = n - 1; j >= 0; --j) {  // L^T x = y
      const double* column = &l_[static_cast<size_t>(j) * width];
      const int last = std::min(n - 1 - j, band);
      double yj = y[j];
      for (int r = 1; r <= last; ++r) yj -= column[r] * y[j + r];
      y[j] = yj;
    }
    return solution;
  }

 private:
  int size_, band_;
  std::vector<double> l_;  // column j: D(j) at [0], then L(j + r, j) at [r]
  std::vector<double> inverse_pivot_;  // 1 / D(j)
  int negative_ = 0;
  bool factorized_ = false;
};

}  // namespace flexkin::internal
