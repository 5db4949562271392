#pragma once
// Subnormal numbers flushed to zero inside the engines' sweeps. Where a chain's motion dies out,
// the far links' moves and the coordinates across a straight chain shrink through the subnormal
// range (below 2.2e-308) on their way to zero; x86 computes with subnormals through microcode,
// tens of times slower, and the tractrix rule, with more operations per link than
// follow-the-leader, paid up to 1.6x for it (docs/BENCHMARKS.md, "Scenes"). Inside a sweep every
// subnormal input is read as 0 and every subnormal result written as 0 (MXCSR's DAZ and FTZ
// bits): a difference below 2.2e-308 in a coordinate, which no link length or metric can show.
// The scope restores the caller's mode on exit, also when an exception leaves it, and a sweep's
// call-backs into the caller's code (a frame captured for a sink) run in the caller's mode
// (CallerFloatingPointMode).

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

namespace flexkin::internal {

#if defined(__SSE2__)
class SubnormalsAsZero {
 public:
  static constexpr unsigned kBits = 0x8040;  // FTZ (bit 15) and DAZ (bit 6)
  SubnormalsAsZero() : saved_(_mm_getcsr()) {
    if ((saved_ & kBits) != kBits) _mm_setcsr(saved_ | kBits);
  }
  ~SubnormalsAsZero() {
    if ((saved_ & kBits) != kBits) _mm_setcsr(saved_);
  }
  SubnormalsAsZero(const SubnormalsAsZero&) = delete;
  SubnormalsAsZero& operator=(const SubnormalsAsZero&) = delete;

 private:
  unsigned saved_;
};

// Inside a SubnormalsAsZero scope: the IEEE mode (subnormals kept) for a call into other code.
class CallerFloatingPointMode {
 public:
  CallerFloatingPointMode() : saved_(_mm_getcsr()) {
    if ((saved_ & SubnormalsAsZero::kBits) != 0) _mm_setcsr(saved_ & ~SubnormalsAsZero::kBits);
  }
  ~CallerFloatingPointMode() {
    if ((saved_ & SubnormalsAsZero::kBits) != 0) _mm_setcsr(saved_);
  }
  CallerFloatingPointMode(const CallerFloatingPointMode&) = delete;
  CallerFloatingPointMode& operator=(const CallerFloatingPointMode&) = delete;

 private:
  unsigned saved_;
};
#else
// Elsewhere subnormals are kept (and cost what the CPU makes them cost).
struct SubnormalsAsZero {};
struct CallerFloatingPointMode {};
#endif

}  // namespace flexkin::internal
