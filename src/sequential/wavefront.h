#pragma once
// The wavefront sweep engine, templated on the xsimd instruction set. Included only by the
// per-instruction-set translation units wavefront_<isa>.cc, each compiled with its own flags.

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>
#include <xsimd/xsimd.hpp>

#include "flexkin/propagate.h"
#include "sequential/link_rules.h"
#include "sequential/rule_table.h"
#include "sequential/sweep.h"
#include "world/contact.h"

namespace flexkin::internal {
namespace {

// exp(x) for a batch with every x <= 0, without a division (xsimd's exp ends with one, and the
// divider is the unit the sweeps are bound by). x is clamped to -708 (exp(-708) = 3.3e-308, the
// smallest normal double): the link rules only use exp(-p/L), for which anything that small is 0
// to rounding. Cody-Waite reduction x = k ln2 + r with |r| <= ln2/2, then the Taylor polynomial
// of degree 13 (truncation error < 5e-18 relative) and 2^k assembled in the exponent bits.
struct BatchExp {
  template <class A>
  xsimd::batch<double, A> operator()(const xsimd::batch<double, A>& x_in) const {
    using B = xsimd::batch<double, A>;
    using I = xsimd::batch<int64_t, A>;
    // Sub-steps shorter than 1/32 of the link (the usual multi-step case): no reduction needed;
    // the Taylor polynomial of degree 7 is then exact to 2.2e-17 relative.
    if (xsimd::all(x_in >= B(-0.03125))) {
      B small = B(1.0 / 5040.0);
      constexpr double kSmall[7] = {1.0 / 720.0, 1.0 / 120.0, 1.0 / 24.0, 1.0 / 6.0, 0.5, 1.0, 1.0};
      for (double c : kSmall) small = xsimd::fma(small, x_in, B(c));
      return small;
    }
    const B x = xsimd::max(x_in, B(-708.0));
    // Adding 1.5 * 2^52 rounds to an integer held in the low mantissa bits.
    constexpr double kShift = 6755399441055744.0;
    const B shifted = xsimd::fma(x, B(1.4426950408889634074), B(kShift));  // x / ln2
    const B k = shifted - B(kShift);
    const B r = xsimd::fnma(k, B(1.9082149292705877000e-10),
                            xsimd::fnma(k, B(6.9314718036912381649e-01), x));  // ln2 = hi + lo
    B poly = B(1.0 / 6227020800.0);                                            // 1/13!
    constexpr double kInvFactorial[13] = {1.0 / 479001600.0,
                                          1.0 / 39916800.0,
                                          1.0 / 3628800.0,
                                          1.0 / 362880.0,
                                          1.0 / 40320.0,
                                          1.0 / 5040.0,
                                          1.0 / 720.0,
                                          1.0 / 120.0,
                                          1.0 / 24.0,
                                          1.0 / 6.0,
                                          0.5,
                                          1.0,
                                          1.0};
    for (double c : kInvFactorial) poly = xsimd::fma(poly, r, B(c));
    // k is in [-1022, 0]: (k << 52) + bits(1.0) are the bits of 2^k.
    const I bits = (xsimd::bitwise_cast<I>(shifted) << 52) + I(int64_t{0x3FF0000000000000});
    return poly * xsimd::bitwise_cast<B>(bits);
  }
};

// [a1, a2, ..., a_{W-1}, b0]: a window register moves one point down the chain and takes in the
// first lane of the register after it.
#if defined(__AVX2__)
inline __m256d SlideIn(__m256d a, __m256d b) {
  return _mm256_blend_pd(_mm256_permute4x64_pd(a, _MM_SHUFFLE(0, 3, 2, 1)),
                         _mm256_permute4x64_pd(b, _MM_SHUFFLE(0, 0, 0, 0)), 0b1000);
}
inline double First(__m256d v) { return _mm_cvtsd_f64(_mm256_castpd256_pd128(v)); }
#endif
#if defined(__AVX512F__)
inline __m512d SlideIn(__m512d a, __m512d b) {
  return _mm512_permutex2var_pd(a, _mm512_setr_epi64(1, 2, 3, 4, 5, 6, 7, 8), b);
}
inline double First(__m512d v) { return _mm_cvtsd_f64(_mm512_castpd512_pd128(v)); }
#endif

// The links of a traced group's lanes `valid` ([a, b], of the given lengths) against the
// colliders near them (SweepContact::set), as KeepOutside measures them. Returns the lanes that
// take KeepOutside itself (KeepLinkOutside):
//  - where every near collider is a sphere, those that enter one (their contact step); the
//    others' clearances (a sphere's: the distance from its centre to the segment's nearest point
//    less its radius, SegmentClearance's form) lower the least clearance here. A sphere a lane is
//    beyond (the segment's squared distance to its centre exceeds the reach, as BeyondSphere has
//    it) is not measured, as KeepOutside leaves it out;
//  - else those within reach of some collider's ball (a sphere's exactly, another's by the link's
//    midpoint, as BeyondBall), all of them for a half-space or before any clearance is measured.
// The reach is KeepOutside's with a margin of 1e-8 instead of 1e-9, so a lane left out here is
// one that test would leave out of every collider.
template <class Arch, int Dim>
[[gnu::always_inline]] inline xsimd::batch_bool<double, Arch> LanesToTest(
    const xsimd::batch<double, Arch>* a, const xsimd::batch<double, Arch>* b,
    const xsimd::batch<double, Arch>& length, const xsimd::batch<double, Arch>& neg_inv_length,
    const xsimd::batch_bool<double, Arch>& valid, SweepContact* contact) {
  using B = xsimd::batch<double, Arch>;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  constexpr double kMargin = 1.0 + 1e-8;
  const SweepSet& set = contact->set;
  const double least = contact->stats.least_clearance;
  const bool measured = least < kInf;
  const B floor = measured && least > 0.0 ? B(least) * length : B(0.0);
  bool spheres_only = true;
  for (char sphere : set.spheres) spheres_only = spheres_only && sphere;
  if (!spheres_only && !measured) return valid;
  auto near = B(0.0) != B(0.0);
  B clear = B(kInf);
  B ab[3], mid[3];
  for (int k = 0; k < 3; ++k) {
    ab[k] = k < Dim ? b[k] - a[k] : B(0.0);
    mid[k] = k < Dim ? B(0.5) * (a[k] + b[k]) : B(0.0);
  }
  const B ab2 = xsimd::fma(ab[0], ab[0], xsimd::fma(ab[1], ab[1], ab[2] * ab[2]));
  // The balls read as doubles: contact_sweep.cc filled them where Eigen aligns a Vector4d to 16
  // bytes, and Eigen here (compiled for AVX) would take one to be aligned to 32.
  const double* balls = reinterpret_cast<const double*>(set.balls.data());
  for (size_t c = 0; c < set.balls.size(); ++c) {
    const double* ball = balls + 4 * c;
    if (ball[3] < 0.0) return valid;
    if (set.spheres[c] && measured) {
      // First by the link's midpoint (BeyondBall's bound, a few operations): a sphere every lane
      // is beyond by it, the usual case, is beyond by the segment's own distance too.
      const B far = (B(0.5) * length + B(ball[3]) + floor) * B(kMargin);
      B m2 = B(0.0);
      for (int k = 0; k < 3; ++k) {
        const B m = mid[k] - B(ball[k]);
        m2 = xsimd::fma(m, m, m2);
      }
      if (xsimd::all(!valid | (m2 > far * far))) continue;
    }
    if (set.spheres[c]) {
      const B reach = (B(ball[3]) + floor) * B(kMargin);
      B ac[3], ac2 = B(0.0), bc2 = B(0.0), along = B(0.0);
      for (int k = 0; k < 3; ++k) {
        ac[k] = k < Dim ? B(ball[k]) - a[k] : B(ball[k]);
        const B bc = k < Dim ? B(ball[k]) - b[k] : B(ball[k]);
        ac2 = xsimd::fma(ac[k], ac[k], ac2);
        bc2 = xsimd::fma(bc, bc, bc2);
        along = xsimd::fma(ac[k], ab[k], along);
      }
      // Inside the segment's span: d^2 |ab|^2 against reach^2 |ab|^2, as BeyondSphere.
      const B across = xsimd::fms(ac2, ab2, along * along);
      const auto inside = (along > B(0.0)) & (along < ab2);
      const B end2 = xsimd::select(along <= B(0.0), ac2, bc2);
      auto beyond = (inside & (across > reach * reach * ab2 * B(kMargin))) |
                    (!inside & (end2 > reach * reach));
      if (!measured) beyond = B(0.0) != B(0.0);
      if (!spheres_only) {
        near = near | !beyond;
        continue;
      }
      const auto measure = valid & !beyond;
      if (!xsimd::any(measure)) continue;
      // SegmentClearance's sphere: the nearest point at t = clamp(ac.ab / ab^2, 0, 1).
      const B t = xsimd::min(xsimd::max(along / ab2, B(0.0)), B(1.0));
      B d2 = B(0.0);
      for (int k = 0; k < 3; ++k) {
        const B p = xsimd::fms(t, ab[k], ac[k]);  // a + t ab - centre
        d2 = xsimd::fma(p, p, d2);
      }
      clear = xsimd::select(measure, xsimd::min(clear, xsimd::sqrt(d2) - B(ball[3])), clear);
    } else {
      const B reach = (B(0.5) * length + B(ball[3]) + floor) * B(kMargin);
      B d2 = B(0.0);
      for (int k = 0; k < 3; ++k) {
        const B m = mid[k] - B(ball[k]);
        d2 = xsimd::fma(m, m, d2);
      }
      near = near | !(d2 > reach * reach);
    }
  }
  if (!spheres_only) return near & valid;
  const auto enter = valid & (clear < B(-kContactSlack) * length);
  const auto lower = valid & (clear < B(kInf)) & !enter;
  if (xsimd::any(lower)) {
    alignas(64) double relative[B::size];
    xsimd::select(lower, clear * -neg_inv_length, B(kInf)).store_aligned(relative);
    double low = contact->stats.least_clearance;
    for (double r : relative) low = std::fmin(low, r);
    contact->stats.least_clearance = low;
  }
  return enter;
}

// Lanes: with U registers of W lanes (G = U W lanes), a group of G consecutive sweeps
// g..g+G-1 advances together; at iteration t, lane j (register j / W) works on point t-G+1+j for
// sweep g+G-1-j. The point a lane reads is the one its neighbour lane (the previous sweep) wrote
// one iteration earlier, so the window stays in registers: each iteration reads one new point
// (t, for the last lane, untouched by this group yet) and writes one finished point (t-G+1, from
// lane 0, the group's last sweep). Nothing goes through memory between lanes (no store-to-load
// forwarding stalls), and the U registers' rule evaluations are independent, so their latencies
// overlap. Returns the number of sweeps done (a multiple of G).
//
// Traced (SweepTrace, for runs): each lane also measures the distance its point moves (summed per
// sweep, plain and weighted, and per point in a window of path lengths that slides down the chain
// with the points), the length of its link after a sweep that ends a leader step, and copies its
// point into a capture slot when its sweep is to be captured.
// Starts at sweep `g` and returns the sweep it stopped at (g plus a multiple of G).
// Contact (traced only): the run's static colliders (SweepTrace::contact), tested in the lanes.
template <class Arch, class Rule, int Dim, int U, bool Traced, bool Contact>
int64_t WavefrontGroups(const double* heads, int64_t g, int64_t num_sweeps, const double* lengths,
                        const double* inv_lengths, int n, double* points, SweepTrace* trace) {
  using B = xsimd::batch<double, Arch>;
  constexpr int W = B::size;
  constexpr int G = U * W;
  static_assert(G - 1 <= SweepTrace::kPad && G <= SweepTrace::kMaxSlots);
  if (num_sweeps - g < G) return g;
  // Link lengths of point i at len[pad + i]; the padding lanes compute garbage never stored.
  // Traced: the trace's arrays, prepared once per chain, and the arc-length weights likewise.
  const int pad = Traced ? SweepTrace::kPad : G - 1;
  std::vector<double> own_len, own_neg_inv_len;
  if constexpr (!Traced) {
    own_len.assign(n + 1 + 2 * pad, 1.0);
    own_neg_inv_len.assign(n + 1 + 2 * pad, -1.0);
    for (int i = 0; i < n; ++i) {
      own_len[pad + 1 + i] = lengths[i];
      own_neg_inv_len[pad + 1 + i] = -inv_lengths[i];
    }
  }
  const double* len = Traced ? trace->padded_lengths.data() : own_len.data();
  const double* neg_inv_len =
      Traced ? trace->padded_neg_inv_lengths.data() : own_neg_inv_len.data();
  [[maybe_unused]] const double* weight = Traced ? trace->padded_weights.data() : nullptr;
  alignas(64) double lane_index[W];
  for (int j = 0; j < W; ++j) lane_index[j] = j;
  const B lane = B::load_aligned(lane_index);
  const B last = B(static_cast<double>(n));

  for (; g + G <= num_sweeps; g += G) {
    // Traced with colliders: those the group's sweeps may meet (their heads lie within `spread`
    // of the first's).
    [[maybe_unused]] SweepContact* contact = nullptr;
    if constexpr (Contact) {
      static_assert(Traced);
      contact = trace->contact;
      double spread2 = 0.0;
      for (int s = 1; s < G; ++s) {
        double d2 = 0.0;
        for (int k = 0; k < Dim; ++k) {
          const double d = heads[(g + s) * Dim + k] - heads[g * Dim + k];
          d2 += d * d;
        }
        spread2 = std::fmax(spread2, d2);
      }
      NearSweepSet(Dim, heads + g * Dim, std::sqrt(spread2) * (1.0 + 1e-12), lengths, n, contact);
      if (contact->set.colliders->empty()) contact = nullptr;
    }
    B head[U][Dim], lead_old[U][Dim], lead_new[U][Dim], window[U][Dim];
    // Traced: per register, the lanes whose sweep ends a leader step, the running sums of the
    // sweeps' distances, the path-length window and the largest length error; the capture slot
    // of each lane (-1: not captured), given in sweep order.
    [[maybe_unused]] xsimd::batch_bool<double, Arch> step_end[U];
    [[maybe_unused]] B l2[U], l2w[U], path[U], worst[U];
    [[maybe_unused]] int slot_of_lane[G];
    [[maybe_unused]] int num_slots = 0;
    if constexpr (Traced) {
      alignas(64) double end_flag[G];
      for (int j = G - 1; j >= 0; --j) {  // lane G-1 has the group's first sweep
        const uint8_t flag = trace->flags[g + G - 1 - j];
        end_flag[j] = (flag & SweepTrace::kStepEnd) ? 1.0 : 0.0;
        slot_of_lane[j] = (flag & SweepTrace::kCapture) ? num_slots++ : -1;
      }
      for (int u = 0; u < U; ++u) {
        step_end[u] = B::load_aligned(end_flag + u * W) != B(0.0);
        l2[u] = l2w[u] = path[u] = worst[u] = B(0.0);
      }
    }
    for (int u = 0; u < U; ++u) {
      for (int k = 0; k < Dim; ++k) {
        alignas(64) double h[W];
        for (int j = 0; j < W; ++j) h[j] = heads[(g + G - 1 - (u * W + j)) * Dim + k];
        head[u][k] = B::load_aligned(h);
        lead_old[u][k] = lead_new[u][k] = window[u][k] = B(0.0);
      }
    }
    for (int t = 0; t < n + G; ++t) {
      const int base = t - G + 1;  // point of lane 0
      for (int k = 0; k < Dim; ++k) {
        for (int u = 0; u + 1 < U; ++u) window[u][k] = B(SlideIn(window[u][k], window[u + 1][k]));
        window[U - 1][k] = B(SlideIn(window[U - 1][k], B(t <= n ? points[t * Dim + k] : 0.0)));
      }
      if constexpr (Traced) {
        for (int u = 0; u + 1 < U; ++u) path[u] = B(SlideIn(path[u], path[u + 1]));
        path[U - 1] = B(SlideIn(path[U - 1], B(t <= n ? trace->path_length[t] : 0.0)));
      }
      [[maybe_unused]] alignas(64) double captured[Traced ? Dim : 1][Traced ? G : 1];
      B tail[U][Dim];
      for (int u = 0; u < U; ++u) {
        const int first = base + u * W;  // point of this register's lane 0
        const B index = B(static_cast<double>(first)) + lane;
        for (int k = 0; k < Dim; ++k) tail[u][k] = window[u][k];
        const B length = B::load_unaligned(&len[pad + first]);
        const B neg_inv_length = B::load_unaligned(&neg_inv_len[pad + first]);
        auto fix = Rule::Apply(lead_old[u], lead_new[u], tail[u], length, neg_inv_length);
        // Lanes whose vector step overflowed (moves near the largest doubles) take the reference
        // too: nothing non-finite leaves the engine where the one-pass loop gives a number.
        // (The sum of the coordinates is not finite where one is not; where it overflows alone,
        // the lane takes the reference for nothing.)
        B sum = tail[u][0];
        for (int k = 1; k < Dim; ++k) sum += tail[u][k];
        fix = fix | !(xsimd::abs(sum) <= B(std::numeric_limits<double>::max()));
        fix = fix & (index >= B(1.0)) & (index <= last);
        if (xsimd::any(fix)) {
          // Rare lanes (degenerate or extreme moves): redo them with the scalar reference.
          alignas(64) double lo[Dim][W], ln[Dim][W], old[Dim][W], out[Dim][W], mask[W], len_j[W];
          for (int k = 0; k < Dim; ++k) {
            lead_old[u][k].store_aligned(lo[k]);
            lead_new[u][k].store_aligned(ln[k]);
            window[u][k].store_aligned(old[k]);
            tail[u][k].store_aligned(out[k]);
          }
          xsimd::select(fix, B(1.0), B(0.0)).store_aligned(mask);
          length.store_aligned(len_j);
          for (int j = 0; j < W; ++j) {
            if (mask[j] == 0.0) continue;
            double a[Dim], b[Dim], c[Dim];
            for (int k = 0; k < Dim; ++k) a[k] = lo[k][j], b[k] = ln[k][j], c[k] = old[k][j];
            Rule::Reference(a, b, c, len_j[j]);
            for (int k = 0; k < Dim; ++k) out[k][j] = c[k];
          }
          for (int k = 0; k < Dim; ++k) tail[u][k] = B::load_aligned(out[k]);
        }
        if (t < G) {
          // Lanes that have not reached the chain yet stay still, so that they carry no
          // garbage (which would, for one, push the whole batch off the exp fast path).
          const auto started = index >= B(1.0);
          for (int k = 0; k < Dim; ++k) {
            tail[u][k] = xsimd::select(started, tail[u][k], window[u][k]);
          }
        }
        const auto is_head = index == B(0.0);
        for (int k = 0; k < Dim; ++k) tail[u][k] = xsimd::select(is_head, head[u][k], tail[u][k]);
        if constexpr (Contact) {
          if (contact != nullptr) {
            // The links within reach of a collider: the contact sweep's test and contact step,
            // lane by lane (window: the link's trailing end before the sweep).
            const auto near = LanesToTest<Arch, Dim>(lead_new[u], tail[u], length, neg_inv_length,
                                                     (index >= B(1.0)) & (index <= last), contact);
            if (xsimd::any(near)) {
              alignas(64) double ln[Dim][W], old[Dim][W], out[Dim][W], mask[W], len_j[W], inv_j[W];
              for (int k = 0; k < Dim; ++k) {
                lead_new[u][k].store_aligned(ln[k]);
                window[u][k].store_aligned(old[k]);
                tail[u][k].store_aligned(out[k]);
              }
              xsimd::select(near, B(1.0), B(0.0)).store_aligned(mask);
              length.store_aligned(len_j);
              neg_inv_length.store_aligned(inv_j);
              for (int j = 0; j < W; ++j) {
                if (mask[j] == 0.0) continue;
                double a[Dim], c[Dim], x[Dim];
                for (int k = 0; k < Dim; ++k) a[k] = ln[k][j], c[k] = old[k][j], x[k] = out[k][j];
                KeepLinkOutside(Dim, first + j, a, c, x, len_j[j], -inv_j[j], contact);
                for (int k = 0; k < Dim; ++k) out[k][j] = x[k];
              }
              for (int k = 0; k < Dim; ++k) tail[u][k] = B::load_aligned(out[k]);
            }
          }
        }
        if constexpr (Traced) {
          // The distance the point moved (window: before the sweep, tail: after) and the length
          // of its link (lead_new: the point before it, after the sweep).
          B moved2 = B(0.0), link2 = B(0.0);
          for (int k = 0; k < Dim; ++k) {
            const B d = tail[u][k] - window[u][k], e = tail[u][k] - lead_new[u][k];
            moved2 = xsimd::fma(d, d, moved2);
            link2 = xsimd::fma(e, e, link2);
          }
          const auto on_chain = (index >= B(0.0)) & (index <= last);
          const B moved = xsimd::select(on_chain, xsimd::sqrt(moved2), B(0.0));
          l2[u] += moved;
          l2w[u] = xsimd::fma(moved, B::load_unaligned(&weight[pad + first]), l2w[u]);
          path[u] += moved;
          // |sqrt(r) - 1| = |r - 1| / (1 + sqrt(r)) with r = q / L^2: |r - 1| / 2 where r is
          // within 1e-9 of 1 (always, unless something is wrong: the difference is then below
          // 1e-18), else the exact form with its square root.
          const B excess = xsimd::abs(xsimd::fms(link2, neg_inv_length * neg_inv_length, B(1.0)));
          B error = excess * B(0.5);
          if (xsimd::any(excess > B(1e-9))) {
            error = excess / (B(1.0) + xsimd::sqrt(link2 * (neg_inv_length * neg_inv_length)));
          }
          worst[u] = xsimd::select(step_end[u] & (index >= B(1.0)) & (index <= last),
                                   xsimd::max(worst[u], error), worst[u]);
          if (num_slots > 0) {
            for (int k = 0; k < Dim; ++k) tail[u][k].store_aligned(&captured[k][u * W]);
          }
        }
        for (int k = 0; k < Dim; ++k) {
          lead_old[u][k] = window[u][k];
          lead_new[u][k] = window[u][k] = tail[u][k];
        }
        if (t >= n) {
          // Lanes that have finished the chain stay still too: their leading end stops moving.
          const auto done = index >= last;
          for (int k = 0; k < Dim; ++k) {
            lead_new[u][k] = xsimd::select(done, lead_old[u][k], lead_new[u][k]);
          }
        }
      }
      if (base >= 0) {
        for (int k = 0; k < Dim; ++k) points[base * Dim + k] = First(tail[0][k]);
        if constexpr (Traced) trace->path_length[base] = First(path[0]);
      }
      if constexpr (Traced) {
        for (int j = 0; j < G && num_slots > 0; ++j) {
          const int point = base + j;
          if (slot_of_lane[j] < 0 || point < 0 || point > n) continue;
          double* slot = trace->slots[slot_of_lane[j]] + point * Dim;
          for (int k = 0; k < Dim; ++k) slot[k] = captured[k][j];
        }
      }
    }
    if constexpr (Traced) {
      alignas(64) double sums[2][G], errors[G];
      for (int u = 0; u < U; ++u) {
        l2[u].store_aligned(&sums[0][u * W]);
        l2w[u].store_aligned(&sums[1][u * W]);
        worst[u].store_aligned(&errors[u * W]);
      }
      for (int j = 0; j < G; ++j) {
        trace->sweep_l2[g + G - 1 - j] = sums[0][j];
        trace->sweep_l2w[g + G - 1 - j] = sums[1][j];
        trace->max_length_error = std::fmax(trace->max_length_error, errors[j]);
      }
      for (int j = G - 1; j >= 0; --j) {
        if (slot_of_lane[j] >= 0) trace->capture(trace->context, g + G - 1 - j, slot_of_lane[j]);
      }
    }
  }
  return g;
}

// Sweeps done by the engine (two registers per coordinate while at least 2 W sweeps are left,
// then one); the caller finishes the fewer than W left with the one-pass loop.
template <class Arch, class Rule, int Dim, bool Traced, bool Contact>
int64_t WavefrontSweepsOf(const double* heads, int64_t num_sweeps, const double* lengths,
                          const double* inv_lengths, int n, double* points, SweepTrace* trace) {
  const int64_t done = WavefrontGroups<Arch, Rule, Dim, 2, Traced, Contact>(
      heads, 0, num_sweeps, lengths, inv_lengths, n, points, trace);
  return WavefrontGroups<Arch, Rule, Dim, 1, Traced, Contact>(heads, done, num_sweeps, lengths,
                                                              inv_lengths, n, points, trace);
}

// The same, the lanes testing their links against the run's colliders where it has some.
template <class Arch, class Rule, int Dim, bool Traced>
int64_t WavefrontSweeps(const double* heads, int64_t num_sweeps, const double* lengths,
                        const double* inv_lengths, int n, double* points, SweepTrace* trace) {
  if constexpr (Traced) {
    if (trace->contact != nullptr) {
      return WavefrontSweepsOf<Arch, Rule, Dim, true, true>(heads, num_sweeps, lengths, inv_lengths,
                                                            n, points, trace);
    }
  }
  return WavefrontSweepsOf<Arch, Rule, Dim, Traced, false>(heads, num_sweeps, lengths, inv_lengths,
                                                           n, points, trace);
}

// Entry point of one instruction set: takes the rule from the table (rule_table.h) and picks the
// dimension; the sweeps left over
// (fewer than the lanes) go through the one-pass loop.
// Traced: `trace` observes every sweep, the engine's and the one-pass loop's.
template <class Arch, bool Traced>
void WavefrontDispatch(Method method, int dim, const double* heads, int64_t num_sweeps,
                       const double* lengths, const double* inv_lengths, int n, double* points,
                       SweepTrace* trace) {
  int64_t done = 0;
  DispatchRule<kWavefrontEngine>(method, [&](auto rule) {
    using Rule = decltype(rule);
    done = dim == 2 ? WavefrontSweeps<Arch, typename Rule::template Step<2, BatchExp>, 2, Traced>(
                          heads, num_sweeps, lengths, inv_lengths, n, points, trace)
                    : WavefrontSweeps<Arch, typename Rule::template Step<3, BatchExp>, 3, Traced>(
                          heads, num_sweeps, lengths, inv_lengths, n, points, trace);
  });
  if constexpr (Traced) {
    TracedSweepsScalarFrom(method, dim, heads, done, num_sweeps, lengths, inv_lengths, n, points,
                           trace);
  } else {
    SweepsScalar(method, dim, heads + done * dim, num_sweeps - done, lengths, inv_lengths, n,
                 points);
  }
}

}  // namespace
}  // namespace flexkin::internal
