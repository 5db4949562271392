#include "chain/simd.h"

#include <cstdlib>
#include <string>

namespace flexkin::internal {

const SimdSupport& CpuSimd() {
  static const SimdSupport support = [] {
    SimdSupport s;
#if defined(__x86_64__) || defined(__i386__)
    __builtin_cpu_init();
    s.avx2_fma = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    s.avx512 = s.avx2_fma && __builtin_cpu_supports("avx512f") &&
               __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512cd");
#endif
    return s;
  }();
  return support;
}

const SimdSupport& AllowedSimd() {
  static const SimdSupport allowed = [] {
    SimdSupport s = CpuSimd();
    const char* cap = std::getenv("FLEXKIN_SIMD");
    const std::string name = cap != nullptr ? cap : "avx512";
    if (name == "scalar") s.avx2_fma = false;
    if (name != "avx512") s.avx512 = false;
    return s;
  }();
  return allowed;
}

}  // namespace flexkin::internal
