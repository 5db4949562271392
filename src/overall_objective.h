#pragma once
// The step metrics of the overall optimization and their derivatives, shared by the solver
// (overall.cc) and OverallObjective (overall_objective.cc).

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "flexkin/overall.h"

namespace flexkin::internal {

using Triplets = std::vector<Eigen::Triplet<double>>;

// Where the objective's derivatives go. Points are numbered 0..n; point 0 is fixed, so its
// entries are dropped. `offset(j)` is the first row of point j's coordinates in the unknowns.
struct Sink {
  int dim = 0;
  Eigen::VectorXd* gradient = nullptr;  // may be null
  Triplets* hessian = nullptr;          // may be null
  std::vector<int> offset;              // offset[j] for j = 1..n; offset[0] unused

  void Gradient(int j, const double* g, double scale) const {
    if (gradient == nullptr || j == 0) return;
    for (int k = 0; k < dim; ++k) (*gradient)[offset[j] + k] += scale * g[k];
  }
  // Adds scale * block (dim by dim, row-major in `b`) at (point p, point q).
  void Block(int p, int q, const double* b, double scale) const {
    if (hessian == nullptr || p == 0 || q == 0) return;
    for (int r = 0; r < dim; ++r) {
      for (int c = 0; c < dim; ++c) {
        // Zeros too: the pattern must not change between iterations.
        hessian->emplace_back(offset[p] + r, offset[q] + c, scale * b[r * dim + c]);
      }
    }
  }
  void Identity(int p, int q, double scale) const {
    if (hessian == nullptr || p == 0 || q == 0) return;
    for (int r = 0; r < dim; ++r) hessian->emplace_back(offset[p] + r, offset[q] + r, scale);
  }
};

// The metric of one step, from `old_points` to `x`, and (into `sink`) its derivatives.
double Evaluate(const ObjectiveWeights& w, const Eigen::VectorXd& lengths, const Points& old_points,
                const Points& x, const Sink& sink);

}  // namespace flexkin::internal
