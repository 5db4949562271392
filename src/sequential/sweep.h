#pragma once
// Internal sweep engines: the leading end visits `num_sweeps` positions (`heads`, row-major,
// num_sweeps by dim) and after each one every link, from the leading end down, applies the
// method's rule. `points` is the (n+1) by dim row-major chain, updated in place.

#include <cstdint>
#include <vector>

#include "flexkin/propagate.h"

namespace flexkin::internal {

// One sweep after another: the reference order of operations.
void SweepsScalar(Method method, int dim, const double* heads, int64_t num_sweeps,
                  const double* lengths, const double* inv_lengths, int num_links, double* points);

// The same sweeps, several in flight at once: sweep s+1 works on link i-1 while sweep s works on
// link i (a wavefront), one sweep per SIMD lane, for the best instruction set this CPU has.
// Gives the same result as SweepsScalar up to the rounding of the vector exp (about 1 ulp).
void SweepsWavefront(Method method, int dim, const double* heads, int64_t num_sweeps,
                     const double* lengths, const double* inv_lengths, int num_links,
                     double* points);

// The sequential rules of the rotation and joint-angle metrics (metric_rules.cc).
void SweepsMinRotation(int dim, const double* heads, int64_t num_sweeps, int num_links,
                       double* points);
void SweepsMinJointAngle(int dim, const double* heads, int64_t num_sweeps, const double* lengths,
                         const double* inv_lengths, int num_links, double* points);

// Number of sweeps in flight in SweepsWavefront on this CPU (the SIMD width in doubles).
int WavefrontLanes();

// Every wavefront engine this CPU can run, by name ("avx2", "avx512"), so tests can check each
// against SweepsScalar whatever FLEXKIN_SIMD says.
using SweepsFn = void (*)(Method, int, const double*, int64_t, const double*, const double*, int,
                          double*);
struct WavefrontEngine {
  const char* name;
  SweepsFn fn;
  int lanes;
};
std::vector<WavefrontEngine> AvailableWavefronts();

}  // namespace flexkin::internal
