#pragma once
// The overall projection of a dynamic sub-step (docs/dynamics.md, "The overall projection's
// solver"): the least mass-weighted motion from the prediction p that gives every link its length,
//
//   minimize 1/2 sum_i m_i |x_i - p_i|^2  subject to  c_i = (|x_i - x_{i-1}|^2 - L_i^2) / 2 = 0,
//
// links i = head + 1 .. n, the points 0 .. head held where they are. Newton's method on the KKT
// conditions (SQP with the exact Hessian of the Lagrangian): each step minimizes
// 1/2 dx' H dx + g' dx subject to c_i + d_i . (dx_i - dx_{i-1}) = 0, with g_i = m_i (x_i - p_i),
// d_i = x_i - x_{i-1} and H = (M + the multipliers' chain Laplacian) x I, and its own multipliers
// are the next ones. H couples a point only to its neighbours, so the step is solved exactly by a
// recursion from the free end to the held points (the cost-to-go of the points beyond a point, a
// Dim x Dim quadratic in that point's step) and one sweep back: O(n) per Newton step, no
// pivoting, the same operations in every lane. Where compression (negative multipliers) would make
// a matrix of the recursion indefinite or nearly so, that lane's multipliers enter the Hessian
// clamped at -0.2 of its least mass (the model then stays positive definite, the iteration's fixed
// point is unchanged, and it converges linearly instead of quadratically).
//
// Written once for any lane type B: `double` (one chain, or one lane of the scalar strand engine:
// the very same operations) or an xsimd batch (strands_isa.cc, compiled per instruction set).
// Included by translation units built for different instruction sets: everything here has
// internal linkage.

#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>

namespace flexkin::internal {
namespace {

// Loads and stores of one lane (double) or of B::size lanes (a batch) at `p`.
inline double LoadLanes(const double* p, double) { return *p; }
inline void StoreLanes(double value, double* p) { *p = value; }
template <class B>
inline B LoadLanes(const double* p, B) {
  return B::load_aligned(p);
}
template <class B>
inline void StoreLanes(const B& value, double* p) {
  value.store_aligned(p);
}
template <class B>
constexpr int LanesOf() {
  if constexpr (std::is_same_v<B, double>) {
    return 1;
  } else {
    return static_cast<int>(B::size);
  }
}

// Lane-wise max, abs, select and "any lane": std's for double, xsimd's (by argument-dependent
// lookup) for a batch.
inline double MaxLanes(double a, double b) { return a > b ? a : b; }
template <class B>
inline B MaxLanes(const B& a, const B& b) {
  return max(a, b);
}
inline double AbsLanes(double a) { return std::fabs(a); }
template <class B>
inline B AbsLanes(const B& a) {
  return abs(a);
}
inline double SelectLanes(bool mask, double a, double b) { return mask ? a : b; }
template <class M, class B>
inline B SelectLanes(const M& mask, const B& a, const B& b) {
  return select(mask, a, b);
}
inline bool OrLanes(bool a, bool b) { return a || b; }
template <class M>
inline M OrLanes(const M& a, const M& b) {
  return a | b;
}
inline bool AndLanes(bool a, bool b) { return a && b; }
template <class M>
inline M AndLanes(const M& a, const M& b) {
  return a & b;
}
inline bool AnyLanes(bool mask) { return mask; }
template <class M>
inline bool AnyLanes(const M& mask) {
  return any(mask);
}

// One chain's (or a block of lanes') projection problem. Every array holds one lane's values
// `stride` apart (the lanes of a block in between): point i's coordinate k at (i Dim + k) stride,
// point i's mass at i stride, link i's length (1 <= i <= n) at (i - 1) stride.
struct LeastConstraintProblem {
  int n = 0, head = 0;
  size_t stride = 1;
  const double* p = nullptr;  // the prediction
  double* x = nullptr;        // in: a configuration with the lengths (the start); out: the result
  const double* mass = nullptr;
  const double* lengths = nullptr;
  const double* inv_lengths = nullptr;
  double* work = nullptr;  // LeastConstraintWork(Dim, n) values per lane (aligned as x)
  // If set: link i's multiplier at i stride, in: where Newton starts (the last sub-step's: they
  // change little from one to the next), out: the result's (0 where it did not converge). If not
  // set, Newton starts from multipliers 0.
  double* multipliers = nullptr;
  // If set: per lane (one value, at 0), 1 where the caller will not use the result: that lane
  // counts as converged from the start (its points and multipliers are then not meaningful).
  const double* ignore = nullptr;
  int max_iterations = 30;
};

// Per link: the inverse of (A + lambda I) (symmetric), the cost-to-go's gradient b, q (Dim
// each), 1 / s, the multiplier used, c, the multiplier, and the start's point (Dim).
template <int Dim>
constexpr int kLeastConstraintSlots = Dim*(Dim + 1) / 2 + 3 * Dim + 4;
inline size_t LeastConstraintWork(int dim, int n) {
  return static_cast<size_t>(n + 1) *
         (dim == 2 ? kLeastConstraintSlots<2> : kLeastConstraintSlots<3>);
}

// Index of entry (j, k) of a symmetric Dim x Dim matrix stored by its upper triangle's rows.
template <int Dim>
constexpr int Sym(int j, int k) {
  if (j > k) return Sym<Dim>(k, j);
  return j * Dim - j * (j - 1) / 2 + (k - j);
}

// The inverse of the symmetric `m` into `inv` (by cofactors). Returns 1 in the lanes where link
// i's sub-problem, min 1/2 z' m z + ... subject to d . z = given, has a unique minimizer, not
// nearly singular (`tiny` the smallest pivot of m's LDL' allowed), else 0: m positive definite
// across d. By Haynsworth's inertia formula, the bordered matrix [m d; d' 0] has m's inertia plus
// that of -s (s = d' m^-1 d), so: m positive definite and s > 0, or m with one negative
// eigenvalue and s < 0. (m's inertia is the number of sign changes along its leading minors.)
template <class B, int Dim>
inline B InverseSym(const B* m, const B* d, const B& tiny, B* inv, B* q, B* s) {
  B minors[Dim];
  if constexpr (Dim == 2) {
    const B det = m[0] * m[2] - m[1] * m[1];
    const B r = B(1.0) / det;
    inv[0] = m[2] * r;
    inv[1] = -m[1] * r;
    inv[2] = m[0] * r;
    minors[0] = m[0];
    minors[1] = det;
  } else {
    const B a = m[0], b = m[1], c = m[2], e = m[4], f = m[5], dd = m[3];
    const B c00 = dd * f - e * e, c01 = c * e - b * f, c02 = b * e - c * dd;
    const B det = a * c00 + b * c01 + c * c02;
    const B r = B(1.0) / det;
    const B c22 = a * dd - b * b;
    inv[0] = c00 * r;
    inv[1] = c01 * r;
    inv[2] = c02 * r;
    inv[3] = (a * f - c * c) * r;
    inv[4] = (b * c - a * e) * r;
    inv[5] = c22 * r;
    minors[0] = a;
    minors[1] = c22;
    minors[2] = det;
  }
  *s = B(0.0);
  for (int j = 0; j < Dim; ++j) {
    q[j] = B(0.0);
    for (int k = 0; k < Dim; ++k) q[j] += inv[Sym<Dim>(j, k)] * d[k];
    *s += d[j] * q[j];
  }
  B negative(0.0), small(0.0), above(1.0);
  for (int k = 0; k < Dim; ++k) {
    negative += SelectLanes(minors[k] * above < B(0.0), B(1.0), B(0.0));
    small += SelectLanes(AbsLanes(minors[k]) < tiny * AbsLanes(above), B(1.0), B(0.0));
    above = minors[k];
  }
  const auto good = AndLanes(small == B(0.0), OrLanes(AndLanes(negative == B(0.0), *s > B(0.0)),
                                                      AndLanes(negative == B(1.0), *s < B(0.0))));
  return SelectLanes(good, B(1.0), B(0.0));
}

// Solves the problem for the lanes at the pointers (B::size of them, or one for double). Returns
// 1 in each lane that converged, 0 in each that did not: that lane's `x` is left at the start.
// The result's lengths are restored to rounding by a last pass from the held points.
template <class B, int Dim>
B SolveLeastConstraint(const LeastConstraintProblem& pr) {
  constexpr int kSym = Dim * (Dim + 1) / 2;
  constexpr int kB = kSym, kQ = kB + Dim, kRs = kQ + Dim, kUsed = kRs + 1, kC = kUsed + 1,
                kLambda = kC + 1, kX0 = kLambda + 1, kSlots = kX0 + Dim;
  static_assert(kSlots == kLeastConstraintSlots<Dim>);
  using std::sqrt;
  const size_t st = pr.stride;
  const int n = pr.n, head = pr.head;
  const double* const P = pr.p;
  double* const X = pr.x;
  const double* const Mass = pr.mass;
  const double* const Len = pr.lengths;
  const double* const InvLen = pr.inv_lengths;
  double* const W = pr.work;
  // Point i's coordinate k; link i's slot j of the work; link i's length; point i's mass.
#define FLEXKIN_LC_PT(i, k) (static_cast<size_t>((i)*Dim + (k)) * st)
#define FLEXKIN_LC_SLOT(i, j) (static_cast<size_t>((i)*kSlots + (j)) * st)
#define FLEXKIN_LC_LINK(i) (static_cast<size_t>((i)-1) * st)

  // The start kept; the multipliers given, or 0 (the first step then the mass-weighted linearized
  // projection); the least mass, the scale of the clamp and of a singular pivot.
  B least_mass = LoadLanes(Mass + static_cast<size_t>(n) * st, B());
  for (int i = head + 1; i <= n; ++i) {
    for (int k = 0; k < Dim; ++k) {
      StoreLanes(LoadLanes(X + FLEXKIN_LC_PT(i, k), B()), W + FLEXKIN_LC_SLOT(i, kX0 + k));
    }
    StoreLanes(
        pr.multipliers ? LoadLanes(pr.multipliers + static_cast<size_t>(i) * st, B()) : B(0.0),
        W + FLEXKIN_LC_SLOT(i, kLambda));
    least_mass = -MaxLanes(-least_mass, -LoadLanes(Mass + static_cast<size_t>(i) * st, B()));
  }
  const B tiny = B(1e-6) * least_mass;

  // Converged: the step's largest part r (of its link's length) small enough that what is left,
  // at most r times the ratio r / (the step before), is below 1e-12; or r below 1e-13; or below
  // 1e-10 and no longer shrinking (the rounding's level, far from the origin).
  const B ignored = pr.ignore ? LoadLanes(pr.ignore, B()) : B(0.0);
  B done = ignored, previous(0.0);
  for (int iteration = 0; iteration < pr.max_iterations; ++iteration) {
    // From the free end: the cost-to-go of the points beyond point i - 1 as a function of its
    // step w, 1/2 w' A w + b' w, link by link. Where the multipliers leave a link's sub-problem
    // without a minimizer (or nearly so), that lane's multipliers enter clamped at -0.2 of its
    // least mass, for this step (at a strict minimizer every sub-problem has one: the steps near
    // it are Newton's).
    B clamp(-std::numeric_limits<double>::infinity());
    for (int pass = 0; pass < 2; ++pass) {
      B A[kSym], b[Dim], fit(1.0);
      for (int j = 0; j < kSym; ++j) A[j] = B(0.0);
      for (int k = 0; k < Dim; ++k) b[k] = B(0.0);
      for (int i = n; i > head; --i) {
        const B m = LoadLanes(Mass + static_cast<size_t>(i) * st, B());
        B d[Dim], dd(0.0);
        for (int k = 0; k < Dim; ++k) {
          const B xi = LoadLanes(X + FLEXKIN_LC_PT(i, k), B());
          A[Sym<Dim>(k, k)] += m;
          b[k] += m * (xi - LoadLanes(P + FLEXKIN_LC_PT(i, k), B()));
          d[k] = xi - LoadLanes(X + FLEXKIN_LC_PT(i - 1, k), B());
          dd += d[k] * d[k];
        }
        const B length = LoadLanes(Len + FLEXKIN_LC_LINK(i), B());
        const B c = B(0.5) * (dd - length * length);
        const B lambda = MaxLanes(LoadLanes(W + FLEXKIN_LC_SLOT(i, kLambda), B()), clamp);
        B bm[kSym], inv[kSym], q[Dim], s;
        for (int j = 0; j < kSym; ++j) bm[j] = A[j];
        for (int k = 0; k < Dim; ++k) bm[Sym<Dim>(k, k)] += lambda;
        fit = fit * InverseSym<B, Dim>(bm, d, tiny, inv, q, &s);
        B qb(0.0), ib[Dim];
        for (int j = 0; j < Dim; ++j) {
          ib[j] = B(0.0);
          for (int k = 0; k < Dim; ++k) ib[j] += inv[Sym<Dim>(j, k)] * b[k];
          qb += q[j] * b[j];
        }
        const B rs = B(1.0) / s;
        for (int j = 0; j < kSym; ++j) StoreLanes(inv[j], W + FLEXKIN_LC_SLOT(i, j));
        for (int k = 0; k < Dim; ++k) {
          StoreLanes(b[k], W + FLEXKIN_LC_SLOT(i, kB + k));
          StoreLanes(q[k], W + FLEXKIN_LC_SLOT(i, kQ + k));
        }
        StoreLanes(rs, W + FLEXKIN_LC_SLOT(i, kRs));
        StoreLanes(lambda, W + FLEXKIN_LC_SLOT(i, kUsed));
        StoreLanes(c, W + FLEXKIN_LC_SLOT(i, kC));
        // Link i's constraint eliminated: with u = (lambda q - d) / s and mu0 = (c - q.b) / s,
        // A <- lambda I - lambda^2 inv + s u u', b <- lambda inv b + mu0 s u.
        B u[Dim];
        for (int k = 0; k < Dim; ++k) u[k] = (lambda * q[k] - d[k]) * rs;
        const B mu0s = c - qb;
        const B lambda2 = lambda * lambda;
        for (int j = 0; j < Dim; ++j) {
          for (int k = j; k < Dim; ++k) {
            A[Sym<Dim>(j, k)] = s * u[j] * u[k] - lambda2 * inv[Sym<Dim>(j, k)];
          }
          A[Sym<Dim>(j, j)] += lambda;
          b[j] = lambda * ib[j] + mu0s * u[j];
        }
      }
      const auto unfit = fit == B(0.0);
      if (pass == 1 || !AnyLanes(unfit)) break;
      clamp = SelectLanes(unfit, B(-0.2) * least_mass, clamp);
    }
    // Back from the held points (their step 0): each point's step and its link's multiplier.
    B step[Dim], lead[Dim], r(0.0);  // lead: point i - 1 before its step
    for (int k = 0; k < Dim; ++k) {
      step[k] = B(0.0);
      lead[k] = LoadLanes(X + FLEXKIN_LC_PT(head, k), B());
    }
    for (int i = head + 1; i <= n; ++i) {
      const B lambda = LoadLanes(W + FLEXKIN_LC_SLOT(i, kUsed), B());
      B t[Dim], xi[Dim], qt(0.0), dw(0.0);
      for (int k = 0; k < Dim; ++k) {
        xi[k] = LoadLanes(X + FLEXKIN_LC_PT(i, k), B());
        t[k] = lambda * step[k] - LoadLanes(W + FLEXKIN_LC_SLOT(i, kB + k), B());
        qt += LoadLanes(W + FLEXKIN_LC_SLOT(i, kQ + k), B()) * t[k];
        dw += (xi[k] - lead[k]) * step[k];
      }
      const B mu = (qt - dw + LoadLanes(W + FLEXKIN_LC_SLOT(i, kC), B())) *
                   LoadLanes(W + FLEXKIN_LC_SLOT(i, kRs), B());
      StoreLanes(mu, W + FLEXKIN_LC_SLOT(i, kLambda));
      B largest(0.0);
      for (int j = 0; j < Dim; ++j) {
        B z = -mu * LoadLanes(W + FLEXKIN_LC_SLOT(i, kQ + j), B());
        for (int k = 0; k < Dim; ++k)
          z += LoadLanes(W + FLEXKIN_LC_SLOT(i, Sym<Dim>(j, k)), B()) * t[k];
        largest = MaxLanes(largest, AbsLanes(z));
        StoreLanes(xi[j] + z, X + FLEXKIN_LC_PT(i, j));
        step[j] = z;
        lead[j] = xi[j];
      }
      r = MaxLanes(r, largest * LoadLanes(InvLen + FLEXKIN_LC_LINK(i), B()));
    }
    const auto now = OrLanes(OrLanes(r * r <= B(1e-12) * previous, r <= B(1e-13)),
                             AndLanes(r <= B(1e-10), r >= B(0.5) * previous));
    done = SelectLanes(now, B(1.0), done);
    previous = r;
    if (!AnyLanes(done == B(0.0))) break;
  }

  // The lengths restored to rounding from the held points; a lane that did not converge back at
  // its start.
  const auto ok = done != B(0.0);
  for (int i = head + 1; i <= n; ++i) {
    B d[Dim], dd(0.0);
    for (int k = 0; k < Dim; ++k) {
      d[k] = LoadLanes(X + FLEXKIN_LC_PT(i, k), B()) - LoadLanes(X + FLEXKIN_LC_PT(i - 1, k), B());
      dd += d[k] * d[k];
    }
    const B f = LoadLanes(Len + FLEXKIN_LC_LINK(i), B()) / sqrt(dd);
    for (int k = 0; k < Dim; ++k) {
      const B placed = LoadLanes(X + FLEXKIN_LC_PT(i - 1, k), B()) + f * d[k];
      StoreLanes(SelectLanes(ok, placed, LoadLanes(W + FLEXKIN_LC_SLOT(i, kX0 + k), B())),
                 X + FLEXKIN_LC_PT(i, k));
    }
    if (pr.multipliers) {
      // (An ignored lane's kept as they were.)
      double* const at = pr.multipliers + static_cast<size_t>(i) * st;
      const B result = SelectLanes(ok, LoadLanes(W + FLEXKIN_LC_SLOT(i, kLambda), B()), B(0.0));
      StoreLanes(SelectLanes(ignored != B(0.0), LoadLanes(at, B()), result), at);
    }
  }
#undef FLEXKIN_LC_PT
#undef FLEXKIN_LC_SLOT
#undef FLEXKIN_LC_LINK
  return done;
}

}  // namespace
}  // namespace flexkin::internal
