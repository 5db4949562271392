#pragma once
// The step metrics of the overall optimization and their derivatives, shared by the solver
// (kkt.cc, active_set.cc) and OverallObjective (objective.cc).

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cassert>
#include <cstdlib>
#include <vector>

#include "flexkin/overall.h"
#include "overall/banded_lu.h"

namespace flexkin::internal {

using Triplets = std::vector<Eigen::Triplet<double>>;

// Where the objective's derivatives go. Points are numbered 0..n; point 0 is fixed, and so may be
// a tail of still points (the L2 metric's active set): their entries are dropped.
// `offset[j]` is the first row of point j's coordinates in the unknowns, or -1 for a fixed point.
struct Sink {
  int dim = 0;
  double* gradient = nullptr;  // indexed like the unknowns; may be null
  // The Hessian goes to `band` if set (the solver), else into the quadratic form
  // `*form` += v' H v with v = `form_vector` (indexed like the unknowns) if set, else to
  // `hessian` if set.
  BandMatrix* band = nullptr;
  double* form = nullptr;
  const double* form_vector = nullptr;
  Triplets* hessian = nullptr;
  std::vector<int> offset;  // offset[j] for j = 0..n; -1: point j is fixed
  // With `band`: if set, Identity() terms are summed here by point instead, s I at (j, j) into
  // identity_diagonal[j] and at (j, j - 1) into identity_below[j] (its mirror (j - 1, j) is not
  // summed again), and the caller writes them into the band in one pass. (Such terms, of the
  // squared and rotation metrics and of the constraints, couple neighbours only.)
  double* identity_diagonal = nullptr;
  double* identity_below = nullptr;
  // If set (n + 1 entries, [0] unused): the squared metric's weight of each point j instead of
  // squared + squared_weighted (L_j + L_{j+1}) / 2 (a dynamic chain's masses, dynamics.cc; the
  // squared or squared_weighted weight must be > 0 for the term to be evaluated).
  const double* point_weights = nullptr;

  bool WantsHessian() const { return band != nullptr || form != nullptr || hessian != nullptr; }
  void Gradient(int j, const double* g, double scale) const {
    if (gradient == nullptr || offset[j] < 0) return;
    for (int k = 0; k < dim; ++k) gradient[offset[j] + k] += scale * g[k];
  }
  // Adds scale * block (dim by dim, row-major in `b`) at (point p, point q).
  void Block(int p, int q, const double* b, double scale) const {
    if (!WantsHessian() || offset[p] < 0 || offset[q] < 0) return;
    for (int r = 0; r < dim; ++r) {
      for (int c = 0; c < dim; ++c) Add(offset[p] + r, offset[q] + c, scale * b[r * dim + c]);
    }
  }
  void Identity(int p, int q, double scale) const {
    if (band != nullptr && identity_diagonal != nullptr) {
      assert(std::abs(p - q) <= 1);
      if (p == q) {
        identity_diagonal[p] += scale;
      } else if (p == q + 1) {
        identity_below[p] += scale;
      }
      return;
    }
    if (!WantsHessian() || offset[p] < 0 || offset[q] < 0) return;
    for (int r = 0; r < dim; ++r) Add(offset[p] + r, offset[q] + r, scale);
  }
  void Add(int row, int col, double value) const {
    if (band != nullptr) {
      band->Add(row, col, value);
    } else if (form != nullptr) {
      *form += value * form_vector[row] * form_vector[col];
    } else {
      hessian->emplace_back(row, col, value);
    }
  }
};

// The metric of one step, from `old_points` to `x`, and (into `sink`) its derivatives. Only the
// terms of points 1..`last` and of the links and joints among points 0..`last` are evaluated
// (-1: all); the caller guarantees the others are 0 (points after `last` still).
// The L2 term contributes the subgradient 0 and no Hessian at a point that has not moved. With
// `smoothing` mu > 0 (a length), each |x_j - a_j| becomes sqrt(|x_j - a_j|^2 + mu^2): the
// solver's path into the kinks, never its answer.
double Evaluate(const ObjectiveWeights& w, const Eigen::VectorXd& lengths, const Points& old_points,
                const Points& x, const Sink& sink, int last = -1, double smoothing = 0.0);

// The L2 metric's weight of point j = 1..n: l2 + l2_weighted (L_j + L_{j+1}) / 2 (L_n / 2 at
// the trailing end).
double L2Weight(const ObjectiveWeights& w, const Eigen::VectorXd& lengths, int j);

// The sum of the weights, each scaled to a curvature (per unit length squared): the scale of the
// metric's Hessian, for the optimality measure's rounding level and the curvature test.
double WeightSum(const ObjectiveWeights& w, const Eigen::VectorXd& lengths);

}  // namespace flexkin::internal
