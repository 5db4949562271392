// The tree wavefront (tree_wavefront.h) compiled for one instruction set. CMakeLists.txt builds
// this file once per instruction set with its flags and FLEXKIN_ISA set to 2 (AVX2+FMA) or 3
// (AVX-512), beside the chain's wavefront_isa.cc (a translation unit of its own, so that the
// chain's engine is compiled as it was); tree.cc calls the entry point only after checking at run
// time that the CPU has it.
#include "sequential/tree_wavefront.h"

namespace flexkin::internal {

#if FLEXKIN_ISA == 2
#define FLEXKIN_TREE_ENTRY TreeWavefrontAvx2
using TreeArch = xsimd::fma3<xsimd::avx2>;
#elif FLEXKIN_ISA == 3
#define FLEXKIN_TREE_ENTRY TreeWavefrontAvx512
using TreeArch = xsimd::avx512f;
#else
#error "FLEXKIN_ISA must be 2 or 3"
#endif

int64_t FLEXKIN_TREE_ENTRY(Method method, int dim, const double* heads, int64_t num_sweeps,
                           const TreeLinks& tree, double* points) {
  return TreeWavefrontDispatch<TreeArch>(method, dim, heads, num_sweeps, tree, points);
}

}  // namespace flexkin::internal
