#pragma once
// Internal sweep engines: the leading end visits `num_sweeps` positions (`heads`, row-major,
// num_sweeps by dim) and after each one every link, from the leading end down, applies the
// method's rule. `points` is the (n+1) by dim row-major chain, updated in place.

#include <cstdint>
#include <limits>
#include <vector>

#include "flexkin/colliders.h"
#include "flexkin/propagate.h"

namespace flexkin::internal {

// One sweep after another: the reference order of operations.
// MakeStepper without its checks, for callers that validated `chain` and know `method` is a link
// rule (Run: checked once, at the boundary).
Stepper MakeStepperUnchecked(Method method, const Chain& chain);

void SweepsScalar(Method method, int dim, const double* heads, int64_t num_sweeps,
                  const double* lengths, const double* inv_lengths, int num_links, double* points);

// The same sweeps, several in flight at once: sweep s+1 works on link i-1 while sweep s works on
// link i (a wavefront), one sweep per SIMD lane, for the best instruction set this CPU has.
// Gives the same result as SweepsScalar up to the rounding of the vector exp (about 1 ulp).
void SweepsWavefront(Method method, int dim, const double* heads, int64_t num_sweeps,
                     const double* lengths, const double* inv_lengths, int num_links,
                     double* points);

struct SweepContact;

// What a run observes of its sweeps (src/run/run.cc), filled in by the traced engines below in
// the same pass that moves the chain.
struct SweepTrace {
  static constexpr uint8_t kStepEnd = 1;  // the last sub-step of a leader step: lengths checked
  static constexpr uint8_t kCapture = 2;  // the configuration after it is handed to `capture`
  static constexpr int kMaxSlots = 16;    // the most captures one call keeps at once
  static constexpr int kPad = 15;         // padding of the arrays below: the most lanes - 1
  // The link lengths of point i (from point i-1), their negated inverses, and the arc-length
  // weights of point i, at index kPad + i, padded with kPad entries either side (lengths 1,
  // weights 0) as the wavefront's lanes read them. Prepare fills them once per chain.
  std::vector<double> padded_lengths, padded_neg_inv_lengths, padded_weights;
  void Prepare(const double* lengths, const double* inv_lengths, const double* point_weights,
               int num_links) {
    const size_t size = static_cast<size_t>(num_links) + 1 + 2 * kPad;
    padded_lengths.assign(size, 1.0);
    padded_neg_inv_lengths.assign(size, -1.0);
    padded_weights.assign(size, 0.0);
    for (int i = 0; i < num_links; ++i) {
      padded_lengths[kPad + 1 + i] = lengths[i];
      padded_neg_inv_lengths[kPad + 1 + i] = -inv_lengths[i];
    }
    for (int i = 0; i <= num_links; ++i) padded_weights[kPad + i] = point_weights[i];
    weights = point_weights;
  }
  // In: per sweep of the call, kStepEnd | kCapture.
  const uint8_t* flags = nullptr;
  // In: the n+1 arc-length weights of the weighted L2 metric (set by Prepare).
  const double* weights = nullptr;
  // Exact accounting (the scalar engine): if not null, moved[j] += the distance point j moves in
  // each sweep, and the caller does the rest at the end of each leader step; sweep_l2, sweep_l2w,
  // path_length and max_length_error are then left alone.
  double* moved = nullptr;
  // Out, per sweep of the call: the sum over the points of the distance each moves, and that sum
  // weighted by `weights`.
  double* sweep_l2 = nullptr;
  double* sweep_l2w = nullptr;
  // Accumulated: the distance each of the n+1 points has moved.
  double* path_length = nullptr;
  // Accumulated: the largest |(|x_i - x_{i-1}| - L_i)| / L_i after a kStepEnd sweep.
  double max_length_error = 0.0;
  // Capture slots, kMaxSlots arrays of (n+1) * dim doubles the wavefront copies configurations
  // into; `capture(context, sweep, slot)` is called for every kCapture sweep, in sweep order, with
  // the slot holding it, or slot -1 when the chain itself (`points`) holds it.
  double* const* slots = nullptr;
  void (*capture)(void* context, int64_t sweep, int slot) = nullptr;
  void* context = nullptr;
  // Static colliders (a run's, through its sweep pipeline), or null: every link's rule step is
  // then kept outside them as ContactSweep keeps it (SweepContact).
  SweepContact* contact = nullptr;
};

// SweepsScalar and SweepsWavefront, observed: the same motion, bit for bit, plus `trace`.
void TracedSweepsScalar(Method method, int dim, const double* heads, int64_t num_sweeps,
                        const double* lengths, const double* inv_lengths, int num_links,
                        double* points, SweepTrace* trace);
// TracedSweepsScalar from sweep `first` on (heads, flags and per-sweep outputs indexed from the
// call's start): the wavefront finishes its last few sweeps with it.
void TracedSweepsScalarFrom(Method method, int dim, const double* heads, int64_t first,
                            int64_t num_sweeps, const double* lengths, const double* inv_lengths,
                            int num_links, double* points, SweepTrace* trace);
void TracedSweepsWavefront(Method method, int dim, const double* heads, int64_t num_sweeps,
                           const double* lengths, const double* inv_lengths, int num_links,
                           double* points, SweepTrace* trace);

// What the colliders did to a run's sweeps (ContactSweep).
struct ContactStats {
  int64_t contact_link_steps = 0;  // link steps whose rule step entered a collider
  // The least clearance of any link after any sweep, relative to its length (+inf: none
  // measured); at least -kContactSlack (world/contact.h).
  double least_clearance = std::numeric_limits<double>::infinity();
};

// The colliders a sweep, or a group of sweeps whose heads lie close together, may meet, with a
// ball that holds each: its pose's translation and BoundingRadius (a radius < 0 for a half-space,
// which no ball holds). contact_sweep.cc.
struct SweepSet {
  const std::vector<Collider>* colliders = nullptr;
  // Centre x, y, z and radius. Filled where Eigen aligns a Vector4d to 16 bytes; the wavefront's
  // translation units (AVX: Eigen assumes 32) read them as doubles, never as Vector4d.
  std::vector<Eigen::Vector4d> balls;
  std::vector<char> spheres;                // whether the collider is a sphere (its ball is itself)
  std::vector<Eigen::Isometry3d> to_local;  // a mesh's world-to-mesh transform (its pose inverted)
};

// Static colliders in the traced engines (SweepTrace::contact): after each link's rule step the
// link is kept outside them by ContactSweep's test and contact step (KeepLinkOutside), and what
// they did is counted in `stats`. The wavefront skips the test for lanes whose link is beyond
// every ball of `set` by a margin (the test would skip each collider: the same steps and report).
struct SweepContact {
  const std::vector<Collider>* colliders = nullptr;  // the run's
  ContactStats stats;
  SweepSet set;                // those near the sweeps at hand (NearSweepSet)
  std::vector<Collider> near;  // set.colliders when some are left out
};

// Fills contact->set with the colliders that sweeps of a chain of `num_links` links may meet
// whose heads lie within `spread` of `head` (ContactSweep's broad phase, with the chain's reach
// grown by `spread`; for spread 0 the set ContactSweep takes for a sweep to `head`).
void NearSweepSet(int dim, const double* head, double spread, const double* lengths, int num_links,
                  SweepContact* contact);

// Link i (1-based), its leading end `lead` placed and `tail` at its rule step: kept where the
// link stays outside every collider of contact->set, else the contact step from `toward` (its
// trailing end before the sweep), as ContactSweep does; counted in contact->stats. Returns
// whether it met a collider; throws InputError when the colliders leave the link no room.
bool KeepLinkOutside(int dim, int i, const double* lead, const double* toward, double* tail,
                     double length, double inv_length, SweepContact* contact);

// One sweep (the leading end to `head`) of a sequential rule (tractrix, ftl, min_rotation,
// min_joint_angle) with colliders: each link's rule step, kept where the link stays outside every
// collider, else replaced by the least-motion position of its trailing end that keeps it outside
// (contact_sweep.cc; for min_rotation and min_joint_angle the clear direction nearest the rule's,
// the links behind then moved relative to it: docs/colliders.md). 2D chains lie in the plane
// z = 0. Throws InputError when the colliders leave a link no room.
void ContactSweep(Method method, int dim, const double* head, const double* lengths,
                  const double* inv_lengths, int num_links, double* points,
                  const std::vector<Collider>& colliders, ContactStats* stats);

// The sequential rules of the rotation and joint-angle metrics (metric_rules.cc).
void SweepsMinRotation(int dim, const double* heads, int64_t num_sweeps, int num_links,
                       double* points);
void SweepsMinJointAngle(int dim, const double* heads, int64_t num_sweeps, const double* lengths,
                         const double* inv_lengths, int num_links, double* points);

// out[i] = atan2(sqrt(across2[i]), along[i]) for i < count, with the widest instruction set the
// engines may use (the one-pass loop's std::atan2 without one; a vector atan2 within a few ulps of
// it with one). `out` may be `along`.
void Atan2OfSqrt(const double* across2, const double* along, int64_t count, double* out);

// Number of sweeps in flight in SweepsWavefront on this CPU (the SIMD width in doubles).
int WavefrontLanes();

// Every wavefront engine this CPU can run, by name ("avx2", "avx512"), so tests can check each
// against SweepsScalar whatever FLEXKIN_SIMD says.
using SweepsFn = void (*)(Method, int, const double*, int64_t, const double*, const double*, int,
                          double*);
using TracedSweepsFn = void (*)(Method, int, const double*, int64_t, const double*, const double*,
                                int, double*, SweepTrace*);
struct WavefrontEngine {
  const char* name;
  SweepsFn fn;
  TracedSweepsFn traced;
  int lanes;
};
std::vector<WavefrontEngine> AvailableWavefronts();

}  // namespace flexkin::internal
