#pragma once
// The whole-chain rules (minimum body rotation, minimum joint-angle change; metric_rules.cc) on
// the SIMD engine. Each sweep of these rules moves the chain rigidly behind its first few points:
//  - min_rotation: every point by the shift that takes point 0 to the new head, p <- p + shift;
//  - min_joint_angle: points 0 and 1 are placed (the head, the first link's tractrix step), and
//    every later point turns with the first link, p <- to + R (p - from).
// The rigid motion of each sweep depends only on the placed points, so a call first computes the
// motions of all its sweeps one after another, as the reference loop does (scalar, the same
// operations), then applies them to the rest of the chain with a kernel compiled per instruction
// set that holds the chain as coordinate arrays (x..., y..., z...), SIMD lanes along the chain.
// The kernel measures what a run observes (SweepTrace, sweep.h) in the same pass.
//
// Results are those of the sub-step by sub-step loop up to rounding (the kernel's fused
// multiply-adds and its order of summation): within a few ulps of each coordinate.

#include <cstdint>
#include <vector>

#include "flexkin/propagate.h"
#include "sequential/sweep.h"

namespace flexkin::internal {

// The buffers of the whole-chain engine, sized once per chain (Prepare) for calls of at most
// `max_sweeps` sweeps: nothing is allocated per call.
struct WholeChainWork {
  static constexpr int kPad = 8;  // the most lanes: the coordinate arrays' padding
  int dim = 0, n = 0;
  int first = 0;        // points [0, first) are placed by the rule; [first, n] move rigidly
  bool rotate = false;  // p <- to + R (p - from); else p <- p + to (a shift)
  int max_sweeps = 0;
  // Per sweep of a call: 3 doubles of `from`, 3 of `to`, 9 of R (row-major, 3 by 3), and the
  // first * dim coordinates of the placed points after it.
  std::vector<double> from, to, rotation, placed;
  // The kernel's arrays, index j for point first + j, padded to whole lanes: the coordinates
  // (dim arrays of `stride`, each with one entry before index 0: point first - 1, or 0), the
  // distance each point has moved in the call, the arc-length weights, the link lengths (of the
  // link ending at the point) and their inverses (0 for a point without a link, and for padding,
  // so that no length error is counted there), and 1 for a real point, 0 for padding.
  int stride = 0, lanes_padded = 0;
  std::vector<double> coords, moved, weights, lengths, inv_lengths, valid;

  void Prepare(Method method, int dim, const double* lengths, const double* point_weights,
               int num_links, int max_sweeps);
};

// The kernels, one per instruction set (wavefront_isa.cc), on a call's motions.
using WholeChainKernelFn = void (*)(int64_t num_sweeps, WholeChainWork* work, double* points,
                                    SweepTrace* trace);
// The kernel of the widest instruction set AllowedSimd() permits, or null without AVX2 and FMA.
WholeChainKernelFn WholeChainKernel();

// Whether the whole-chain rules have a SIMD kernel on this CPU (what FLEXKIN_SIMD allows).
bool WholeChainOnSimd();

// TracedSweepsWavefront's counterpart for the whole-chain rules (`work` prepared for the method,
// num_sweeps <= work->max_sweeps, WholeChainOnSimd()):
// the same motion as SweepsMinRotation / SweepsMinJointAngle, plus `trace` (not its exact
// accounting: trace->moved must be null).
void TracedWholeChainSweeps(const double* heads, int64_t num_sweeps, const double* lengths,
                            const double* inv_lengths, double* points, WholeChainWork* work,
                            SweepTrace* trace);

}  // namespace flexkin::internal
