#pragma once
// The wavefront engine for trees driven at one point (flexkin/tree.h), templated on the xsimd
// instruction set; included by tree_isa.cc, compiled once per instruction set.
//
// As the chain's wavefront (wavefront.h), consecutive sweeps (sub-steps) advance together, one
// per lane: in a group of W sweeps g..g+W-1, at iteration t lane l works on link t - l of the
// visiting order for sweep g + l. Link j's trailing end in sweep g + l needs its own position
// after sweep g + l - 1 (lane l - 1, the iteration before) and its leading end's positions after
// sweeps g + l - 1 and g + l; that leading end is the driven point or the trailing end of an
// earlier link (source[j]), finished by lanes l - 1 and l at earlier iterations. Any order in
// which a link comes after its source works. The chain's engine keeps its data in registers
// (source[j] = j - 1); here every iteration's results go to `rows` and are read back by link and
// lane (a gather).

#include <immintrin.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>
#include <xsimd/xsimd.hpp>

#include "sequential/link_rules.h"
#include "sequential/rule_table.h"
#include "sequential/tree_sweep.h"
#include "sequential/wavefront.h"  // BatchExp

namespace flexkin::internal {
namespace {

// Sweeps done by the engine (a multiple of the lanes W); the caller finishes the rest with the
// one-pass sweep.
// Lane i: base[index[i]], by the hardware gather (xsimd 8's own gather of doubles by 64-bit
// indices for AVX-512 is a loop over the lanes, not inlined).
#if defined(__AVX512F__)
inline __m512d GatherAt(const double* base, __m512i index) {
  return _mm512_i64gather_pd(index, base, 8);
}
#endif
#if defined(__AVX2__)
inline __m256d GatherAt(const double* base, __m256i index) {
  return _mm256_i64gather_pd(base, index, 8);
}
#endif

// U registers of W lanes: G = U W sweeps in flight (the registers' rule evaluations are
// independent, so their latencies overlap). Starts at sweep `g`, returns the sweep it stopped at.
//
// Lane l of iteration t works on link j = t - l: its values are at index P + m - 1 - t + l of the
// link arrays below, reversed and padded by P = G - 1 either side (so that a register's lanes are
// one contiguous load), and its leading end's positions are gathered (from the rows, or from
// `heads` for the links from the driven point). A lane whose j is not a link (the group's first
// and last G - 1 iterations) steps a unit link whose leading end stays still: finite, on the exp's
// fast path, and read by no other lane.
constexpr double kLargest = std::numeric_limits<double>::max();

template <class Arch, class Rule, int Dim, int U>
int64_t TreeWavefrontGroups(const double* heads, int64_t g, int64_t num_sweeps,
                            const TreeLinks& tree, double* points) {
  using B = xsimd::batch<double, Arch>;
  using I = xsimd::batch<int64_t, Arch>;
  constexpr int W = B::size;
  constexpr int G = U * W;
  constexpr int P = G - 1;
  constexpr int64_t kRow = Dim * G;  // doubles in one iteration's row
  const int m = tree.num_links;
  if (num_sweeps - g < G || m == 0) return g;
  // rows[t], iteration t: lane l's trailing end of link t - l after sweep g + l, as [k][l]; one
  // row more in front, which lane 0's read of the row before, one lane before, touches at t = 1.
  const int iterations = m + G - 1;
  thread_local std::vector<double, xsimd::aligned_allocator<double>> rows;
  rows.resize(static_cast<size_t>(iterations + 1) * kRow);
  double* const base = rows.data() + kRow;
  const auto row = [&](int t) { return base + static_cast<size_t>(t) * kRow; };
  // Per link, reversed and padded: where its leading end's row starts (0 for the driven point),
  // whether that is the driven point, its length and inverse, whether it is a link at all.
  thread_local std::vector<int64_t> source_row;
  thread_local std::vector<double> rev_len, rev_inv, rev_driven, rev_on;
  source_row.assign(m + 2 * P, 0);
  rev_len.assign(m + 2 * P, 1.0);
  rev_inv.assign(m + 2 * P, 1.0);
  rev_driven.assign(m + 2 * P, 0.0);
  rev_on.assign(m + 2 * P, 0.0);
  for (int j = 0; j < m; ++j) {
    const int r = P + m - 1 - j;
    source_row[r] = tree.source[j] < 0 ? 0 : tree.source[j] * kRow;
    rev_len[r] = tree.lengths[j];
    rev_inv[r] = tree.inv_lengths[j];
    rev_driven[r] = tree.source[j] < 0 ? 1.0 : 0.0;
    rev_on[r] = 1.0;
  }
  // The iterations whose lanes all work on links (G - 1 <= t < m), none from the driven point,
  // need no masks.
  thread_local std::vector<char> plain;
  plain.assign(iterations, 0);
  int driven_leads = 0;  // among links t - G + 1 .. t
  for (int t = 0; t < iterations; ++t) {
    if (t < m) driven_leads += tree.source[t] < 0;
    if (t >= G && t - G < m) driven_leads -= tree.source[t - G] < 0;
    plain[t] = t >= G - 1 && t < m && driven_leads == 0;
  }
  alignas(64) int64_t row_step[G], head_step[G];
  alignas(64) double lane_index[W];
  for (int l = 0; l < G; ++l) row_step[l] = l * (kRow + 1), head_step[l] = l * Dim;
  for (int l = 0; l < W; ++l) lane_index[l] = l;
  const auto lane0 = B::load_aligned(lane_index) == B(0.0);
  const int d = tree.driven;
  for (; g + G <= num_sweeps; g += G) {
    for (int t = 0; t < iterations; ++t) {
      double* out = row(t);
      // Lane 0 (sweep g) reads the positions before the group.
      const bool lane0_on = t < m;
      const int a0 = lane0_on ? tree.lead[t] : 0, b0 = lane0_on ? tree.tail[t] : 0;
      const bool masked = !plain[t];
      for (int u = 0; u < U; ++u) {
        const int rev = P + m - 1 - t + u * W;
        const auto on = B::load_unaligned(rev_on.data() + rev) != B(0.0);
        const auto driven = B::load_unaligned(rev_driven.data() + rev) != B(0.0);
        // Lane l: its leading end after sweep g + l at row(source + l), lane l, and after sweep
        // g + l - 1 one row and one lane before (the driven point: heads g + l and g + l - 1);
        // its own old position in the last row, one lane before.
        const I at = I::load_unaligned(source_row.data() + rev) + I::load_aligned(row_step + u * W);
        const I before = xsimd::max(at - I(kRow + 1), I(0));
        const I head_at = I(g * Dim) + I::load_aligned(head_step + u * W);
        const I head_before = xsimd::max(head_at - I(Dim), I(0));
        const bool any_driven = masked && xsimd::any(driven);
        B lead_old[Dim], lead_new[Dim], tail[Dim];
        for (int k = 0; k < Dim; ++k) {
          const double* lanes = base + k * G;
          lead_new[k] = B(GatherAt(lanes, at));
          lead_old[k] = B(GatherAt(lanes, before));
          if (any_driven) {
            lead_new[k] = xsimd::select(driven, B(GatherAt(heads + k, head_at)), lead_new[k]);
            lead_old[k] = xsimd::select(driven, B(GatherAt(heads + k, head_before)), lead_old[k]);
          }
          tail[k] = t > 0 ? B::load_unaligned(row(t - 1) + k * G + u * W - 1) : B(0.0);
          if (u == 0 && lane0_on) {
            lead_old[k] = xsimd::select(lane0, B(points[a0 * Dim + k]), lead_old[k]);
            tail[k] = xsimd::select(lane0, B(points[b0 * Dim + k]), tail[k]);
          }
          if (masked) {
            lead_old[k] = xsimd::select(on, lead_old[k], B(k == 0 ? 1.0 : 0.0));
            lead_new[k] = xsimd::select(on, lead_new[k], B(k == 0 ? 1.0 : 0.0));
            tail[k] = xsimd::select(on, tail[k], B(0.0));
          }
        }
        const B length = B::load_unaligned(rev_len.data() + rev);
        const B inv = B::load_unaligned(rev_inv.data() + rev);
        B old[Dim];
        for (int k = 0; k < Dim; ++k) old[k] = tail[k];
        auto fix = Rule::Apply(lead_old, lead_new, tail, length, -inv);
        // Lanes whose vector step overflowed (moves near the largest doubles) take the reference
        // too: nothing non-finite leaves the engine where the one-pass sweep gives a number.
        // (The sum of the coordinates is not finite where one is not; where it overflows alone,
        // the lane takes the reference for nothing.)
        B sum = tail[0];
        for (int k = 1; k < Dim; ++k) sum += tail[k];
        fix = fix | !(xsimd::abs(sum) <= B(kLargest));
        fix = fix & on;
        for (int k = 0; k < Dim; ++k) tail[k].store_aligned(out + k * G + u * W);
        if (xsimd::any(fix)) {
          // Rare lanes (degenerate or extreme moves): the scalar reference, as the chain's.
          alignas(64) double lo[Dim][W], ln[Dim][W], tl[Dim][W], len[W], mask[W];
          for (int k = 0; k < Dim; ++k) {
            lead_old[k].store_aligned(lo[k]);
            lead_new[k].store_aligned(ln[k]);
            old[k].store_aligned(tl[k]);
          }
          length.store_aligned(len);
          xsimd::select(fix, B(1.0), B(0.0)).store_aligned(mask);
          for (int l = 0; l < W; ++l) {
            if (mask[l] == 0.0) continue;
            double a[Dim], b[Dim], c[Dim];
            for (int k = 0; k < Dim; ++k) a[k] = lo[k][l], b[k] = ln[k][l], c[k] = tl[k][l];
            Rule::Reference(a, b, c, len[l]);
            for (int k = 0; k < Dim; ++k) out[k * G + u * W + l] = c[k];
          }
        }
      }
    }
    // The group's last sweep (lane G - 1) is the tree's state for the next group.
    for (int j = 0; j < m; ++j) {
      const double* final_row = row(j + G - 1);
      for (int k = 0; k < Dim; ++k) points[tree.tail[j] * Dim + k] = final_row[k * G + G - 1];
    }
    for (int k = 0; k < Dim; ++k) points[d * Dim + k] = heads[(g + G - 1) * Dim + k];
  }
  return g;
}

// Two registers while at least 2 W sweeps are left, then one; returns the sweeps done.
template <class Arch, class Rule, int Dim>
int64_t TreeWavefrontSweeps(const double* heads, int64_t num_sweeps, const TreeLinks& tree,
                            double* points) {
  const int64_t done = TreeWavefrontGroups<Arch, Rule, Dim, 2>(heads, 0, num_sweeps, tree, points);
  return TreeWavefrontGroups<Arch, Rule, Dim, 1>(heads, done, num_sweeps, tree, points);
}

template <class Arch>
int64_t TreeWavefrontDispatch(Method method, int dim, const double* heads, int64_t num_sweeps,
                              const TreeLinks& tree, double* points) {
  int64_t done = 0;
  DispatchRule<kTreeEngine>(method, [&](auto rule) {
    using Rule = decltype(rule);
    done = dim == 2 ? TreeWavefrontSweeps<Arch, typename Rule::template Step<2, BatchExp>, 2>(
                          heads, num_sweeps, tree, points)
                    : TreeWavefrontSweeps<Arch, typename Rule::template Step<3, BatchExp>, 3>(
                          heads, num_sweeps, tree, points);
  });
  return done;
}

}  // namespace
}  // namespace flexkin::internal
