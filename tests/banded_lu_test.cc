// The overall solver's banded LU against LAPACK's dgbtrf/dgbtrs (the same algorithm, so the same
// answers to rounding) and against Eigen's dense LU, and its inertia count against the
// eigenvalues of the same symmetric matrices.

#include "overall/banded_lu.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cstddef>
#include <random>

extern "C" {
void dgbtrf_(const int* m, const int* n, const int* kl, const int* ku, double* ab, const int* ldab,
             int* ipiv, int* info);
void dgbtrs_(const char* trans, const int* n, const int* kl, const int* ku, const int* nrhs,
             const double* ab, const int* ldab, const int* ipiv, double* b, const int* ldb,
             int* info, size_t trans_length);
}

namespace flexkin::internal {
namespace {

// A random banded matrix (with a zero diagonal in every third row, as the KKT matrices have, so
// that pivoting is needed), as a BandMatrix and as a dense matrix.
void RandomBanded(int size, int band, bool symmetric, std::mt19937* rng, BandMatrix* a,
                  Eigen::MatrixXd* dense) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  *dense = Eigen::MatrixXd::Zero(size, size);
  for (int j = 0; j < size; ++j) {
    for (int i = std::max(0, j - band); i <= std::min(size - 1, j + band); ++i) {
      if (symmetric && i < j) continue;
      const double v = (i == j && i % 3 == 2) ? 0.0 : uniform(*rng);
      (*dense)(i, j) = v;
      if (symmetric) (*dense)(j, i) = v;
    }
  }
  for (int j = 0; j < size; ++j) {
    for (int i = std::max(0, j - band); i <= std::min(size - 1, j + band); ++i) {
      a->Add(i, j, (*dense)(i, j));
    }
  }
}

Eigen::VectorXd LapackSolve(const Eigen::MatrixXd& dense, int band, const Eigen::VectorXd& rhs) {
  const int n = static_cast<int>(dense.rows()), ldab = 3 * band + 1;
  std::vector<double> ab(static_cast<size_t>(ldab) * n, 0.0);
  for (int j = 0; j < n; ++j) {
    for (int i = std::max(0, j - band); i <= std::min(n - 1, j + band); ++i) {
      ab[static_cast<size_t>(j) * ldab + 2 * band + i - j] = dense(i, j);
    }
  }
  std::vector<int> ipiv(n);
  int info = 0;
  dgbtrf_(&n, &n, &band, &band, ab.data(), &ldab, ipiv.data(), &info);
  EXPECT_EQ(info, 0);
  Eigen::VectorXd x = rhs;
  const char trans = 'N';
  const int one = 1;
  dgbtrs_(&trans, &n, &band, &band, &one, ab.data(), &ldab, ipiv.data(), x.data(), &n, &info, 1);
  return x;
}

TEST(BandedLuTest, SolvesAsLapackAndDenseLuDo) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (const int band : {0, 1, 2, 5, 7}) {
    for (const int size : {1, 2, 3, 8, 31, 120}) {
      const int b = std::min(band, size - 1);
      BandMatrix a(size, b);
      Eigen::MatrixXd dense;
      RandomBanded(size, b, false, &rng, &a, &dense);
      if (band == 0) {
        for (int i = 0; i < size; ++i) {  // a diagonal matrix needs a non-zero diagonal
          a.Add(i, i, 2.0 - dense(i, i));
          dense(i, i) = 2.0;
        }
      }
      Eigen::VectorXd rhs(size);
      for (int i = 0; i < size; ++i) rhs[i] = uniform(rng);
      BandedLu lu(a);
      ASSERT_TRUE(lu.Factorize(a)) << "size " << size << " band " << b;
      const Eigen::VectorXd x = lu.Solve(rhs);
      const Eigen::VectorXd reference = LapackSolve(dense, b, rhs);
      const Eigen::VectorXd eigen = dense.partialPivLu().solve(rhs);
      EXPECT_LE((x - reference).norm(), 1e-13 * (1.0 + reference.norm()))
          << "size " << size << " band " << b;
      EXPECT_LE((x - eigen).norm(), 1e-9 * (1.0 + eigen.norm()))
          << "size " << size << " band " << b;
      EXPECT_LE((a.Multiply(x) - rhs).norm(), 1e-12 * (1.0 + rhs.norm()));
      EXPECT_LE((dense * x - rhs).norm(), 1e-12 * (1.0 + rhs.norm()));
    }
  }
}

TEST(BandedLuTest, ReportsASingularMatrix) {
  BandMatrix a(4, 1);
  a.Add(0, 0, 1.0);
  a.Add(1, 1, 1.0);  // rows 2 and 3 all zero
  BandedLu lu(a);
  EXPECT_FALSE(lu.Factorize(a));
  EXPECT_FALSE(lu.factorized());
}

TEST(BandedLuTest, LdltNegativePivotsCountNegativeEigenvalues) {
  std::mt19937 rng(11);
  int compared = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int size = 2 + trial % 40, band = 1 + trial % 8;
    const int b = std::min(band, size - 1);
    BandMatrix a(size, b);
    Eigen::MatrixXd dense;
    RandomBanded(size, b, true, &rng, &a, &dense);
    const Eigen::VectorXd eigenvalues =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(dense).eigenvalues();
    BandedLdlt ldlt(a);
    if (!ldlt.Factorize(a, 1e-12)) continue;  // a tiny pivot: undecided, allowed
    const int negative = ldlt.negative();
    EXPECT_EQ(negative, (eigenvalues.array() < 0.0).count()) << "trial " << trial;
    const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(size, -1.0, 2.0);
    EXPECT_LE((a.MultiplySymmetric(x) - dense * x).cwiseAbs().maxCoeff(), 1e-14 * size);
    // The solve (fixed-size kernels for bands 5 and 7, run-time band otherwise) against the
    // dense matrix, relative to the size of the solution.
    const Eigen::VectorXd rhs = dense * x;
    const Eigen::VectorXd solved = ldlt.Solve(rhs);
    EXPECT_LE((dense * solved - rhs).cwiseAbs().maxCoeff(),
              1e-10 * (1.0 + dense.cwiseAbs().maxCoeff() * solved.cwiseAbs().maxCoeff()))
        << "trial " << trial;
    ++compared;
  }
  EXPECT_GE(compared, 150);  // undecided must stay the exception
}

}  // namespace
}  // namespace flexkin::internal
