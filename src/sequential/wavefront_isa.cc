// The wavefront engine compiled for one instruction set. CMakeLists.txt builds this file once per
// instruction set with its flags and FLEXKIN_ISA set to 2 (AVX2+FMA) or 3 (AVX-512);
// propagate.cc calls the entry point only after checking at run time that the CPU has it.
#include <cmath>

#include "sequential/wavefront.h"
#include "sequential/whole_chain_kernel.h"

namespace flexkin::internal {

#if FLEXKIN_ISA == 2
#define FLEXKIN_ENTRY SweepsWavefrontAvx2
#define FLEXKIN_TRACED_ENTRY TracedSweepsWavefrontAvx2
#define FLEXKIN_ATAN2_ENTRY Atan2OfSqrtAvx2
#define FLEXKIN_WHOLE_CHAIN_ENTRY WholeChainSweepsAvx2
using Arch = xsimd::fma3<xsimd::avx2>;
#elif FLEXKIN_ISA == 3
#define FLEXKIN_ENTRY SweepsWavefrontAvx512
#define FLEXKIN_TRACED_ENTRY TracedSweepsWavefrontAvx512
#define FLEXKIN_ATAN2_ENTRY Atan2OfSqrtAvx512
#define FLEXKIN_WHOLE_CHAIN_ENTRY WholeChainSweepsAvx512
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

void FLEXKIN_WHOLE_CHAIN_ENTRY(int64_t num_sweeps, WholeChainWork* work, double* points,
                               SweepTrace* trace) {
  WholeChainSweepsOn<Arch>(num_sweeps, work, points, trace);
}

void FLEXKIN_ATAN2_ENTRY(const double* across2, const double* along, int64_t count, double* out) {
  using B = xsimd::batch<double, Arch>;
  int64_t i = 0;
  for (; i + static_cast<int64_t>(B::size) <= count; i += B::size) {
    const B y = xsimd::sqrt(B::load_unaligned(across2 + i));
    xsimd::atan2(y, B::load_unaligned(along + i)).store_unaligned(out + i);
  }
  for (; i < count; ++i) out[i] = std::atan2(std::sqrt(across2[i]), along[i]);
}

}  // namespace flexkin::internal
