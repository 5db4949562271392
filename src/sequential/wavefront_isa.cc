// The wavefront engine compiled for one instruction set. CMakeLists.txt builds this file once per
// instruction set with its flags and FLEXKIN_ISA set to 2 (AVX2+FMA) or 3 (AVX-512);
// propagate.cc calls the entry point only after checking at run time that the CPU has it.
#include "sequential/wavefront.h"

namespace flexkin::internal {

#if FLEXKIN_ISA == 2
#define FLEXKIN_ENTRY SweepsWavefrontAvx2
#define FLEXKIN_TRACED_ENTRY TracedSweepsWavefrontAvx2
using Arch = xsimd::fma3<xsimd::avx2>;
#elif FLEXKIN_ISA == 3
#define FLEXKIN_ENTRY SweepsWavefrontAvx512
#define FLEXKIN_TRACED_ENTRY TracedSweepsWavefrontAvx512
using Arch = xsimd::avx512f;
#else
#error "FLEXKIN_ISA must be 2 or 3"
#endif

void FLEXKIN_ENTRY(Method method, int dim, const double* heads, int64_t num_sweeps,
                   const double* lengths, const double* inv_lengths, int n, double* points) {
  WavefrontDispatch<Arch, false>(method, dim, heads, num_sweeps, lengths, inv_lengths, n, points,
                                 nullptr);
}

void FLEXKIN_TRACED_ENTRY(Method method, int dim, const double* heads, int64_t num_sweeps,
                          const double* lengths, const double* inv_lengths, int n, double* points,
                          SweepTrace* trace) {
  WavefrontDispatch<Arch, true>(method, dim, heads, num_sweeps, lengths, inv_lengths, n, points,
                                trace);
}

}  // namespace flexkin::internal
