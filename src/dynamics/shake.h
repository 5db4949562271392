#pragma once
// The SHAKE projection of a dynamic sub-step (docs/dynamics.md): the correction of the prediction
// p along the links' directions at the sub-step's start,
//
//   x_j = p_j + w_j (lambda_j D_j - lambda_{j+1} D_{j+1}),
//
// w_j the inverse masses (0 for the held points 0 .. head), D_i = old_i - old_{i-1} the links at
// the start (D_{n+1} = 0), with the multipliers lambda that give every link i = head + 1 .. n its
// length: Newton's method on f_i = |x_i - x_{i-1}|^2 - L_i^2, whose Jacobian in lambda is
// tridiagonal (the Thomas algorithm, O(n) per step). A lane has converged when every |f_i| is at
// the rounding of its positions; it fails after 30 steps or where a multiplier is not finite
// (SHAKE's forces are the start's: past its stability limit the lengths have no solution).
//
// Written once for any lane type B: `double` (one chain, SimulateChain, or one lane of the scalar
// strand engine: the very same operations) or an xsimd batch (strands_isa.cc). Included by
// translation units built for different instruction sets: everything here has internal linkage.

#include <cmath>
#include <cstddef>
#include <limits>

#include "dynamics/least_constraint.h"

namespace flexkin::internal {
namespace {

// The multiplier, the residual, the Jacobian's three diagonals, the inverse mass and the old
// link, per point.
template <int Dim>
constexpr int kShakeSlots = 6 + Dim;
static_assert(kShakeSlots<2> <= kLeastConstraintSlots<2> &&
              kShakeSlots<3> <= kLeastConstraintSlots<3>);

// One chain's (or a block of lanes') SHAKE problem, laid out as LeastConstraintProblem's: point
// i's coordinate k at (i Dim + k) stride, point i's mass at i stride, link i's length at (i - 1)
// stride; `work` holds LeastConstraintWork(Dim, n) values per lane (it needs fewer).
struct ShakeProblem {
  int n = 0, head = 0;
  size_t stride = 1;
  const double* p = nullptr;    // the prediction (its held points are copied to x)
  const double* old = nullptr;  // the points at the sub-step's start
  double* x = nullptr;          // out: the projection (not meaningful where it did not converge)
  const double* mass = nullptr;
  const double* lengths = nullptr;
  double* work = nullptr;
  // If set: per lane (one value, at 0), 1 where the caller will not use the result: that lane
  // counts as converged from the start.
  const double* ignore = nullptr;
  int max_iterations = 30;
};

// Solves the problem for the lanes at the pointers (B::size of them, or one for double). Returns
// 1 in each lane that converged, 0 in each that did not.
template <class B, int Dim>
B SolveShake(const ShakeProblem& pr) {
  constexpr int kLambda = 0, kF = 1, kLower = 2, kDiag = 3, kUpper = 4, kW = 5, kD = 6;
  constexpr int kSlots = kShakeSlots<Dim>;
  const size_t st = pr.stride;
  const int n = pr.n, head = pr.head;
  double* const W = pr.work;
  double* const X = pr.x;
#define FLEXKIN_SH_PT(i, k) (static_cast<size_t>((i)*Dim + (k)) * st)
#define FLEXKIN_SH_SLOT(i, j) (static_cast<size_t>((i)*kSlots + (j)) * st)
  const auto load = [](const double* at) { return LoadLanes(at, B()); };
  // The inverse mass of point j (0 for the held points).
  const auto w = [&](int j) { return j > head ? load(W + FLEXKIN_SH_SLOT(j, kW)) : B(0.0); };
  for (int i = 0; i <= head; ++i) {
    for (int k = 0; k < Dim; ++k)
      StoreLanes(load(pr.p + FLEXKIN_SH_PT(i, k)), X + FLEXKIN_SH_PT(i, k));
  }
  for (int i = head + 1; i <= n; ++i) {
    StoreLanes(B(0.0), W + FLEXKIN_SH_SLOT(i, kLambda));
    StoreLanes(B(1.0) / load(pr.mass + static_cast<size_t>(i) * st), W + FLEXKIN_SH_SLOT(i, kW));
    for (int k = 0; k < Dim; ++k) {
      StoreLanes(load(pr.old + FLEXKIN_SH_PT(i, k)) - load(pr.old + FLEXKIN_SH_PT(i - 1, k)),
                 W + FLEXKIN_SH_SLOT(i, kD + k));
    }
  }
  // x from the multipliers.
  const auto place = [&]() {
    for (int j = head + 1; j <= n; ++j) {
      const B wj = w(j), lj = load(W + FLEXKIN_SH_SLOT(j, kLambda));
      const B lnext = j < n ? load(W + FLEXKIN_SH_SLOT(j + 1, kLambda)) : B(0.0);
      for (int k = 0; k < Dim; ++k) {
        const B dnext = j < n ? load(W + FLEXKIN_SH_SLOT(j + 1, kD + k)) : B(0.0);
        StoreLanes(load(pr.p + FLEXKIN_SH_PT(j, k)) +
                       wj * (lj * load(W + FLEXKIN_SH_SLOT(j, kD + k)) - lnext * dnext),
                   X + FLEXKIN_SH_PT(j, k));
      }
    }
  };
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  const B ignored = pr.ignore ? load(pr.ignore) : B(0.0);
  // done: converged (or ignored); failed: a multiplier not finite. Neither takes further steps.
  B done = ignored, failed(0.0);
  for (int iteration = 0; iteration < pr.max_iterations; ++iteration) {
    place();
    B worst(0.0);
    for (int i = head + 1; i <= n; ++i) {
      const B length = load(pr.lengths + static_cast<size_t>(i - 1) * st);
      const B wi = w(i), wl = w(i - 1);
      B d[Dim], dd(0.0), top_i(0.0), top_l(0.0);
      for (int k = 0; k < Dim; ++k) {
        const B xi = load(X + FLEXKIN_SH_PT(i, k)), xl = load(X + FLEXKIN_SH_PT(i - 1, k));
        d[k] = xi - xl;
        dd += d[k] * d[k];
        top_i = MaxLanes(top_i, AbsLanes(xi));
        top_l = MaxLanes(top_l, AbsLanes(xl));
      }
      const B f = dd - length * length;
      // |D|^2 - L^2 at the rounding of the positions: 2 |D| (eps |x|) each way.
      const B level = B(8.0 * kEps) * length * (top_i + top_l + length);
      const B ratio = AbsLanes(f) / level;
      worst = SelectLanes(ratio > worst, ratio, worst);  // a NaN ratio leaves it (as fmax)
      // d f_i / d lambda_{i-1}, lambda_i, lambda_{i+1}.
      B lower(0.0), diag(0.0), upper(0.0);
      for (int k = 0; k < Dim; ++k) {
        if (i > head + 1) lower += d[k] * (-wl * load(W + FLEXKIN_SH_SLOT(i - 1, kD + k)));
        diag += d[k] * ((wi + wl) * load(W + FLEXKIN_SH_SLOT(i, kD + k)));
        if (i < n) upper += d[k] * (-wi * load(W + FLEXKIN_SH_SLOT(i + 1, kD + k)));
      }
      StoreLanes(f, W + FLEXKIN_SH_SLOT(i, kF));
      StoreLanes(B(2.0) * lower, W + FLEXKIN_SH_SLOT(i, kLower));
      StoreLanes(B(2.0) * diag, W + FLEXKIN_SH_SLOT(i, kDiag));
      StoreLanes(B(2.0) * upper, W + FLEXKIN_SH_SLOT(i, kUpper));
    }
    // Every length at the rounding of the positions.
    done = SelectLanes(AndLanes(worst <= B(1.0), failed == B(0.0)), B(1.0), done);
    const auto active = AndLanes(done == B(0.0), failed == B(0.0));
    if (!AnyLanes(active)) break;
    // The tridiagonal solve, J delta = -f (the Thomas algorithm), and lambda -= delta.
    for (int i = head + 2; i <= n; ++i) {
      const B m = load(W + FLEXKIN_SH_SLOT(i, kLower)) / load(W + FLEXKIN_SH_SLOT(i - 1, kDiag));
      StoreLanes(load(W + FLEXKIN_SH_SLOT(i, kDiag)) - m * load(W + FLEXKIN_SH_SLOT(i - 1, kUpper)),
                 W + FLEXKIN_SH_SLOT(i, kDiag));
      StoreLanes(load(W + FLEXKIN_SH_SLOT(i, kF)) - m * load(W + FLEXKIN_SH_SLOT(i - 1, kF)),
                 W + FLEXKIN_SH_SLOT(i, kF));
    }
    B finite(1.0);
    for (int i = n; i > head; --i) {
      B f = load(W + FLEXKIN_SH_SLOT(i, kF));
      if (i < n)
        f = f - load(W + FLEXKIN_SH_SLOT(i, kUpper)) * load(W + FLEXKIN_SH_SLOT(i + 1, kF));
      f = f / load(W + FLEXKIN_SH_SLOT(i, kDiag));
      StoreLanes(f, W + FLEXKIN_SH_SLOT(i, kF));
      const B lambda = load(W + FLEXKIN_SH_SLOT(i, kLambda));
      const B next = lambda - f;
      finite =
          SelectLanes(AndLanes(active, !(AbsLanes(next) <= B(std::numeric_limits<double>::max()))),
                      B(0.0), finite);
      StoreLanes(SelectLanes(active, next, lambda), W + FLEXKIN_SH_SLOT(i, kLambda));
    }
    failed = SelectLanes(finite == B(0.0), B(1.0), failed);
  }
#undef FLEXKIN_SH_PT
#undef FLEXKIN_SH_SLOT
  return SelectLanes(AndLanes(done != B(0.0), failed == B(0.0)), B(1.0), B(0.0));
}

}  // namespace
}  // namespace flexkin::internal
