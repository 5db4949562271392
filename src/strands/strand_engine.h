#pragma once
// The strand engine's sweeps over one block of strands (flexkin/strands.h, docs/strands.md).
//
// A block is kStrandLanes strands with the same link count n, stored as structure of arrays:
// coordinate k of point i of lane j at points[(i * dim + k) * kStrandLanes + j], link i's length
// (points i-1 to i, 1-based) at lengths[(i - 1) * kStrandLanes + j]. Lanes beyond the strands of
// a block repeat one of its strands, so that every lane computes something sensible.

#include <cstdint>

#include "flexkin/propagate.h"

namespace flexkin::internal {

constexpr int kStrandLanes = 16;

// The leading end, point `head` of every lane, visits `num_sweeps` positions (heads, sweep s at
// heads[(s * dim + k) * kStrandLanes + j]); after each, links head+1..n, from the leading end
// down, apply the method's rule (tractrix or ftl), as SweepsScalar does for one chain.
using StrandSweepsFn = void (*)(Method method, int dim, int n, int head, int num_sweeps,
                                const double* heads, const double* lengths,
                                const double* inv_lengths, double* points);

// The reference: each lane by itself, the very operations of SweepsScalar (bit for bit).
void StrandSweepsScalar(Method method, int dim, int n, int head, int num_sweeps,
                        const double* heads, const double* lengths, const double* inv_lengths,
                        double* points);

// A collider as the lanes' first test sees it: a ball that holds it (exact for a sphere), or a
// half-space's plane.
struct ColliderBound {
  bool half_space = false;
  bool exact = false;     // a sphere: the ball is the collider
  double center[3] = {};  // the ball's centre, or a point of the plane
  double up[3] = {};      // the plane's outward normal
  double radius = 0.0;    // the ball's radius
};

// The clearance of every free link (head + 1 .. n) of every lane from every bound: link i's from
// bound c at clearances[((i - head - 1) * num_bounds + c) * kStrandLanes + lane] (the least
// distance of the segment to the ball less its radius, or the least height of its ends above the
// plane).
using StrandBoundsFn = void (*)(int dim, int n, int head, const double* points,
                                const ColliderBound* bounds, int num_bounds, double* clearances);
void StrandBoundsScalar(int dim, int n, int head, const double* points, const ColliderBound* bounds,
                        int num_bounds, double* clearances);

// One sphere the lanes stay outside of (flexkin/strands.h colliders, docs/colliders.md), placed
// in the world, and what a sweep against it reports.
struct StrandSphere {
  double center[3] = {};
  double radius = 0.0;
  double slack = 0.0;  // the relative depth a link may lie inside (world/contact.h kContactSlack)
};

// One sweep (the leading end to `heads`, dim x lanes) of the method's rule, as StrandSweeps*,
// with the contact step against one sphere in the lanes: where a link's rule step would enter
// it, the least-motion step that keeps it outside, in closed form (the direction of the old
// trailing end where that is clear, else the boundary of the cone of directions the sphere
// blocks, on the great circle through that direction: docs/colliders.md, "One sphere"), as the
// scalar contact step (world/contact.h ContactTail) computes it, to rounding. contact[i * lanes +
// j] is set to 1 where link i of lane j took the contact step (0 elsewhere); fallback[j] is
// lowered to the first link of lane j that the closed form could not step (a head inside the
// sphere, a degenerate direction, a result the rounding left inside): that link and those after it
// hold meaningless values, for the caller to step again.
// `saved` receives the points head .. n as they were before the sweep (the block's layout from
// point `head` on), for the caller to step a lane again from there. `found` receives the check of
// the sphere after the sweep (StrandSphereCheckFn's answers, from least infinity, first_enter
// n + 1 and near 0), made link by link as the sweep leaves each link: the same bits; and, per
// lane, how many links took the contact step (the count of its `contact` flags).
struct StrandSphereFound {
  double least[kStrandLanes];
  int first_enter[kStrandLanes];
  uint8_t near[kStrandLanes];
  int contacts[kStrandLanes];
};
using StrandSphereSweepFn = void (*)(Method method, int dim, int n, int head, const double* heads,
                                     const double* lengths, const double* inv_lengths,
                                     double* points, const StrandSphere& sphere, uint8_t* contact,
                                     int* fallback, double* saved, StrandSphereFound* found);

// The exact check of one sphere (a ColliderBound with `exact`) after a sweep, for every free link
// (head + 1 .. n) of every lane, as CheckLanes makes it from StrandBoundsFn's clearances, bit for
// bit: where link i of lane j comes nearer the sphere than its length, near[j] is set to 1,
// least[j] lowered to the link's clearance over its length, and first_enter[j] lowered to i where
// the clearance is below -slack times the length. A link whose squared distance (without a
// division or a root) shows it further from the sphere, by a margin above the rounding, than the
// least relative clearance this sphere has given the lane so far (or than its length, before any)
// can change none of them and is not measured exactly.
using StrandSphereCheckFn = void (*)(int dim, int n, int head, const double* points,
                                     const double* lengths, const double* inv_lengths,
                                     const ColliderBound& bound, double slack, double* least,
                                     int* first_enter, uint8_t* near);

// Dynamic strands (flexkin/strands.h `dynamics`): one sub-step of one block, in stages.
// Stage 1: the pinned points 0 .. head are at the sub-step's end in x (their start in x_old), the
// free points head + 1 .. n at its start in x with velocities v; afterwards x_old holds the free
// points' start too, p the inertial prediction (the pinned points' new places) and x its
// sequential projection (tractrix or dftl). Stage 2: v becomes (x - x_old) / h, with Mueller et
// al.'s correction -s (x_{j+1} - p_{j+1}) / h where `correct`. Stage 3 (between them, for the
// overall projection): x becomes the overall projection of p (dynamics/least_constraint.h) where it
// converges. Stage 4 (between them, for SHAKE): x becomes the SHAKE projection of p about x_old
// (dynamics/shake.h), `converged` 1 where it converged. The operations are SimulateChain's.
struct DynamicLaneStep {
  int n = 0, head = 0;
  bool tractrix = true;  // else dftl
  bool correct = true;   // stage 2: the sequential projections' velocity correction
  double h = 0.0, damping = 0.0, dftl_damping = 0.0;
  double gravity[3] = {}, wind[3] = {};
  const double* lengths = nullptr;
  const double* inv_lengths = nullptr;
  double *x = nullptr, *x_old = nullptr, *p = nullptr, *v = nullptr;
  // Stage 1 on the SIMD engines, if set: the sequential projection's contact step against this
  // sphere in the lanes (as StrandSphereSweepFn's), link i of lane j flagged in
  // contact[i * kStrandLanes + j] (1 where it took it, else 0) and fallback[j] lowered to the first
  // link the closed form could not step. The scalar engine leaves every contact to its caller.
  const StrandSphere* sphere = nullptr;
  uint8_t* contact = nullptr;
  int* fallback = nullptr;
  // Stages 3 and 4, the overall projection (from the tractrix projection in x) and SHAKE: the
  // points' masses (point i of lane j at i * kStrandLanes + j), the solver's scratch
  // (LeastConstraintWork(dim, n) * kStrandLanes, aligned) and, per lane, 1 where it converged,
  // else 0.
  const double* mass = nullptr;
  double* work = nullptr;
  double* multipliers = nullptr;   // the links' (as mass), kept from sub-step to sub-step
  const double* ignore = nullptr;  // per lane: 1 where the stage's projection is not wanted
  // Stage 2 without `correct`: per lane, 1 where the velocities take the correction (the overall
  // projection's lanes that took the tractrix projection with contacts), else 0.
  const double* correct_lanes = nullptr;
  double* converged = nullptr;
};
using StrandDynamicFn = void (*)(int dim, const DynamicLaneStep& q, int stage);
void StrandDynamicScalar(int dim, const DynamicLaneStep& q, int stage);

#if FLEXKIN_HAVE_WAVEFRONT
void StrandDynamicAvx2(int dim, const DynamicLaneStep& q, int stage);
void StrandDynamicAvx512(int dim, const DynamicLaneStep& q, int stage);
// The lanes in SIMD registers (strands_isa.cc, compiled per instruction set); equal to the
// reference up to the vector exp's rounding, as the wavefront engine.
void StrandSweepsAvx2(Method method, int dim, int n, int head, int num_sweeps, const double* heads,
                      const double* lengths, const double* inv_lengths, double* points);
void StrandSweepsAvx512(Method method, int dim, int n, int head, int num_sweeps,
                        const double* heads, const double* lengths, const double* inv_lengths,
                        double* points);
void StrandBoundsAvx2(int dim, int n, int head, const double* points, const ColliderBound* bounds,
                      int num_bounds, double* clearances);
void StrandBoundsAvx512(int dim, int n, int head, const double* points, const ColliderBound* bounds,
                        int num_bounds, double* clearances);
void StrandSphereSweepAvx2(Method method, int dim, int n, int head, const double* heads,
                           const double* lengths, const double* inv_lengths, double* points,
                           const StrandSphere& sphere, uint8_t* contact, int* fallback,
                           double* saved, StrandSphereFound* found);
void StrandSphereSweepAvx512(Method method, int dim, int n, int head, const double* heads,
                             const double* lengths, const double* inv_lengths, double* points,
                             const StrandSphere& sphere, uint8_t* contact, int* fallback,
                             double* saved, StrandSphereFound* found);
void StrandSphereCheckAvx2(int dim, int n, int head, const double* points, const double* lengths,
                           const double* inv_lengths, const ColliderBound& bound, double slack,
                           double* least, int* first_enter, uint8_t* near);
void StrandSphereCheckAvx512(int dim, int n, int head, const double* points, const double* lengths,
                             const double* inv_lengths, const ColliderBound& bound, double slack,
                             double* least, int* first_enter, uint8_t* near);
#endif

}  // namespace flexkin::internal

namespace flexkin {
class StrandBatch;
namespace internal {
// For tests and benchmarks: steps `batch` with the named engine ("scalar", "avx2", "avx512")
// from now on. Returns false (and changes nothing) where this CPU has no such engine.
bool SetStrandEngine(StrandBatch* batch, const char* name);
// For tests: the named engine's entry points (the scalar engine has no sphere sweep or sphere
// check: it measures a sphere as any bound). Returns false where this CPU or build has no such
// engine.
struct StrandEngineEntries {
  StrandSweepsFn sweeps = nullptr;
  StrandSphereSweepFn sphere_sweep = nullptr;
  StrandBoundsFn bounds = StrandBoundsScalar;
  StrandSphereCheckFn check_sphere = nullptr;
  StrandDynamicFn dynamic = StrandDynamicScalar;
};
bool StrandEngineOf(const char* name, StrandEngineEntries* out);
}  // namespace internal
}  // namespace flexkin
