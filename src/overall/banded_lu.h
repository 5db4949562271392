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
// columns: A(i, j) = ab[j * ldab + offset + i - j]. Layouts:
//  - kGeneral: LAPACK's band layout, ldab = 2 band + 1 and offset = band;
//  - kWithFill: ldab = 3 band + 1 and offset = 2 band, the extra rows above holding the fill-in of
//    partial pivoting (BandedLu's own copy);
//  - kLowerSymmetric: a symmetric matrix by its lower band, ldab = band + 1 and offset = 0, with
//    `band` columns of room after the last (BandedLdlt factors it in place). Add() ignores entries
//    above the diagonal: symmetric assemblers add both (i, j) and (j, i).
class BandMatrix {
 public:
  enum class Layout { kGeneral, kWithFill, kLowerSymmetric };
  BandMatrix() = default;  // 0 by 0: Resize before use
  BandMatrix(int size, int band, Layout layout = Layout::kGeneral) { Resize(size, band, layout); }

  // Makes this a zero matrix of the given shape, reusing the storage (no allocation when it is
  // no larger than before: the overall solver's size changes with its active set).
  void Resize(int size, int band, Layout layout = Layout::kGeneral) {
    size_ = size;
    band_ = band;
    ldab_ = layout == Layout::kWithFill  ? 3 * band + 1
            : layout == Layout::kGeneral ? 2 * band + 1
                                         : band + 1;
    offset_ = layout == Layout::kWithFill ? 2 * band : layout == Layout::kGeneral ? band : 0;
    lower_ = layout == Layout::kLowerSymmetric;
    ab_.assign(static_cast<size_t>(ldab_) * (size + (lower_ ? band : 0)), 0.0);
  }

  // Makes room for a matrix of that shape without changing this one (the next Resize to it or
  // smaller then allocates nothing).
  void Reserve(int size, int band, Layout layout = Layout::kGeneral) {
    const int ldab = layout == Layout::kWithFill  ? 3 * band + 1
                     : layout == Layout::kGeneral ? 2 * band + 1
                                                  : band + 1;
    ab_.reserve(static_cast<size_t>(ldab) *
                (size + (layout == Layout::kLowerSymmetric ? band : 0)));
  }

  int size() const { return size_; }
  int band() const { return band_; }
  void SetZero() { std::fill(ab_.begin(), ab_.end(), 0.0); }
  // Adds v to A(i, j); (i, j) must lie in the band.
  void Add(int i, int j, double v) {
    assert(i >= 0 && j >= 0 && i < size_ && j < size_ && std::abs(i - j) <= band_);
    if (lower_ && i < j) return;
    ab_[Index(i, j)] += v;
  }
  // Adds v to A(i, j), i >= j, and to A(j, i) where the layout stores it: for symmetric
  // assemblers that write each entry's pair once, their pattern's bounds checked by the caller
  // (no check per entry).
  void AddSymmetric(int i, int j, double v) {
    ab_[Index(i, j)] += v;
    if (!lower_ && i != j) ab_[Index(j, i)] += v;
  }
  double operator()(int i, int j) const {
    if (lower_ && i < j) std::swap(i, j);
    return std::abs(i - j) <= band_ ? ab_[Index(i, j)] : 0.0;
  }
  // y = A x for a symmetric A (general layout): y_i = (column i) . x over the band, since
  // A(i, j) = A(j, i). (Dot products: no chain of updates to the same y_i.)
  Eigen::VectorXd MultiplySymmetric(const Eigen::VectorXd& x) const {
    assert(!lower_);
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
    assert(!lower_);
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
  size_t Index(int i, int j) const { return static_cast<size_t>(j) * ldab_ + (offset_ + i - j); }

  int size_ = 0, band_ = 0, ldab_ = 1, offset_ = 0;
  bool lower_ = false;
  std::vector<double> ab_;
};

// LU factorization with partial pivoting of a BandMatrix. Cost O(size band^2).
class BandedLu {
 public:
  BandedLu() = default;  // Resize before use
  explicit BandedLu(const BandMatrix& shape) { Resize(shape); }

  // Takes the shape of `shape`, reusing the storage.
  void Resize(const BandMatrix& shape) {
    lu_.Resize(shape.size(), shape.band(), BandMatrix::Layout::kWithFill);
    ipiv_.assign(shape.size(), 0);
    factorized_ = false;
  }
  // Makes room for factors of that shape without changing these.
  void Reserve(int size, int band) {
    lu_.Reserve(size, band, BandMatrix::Layout::kWithFill);
    ipiv_.reserve(size);
  }

  // Factors a copy of `a` (of the shape given at construction). False if it is singular.
  bool Factorize(const BandMatrix& a) {
    assert(a.size() == lu_.size_ && a.band() == lu_.band_ && !a.lower_);
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
        for (int c = j; c <= ju; ++c)
          std::swap(lu_.ab_[lu_.Index(j, c)], lu_.ab_[lu_.Index(j + jp, c)]);
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
    Eigen::VectorXd solution(rhs.size());
    SolveInto(rhs, solution);
    return solution;
  }
  // The same into `solution` (of the matrix's size; no allocation).
  void SolveInto(const Eigen::Ref<const Eigen::VectorXd>& rhs,
                 Eigen::Ref<Eigen::VectorXd> solution) const {
    assert(factorized_ && rhs.size() == lu_.size_ && solution.size() == lu_.size_);
    const int n = lu_.size_, kl = lu_.band_, kv = 2 * lu_.band_;
    solution = rhs;
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
  }
  bool factorized() const { return factorized_; }

 private:
  BandMatrix lu_;
  std::vector<int> ipiv_;
  bool factorized_ = false;
};

// LDL^T factorization without pivoting of a symmetric banded matrix: a quarter of the LU's
// work, and the inertia comes with it (by Sylvester's law, the signs of the pivots). Without
// pivoting it can fail or be inaccurate: Factorize returns false when a pivot is tiny (below
// `tiny` times the largest entry) or when the factors grew, and the caller then uses BandedLu
// (or decides another way). The growth bound: the computed factors are exact for A + E with
// |E| <= c eps |L| |D| |L^T| entrywise (the backward error of Gaussian elimination), and every
// entry of |L| |D| |L^T| is at most (band + 1) max_j |D(j)| max(1, max_i |L(i, j)|)^2; the
// factorization is accepted while that is within `max_growth` times the largest entry of A.
//
// The matrix is assembled into matrix() (lower symmetric layout) and factored in place. Its
// `band` columns of room after the last are set to the identity, so that every column's loops
// run over the full band (no end-of-matrix bounds): their entries are 0 off the diagonal and
// change nothing. The overall solver's half-bandwidths (5 and 7: 2 dim + 1 in 2D and 3D, 3 dim + 1
// with the joint-angle term in 2D) get loops of compile-time length, which the compiler unrolls:
// these small systems are solved at every Newton iteration.
class BandedLdlt {
 public:
  BandedLdlt() = default;  // Resize before use
  BandedLdlt(int size, int band) { Resize(size, band); }
  explicit BandedLdlt(const BandMatrix& shape) : BandedLdlt(shape.size(), shape.band()) {}

  // Takes the shape (size, band), reusing the storage; matrix() is then zero.
  void Resize(int size, int band) {
    size_ = size;
    band_ = band;
    a_.Resize(size, band, BandMatrix::Layout::kLowerSymmetric);
    inverse_pivot_.assign(size, 0.0);
    work_.assign(size + band, 0.0);
    growth_ = 0.0;
    negative_ = 0;
    factorized_ = false;
  }
  // Makes room for that shape without changing this factorization.
  void Reserve(int size, int band) {
    a_.Reserve(size, band, BandMatrix::Layout::kLowerSymmetric);
    inverse_pivot_.reserve(size);
    work_.reserve(size + band);
  }

  // Where to assemble the matrix to factor (call SetZero first); the factors replace it.
  BandMatrix& matrix() { return a_; }

  // Factors matrix() in place.
  bool Factorize(double tiny, double max_growth = 1e4) {
    const int n = size_, band = band_, width = band + 1;
    for (int j = n; j < n + band; ++j) {  // room after the last column: the identity
      double* column = &a_.ab_[static_cast<size_t>(j) * width];
      column[0] = 1.0;
      for (int r = 1; r <= band; ++r) column[r] = 0.0;
    }
    // The largest entry (Eigen's reduction runs in SIMD registers; a plain loop of std::max is
    // one latency-bound chain).
    const Eigen::Index stored = static_cast<Eigen::Index>(n) * width;
    const double scale =
        stored > 0 ? Eigen::Map<const Eigen::ArrayXd>(a_.ab_.data(), stored).abs().maxCoeff() : 0.0;
    bool ok = false;
    switch (band) {
      case 5:
        ok = Run<5>(tiny * scale);
        break;
      case 7:
        ok = Run<7>(tiny * scale);
        break;
      default:
        ok = Run<0>(tiny * scale);
    }
    factorized_ = ok && (band + 1) * growth_ <= max_growth * scale;
    return factorized_;
  }
  // Copies the lower band of `a` (any layout) into matrix() and factors it.
  bool Factorize(const BandMatrix& a, double tiny, double max_growth = 1e4) {
    assert(a.size() == size_ && a.band() == band_);
    a_.SetZero();
    for (int j = 0; j < size_; ++j) {
      for (int i = j; i <= std::min(size_ - 1, j + band_); ++i) a_.Add(i, j, a(i, j));
    }
    return Factorize(tiny, max_growth);
  }
  // The number of negative pivots, i.e. of negative eigenvalues, of the last factorization.
  int negative() const { return negative_; }
  bool factorized() const { return factorized_; }

  Eigen::VectorXd Solve(const Eigen::VectorXd& rhs) const {
    Eigen::VectorXd solution(size_);
    SolveInto(rhs, solution);
    return solution;
  }
  // Solve into `solution` (of the matrix's size; no allocation).
  void SolveInto(const Eigen::Ref<const Eigen::VectorXd>& rhs,
                 Eigen::Ref<Eigen::VectorXd> solution) const {
    assert(factorized_);
    switch (band_) {
      case 5:
        return SolveFixed<5>(rhs, solution);
      case 7:
        return SolveFixed<7>(rhs, solution);
      default:
        return SolveFixed<0>(rhs, solution);
    }
  }

 private:
  // The factorization proper, for half-bandwidth B (0: the run-time band_). Column j of the
  // storage: D(j) at [0], then L(j + r, j) at [r].
  //
  // Its speed is the chain from one pivot to the next, D(j + 1) = A(j + 1, j + 1) - (A(j + 1, j)
  // / D(j)) A(j + 1, j): a division, two multiplications and a subtraction per column. The next
  // pivot is therefore computed first and carried in a register (not stored and loaded back),
  // the other updates, off that chain, overlap with it; for the fixed bands the loops are
  // unrolled (straight-line code, no loop control). Every entry gets the same operations in the
  // same order as in the plain loop (each entry of the trailing block is updated once per
  // column), so the factors are the same to the last bit.
  template <int B>
  bool Run(double smallest) {
    const int n = size_, band = B > 0 ? B : band_, width = band + 1;
    double* const ab = a_.ab_.data();
    int negative = 0;
    double growth = 0.0;
    bool ok = true;
    double pivot = n > 0 ? ab[0] : 0.0;  // D(j), carried from column j - 1's update
    for (int j = 0; j < n; ++j) {
      double* const column = ab + static_cast<size_t>(j) * width;
      if (!(std::fabs(pivot) > smallest)) {
        ok = false;
        break;
      }
      if (pivot < 0.0) ++negative;
      // A(j + i, j + k) -= A(j + i, j) A(j + k, j) / pivot for 1 <= k <= i <= band (column
      // j + k of the factor), then L(j + r, j) = A(j + r, j) / pivot. (The columns after the
      // last are the identity, and the entries below the matrix 0: no bounds needed.)
      const double inverse = 1.0 / pivot;
      double next_pivot = column[width];  // A(j + 1, j + 1) (band 0: nothing to update)
      if (band >= 1) {
        const double f = column[1] * inverse;
        next_pivot -= f * column[1];
        column[width] = next_pivot;
        double* const target = column + width;
#pragma GCC unroll 8
        for (int i = 2; i <= band; ++i) target[i - 1] -= f * column[i];
      }
#pragma GCC unroll 8
      for (int k = 2; k <= band; ++k) {
        const double f = column[k] * inverse;
        double* const target = column + static_cast<size_t>(k) * width;
#pragma GCC unroll 8
        for (int i = k; i <= band; ++i) target[i - k] -= f * column[i];
      }
      // |D(j)| max(1, max_r |L(j + r, j)|)^2 = max(|pivot|, m^2 / |pivot|), m the largest
      // entry below the pivot before scaling.
      const double m = MaxBelowPivot<B>(column, band);
      growth = std::max(growth, std::max(std::fabs(pivot), m * m * std::fabs(inverse)));
#pragma GCC unroll 8
      for (int r = 1; r <= band; ++r) column[r] *= inverse;
      inverse_pivot_[j] = inverse;
      pivot = next_pivot;
    }
    negative_ = negative;
    growth_ = growth;
    return ok && std::isfinite(growth);
  }

  // max_{1 <= r <= band} |column[r]|, as a tree of independent comparisons for the fixed bands
  // (a chain of max would be as long as the band).
  template <int B>
  static double MaxBelowPivot(const double* column, int band) {
    auto a = [column](int r) { return std::fabs(column[r]); };
    if constexpr (B == 5) {
      return std::max(std::max(a(1), a(2)), std::max(std::max(a(3), a(4)), a(5)));
    } else if constexpr (B == 7) {
      return std::max(std::max(std::max(a(1), a(2)), std::max(a(3), a(4))),
                      std::max(std::max(a(5), a(6)), a(7)));
    } else {
      double even = 0.0, odd = 0.0;
      for (int r = 1; r + 1 <= band; r += 2) {
        odd = std::max(odd, a(r));
        even = std::max(even, a(r + 1));
      }
      if (band % 2 == 1) odd = std::max(odd, a(band));
      return std::max(even, odd);
    }
  }

  template <int B>
  void SolveFixed(const Eigen::Ref<const Eigen::VectorXd>& rhs,
                  Eigen::Ref<Eigen::VectorXd> solution) const {
    const int n = size_, band = B > 0 ? B : band_, width = band + 1;
    assert(rhs.size() == n && solution.size() == n);
    const double* l = a_.ab_.data();
    const double* const in = rhs.data();
    const double* const inverse_pivot = inverse_pivot_.data();
    double* y = work_.data();
    for (int i = 0; i < n; ++i) y[i] = in[i];
    for (int i = n; i < n + band; ++i) y[i] = 0.0;
    // L y = rhs by columns: y_{j+r} -= L(j + r, j) y_j. On the critical path is only y_{j+1}'s
    // update, one multiply-add per row. y_j is final once used: D^-1 is applied then.
    for (int j = 0; j < n; ++j) {
      const double* column = l + static_cast<size_t>(j) * width;
      const double yj = y[j];
#pragma GCC unroll 8
      for (int r = 1; r <= band; ++r) y[j + r] -= column[r] * yj;
      y[j] = yj * inverse_pivot[j];
    }
    // L^T x = y by rows, the term of x_{j+1} (just computed) last: again one multiply-add per row
    // on the critical path.
    if (band >= 1) {
      for (int j = n - 1; j >= 0; --j) {
        const double* column = l + static_cast<size_t>(j) * width;
        double others = 0.0;
#pragma GCC unroll 8
        for (int r = band; r >= 2; --r) others += column[r] * y[j + r];
        y[j] = (y[j] - others) - column[1] * y[j + 1];
      }
    }
    double* const out = solution.data();
    for (int i = 0; i < n; ++i) out[i] = y[i];
  }

  int size_ = 0, band_ = 0;
  BandMatrix a_;                       // the matrix, then its factors (lower symmetric layout)
  std::vector<double> inverse_pivot_;  // 1 / D(j)
  mutable std::vector<double> work_;   // the solve's right-hand side, padded
  double growth_ = 0.0;                // max_j |D(j)| max(1, max_i |L(i, j)|)^2
  int negative_ = 0;
  bool factorized_ = false;
};

}  // namespace flexkin::internal
