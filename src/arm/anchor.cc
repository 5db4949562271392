// Batched atan2 and sine/cosine for the planar arm's re-anchoring (arm_anchor.h), AVX2 + FMA.
// Only the two functions of the header have external linkage; nothing here instantiates a
// template that another translation unit could share (checked with nm -C for weak symbols).
#include "arm/anchor.h"

#include <cmath>
#include <cstdint>
#include <xsimd/xsimd.hpp>

namespace flexkin::internal {
namespace {

using Arch = xsimd::fma3<xsimd::avx2>;
using B = xsimd::batch<double, Arch>;
constexpr int kWidth = B::size;  // 4

// Loads count - i (< kWidth) values from p + i into a batch, padded with `pad`.
B LoadTail(const double* p, int i, int count, double pad) {
  alignas(32) double v[kWidth];
  for (int l = 0; l < kWidth; ++l) v[l] = i + l < count ? p[i + l] : pad;
  return B::load_aligned(v);
}

void StoreTail(const B& b, int i, int count, double* p) {
  alignas(32) double v[kWidth];
  b.store_aligned(v);
  for (int l = 0; i + l < count; ++l) p[i + l] = v[l];
}

// sin(x) and cos(x). xsimd's sincos is not used: its reduction of huge arguments is an inline
// function with external linkage (a weak symbol that another instruction set's translation unit
// could share). Here x = k pi/2 + r, |r| <= pi/4, with pi/2 in three parts by fused
// multiply-adds (exact enough for |k| < 2^20, i.e. |x| < 1.6e6 rad; a batch with a larger or
// non-finite x is handed to the C library), then the Taylor polynomials of sin r (to r^17)
// and cos r (to r^18), truncation < 1e-19, and the quadrant's signs and swap.
void SinCos(const B& x, B* s, B* c) {
  if (xsimd::any(!(xsimd::abs(x) < B(1.6e6)))) {
    alignas(32) double v[kWidth], vs[kWidth], vc[kWidth];
    x.store_aligned(v);
    for (int l = 0; l < kWidth; ++l) vs[l] = std::sin(v[l]), vc[l] = std::cos(v[l]);
    *s = B::load_aligned(vs);
    *c = B::load_aligned(vc);
    return;
  }
  const B k = xsimd::nearbyint(x * B(0.63661977236758134308));  // x / (pi/2)
  B r = xsimd::fma(k, B(-1.5707963267948966), x);
  r = xsimd::fma(k, B(-6.123233995736766e-17), r);
  r = xsimd::fma(k, B(1.4973849048591698e-33), r);
  const B r2 = r * r;
  // sin r = r (1 - r^2/3! + ... + r^16/17!), cos r = 1 - r^2/2! + ... - r^18/18!: Horner in r^2,
  // the coefficients from the highest power down.
  constexpr double kSin[9] = {1.0 / 355687428096000.0,
                              -1.0 / 1307674368000.0,
                              1.0 / 6227020800.0,
                              -1.0 / 39916800.0,
                              1.0 / 362880.0,
                              -1.0 / 5040.0,
                              1.0 / 120.0,
                              -1.0 / 6.0,
                              1.0};
  constexpr double kCos[10] = {-1.0 / 6402373705728000.0,
                               1.0 / 20922789888000.0,
                               -1.0 / 87178291200.0,
                               1.0 / 479001600.0,
                               -1.0 / 3628800.0,
                               1.0 / 40320.0,
                               -1.0 / 720.0,
                               1.0 / 24.0,
                               -0.5,
                               1.0};
  B ps(kSin[0]);
  for (int i = 1; i < 9; ++i) ps = xsimd::fma(ps, r2, B(kSin[i]));
  B pc(kCos[0]);
  for (int i = 1; i < 10; ++i) pc = xsimd::fma(pc, r2, B(kCos[i]));
  const B sin_r = ps * r, cos_r = pc;
  // Quadrant q = k mod 4: (sin, cos) = (s, c), (c, -s), (-s, -c), (-c, s).
  const B kq = k - B(4.0) * xsimd::floor(k * B(0.25));  // 0, 1, 2 or 3
  const auto odd = (kq == B(1.0)) | (kq == B(3.0));
  const auto sin_negative = kq >= B(2.0);
  const auto cos_negative = (kq == B(1.0)) | (kq == B(2.0));
  const B sv = xsimd::select(odd, cos_r, sin_r), cv = xsimd::select(odd, sin_r, cos_r);
  *s = xsimd::select(sin_negative, -sv, sv);
  *c = xsimd::select(cos_negative, -cv, cv);
}

}  // namespace

void Atan2Avx2(const double* y, const double* x, int count, double* out) {
  int i = 0;
  for (; i + kWidth <= count; i += kWidth) {
    xsimd::atan2(B::load_unaligned(y + i), B::load_unaligned(x + i)).store_unaligned(out + i);
  }
  if (i < count)
    StoreTail(xsimd::atan2(LoadTail(y, i, count, 0.0), LoadTail(x, i, count, 1.0)), i, count, out);
}

void SinCosAvx2(const double* a, int count, double* s, double* c) {
  int i = 0;
  for (; i + kWidth <= count; i += kWidth) {
    B sn, cs;
    SinCos(B::load_unaligned(a + i), &sn, &cs);
    sn.store_unaligned(s + i);
    cs.store_unaligned(c + i);
  }
  if (i < count) {
    B sn, cs;
    SinCos(LoadTail(a, i, count, 0.0), &sn, &cs);
    StoreTail(sn, i, count, s);
    StoreTail(cs, i, count, c);
  }
}

}  // namespace flexkin::internal
