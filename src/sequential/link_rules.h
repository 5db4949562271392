#pragma once
// Per-link update rules used by every sweep, written once for a scalar `double` and for an
// xsimd batch (several lanes at once). Each rule updates `tail` in place and returns the mask of
// lanes that must be redone with the scalar reference form (rare: degenerate or extreme inputs).
// Everything here has internal linkage so that translation units compiled for different
// instruction sets never share a copy.

#include <cmath>
#include <limits>

namespace flexkin::internal {
namespace {

inline double select(bool mask, double a, double b) { return mask ? a : b; }
inline bool none(bool mask) { return !mask; }
inline bool all(bool mask) { return mask; }
inline double fma(double a, double b, double c) { return std::fma(a, b, c); }
// Lane mask of T: bool for a double, batch_bool for a batch.
template <class T>
using Mask = decltype(T() < T());

using std::abs;
using std::sqrt;

// exp of a non-positive argument; the wavefront engine substitutes a vector version.
struct StdExp {
  double operator()(double x) const { return std::exp(x); }
};

// a b - c d to within about one ulp even when the products nearly cancel (Kahan's algorithm; it
// needs a fused multiply-add).
template <class T>
inline T DiffOfProducts(T a, T b, T c, T d) {
  const T cd = c * d;
  return fma(a, b, -cd) + fma(-c, d, cd);
}

// v = dd r - (r.d) d = d x (r x d), the part of r across d scaled by dd, with r x d from
// DiffOfProducts: accurate relative to |v| even when r is nearly along d (exactly 0 if it is
// exactly along d), and so orthogonal to d to rounding. Returns |v|^2.
template <int Dim, class T>
inline T RejectAccurately(const T* r, const T* d, T dd, T* v) {
  if constexpr (Dim == 2) {
    const T c = DiffOfProducts(r[0], d[1], r[1], d[0]);
    v[0] = c * d[1];
    v[1] = -(c * d[0]);
    return (c * c) * dd;
  } else {
    const T w[3] = {DiffOfProducts(r[1], d[2], r[2], d[1]), DiffOfProducts(r[2], d[0], r[0], d[2]),
                    DiffOfProducts(r[0], d[1], r[1], d[0])};
    v[0] = d[1] * w[2] - d[2] * w[1];
    v[1] = d[2] * w[0] - d[0] * w[2];
    v[2] = d[0] * w[1] - d[1] * w[0];
    return dd * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  }
}

template <int Dim, class T>
inline T Dot(const T* a, const T* b) {
  T s = a[0] * b[0];
  for (int k = 1; k < Dim; ++k) s += a[k] * b[k];
  return s;
}

// Reference form of the tractrix step (scalar), used where the fast form could under- or
// overflow. Frame: u = unit direction of the head's move, r = tail - head_old = X0 u + v with
// v _|_ u, Y0 = |v|. The tail's velocity along the link gives dX/dp = -(1 - X^2/L^2), so
// phi = atanh(X/L) decreases linearly: phi(p) = phi0 - p/L with phi0 = asinh(X0/Y0), and
//   r_new = L (tanh(phi) u + sech(phi) v/Y0).
// asinh(X0/Y0) is exact as Y0 -> 0 (it goes to +-inf): no 1 + t*tau cancellation.
template <int Dim>
inline void TractrixStepReference(const double* head_old, const double* head_new, double* tail,
                                  double length) {
  double d[Dim], r[Dim];
  for (int k = 0; k < Dim; ++k) {
    d[k] = head_new[k] - head_old[k];
    r[k] = tail[k] - head_old[k];
  }
  // Lengths are scaled by their largest component before squaring so nothing over/underflows.
  auto norm = [](const double* x) {
    double m = 0.0;
    for (int k = 0; k < Dim; ++k) m = std::fmax(m, std::fabs(x[k]));
    if (m == 0.0) return 0.0;
    double s = 0.0;
    for (int k = 0; k < Dim; ++k) s += (x[k] / m) * (x[k] / m);
    return m * std::sqrt(s);
  };
  const double p = norm(d);
  if (p == 0.0) return;  // the head did not move
  const double inv_length = 1.0 / length;
  // In units of the link length: r_hat = r / L = x0 u + v, v from RejectAccurately (u.u = 1).
  double u[Dim], r_hat[Dim], v[Dim];
  for (int k = 0; k < Dim; ++k) {
    u[k] = d[k] / p;
    r_hat[k] = r[k] * inv_length;
  }
  const double x0 = Dot<Dim>(r_hat, u);
  RejectAccurately<Dim>(r_hat, u, 1.0, v);
  const double y0 = norm(v);
  if (y0 == 0.0 && x0 > 0.0) {
    // Exactly on the unstable equilibrium: the head moves straight at the tail, which is pushed
    // ahead of it; the link translates.
    for (int k = 0; k < Dim; ++k) tail[k] += d[k];
    return;
  }
  const double phi0 = (y0 == 0.0) ? -std::numeric_limits<double>::infinity() : std::asinh(x0 / y0);
  const double phi = phi0 - p * inv_length;  // may be -inf for huge moves of tiny links
  const double th = std::tanh(phi);
  const double sech = 1.0 / std::cosh(phi);  // cosh overflows to inf for |phi| > 710: sech = 0
  for (int k = 0; k < Dim; ++k) {
    const double across = (y0 > 0.0) ? sech * (v[k] / y0) : 0.0;
    tail[k] = head_new[k] + length * (th * u[k] + across);
  }
}

// Tractrix step in a rational form: one sqrt, one exp and one division.
// With E = exp(-p/L) and sigma = exp(phi), the reference form gives
//   pulling (X0 <= 0): sigma = Y0 E / (L - X0),   pushing (X0 > 0): sigma = (L + X0) E / Y0,
// and tanh, sech are rational in sigma. Scaling numerator and denominator by powers of p removes
// u = d/p and Y0 = |v|: with rd = r.d, dd = d.d, V = dd r - rd d (= p^2 v):
//   pulling: s1 = |V|^2 E^2,          s2 = (L p - rd)^2 dd,  c = 2 E (L p - rd) dd
//   pushing: s1 = (L p + rd)^2 E^2 dd, s2 = |V|^2,            c = 2 E (L p + rd) dd
//   r_new = L ((s1 - s2) d + c V) / (p (s1 + s2)).
// Each branch's denominator is a sum of non-negative terms: no cancellation. |r_new| = L holds
// algebraically (c^2 |V|^2 = 4 s1 s2 dd), so the length is kept to rounding and rounding never
// accumulates from step to step.
// Apart from E, r_new is homogeneous of degree 0 in d: the same r_new comes from d scaled by any
// factor, E kept. Where the motion dies out along a chain a link's move falls below about 1e-50
// of its length and the denominator (about L^2 p^5) under 1e-250; such lanes, and moves over
// about 1e50 links, are computed again in the same form with d scaled to the link's length, in
// the vector lanes (the other lanes keep their bits). Only lanes still out of range (a non-finite
// input, a link of extreme length) are flagged for the reference form.
template <int Dim, class Exp = StdExp>
struct TractrixRule {
  template <class T>
  static auto Apply(const T* head_old, const T* head_new, T* tail, T length, T neg_inv_length) {
    T d[Dim], r[Dim];
    for (int k = 0; k < Dim; ++k) {
      d[k] = head_new[k] - head_old[k];
      r[k] = tail[k] - head_old[k];
    }
    const T dd = Dot<Dim>(d, d);
    // Where the motion has died out the head does not move and neither does the tail. Lanes
    // that did not move among lanes that did keep their tail below.
    if (none(dd > T(0.0))) return Mask<T>(dd != dd);
    const T p = sqrt(dd);
    T out[Dim];
    const T den = Rational(d, r, dd, p, Exp()(p * neg_inv_length), head_new, length, out);
    const auto out_of_range = (den <= T(1e-250)) | (den >= T(1e250));
    if (none(out_of_range)) {
      for (int k = 0; k < Dim; ++k) tail[k] = out[k];
      return Mask<T>(den != den);
    }
    // A lane whose head did not move (dd = 0: every coordinate of the move below 1e-162, below
    // the rounding of any coordinate over 1e-146) keeps its tail, as the reference form does.
    const auto moved_out_of_range = out_of_range & (dd > T(0.0));
    if (none(moved_out_of_range)) {
      for (int k = 0; k < Dim; ++k) tail[k] = select(out_of_range, tail[k], out[k]);
      return Mask<T>(den != den);
    }
    // The move scaled to the link's length (its largest coordinate to L): the same r_new, the
    // terms in range. A lane that did not move keeps its tail, as above.
    T a = abs(d[0]);
    for (int k = 1; k < Dim; ++k) a = select(abs(d[k]) > a, abs(d[k]), a);
    const auto moved = dd > T(0.0);
    T scale = select(moved, length / select(a > T(0.0), a, length), T(1.0));
    scale = select(scale > T(1e300), T(1e300), scale);
    T ds[Dim], scaled[Dim];
    for (int k = 0; k < Dim; ++k) ds[k] = d[k] * scale;
    const T dds = Dot<Dim>(ds, ds);
    const T ps = sqrt(dds);
    const T den_scaled =
        Rational(ds, r, dds, ps, Exp()((ps / scale) * neg_inv_length), head_new, length, scaled);
    for (int k = 0; k < Dim; ++k) {
      tail[k] = select(out_of_range, select(moved, scaled[k], tail[k]), out[k]);
    }
    const auto scaled_bad =
        (den_scaled <= T(1e-250)) | (den_scaled >= T(1e250)) | (den_scaled != den_scaled);
    // NaN is in no range: a lane is flagged if its denominator is NaN, or if it moved out of
    // range and the scaled form is out of range too.
    return Mask<T>((den != den) | (out_of_range & moved & scaled_bad));
  }
  static void Reference(const double* head_old, const double* head_new, double* tail,
                        double length) {
    TractrixStepReference<Dim>(head_old, head_new, tail, length);
  }

 private:
  // The rational form for a move d (dd = d.d, p = |d|) with E = e: the new tail into `out`;
  // returns the denominator p (s1 + s2), whose range says whether `out` can be trusted.
  template <class T>
  static T Rational(const T* d, const T* r, T dd, T p, T e, const T* head_new, T length, T* out) {
    T v[Dim];
    const T rd = Dot<Dim>(r, d);
    const auto pulling = rd <= T(0.0);
    T m, s1, s2;
    if (all(pulling)) {
      // Pulling: v enters only beside the dominant (L p - rd)^2 dd term, so the plain form
      // (whose error is eps L p^2 absolute) moves the tail by rounding only.
      for (int k = 0; k < Dim; ++k) v[k] = dd * r[k] - rd * d[k];
      m = length * p - rd;
      s1 = (e * e) * Dot<Dim>(v, v);
      s2 = (m * m) * dd;
    } else {
      // Pushing: with the tail nearly ahead of the head, v is small and decides which way the
      // link swings; it needs full relative accuracy (and v.d = 0 keeps the length).
      const T vv = RejectAccurately<Dim>(r, d, dd, v);
      // m = L p - rd when pulling, L p + rd when pushing: L p + |rd|, no cancellation.
      m = length * p + abs(rd);
      const T mmdd = (m * m) * dd;
      s1 = (e * e) * select(pulling, vv, mmdd);
      s2 = select(pulling, mmdd, vv);
    }
    const T c = (e * m) * (dd + dd);
    const T den = p * (s1 + s2);
    const T f = length / den;
    const T g = f * (s1 - s2);
    const T h = f * c;
    for (int k = 0; k < Dim; ++k) out[k] = g * d[k] + (h * v[k] + head_new[k]);
    return den;
  }
};

// Follow-the-leader: the tail goes to the point of the sphere |x - head_new| = L nearest to it.
// If the head landed exactly on the tail the reference keeps the link's old direction.
template <int Dim>
struct FollowTheLeaderRule {
  template <class T>
  static auto Apply(const T* head_old, const T* head_new, T* tail, T length, T /*neg_inv_length*/) {
    // Where the motion has died out the head does not move; projecting the tail again would
    // only change it by rounding, so leave it (the same shortcut as the tractrix rule's).
    T d[Dim];
    for (int k = 0; k < Dim; ++k) d[k] = head_new[k] - head_old[k];
    if (none(Dot<Dim>(d, d) > T(0.0))) return Mask<T>(length != length);
    T r[Dim];
    for (int k = 0; k < Dim; ++k) r[k] = tail[k] - head_new[k];
    const T rr = Dot<Dim>(r, r);
    const T f = length / sqrt(rr);
    for (int k = 0; k < Dim; ++k) tail[k] = head_new[k] + f * r[k];
    return Mask<T>((rr <= T(0.0)) | (rr != rr));
  }
  static void Reference(const double* head_old, const double* head_new, double* tail,
                        double length) {
    double r[Dim];
    for (int k = 0; k < Dim; ++k) r[k] = tail[k] - head_new[k];
    double rr = Dot<Dim>(r, r);
    if (!(rr > 0.0)) {
      for (int k = 0; k < Dim; ++k) r[k] = tail[k] - head_old[k];
      rr = Dot<Dim>(r, r);
    }
    const double f = length / std::sqrt(rr);
    for (int k = 0; k < Dim; ++k) tail[k] = head_new[k] + f * r[k];
  }
};

// Scalar application of a rule with its fallback.
template <class Rule, int Dim>
inline void ApplyScalar(const double* head_old, const double* head_new, double* tail, double length,
                        double inv_length) {
  const double neg_inv_length = -inv_length;
  double saved[Dim];
  for (int k = 0; k < Dim; ++k) saved[k] = tail[k];
  if (Rule::Apply(head_old, head_new, tail, length, neg_inv_length)) {
    for (int k = 0; k < Dim; ++k) tail[k] = saved[k];
    Rule::Reference(head_old, head_new, tail, length);
  }
}

// Scalar steps of one link (the public TractrixStep and FollowTheLeaderStep call these).
template <int Dim>
inline void TractrixStep(const double* head_old, const double* head_new, double* tail,
                         double length, double inv_length) {
  ApplyScalar<TractrixRule<Dim>, Dim>(head_old, head_new, tail, length, inv_length);
}
template <int Dim>
inline void FollowTheLeaderStep(const double* head_old, const double* head_new, double* tail,
                                double length, double inv_length) {
  ApplyScalar<FollowTheLeaderRule<Dim>, Dim>(head_old, head_new, tail, length, inv_length);
}

}  // namespace
}  // namespace flexkin::internal
