#pragma once
// Many strands at once (hair, fur, grass): a batch of independent chains, each with its own link
// count and lengths, all 2D or all 3D, stepped by one call per frame. The batch holds the points
// in the layout the engine wants (structure of arrays, strands of one link count side by side in
// SIMD lanes) and is made once and reused: a frame allocates nothing.
//
// Each frame the roots move, given either as points (StepStrands(batch, roots)) or by the rigid
// transform of the body they grow from (StepStrands(batch, pose)). The first `pinned` points of
// each strand (k = 1 by default: the root alone) are set rigidly from the body; the rest of the
// strand follows by the method's link rule, with the leading end of link k (point k-1) moving in a
// straight line from its old to its new position in `substeps` equal sub-steps, exactly as
// MoveLeader moves a single chain. Each strand's result is, bit for bit on the scalar engine and
// to about 1e-14 relative on the SIMD ones, MoveLeader of its chain from point k-1 on to the new
// point k-1 (docs/strands.md). Results do not depend on the number of threads, bit for bit.

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/colliders.h"
#include "flexkin/dynamics.h"
#include "flexkin/error.h"
#include "flexkin/propagate.h"

namespace flexkin {

struct StrandOptions {
  // "tractrix" or "ftl" (follow-the-leader, the baseline of hair simulators).
  Method method = Method::kTractrix;
  // Sub-steps per frame (>= 1): the leading end of the first free link moves in this many equal
  // straight pieces, as MoveLeader's substeps.
  int substeps = 1;
  // Points of each strand moved rigidly with the body (>= 1); a strand with fewer points is
  // rigid as a whole. 1: the root point only. k > 1: the root link(s) leave the body along their
  // rest direction.
  int pinned = 1;
  // Threads stepping the strands (>= 0; 0: std::thread::hardware_concurrency()). Only the speed
  // depends on it, never the result.
  int threads = 1;
  // Colliders the free points and links of every strand stay outside of (docs/colliders.md):
  // `body_colliders` are in body coordinates and move with the body (a groom's scalp, a neck);
  // `colliders` are in the world: where they are, or carried by their keyframed motion
  // (Collider::motion; times those given to the batch and to StepStrands, a groom's seconds), at
  // each sub-step's time between the frames'. A link whose rule step would enter one takes
  // the least-motion step that keeps it outside instead; a strand that touches nothing is
  // stepped exactly as without colliders. With body colliders and sub-steps > 1 the pinned
  // points follow the body's own motion between frames (the rotation interpolated by slerp, the
  // translation linearly), so that the roots stay on the body at every sub-step.
  std::vector<Collider> colliders;
  std::vector<Collider> body_colliders;
  // Dynamic strands (docs/dynamics.md, "Strands"): when set, the strands have inertia. Each
  // sub-step the pinned points go to the body's pose at the sub-step's time (slerp and linear
  // between the frames' poses; roots given as points move linearly), the free points are
  // predicted inertially (velocity, gravity, damping, wind) and put back to their lengths by the
  // projection (overall, shake, tractrix or dftl), exactly as SimulateChain
  // does for one chain: with one pinned point and no collider, each strand's frames are those of
  // SimulateChain of its chain with the root's path, bit for bit on the scalar engine and to
  // about 1e-14 relative on the SIMD ones. `method` is not used. The sub-steps are `substeps`
  // (dynamics->substeps must be 1 or equal to it); a frame lasts 1 / dynamics->frame_rate;
  // keyframed wind is read at the sub-step's middle (seconds from the batch's making); given
  // masses: `dynamics->masses` (n entries) is every strand's profile, for batches whose strands
  // all have n links; `masses` below gives strands their own. With colliders, a link the projection
  // would leave inside one takes the nearest clear direction (tractrix, dftl: ContactTail from its
  // new leading end, nearest the projection's own position; overall: the strand's sub-step is
  // projected by the tractrix projection with contacts, counted in
  // StrandDynamics::contact_substeps).
  std::optional<DynamicOptions> dynamics;
  // Dynamic strands' own masses: empty, every strand as `dynamics` says (mass_by_length, or the
  // profile dynamics->masses); else one entry per strand, each empty (that strand as the others)
  // or one finite mass > 0 per free point 1 .. n_i of that strand. As for SimulateChain only the
  // ratios matter: each strand's free points weigh 1 in all. Given without dynamics, refused.
  std::vector<Eigen::VectorXd> masses;

  // Problems with fields "method", "substeps", "pinned", "threads", "colliders[i]...",
  // "body_colliders[i]...", "dynamics...". `masses` is checked against the strands by the batch
  // ("masses[i][j]", "dynamics.masses").
  Problems Validate() const;
};

// What the colliders did to the strands, from the batch's making on.
struct StrandContacts {
  int64_t contact_link_steps = 0;  // link steps that took the contact step
  // The least clearance, relative to the link's length, of the links near a collider after each
  // sub-step (+inf when no link came near one); never below -1e-12 (rounding; as
  // ContactReport::least_clearance).
  double least_clearance = std::numeric_limits<double>::infinity();
};

// The methods the strand engine runs, from the one table of link rules
// (src/sequential/rule_table.h): "tractrix" and "ftl".
bool IsStrandMethod(Method method);
std::vector<std::string> StrandMethodNames();
// The strand method named `name`; throws InputError naming `field`: for an unknown name (with a
// suggestion for a near miss) or a method the strand engine does not run, listing those it does.
Method ParseStrandMethod(std::string_view name, const std::string& field);

// A strand that starts inside a collider: the first free point (after the pinned ones) inside
// one, or else the first free link through one.
struct StrandInside {
  int strand = 0;
  int point = 0;      // the point inside, or the link's trailing end (link `point` joins
  bool link = false;  // points point-1 and point)
  bool body = false;  // the collider is options.body_colliders[collider], else colliders[...]
  int collider = 0;
  double depth = 0.0;     // how far inside
  double relative = 0.0;  // depth / the link's length
};

// The first free point or link of `strands` (at the body pose `rest`, body colliders placed at
// it) that lies inside a collider of `options` by more than 1e-13 of its link's length; none if
// every strand starts outside. StrandBatch refuses such a start.
// Keyframed world colliders are placed at `time`.
std::optional<StrandInside> FindStrandInside(const std::vector<Points>& strands,
                                             const StrandOptions& options, const BodyPose& rest,
                                             double time = 0.0);

// What the dynamics did (StrandBatch::dynamics()), from the batch's making on.
struct StrandDynamics {
  // The strands' total energy after the last frame: each strand's free points weigh 1 together
  // (as DynamicResult::energy, there for one chain), kinetic plus potential (-m g . x), at the
  // middle of the frame's last sub-step. NaN before the first frame.
  double energy = std::numeric_limits<double>::quiet_NaN();
  // Overall projection: strand sub-steps whose Newton solve did not converge (they keep the
  // tractrix projection).
  int64_t failures = 0;
  // Overall projection with colliders: strand sub-steps projected by the tractrix projection
  // with contacts because the overall one left a link inside a collider.
  int64_t contact_substeps = 0;
};

namespace internal {
struct StrandBatchImpl;
}

// The strands and everything the engine needs between frames. Move-only.
class StrandBatch {
 public:
  // `strands[i]` is strand i's points, (n_i + 1) by dim, row 0 its root; every strand must be a
  // valid chain (ValidateChain: n_i >= 1, finite, links of positive length) and all of one dim
  // (2 or 3). The strands are taken to be at the body pose `rest` (identity by default): their
  // first `pinned` points are kept in body coordinates from these. Throws InputError naming
  // "strands[i]" or an option's field. `time` is the time of `rest`, at which keyframed world
  // colliders are placed (and the start is checked against them).
  StrandBatch(const std::vector<Points>& strands, const StrandOptions& options = {},
              const BodyPose& rest = {}, double time = 0.0);
  StrandBatch(StrandBatch&&) noexcept;
  StrandBatch& operator=(StrandBatch&&) noexcept;
  ~StrandBatch();

  int size() const;                 // number of strands
  int dim() const;                  // 2 or 3 (0 for an empty batch)
  int num_links(int strand) const;  // n_i
  const StrandOptions& options() const;
  // The engine that steps the batch: "avx512", "avx2" or "scalar" (FLEXKIN_SIMD caps it).
  const char* engine() const;
  // What the colliders did so far (zeros and +inf without colliders).
  StrandContacts contacts() const;
  // What the dynamics did (options().dynamics set; defaults otherwise).
  StrandDynamics dynamics() const;

  // Strand `strand`'s points now, (n_i + 1) by dim. Throws InputError ("strand") out of range.
  Points strand(int strand) const;
  void CopyStrand(int strand, Points* out) const;  // the same into a reused matrix

  internal::StrandBatchImpl& impl() { return *impl_; }

 private:
  std::unique_ptr<internal::StrandBatchImpl> impl_;
};

// One frame: the body moves to `pose`; each strand's first k points go to pose(their body
// coordinates) and the rest follows. Allocates nothing. Throws InputError ("pose.rotation",
// "pose.translation") for a non-finite pose or a rotation that is not one.
void StepStrands(StrandBatch* batch, const BodyPose& pose);
// The same, the frame at `time`: keyframed world colliders are placed at each sub-step's time,
// from the last frame's time (the batch's `time` for the first) to `time`, linearly. Throws
// InputError ("time") for a time that is not finite. Without a time (above), the last one stays.
void StepStrands(StrandBatch* batch, const BodyPose& pose, double time);

// One frame: root i moves to `roots.row(i)` (S by dim); the strand's other pinned points (k > 1)
// translate with it. Allocates nothing. Throws InputError ("roots") for a wrong shape or a
// non-finite value, or for a batch with body colliders (it has no body pose to place them at).
void StepStrands(StrandBatch* batch, const Eigen::Ref<const Points>& roots);

}  // namespace flexkin
