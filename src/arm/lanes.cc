// The fixed-base arm's sweeps for AVX2 + FMA (arm_lanes.h). CMakeLists.txt compiles this file
// with -mavx2 -mfma; src/arm/sweep.cc calls it only after checking that the CPU has both.
//
// A sweep is latency-bound: each link waits for the one before it, through a sqrt, an exp and a
// division. Two things shorten or fill that wait here, without touching the link rule
// (link_rules.h): the exp is evaluated with Estrin's scheme (a dependency chain of about 8
// operations instead of Horner's 14), and the point just placed stays in registers for the next
// link instead of going through memory. Several translations (the finite-difference lanes of a
// Jacobian) share one register, so they cost about one sweep.
#include "arm/lanes.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>
#include <xsimd/xsimd.hpp>

#include "chain/substep.h"
#include "sequential/link_rules.h"

namespace flexkin::internal {
namespace {

using Arch = xsimd::fma3<xsimd::avx2>;
using B = xsimd::batch<double, Arch>;
using I = xsimd::batch<int64_t, Arch>;
constexpr int kWidth = B::size;  // 4

// 1/k! for k = 0..13.
constexpr double kInvFactorial[14] = {1.0,
                                      1.0,
                                      0.5,
                                      1.0 / 6.0,
                                      1.0 / 24.0,
                                      1.0 / 120.0,
                                      1.0 / 720.0,
                                      1.0 / 5040.0,
                                      1.0 / 40320.0,
                                      1.0 / 362880.0,
                                      1.0 / 3628800.0,
                                      1.0 / 39916800.0,
                                      1.0 / 479001600.0,
                                      1.0 / 6227020800.0};

// exp(x) for x <= 0 (the link rule's exp(-p/L)); x is clamped to -708, where exp is 3.3e-308 and
// anything smaller is 0 to rounding in the rule. Cody-Waite reduction x = k ln2 + r, |r| <=
// ln2/2, then the Taylor polynomial of degree 13 (truncation < 5e-18 relative) by Estrin's
// scheme, and 2^k assembled in the exponent bits. Written once for a double and for a batch.
template <class T, class Int>
struct EstrinExpImpl {
  static T Fma(T a, T b, T c) {
    if constexpr (std::is_same_v<T, double>) {
      return std::fma(a, b, c);
    } else {
      return xsimd::fma(a, b, c);
    }
  }
  static T Max(T a, T b) {
    if constexpr (std::is_same_v<T, double>) {
      return a > b ? a : b;
    } else {
      return xsimd::max(a, b);
    }
  }
  T operator()(T x_in) const {
    const T x = Max(x_in, T(-708.0));
    // Adding 1.5 * 2^52 rounds to an integer held in the low mantissa bits.
    constexpr double kShift = 6755399441055744.0;
    const T shifted = Fma(x, T(1.4426950408889634074), T(kShift));  // x / ln2
    const T k = shifted - T(kShift);
    const T r = Fma(k, T(-1.9082149292705877000e-10), Fma(k, T(-6.9314718036912381649e-01), x));
    const T r2 = r * r, r4 = r2 * r2, r8 = r4 * r4;
    T q[7];
    for (int i = 0; i < 7; ++i) q[i] = Fma(T(kInvFactorial[2 * i + 1]), r, T(kInvFactorial[2 * i]));
    const T w0 = Fma(q[1], r2, q[0]), w1 = Fma(q[3], r2, q[2]), w2 = Fma(q[5], r2, q[4]);
    const T z0 = Fma(w1, r4, w0), z1 = Fma(q[6], r4, w2);
    const T poly = Fma(z1, r8, z0);
    // k is in [-1022, 0]: (k << 52) + bits(1.0) are the bits of 2^k.
    if constexpr (std::is_same_v<T, double>) {
      // Unsigned: the shift drops the high bits by design (a signed shift would overflow).
      uint64_t bits;
      std::memcpy(&bits, &shifted, sizeof bits);
      bits = (bits << 52) + uint64_t{0x3FF0000000000000};
      double scale;
      std::memcpy(&scale, &bits, sizeof scale);
      return poly * scale;
    } else {
      const Int bits = (xsimd::bitwise_cast<Int>(shifted) << 52) + Int(int64_t{0x3FF0000000000000});
      return poly * xsimd::bitwise_cast<T>(bits);
    }
  }
};

struct EstrinExp {
  double operator()(double x) const { return EstrinExpImpl<double, int64_t>()(x); }
  B operator()(const B& x) const { return EstrinExpImpl<B, I>()(x); }
};

// One translation, scalar. `p` holds the start already translated, swept in place.
template <int Dim>
void SweepOne(const double* target, int substeps, const double* lengths, const double* inv_lengths,
              int n, double* p) {
  using Rule = TractrixRule<Dim, EstrinExp>;
  double from[Dim];
  for (int k = 0; k < Dim; ++k) from[k] = p[n * Dim + k];
  for (int s = 1; s <= substeps; ++s) {
    double head_old[Dim], head[Dim];
    for (int k = 0; k < Dim; ++k) {
      head_old[k] = p[n * Dim + k];
      head[k] = internal::SubstepHead(from[k], target[k], s, substeps);
      p[n * Dim + k] = head[k];
    }
    for (int j = n; j >= 1; --j) {
      double tail[Dim], tail_old[Dim];
      for (int k = 0; k < Dim; ++k) tail[k] = tail_old[k] = p[(j - 1) * Dim + k];
      if (Rule::Apply(head_old, head, tail, lengths[j - 1], -inv_lengths[j - 1])) {
        for (int k = 0; k < Dim; ++k) tail[k] = tail_old[k];
        Rule::Reference(head_old, head, tail, lengths[j - 1]);
      }
      for (int k = 0; k < Dim; ++k) {
        p[(j - 1) * Dim + k] = tail[k];
        head_old[k] = tail_old[k];
        head[k] = tail[k];
      }
    }
  }
}

// Up to kWidth translations, one per lane; lanes past `lanes` repeat lane 0.
template <int Dim>
void SweepLanes(int lanes, const double* start, const double* u, const double* target, int substeps,
                const double* lengths, const double* inv_lengths, int n, double* points0,
                double* bases) {
  using Rule = TractrixRule<Dim, EstrinExp>;
  B shift[Dim];
  for (int k = 0; k < Dim; ++k) {
    alignas(32) double v[kWidth];
    for (int l = 0; l < kWidth; ++l) v[l] = u[(l < lanes ? l : 0) * Dim + k];
    shift[k] = B::load_aligned(v);
  }
  // The lanes' points, point i's coordinate k at buf[i * Dim + k].
  std::vector<B, xsimd::aligned_allocator<B>> buf((n + 1) * Dim);
  for (int i = 0; i <= n; ++i) {
    for (int k = 0; k < Dim; ++k) buf[i * Dim + k] = B(start[i * Dim + k]) + shift[k];
  }
  B from[Dim];
  for (int k = 0; k < Dim; ++k) from[k] = buf[n * Dim + k];
  for (int s = 1; s <= substeps; ++s) {
    const B fraction = B(double(s) / substeps);
    B head_old[Dim], head[Dim];
    for (int k = 0; k < Dim; ++k) {
      head_old[k] = buf[n * Dim + k];
      head[k] = s == substeps ? B(target[k]) : from[k] + (B(target[k]) - from[k]) * fraction;
      buf[n * Dim + k] = head[k];
    }
    for (int j = n; j >= 1; --j) {
      B tail[Dim], tail_old[Dim];
      for (int k = 0; k < Dim; ++k) tail[k] = tail_old[k] = buf[(j - 1) * Dim + k];
      const auto fix = Rule::Apply(head_old, head, tail, B(lengths[j - 1]), B(-inv_lengths[j - 1]));
      if (xsimd::any(fix)) {
        // Rare lanes (degenerate or extreme moves): redo them with the scalar reference.
        alignas(32) double ho[Dim][kWidth], hn[Dim][kWidth], old[Dim][kWidth], out[Dim][kWidth];
        alignas(32) double mask[kWidth];
        for (int k = 0; k < Dim; ++k) {
          head_old[k].store_aligned(ho[k]);
          head[k].store_aligned(hn[k]);
          tail_old[k].store_aligned(old[k]);
          tail[k].store_aligned(out[k]);
        }
        xsimd::select(fix, B(1.0), B(0.0)).store_aligned(mask);
        for (int l = 0; l < kWidth; ++l) {
          if (mask[l] == 0.0) continue;
          double a[Dim], b[Dim], c[Dim];
          for (int k = 0; k < Dim; ++k) a[k] = ho[k][l], b[k] = hn[k][l], c[k] = old[k][l];
          Rule::Reference(a, b, c, lengths[j - 1]);
          for (int k = 0; k < Dim; ++k) out[k][l] = c[k];
        }
        for (int k = 0; k < Dim; ++k) tail[k] = B::load_aligned(out[k]);
      }
      for (int k = 0; k < Dim; ++k) {
        buf[(j - 1) * Dim + k] = tail[k];
        head_old[k] = tail_old[k];
        head[k] = tail[k];
      }
    }
  }
  for (int i = 0; i <= n; ++i) {
    for (int k = 0; k < Dim; ++k) points0[i * Dim + k] = buf[i * Dim + k].get(0);
  }
  for (int k = 0; k < Dim; ++k) {
    alignas(32) double v[kWidth];
    buf[k].store_aligned(v);
    for (int l = 0; l < lanes; ++l) bases[l * Dim + k] = v[l];
  }
}

template <int Dim>
void Dispatch(int lanes, const double* start, const double* u, const double* target, int substeps,
              const double* lengths, const double* inv_lengths, int n, double* points0,
              double* bases) {
  if (lanes == 1) {
    for (int i = 0; i <= n; ++i) {
      for (int k = 0; k < Dim; ++k) points0[i * Dim + k] = start[i * Dim + k] + u[k];
    }
    SweepOne<Dim>(target, substeps, lengths, inv_lengths, n, points0);
    for (int k = 0; k < Dim; ++k) bases[k] = points0[k];
    return;
  }
  SweepLanes<Dim>(lanes, start, u, target, substeps, lengths, inv_lengths, n, points0, bases);
}

}  // namespace

void ArmSweepLanesAvx2(int dim, int lanes, const double* start, const double* u,
                       const double* target, int substeps, const double* lengths,
                       const double* inv_lengths, int n, double* points0, double* bases) {
  if (dim == 2) {
    Dispatch<2>(lanes, start, u, target, substeps, lengths, inv_lengths, n, points0, bases);
  } else {
    Dispatch<3>(lanes, start, u, target, substeps, lengths, inv_lengths, n, points0, bases);
  }
}

}  // namespace flexkin::internal
