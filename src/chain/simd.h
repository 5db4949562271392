#pragma once
// The instruction sets the engines may use, decided once per process: what the CPU has, capped by
// FLEXKIN_SIMD=scalar|avx2|avx512 in the environment (unset: avx512) (to compare the engines, or to
// test each one on one machine). The sequential sweeps (src/sequential) and the arms' lanes
// (src/arm) both ask here, so one variable switches every engine.

namespace flexkin::internal {

struct SimdSupport {
  bool avx2_fma = false;  // the CPU has AVX2 and FMA
  bool avx512 = false;    // ... and AVX-512 F, CD and DQ
};

// What the CPU supports, whatever FLEXKIN_SIMD says.
const SimdSupport& CpuSimd();
// What the engines may use: CpuSimd() capped by FLEXKIN_SIMD.
const SimdSupport& AllowedSimd();

}  // namespace flexkin::internal
