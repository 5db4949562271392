#pragma once
// Helpers shared by the arm's kinematics (arm_kinematics.cc) and its solver (arm_solver.cc).

#include <Eigen/Core>

#include "flexkin/arm.h"

namespace flexkin::arm_internal {

// Vectors and matrices of at most 3 by 3 (the translation, the base residual, its Jacobian),
// sized dim at run time but stored inline: the solver's arithmetic allocates nothing.
using SmallVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1>;
using SmallMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, 3>;

// ForwardKinematics and JointAnglesFromPoints without their checks of the model and the input
// (for the solver, whose input is checked once).
Points ForwardUnchecked(const ArmModel& model, const JointAngles& angles);
// With `rebuilt`, AnglesUnchecked also gives ForwardUnchecked of the angles it returns (the same
// points bit for bit; for spherical joints from the frames it accumulates anyway, without a
// second pass).
JointAngles AnglesUnchecked(const ArmModel& model, const Points& points, Points* rebuilt = nullptr);

// Whether the CPU has AVX2 and FMA and FLEXKIN_SIMD does not ask for scalar code: the AVX2
// arm code (src/arm/lanes.h, arm_anchor.h) may run.
bool HasAvx2Fma();

// out[i] = atan2(y[i], x[i]) and s[i], c[i] = sin, cos(a[i]) for i < count: batched with AVX2
// (src/arm/anchor.h) where HasAvx2Fma() and `batched`, otherwise the C library's.
// Both agree to a few units in the last place.
void Atan2All(const double* y, const double* x, int count, double* out, bool batched = true);
void SinCosAll(const double* a, int count, double* s, double* c, bool batched = true);

// Throws InputError with model.Validate()'s reason, if any.
void CheckModel(const ArmModel& model);

// Angle in [lo, hi] nearest to `theta` on the circle (theta, lo, hi in [-pi, pi]).
double ClampCircular(double theta, double lo, double hi);

// Clamps every joint of `angles` into the model's limits (no-op without limits). Returns
// whether any angle changed.
bool ClampToLimits(const ArmModel& model, JointAngles* angles);

// Puts unit vector `dir` into the set the joint limit allows relative to the unit `reference`
// direction: for a planar joint the signed angle from `reference` to `dir` is clamped into
// [lo, hi]; for a spherical joint the angle between them to <= hi (lo unused). Returns whether
// `dir` changed. `dim` is 2 or 3; both point to dim doubles.
bool ClampDirection(int dim, const double* reference, double lo, double hi, double* dir);

}  // namespace flexkin::arm_internal
