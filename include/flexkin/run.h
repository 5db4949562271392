#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/colliders.h"
#include "flexkin/error.h"
#include "flexkin/frames.h"
#include "flexkin/overall.h"
#include "flexkin/propagate.h"

namespace flexkin {

// Options of a whole run: a chain whose leading end visits a list of targets (the leader steps).
struct RunOptions {
  // Tractrix (the paper's sequential optimization), follow-the-leader, overall (all points
  // at once, each sub-step solved by OverallStep with `overall`), or follow_path (every point on
  // the head's path; RunResult::path reports it).
  Method method = Method::kTractrix;
  // The metric and solver options of the overall method; unused by the others.
  OverallOptions overall;
  // Equal sub-steps each leader step is split into; computed but not recorded. >= 1.
  // With `tolerance` > 0 this is the starting value of the automatic choice. Typical: 1 to 64.
  // follow_path: the configuration after a leader step does not depend on them (every point is
  // placed from the head's position alone); they refine the metrics and the clearance checks.
  int substeps = 1;
  // Keep the initial frame, every `record_every`-th leader step and the last one. >= 1.
  int record_every = 1;
  // Accuracy control. If > 0, `substeps` is doubled until the estimated largest distance of any
  // point, at any leader step, from the continuous motion (every point's velocity along its
  // link) is at most `tolerance`, in the chain's length unit. 0 turns it off. Typical: 1e-6.
  // Tractrix and ftl only (the overall method's order of convergence is not established).
  // The runs that pick `substeps` cost about as much as the final run again.
  double tolerance = 0.0;
  // Upper bound for the automatic choice of `substeps`; >= 2 when `tolerance` > 0. Typical: 65536.
  int max_substeps = 1 << 16;
  // Compute Frame::link_angles for each recorded frame (an atan2 per link per frame). false leaves
  // them empty: a recorded frame then costs a copy of its points and nothing more.
  bool link_angles = true;
  // Called with (leader steps done, total) about every 0.1 s of work (with 0 done while accuracy
  // control chooses the sub-steps); may be empty. It may throw to stop the run: the exception
  // propagates out of Run.
  std::function<void(int64_t done, int64_t total)> progress;
  // Things in the world the chain stays outside of (flexkin/colliders.h, docs/colliders.md): each
  // link's rule step is kept where the link stays outside every collider, else replaced by the
  // least-motion position of its trailing end that keeps it outside. Tractrix and ftl; no
  // accuracy control. A 2D chain lies in the plane z = 0. Empty: the run is exactly the one
  // without colliders. follow_path does not move points off the head's path: it only measures
  // the clearances (RunResult::path, ContactReport::least_clearance, which may then be < 0).
  std::vector<Collider> colliders;
  // The links' radius (length unit, >= 0): each link is a capsule of this radius about its axis
  // (a rope's thickness, a snake robot's body), kept outside the colliders by keeping its axis
  // outside each collider grown by the radius (Collider::margin; exact, the shapes being
  // convex). Clearances in the reports are then the capsules' surfaces' distances. 0: links are
  // segments.
  double link_radius = 0.0;

  // Every problem with the options (empty if valid), each naming its member ("substeps",
  // "overall.weights.l2").
  Problems Validate() const;
};

// What the colliders did to a run.
struct ContactReport {
  int num_colliders = 0;
  // Link steps (a link's move in one sub-step) whose rule step would have entered a collider and
  // that slid along it instead.
  int64_t contact_link_steps = 0;
  // The least clearance of any link from any collider after any sub-step, relative to the link's
  // length (+inf without colliders); never below -1e-12 (the rounding of points on surfaces:
  // typically above -1e-13, down to -5e-13 against meshes and where two contacts meet;
  // docs/colliders.md), except with follow_path, which measures the clearances without acting on
  // them (after each sub-step; < 0 where the body passes through a collider).
  double least_clearance = std::numeric_limits<double>::infinity();
};

// What a follow_path run did (method "follow_path" only; docs/colliders.md "Follow the path").
// The head's path is the polyline through the chain's initial points reversed (point n first),
// then the leader targets (HeadPath); s_head is its arc length up to the head's position.
struct PathReport {
  bool enabled = false;  // the run's method is follow_path (all else empty otherwise)
  // Per leader step (m values); the tip error and the deviation after its last sub-step.
  // The least clearance of any link from any collider after any of the step's sub-steps, in the
  // length unit (+inf without colliders; negative: the body passes through a collider, which the
  // head's path does too, or a link's chord cuts a corner into it).
  Eigen::VectorXd clearance;
  // The distance of the last point (the tip) from the point of the head's path at arc length
  // s_head - (L_1 + ... + L_n) (the path's start if that is negative): 0 on a straight path,
  // > 0 where the path turns (the chords of the links are shorter than the arcs they span).
  Eigen::VectorXd tip_error;
  // The largest distance of any point from the head's path travelled so far (~1e-16 by
  // construction; computed as PathDeviation does for any run).
  Eigen::VectorXd deviation;
  // Over the run: the least clearance (+inf without colliders), the largest tip error and the
  // largest deviation; the leader step (1-based) of the least clearance (0 without colliders).
  double least_clearance = std::numeric_limits<double>::infinity();
  int64_t least_clearance_step = 0;
  double max_tip_error = 0.0;
  double max_deviation = 0.0;
};

// How far a run's frames are from the head's path (PathDeviation).
struct PathComparison {
  // (F, n+1): per frame, each point's distance from the head's path up to the head's position at
  // that frame's step (the initial points reversed, then the targets reached).
  Eigen::MatrixXd deviation;
  // (F,): per frame, the tip error as PathReport::tip_error.
  Eigen::VectorXd tip_error;
};

// The head's path of a run of `chain` through `leader_steps`: the chain's points reversed (point
// n first, point 0 last), then the rows of `leader_steps`: (n+1+m) by dim.
Points HeadPath(const Chain& chain, const Points& leader_steps);

// The distance of every point of every frame of a run (any method: a follow_path run's are ~0,
// a tractrix run's are > 0 where the path turns) from the head's path (HeadPath) up to the head's
// position at the frame's step, and each frame's tip error. `frames` must be a run of `chain`
// through `leader_steps` (steps within 0..m). Throws InputError otherwise.
PathComparison PathDeviation(const Chain& chain, const Points& leader_steps, const Frames& frames);

// Metrics of a run (paper eq. 6 and Sec. 3.2).
struct Metrics {
  // Per leader step: sum over all points j = 0..n of the distance x_j travels during the step,
  // sub-step by sub-step (with one sub-step: |x_j(after) - x_j(before)|).
  Eigen::VectorXd l2_per_step;
  // The same weighted by arc length (trapezoid weights L_1/2, (L_i + L_{i+1})/2, ..., L_n/2),
  // the discrete form of eq. (6).
  Eigen::VectorXd l2_weighted_per_step;
  double l2_total = 0.0;
  double l2_weighted_total = 0.0;
  // Largest |(|x_i - x_{i-1}| - L_i)| / L_i over every link, after every leader step.
  double max_relative_length_error = 0.0;
  // Distance travelled by each point over the run, sub-steps included: n+1 values.
  // The profile shows the motion dying out along the chain.
  Eigen::VectorXd path_length;
};

// What the accuracy control did.
struct AccuracyReport {
  bool enabled = false;          // tolerance > 0 was asked for
  double tolerance = 0.0;        // the tolerance asked for (RunOptions::tolerance)
  int max_substeps = 0;          // the bound on the sub-steps (RunOptions::max_substeps)
  int substeps = 1;              // sub-steps per leader step actually used
  int order = 2;                 // convergence order assumed in the estimate (2 tractrix, 1 ftl)
  double estimated_error = 0.0;  // Richardson estimate of the largest distance to the continuous
                                 // motion; only meaningful if enabled
  bool met = true;               // estimated_error <= tolerance (always true if not enabled)
};

// What the overall solver did over a run (method "overall" only).
struct OverallRunReport {
  int64_t solves = 0;                 // sub-steps solved
  int64_t failures = 0;               // sub-steps whose solve did not converge
  int64_t iterations = 0;             // Newton iterations in all
  int max_iterations = 0;             // most iterations of one sub-step
  double constraint_violation = 0.0;  // worst over the run
  double optimality = 0.0;            // worst over the run
  std::string first_failure;          // "leader step s, sub-step j: <report>" of the first failure
};

// What a dynamic chain did (a chain scenario's "dynamics": SimulateChain, flexkin/dynamics.h,
// docs/dynamics.md); `enabled` false for every kinematic run.
struct DynamicRunReport {
  bool enabled = false;
  std::string projection;   // "overall", "tractrix", "dftl" or "shake"
  double frame_rate = 0.0;  // frames per second: frame f (leader step f) at f / frame_rate s
  int substeps = 0;         // sub-steps per frame
  // The energy at every frame of the run, 0 .. num_steps, recorded or not (DynamicResult::energy:
  // kinetic plus potential, the free points' masses summing to 1).
  Eigen::VectorXd energy;
  int64_t failures = 0;  // sub-steps whose projection's Newton solve did not converge
  // With colliders (DynamicResult): sub-steps in which a collider moved a point; of those, with
  // the overall projection, the ones solved with the contacts as constraints and the ones whose
  // contact solve did not converge (they took the pushed re-projection).
  int64_t contact_substeps = 0, contact_solves = 0, contact_solve_failures = 0;
};

struct RunResult {
  Method method = Method::kTractrix;
  Eigen::VectorXd lengths;  // the link lengths, fixed at the start
  int64_t num_steps = 0;    // leader steps
  Frames frames;            // dense: one (F, n+1, dim) array of points (frames.h)
  // Frames the run recorded (into RunResult::frames or a sink), and the link angles of the last
  // one (empty without link angles): what the reports print, also when the frames were streamed.
  int64_t recorded_frames = 0;
  Eigen::VectorXd final_link_angles;
  Metrics metrics;
  AccuracyReport accuracy;
  OverallRunReport overall;   // method "overall" only
  ContactReport contacts;     // with colliders only
  PathReport path;            // method "follow_path" only
  DynamicRunReport dynamics;  // a dynamic chain only (a scenario's "dynamics")
  ObjectiveWeights weights;   // the overall method's metric (method "overall" only)
  double seconds = 0.0;       // wall time of the computation

  // One line: method, steps, length error, L2 total, accuracy.
  std::string BriefReport() const;
  // Several lines, including the path-length profile.
  std::string FullReport() const;
};

// Receives a run's recorded configurations as they are produced (frame 0 first, then every
// `record_every`-th leader step and the last), so that a caller can stream them to a file or
// keep only what it needs: the run itself holds one configuration, not the frames.
class FrameSink {
 public:
  virtual ~FrameSink() = default;
  // `points` is (n+1) by dim; `link_angles` as Frame::link_angles. Both are valid only during the
  // call. May throw: the run stops and the exception propagates.
  virtual void Add(int64_t step, const PointsRef& points, const VectorRef& link_angles) = 0;
};

// The sink of Run's plain form: keeps every frame in memory, in `frames`.
class FrameRecorder : public FrameSink {
 public:
  void Add(int64_t step, const PointsRef& points, const VectorRef& link_angles) override;
  Frames frames;
};

// Frames a run of `num_steps` leader steps records with `record_every`: 1 + ceil(num_steps /
// record_every).
int64_t CountRecordedFrames(int64_t num_steps, int record_every);

// Runs `chain` with its leading end moved in straight lines through the rows of `leader_steps`
// (m by dim, the successive targets, not including the start). The recorded frames go to `sink`
// (RunResult::frames stays empty). Throws InputError on invalid input (chain, targets, options)
// before any frame is produced; with follow_path, also at the leader step where the head's path
// turns out too short for the body (naming it), after the frames before it.
RunResult Run(const Chain& chain, const Points& leader_steps, const RunOptions& options,
              FrameSink* sink);
// The same with the frames kept in RunResult::frames.
RunResult Run(const Chain& chain, const Points& leader_steps, const RunOptions& options);

}  // namespace flexkin
