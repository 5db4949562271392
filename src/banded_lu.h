#pragma once
// LU factorization of a banded matrix built from triplets, on LAPACK's dgbtrf/dgbtrs (used by
// the overall solver: its KKT matrix is banded in the interleaved order).

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cassert>
#include <cstdlib>
#include <vector>

// LAPACK's banded LU with partial pivoting (Fortran interface; the trailing size_t is the hidden
// length of the character argument).
extern "C" {
void dgbtrf_(const int* m, const int* n, const int* kl, const int* ku, double* ab, const int* ldab,
             int* ipiv, int* info);
void dgbtrs_(const char* trans, const int* n, const int* kl, const int* ku, const int* nrhs,
             const double* ab, const int* ldab, const int* ipiv, double* b, const int* ldb,
             int* info, size_t trans_length);
}

namespace flexkin::internal {

using Triplets = std::vector<Eigen::Triplet<double>>;

// LU factorization of a square banded matrix (half-bandwidth `band` above and below), built from
// triplets (duplicates summed). Cost linear in the size for a fixed band.
class BandedLu {
 public:
  BandedLu(int size, int band)
      : size_(size),
        band_(band),
        ldab_(3 * band + 1),
        ab_(static_cast<size_t>(ldab_) * size),
        ipiv_(size) {}

  // False if the matrix is singular (or a triplet lies outside the band: a bug).
  bool Factorize(const Triplets& triplets) {
    std::fill(ab_.begin(), ab_.end(), 0.0);
    for (const auto& t : triplets) {
      const int i = t.row(), j = t.col();
      assert(std::abs(i - j) <= band_);
      ab_[static_cast<size_t>(j) * ldab_ + (2 * band_ + i - j)] += t.value();
    }
    int info = 0;
    dgbtrf_(&size_, &size_, &band_, &band_, ab_.data(), &ldab_, ipiv_.data(), &info);
    factorized_ = info == 0;
    return factorized_;
  }
  Eigen::VectorXd Solve(const Eigen::VectorXd& rhs) const {
    Eigen::VectorXd x = rhs;
    const char trans = 'N';
    const int one = 1;
    int info = 0;
    dgbtrs_(&trans, &size_, &band_, &band_, &one, ab_.data(), &ldab_, ipiv_.data(), x.data(),
            &size_, &info, 1);
    return x;
  }
  bool factorized() const { return factorized_; }

 private:
  int size_, band_, ldab_;
  std::vector<double> ab_;
  std::vector<int> ipiv_;
  bool factorized_ = false;
};

}  // namespace flexkin::internal
