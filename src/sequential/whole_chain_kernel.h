#pragma once
// The whole-chain kernel (whole_chain.h), templated on the xsimd instruction set. Included only by
// the per-instruction-set translation unit wavefront_isa.cc.

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <xsimd/xsimd.hpp>

#include "sequential/sweep.h"
#include "sequential/whole_chain.h"

namespace flexkin::internal {
namespace {

// [a_{W-1}, b0, b1, ..., b_{W-2}]: the points before those of b, when a holds the points before
// b's first (in registers: a load from memory just written by a wider store would stall).
#if defined(__AVX512F__)
inline __m512d SlideBack(__m512d a, __m512d b) {
  return _mm512_permutex2var_pd(b, _mm512_setr_epi64(15, 0, 1, 2, 3, 4, 5, 6), a);
}
#elif defined(__AVX2__)
inline __m256d SlideBack(__m256d a, __m256d b) {
  // [a2, a3, b0, b1], then lanes 1, 0', 3, 2' of it and b: [a3, b0, b1, b2].
  return _mm256_shuffle_pd(_mm256_permute2f128_pd(a, b, 0x21), b, 0b0101);
}
#endif

// The largest lane (the values are finite or +inf: no NaN).
template <class B>
double LargestLane(const B& v) {
  alignas(64) double lanes[B::size];
  v.store_aligned(lanes);
  double largest = lanes[0];
  for (size_t i = 1; i < B::size; ++i) largest = lanes[i] > largest ? lanes[i] : largest;
  return largest;
}

// Applies each sweep's rigid motion to points [first, n], held as coordinate arrays, a batch of
// consecutive points at a time; measures in the same pass the distance each point moves, the
// sweep's L2 sums, and at the end of a leader step the length error of every link that ends at a
// moved point.
template <class Arch, int Dim>
void WholeChainSweepsKernel(int64_t num_sweeps, WholeChainWork* w, double* pts, SweepTrace* t) {
  using B = xsimd::batch<double, Arch>;
  constexpr int kW = static_cast<int>(B::size);
  const int first = w->first, count = w->n + 1 - first, padded = w->lanes_padded;
  double* x[Dim];
  for (int k = 0; k < Dim; ++k) {
    x[k] = w->coords.data() + static_cast<size_t>(k) * w->stride + 1;
    for (int j = 0; j < count; ++j) x[k][j] = pts[(first + j) * Dim + k];
    std::fill(x[k] + count, x[k] + padded, 0.0);  // padding: finite, never counted
    x[k][-1] = 0.0;
  }
  std::fill(w->moved.begin(), w->moved.end(), 0.0);
  double* moved = w->moved.data();
  const double *weights = w->weights.data(), *lengths = w->lengths.data(),
               *inv_lengths = w->inv_lengths.data(), *valid = w->valid.data();
  const auto write_back = [&](int64_t s) {
    for (int j = 0; j < count; ++j) {
      for (int k = 0; k < Dim; ++k) pts[(first + j) * Dim + k] = x[k][j];
    }
    const double* placed = w->placed.data() + s * first * Dim;
    for (int i = 0; i < first * Dim; ++i) pts[i] = placed[i];
  };

  for (int64_t s = 0; s < num_sweeps; ++s) {
    const uint8_t flag = t->flags[s];
    const bool step_end = (flag & SweepTrace::kStepEnd) != 0;
    if (first > 0) {
      for (int k = 0; k < Dim; ++k) x[k][-1] = w->placed[(s * first + first - 1) * Dim + k];
    }
    B to[Dim], from[Dim], r[Dim][Dim];
    for (int a = 0; a < Dim; ++a) {
      to[a] = B(w->to[s * 3 + a]);
      if (w->rotate) {
        from[a] = B(w->from[s * 3 + a]);
        for (int c = 0; c < Dim; ++c) r[a][c] = B(w->rotation[s * 9 + a * 3 + c]);
      }
    }
    B l2(0.0), l2w(0.0), worst(0.0);
    // The points before those of the batch (step ends): point first - 1 (or 0) in the last lane.
    B before[Dim];
    for (int k = 0; k < Dim; ++k) before[k] = B(x[k][-1]);
    for (int j = 0; j < padded; j += kW) {
      B old[Dim], now[Dim];
      for (int k = 0; k < Dim; ++k) old[k] = B::load_unaligned(x[k] + j);
      if (w->rotate) {
        B rel[Dim];
        for (int c = 0; c < Dim; ++c) rel[c] = old[c] - from[c];
        for (int a = 0; a < Dim; ++a) {
          B turned = r[a][0] * rel[0];
          for (int c = 1; c < Dim; ++c) turned = xsimd::fma(r[a][c], rel[c], turned);
          now[a] = to[a] + turned;
        }
      } else {
        for (int k = 0; k < Dim; ++k) now[k] = old[k] + to[k];
      }
      B d2(0.0);
      for (int k = 0; k < Dim; ++k) {
        now[k].store_unaligned(x[k] + j);
        const B e = now[k] - old[k];
        d2 = xsimd::fma(e, e, d2);
      }
      B d = xsimd::sqrt(d2);
      if (j + kW > count) d *= B::load_unaligned(valid + j);  // the batch with padding
      (B::load_unaligned(moved + j) + d).store_unaligned(moved + j);
      l2 += d;
      l2w = xsimd::fma(d, B::load_unaligned(weights + j), l2w);
      if (step_end) {
        B q(0.0);
        for (int k = 0; k < Dim; ++k) {
          const B e = now[k] - B(SlideBack(before[k], now[k]));
          q = xsimd::fma(e, e, q);
          before[k] = now[k];
        }
        const B error = xsimd::abs(xsimd::sqrt(q) - B::load_unaligned(lengths + j)) *
                        B::load_unaligned(inv_lengths + j);
        worst = xsimd::max(worst, error);
      }
    }
    t->sweep_l2[s] += xsimd::hadd(l2);
    t->sweep_l2w[s] += xsimd::hadd(l2w);
    if (step_end) {
      const double largest = LargestLane(worst);
      if (largest > t->max_length_error) t->max_length_error = largest;
    }
    if (flag & SweepTrace::kCapture) {
      write_back(s);
      t->capture(t->context, s, -1);
    }
  }
  if (num_sweeps > 0) write_back(num_sweeps - 1);
  for (int j = 0; j < count; ++j) t->path_length[first + j] += moved[j];
}

template <class Arch>
void WholeChainSweepsOn(int64_t num_sweeps, WholeChainWork* w, double* pts, SweepTrace* t) {
  w->dim == 2 ? WholeChainSweepsKernel<Arch, 2>(num_sweeps, w, pts, t)
              : WholeChainSweepsKernel<Arch, 3>(num_sweeps, w, pts, t);
}

}  // namespace
}  // namespace flexkin::internal
