#pragma once
// The planar arm's re-anchoring (joint angles from points and points from joint angles,
// src/arm/kinematics.cc) needs one atan2 per joint and one sine and cosine per link. They are
// independent of each other (only the cheap sums along the arm are sequential), so here they are
// evaluated four at a time with AVX2 + FMA (arm_anchor.cc, compiled with -mavx2 -mfma; called
// only after the CPU was checked to have both). xsimd's functions agree with the C library's to
// a few units in the last place.

namespace flexkin::internal {

// out[i] = atan2(y[i], x[i]) for 0 <= i < count (rad, [-pi, pi]).
void Atan2Avx2(const double* y, const double* x, int count, double* out);
// s[i] = sin(a[i]), c[i] = cos(a[i]) for 0 <= i < count.
void SinCosAvx2(const double* a, int count, double* s, double* c);

}  // namespace flexkin::internal
