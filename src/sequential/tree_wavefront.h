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

#include <algorithm>
#include <cstdint>
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
// U registers of W lanes: G = U W sweeps in flight (the registers' rule evaluations are
// independent, so their latencies overlap). Starts at sweep `g`, returns the sweep it stopped at.
template <class Arch, class Rule, int Dim, int U>
int64_t TreeWavefrontGroups(const double* heads, int64_t g, int64_t num_sweeps,
                            const TreeLinks& tree, double* points) {
  using B = xsimd::batch<double, Arch>;
  using I = xsimd::batch<int64_t, Arch>;
  constexpr int W = B::size;
  constexpr int G = U * W;
  constexpr int64_t kRow = Dim * G;  // doubles in one iteration's row
  const int m = tree.num_links;
  if (num_sweeps - g < G || m == 0) return g;
  // rows[t], iteration t: lane l's trailing end of link t - l after sweep g + l, as [k][l].
  const int iterations = m + G - 1;
  thread_local std::vector<double, xsimd::aligned_allocator<double>> rows;
  rows.resize(static_cast<size_t>(iterations) * kRow);
  const auto row = [&](int t) { return rows.data() + static_cast<size_t>(t) * kRow; };
  // The iterations whose G lanes all work on links (G - 1 <= t < m) whose leading end is not the
  // driven point read their data with vector loads and gathers: lane l of iteration t works on
  // link t - l, whose values are at index m - 1 - t + l of the reversed arrays below. The others
  // (a group's first and last G - 1 iterations, the links from the driven point) gather lane by
  // lane.
  thread_local std::vector<int64_t> source_row;  // where the row of link j's leading end starts
  thread_local std::vector<double> rev_len, rev_inv;
  thread_local std::vector<char> fast;
  source_row.resize(m);
  rev_len.resize(m);
  rev_inv.resize(m);
  fast.assign(iterations, 0);
  int driven_leads = 0;  // among links t - G + 1 .. t
  for (int t = 0; t < iterations; ++t) {
    if (t < m) {
      source_row[m - 1 - t] = tree.source[t] < 0 ? 0 : tree.source[t] * kRow;
      rev_len[m - 1 - t] = tree.lengths[t];
      rev_inv[m - 1 - t] = tree.inv_lengths[t];
      driven_leads += tree.source[t] < 0;
    }
    if (t >= G && t - G < m) driven_leads -= tree.source[t - G] < 0;
    fast[t] = t >= G - 1 && t < m && driven_leads == 0;
  }
  alignas(64) int64_t step_of_lane[G];
  alignas(64) double lane_index[W];
  for (int l = 0; l < G; ++l) step_of_lane[l] = l * (kRow + 1);
  for (int l = 0; l < W; ++l) lane_index[l] = l;
  const auto lane0 = B::load_aligned(lane_index) == B(0.0);
  const int d = tree.driven;
  for (; g + G <= num_sweeps; g += G) {
    for (int t = 0; t < iterations; ++t) {
      B lead_old[U][Dim], lead_new[U][Dim], tail[U][Dim], length[U], inv[U];
      xsimd::batch_bool<double, Arch> active[U];
      if (fast[t]) {
        // Lane l: its leading end after sweep g + l at row(source + l), lane l, and after sweep
        // g + l - 1 one row and one lane before; its own old position in the last row, one lane
        // before. Lane 0 (sweep g) reads the positions before the group.
        const int a = tree.lead[t], b = tree.tail[t];
        for (int u = 0; u < U; ++u) {
          const int rev = m - 1 - t + u * W;
          const I at =
              I::load_unaligned(source_row.data() + rev) + I::load_aligned(step_of_lane + u * W);
          const I before = xsimd::max(at - I(kRow + 1), I(0));
          for (int k = 0; k < Dim; ++k) {
            const double* lanes = rows.data() + k * G;
            lead_new[u][k] = B::gather(lanes, at);
            lead_old[u][k] = B::gather(lanes, before);
            tail[u][k] = B::load_unaligned(row(t - 1) + k * G + u * W - 1);
            if (u == 0) {
              lead_old[u][k] = xsimd::select(lane0, B(points[a * Dim + k]), lead_old[u][k]);
              tail[u][k] = xsimd::select(lane0, B(points[b * Dim + k]), tail[u][k]);
            }
          }
          length[u] = B::load_unaligned(rev_len.data() + rev);
          inv[u] = B::load_unaligned(rev_inv.data() + rev);
          active[u] = B(1.0) == B(1.0);
        }
      } else {
        alignas(64) double lo[Dim][G], ln[Dim][G], tl[Dim][G], len[G], iv[G], on[G];
        for (int l = 0; l < G; ++l) {
          const int j = t - l;
          on[l] = (j >= 0 && j < m) ? 1.0 : 0.0;
          if (on[l] == 0.0) {
            // An idle lane steps a unit link whose leading end does not move: finite, and on the
            // exp's fast path.
            for (int k = 0; k < Dim; ++k) lo[k][l] = ln[k][l] = (k == 0), tl[k][l] = 0.0;
            len[l] = iv[l] = 1.0;
            continue;
          }
          const int a = tree.lead[j], b = tree.tail[j], s = tree.source[j];
          const int64_t sweep = g + l;
          for (int k = 0; k < Dim; ++k) {
            ln[k][l] = s < 0 ? heads[sweep * Dim + k] : row(s + l)[k * G + l];
            if (l == 0) {
              lo[k][l] = points[a * Dim + k];
              tl[k][l] = points[b * Dim + k];
            } else {
              lo[k][l] = s < 0 ? heads[(sweep - 1) * Dim + k] : row(s + l - 1)[k * G + l - 1];
              tl[k][l] = row(t - 1)[k * G + l - 1];
            }
          }
          len[l] = tree.lengths[j];
          iv[l] = tree.inv_lengths[j];
        }
        for (int u = 0; u < U; ++u) {
          for (int k = 0; k < Dim; ++k) {
            lead_old[u][k] = B::load_aligned(lo[k] + u * W);
            lead_new[u][k] = B::load_aligned(ln[k] + u * W);
            tail[u][k] = B::load_aligned(tl[k] + u * W);
          }
          length[u] = B::load_aligned(len + u * W);
          inv[u] = B::load_aligned(iv + u * W);
          active[u] = B::load_aligned(on + u * W) != B(0.0);
        }
      }
      double* out = row(t);
      for (int u = 0; u < U; ++u) {
        B old[Dim];
        for (int k = 0; k < Dim; ++k) old[k] = tail[u][k];
        const auto fix =
            Rule::Apply(lead_old[u], lead_new[u], tail[u], length[u], -inv[u]) & active[u];
        for (int k = 0; k < Dim; ++k) tail[u][k].store_aligned(out + k * G + u * W);
        if (xsimd::any(fix)) {
          // Rare lanes (degenerate or extreme moves): the scalar reference, as the chain's.
          alignas(64) double lo[Dim][W], ln[Dim][W], tl[Dim][W], len[W], mask[W];
          for (int k = 0; k < Dim; ++k) {
            lead_old[u][k].store_aligned(lo[k]);
            lead_new[u][k].store_aligned(ln[k]);
            old[k].store_aligned(tl[k]);
          }
          length[u].store_aligned(len);
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
      const double* last = row(j + G - 1);
      for (int k = 0; k < Dim; ++k) points[tree.tail[j] * Dim + k] = last[k * G + G - 1];
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
