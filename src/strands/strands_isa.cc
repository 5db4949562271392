// The strand engine's SIMD sweeps compiled for one instruction set. CMakeLists.txt builds this
// file once per instruction set with its flags and FLEXKIN_ISA set to 2 (AVX2+FMA) or 3
// (AVX-512); strands.cc calls it only after checking at run time that the CPU has it.
//
// Lanes run across strands: every register holds one coordinate of one point of several strands,
// and all kStrandLanes / W registers of a block are stepped together, so that the latencies of
// their (independent) rule evaluations overlap. The per-link formula is the wavefront engine's:
// the rules of sequential/link_rules.h with the vector exp of sequential/wavefront.h, and the
// scalar reference form for the rare flagged lanes.
#include <xsimd/xsimd.hpp>

#include "sequential/link_rules.h"
#include "sequential/rule_table.h"
#include "sequential/wavefront.h"
#include "strands/strand_engine.h"

namespace flexkin::internal {

#if FLEXKIN_ISA == 2
#define FLEXKIN_STRAND_ENTRY StrandSweepsAvx2
using Arch = xsimd::fma3<xsimd::avx2>;
#elif FLEXKIN_ISA == 3
#define FLEXKIN_STRAND_ENTRY StrandSweepsAvx512
using Arch = xsimd::avx512f;
#else
#error "FLEXKIN_ISA must be 2 or 3"
#endif

namespace {

template <class Rule, int Dim>
void BlockSweeps(int n, int head, int num_sweeps, const double* heads, const double* lengths,
                 const double* inv_lengths, double* points) {
  using B = xsimd::batch<double, Arch>;
  constexpr int W = B::size;
  constexpr int U = kStrandLanes / W;
  constexpr int L = kStrandLanes;
  for (int s = 0; s < num_sweeps; ++s) {
    B lead_old[U][Dim], lead_new[U][Dim];
    double* lead = points + head * Dim * L;
    for (int u = 0; u < U; ++u) {
      for (int k = 0; k < Dim; ++k) {
        lead_old[u][k] = B::load_aligned(lead + k * L + u * W);
        lead_new[u][k] = B::load_aligned(heads + (s * Dim + k) * L + u * W);
        lead_new[u][k].store_aligned(lead + k * L + u * W);
      }
    }
    for (int i = head + 1; i <= n; ++i) {
      double* tail_ptr = points + i * Dim * L;
      const double* len_ptr = lengths + (i - 1) * L;
      const double* inv_ptr = inv_lengths + (i - 1) * L;
      for (int u = 0; u < U; ++u) {
        B old[Dim], tail[Dim];
        for (int k = 0; k < Dim; ++k) {
          old[k] = tail[k] = B::load_aligned(tail_ptr + k * L + u * W);
        }
        const B length = B::load_aligned(len_ptr + u * W);
        const B neg_inv_length = -B::load_aligned(inv_ptr + u * W);
        const auto fix = Rule::Apply(lead_old[u], lead_new[u], tail, length, neg_inv_length);
        if (xsimd::any(fix)) {
          // Rare lanes (degenerate or extreme moves): redo them with the scalar reference.
          alignas(64) double lo[Dim][W], ln[Dim][W], was[Dim][W], out[Dim][W], mask[W];
          for (int k = 0; k < Dim; ++k) {
            lead_old[u][k].store_aligned(lo[k]);
            lead_new[u][k].store_aligned(ln[k]);
            old[k].store_aligned(was[k]);
            tail[k].store_aligned(out[k]);
          }
          xsimd::select(fix, B(1.0), B(0.0)).store_aligned(mask);
          for (int j = 0; j < W; ++j) {
            if (mask[j] == 0.0) continue;
            double a[Dim], b[Dim], c[Dim];
            for (int k = 0; k < Dim; ++k) a[k] = lo[k][j], b[k] = ln[k][j], c[k] = was[k][j];
            Rule::Reference(a, b, c, len_ptr[u * W + j]);
            for (int k = 0; k < Dim; ++k) out[k][j] = c[k];
          }
          for (int k = 0; k < Dim; ++k) tail[k] = B::load_aligned(out[k]);
        }
        for (int k = 0; k < Dim; ++k) {
          tail[k].store_aligned(tail_ptr + k * L + u * W);
          lead_old[u][k] = old[k];
          lead_new[u][k] = tail[k];
        }
      }
    }
  }
}

}  // namespace

void FLEXKIN_STRAND_ENTRY(Method method, int dim, int n, int head, int num_sweeps,
                          const double* heads, const double* lengths, const double* inv_lengths,
                          double* points) {
  DispatchRule<kStrandEngine>(method, [&](auto rule) {
    using Rule = decltype(rule);
    dim == 2 ? BlockSweeps<typename Rule::template Step<2, BatchExp>, 2>(
                   n, head, num_sweeps, heads, lengths, inv_lengths, points)
             : BlockSweeps<typename Rule::template Step<3, BatchExp>, 3>(
                   n, head, num_sweeps, heads, lengths, inv_lengths, points);
  });
}

}  // namespace flexkin::internal
