#pragma once
// The fixed-base arm's sweeps (src/arm/sweep.h) compiled for AVX2 + FMA (arm_lanes.cc, chosen at
// run time by arm_sweep.cc): one translation swept with a scalar loop whose exp has a short
// dependency chain, or up to 4 translations swept together, one per lane of an AVX2 register.
// Arms without joint limits only (the limits' projections stay in the generic loop).

namespace flexkin::internal {

// Sweeps `lanes` (1 to 4) copies of `start` ((n+1) by dim, row-major, base first), copy l
// translated by u[l * dim .. l * dim + dim): the end effector (point n) moves to `target` in
// `substeps` straight pieces and every link follows by the tractrix step. Writes copy 0's points
// to `points0` ((n+1) by dim) and every copy's base (point 0) to bases[l * dim ..].
void ArmSweepLanesAvx2(int dim, int lanes, const double* start, const double* u,
                       const double* target, int substeps, const double* lengths,
                       const double* inv_lengths, int n, double* points0, double* bases);

}  // namespace flexkin::internal
