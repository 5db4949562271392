#pragma once
// The strand engine's sweeps over one block of strands (flexkin/strands.h, docs/strands.md).
//
// A block is kStrandLanes strands with the same link count n, stored as structure of arrays:
// coordinate k of point i of lane j at points[(i * dim + k) * kStrandLanes + j], link i's length
// (points i-1 to i, 1-based) at lengths[(i - 1) * kStrandLanes + j]. Lanes beyond the strands of
// a block repeat one of its strands, so that every lane computes something sensible.

#include <cstdint>

#include "flexkin/propagate.h"

namespace flexkin::internal {

constexpr int kStrandLanes = 16;

// The leading end, point `head` of every lane, visits `num_sweeps` positions (heads, sweep s at
// heads[(s * dim + k) * kStrandLanes + j]); after each, links head+1..n, from the leading end
// down, apply the method's rule (tractrix or ftl), as SweepsScalar does for one chain.
using StrandSweepsFn = void (*)(Method method, int dim, int n, int head, int num_sweeps,
                                const double* heads, const double* lengths,
                                const double* inv_lengths, double* points);

// The reference: each lane by itself, the very operations of SweepsScalar (bit for bit).
void StrandSweepsScalar(Method method, int dim, int n, int head, int num_sweeps,
                        const double* heads, const double* lengths, const double* inv_lengths,
                        double* points);

#if FLEXKIN_HAVE_WAVEFRONT
// The lanes in SIMD registers (strands_isa.cc, compiled per instruction set); equal to the
// reference up to the vector exp's rounding, as the wavefront engine.
void StrandSweepsAvx2(Method method, int dim, int n, int head, int num_sweeps, const double* heads,
                      const double* lengths, const double* inv_lengths, double* points);
void StrandSweepsAvx512(Method method, int dim, int n, int head, int num_sweeps,
                        const double* heads, const double* lengths, const double* inv_lengths,
                        double* points);
#endif

}  // namespace flexkin::internal

namespace flexkin {
class StrandBatch;
namespace internal {
// For tests and benchmarks: steps `batch` with the named engine ("scalar", "avx2", "avx512")
// from now on. Returns false (and changes nothing) where this CPU has no such engine.
bool SetStrandEngine(StrandBatch* batch, const char* name);
}  // namespace internal
}  // namespace flexkin
