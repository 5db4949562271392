#pragma once
// Hyper-redundant robot arms with a fixed base (docs/robots.md): joint angles <-> link points,
// and redundancy resolution by the tractrix sweep from the end effector with the base held.
//
// Order: everything in this header is in robot order, base first. Point 0 is the base, point n
// the end effector; link k (1-based) joins points k-1 and k and has length link_lengths[k-1];
// joint j (0-based) sits at point j and turns link j+1 relative to link j, where "link 0" is the
// base direction of the model. (Internally the sweep runs on flexkin's chain order, point 0 = the
// leading end = the end effector.)
//
// Threads: TrackPath, ArmStep and the kinematics may run in several threads at once, on the same
// const model or on different ones (include/flexkin/flexkin.h).

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/colliders.h"
#include "flexkin/error.h"
#include "flexkin/vocabulary.h"

namespace flexkin {

// Joint angles of an arm with n links.
//   Planar (dim 2), revolute joints: angle[j] is the signed angle (rad, (-pi, pi], counter-
//   clockwise positive) from the direction of link j to the direction of link j+1.
//   Spatial (dim 3), spherical joints without twist: angle[j] is the bend angle (rad, [0, pi])
//   between the directions of links j and j+1, and azimuth[j] (rad, (-pi, pi]) the direction of
//   the bend in link j's frame: link j+1 points along (cos b, sin b cos a, sin b sin a) there.
//   Each link carries a frame whose x axis is along the link; the base frame is the smallest
//   rotation taking the world x axis to the base direction, and each joint's rotation (see
//   JointQuaternions) is the smallest one taking link j's direction to link j+1's: its axis is
//   perpendicular to link j, so no joint twists. azimuth is 0 where angle is 0.
//   Spatial (dim 3), joints about or along given axes (ArmModel::joint_axes, e.g. from a URDF):
//   angle[j] is the right-handed rotation (rad) of link j+1 about joint j's axis, or for a
//   prismatic joint (ArmModel::joint_types) its displacement along the axis (length unit). Every
//   link frame coincides with the world frame when all angles are 0, and link j+1's frame is
//   link j's frame times the rotation about joint j's axis (given in link j's frame); a
//   prismatic joint translates link j+1 and everything after it along its axis instead. Angles
//   are not wrapped: a multi-turn or continuous joint may read 7.5 (rad). azimuth is empty.
struct JointAngles {
  Eigen::VectorXd angle;    // n
  Eigen::VectorXd azimuth;  // n for spherical joints, otherwise empty
};

// The joint kinds.
enum class ArmJoint {
  kRevolute,   // "revolute": one angle per joint; planar arms, or spatial arms with joint_axes
  kSpherical,  // "spherical": spatial arms, bend angle and azimuth per joint
};

// The type of each joint of an arm with joint axes (ArmModel::joint_types).
enum class JointType {
  kRevolute,   // "revolute": turns about its axis; angle in rad
  kPrismatic,  // "prismatic": slides along its axis; displacement in the length unit
};

template <>
struct Vocabulary<JointType> {
  static constexpr const char* kKind = "joint type";
  static constexpr NamedValue<JointType> kEntries[] = {
      {JointType::kRevolute, "revolute", "turns about its axis (rad)"},
      {JointType::kPrismatic, "prismatic", "slides along its axis (length unit)"},
  };
};

template <>
struct Vocabulary<ArmJoint> {
  static constexpr const char* kKind = "joint kind";
  static constexpr NamedValue<ArmJoint> kEntries[] = {
      {ArmJoint::kRevolute, "revolute",
       "one angle per joint: planar arms, or spatial arms with joint_axes"},
      {ArmJoint::kSpherical, "spherical", "spatial arms: bend angle and azimuth per joint"},
  };
};

struct ArmModel {
  int dim = 2;  // 2 (revolute) or 3 (spherical, or revolute/prismatic with axes)
  // n >= 1 lengths, base link first: positive, except with joint_axes, where a link may have
  // length 0 (joints at one point, a universal or spherical joint built from revolute joints, or
  // a tip on its joint: see JointGroups) as long as the sum is positive.
  Eigen::VectorXd link_lengths;
  Eigen::VectorXd base;            // dim; where the base is bolted
  Eigen::VectorXd base_direction;  // dim, non-zero; the direction of "link 0"
  // Joint limits, planar or with joint_axes: joint j stays in [joint_min[j], joint_max[j]].
  // Planar: rad, with -pi <= min <= max <= pi (on the circle). With joint_axes: as written, in
  // rad for revolute joints (multi-turn joints may reach beyond [-pi, pi]; -inf and +inf for a
  // continuous, unlimited joint) and in the length unit for prismatic ones. Empty: no limits.
  Eigen::VectorXd joint_min, joint_max;
  // Spherical limits (rad): joint j's bend angle stays <= max_bend[j], in (0, pi]. Empty: none.
  Eigen::VectorXd max_bend;
  // Spatial joints about or along axes (dim 3): n by 3, row j the unit axis of joint j in link
  // j's frame (the base frame for j = 0), which is the world frame when all angles are 0. An axis
  // may lie along its link (a twist joint, the roll module of a snake). Empty: spherical joints.
  Eigen::MatrixXd joint_axes;
  // With joint_axes: n by 3, row k the unit direction of link k+1 in its own frame (its world
  // direction when all angles are 0). Empty: every link along base_direction.
  Eigen::MatrixXd link_directions;
  // With joint_axes: n types (JointType). Empty: every joint revolute.
  std::vector<JointType> joint_types;
  // Revolute and prismatic joints (planar, or with joint_axes): n speed limits (rad/s, or length
  // unit/s for prismatic joints; +inf: none), respected where ArmOptions::time_step is set.
  // Empty: none.
  Eigen::VectorXd max_velocity;
  // With joint_axes: the tool frame (the tip link's frame, whose origin is the end effector) in
  // the last link's frame, as a unit quaternion (w, x, y, z): what ArmOptions::pointing's axis is
  // given in. Identity by default.
  Eigen::Vector4d tip_rotation = Eigen::Vector4d(1.0, 0.0, 0.0, 0.0);
  // Optional names of the n joints (a URDF's), for reports; empty: "joint 0", "joint 1", ...
  std::vector<std::string> joint_names;
  // The links' radii (length unit, >= 0 and finite): link k is a capsule of radius
  // link_radii[k-1] about its axis (a URDF's collision cylinder, capsule or sphere), kept outside
  // ArmOptions::colliders. Empty: every link a segment (radius 0). Typical: 0.02 to 0.05 of a
  // meter for snake modules.
  Eigen::VectorXd link_radii;
  JointAngles initial;  // the joint angles at the start; within the limits

  bool has_axes() const { return joint_axes.size() > 0; }
  bool prismatic(int j) const {
    return !joint_types.empty() && joint_types[j] == JointType::kPrismatic;
  }
  ArmJoint joint() const {
    return dim == 2 || has_axes() ? ArmJoint::kRevolute : ArmJoint::kSpherical;
  }
  int num_links() const { return static_cast<int>(link_lengths.size()); }
  bool has_limits() const { return joint_min.size() > 0 || max_bend.size() > 0; }
  // The largest of link_radii (0 if empty).
  double max_link_radius() const { return link_radii.size() > 0 ? link_radii.maxCoeff() : 0.0; }
  double reach() const { return link_lengths.sum(); }
  // The problems that make the model unusable (none if it is usable), each field the member as
  // named above ("joint_min[2]", "initial.angle[0]"): the first of each independent part (the
  // base, the axes, the limits, the names and speeds, the initial angles, these checked against
  // valid limits only); a model without a valid dimension or links has only that problem.
  // FirstProblem is the first of them.
  Problems Validate() const;
  std::optional<Problem> FirstProblem() const;
};

// A straight arm of `links` links of length `link_length` from the origin along +x (all joint
// angles 0, no limits): the usual start for tests and benchmarks.
ArmModel StraightArm(int dim, int links, double link_length);

// Forward kinematics: the (n+1) by dim points (base first) of the arm at `angles`. Throws
// InputError if the model is invalid or the angles have the wrong size or non-finite values.
Points ForwardKinematics(const ArmModel& model, const JointAngles& angles);
// Inverse: the joint angles of an arm whose points are `points` (base first; the link lengths
// are taken from the model, the points' own distances are not checked). FK of the result
// reproduces `points` to rounding when the points have the model's link lengths and base.
JointAngles JointAnglesFromPoints(const ArmModel& model, const Points& points);
// Each joint's rotation as a unit quaternion, in the frame of the link before it: an n by 4
// matrix of rows (w, x, y, z). Planar arms: rotations about z. See JointAngles.
Eigen::MatrixXd JointQuaternions(const ArmModel& model, const JointAngles& angles);
// Whether every joint is within its limits, with `slack` (rad) of tolerance.
bool WithinLimits(const ArmModel& model, const JointAngles& angles, double slack = 0.0);

// Joints at one point: ForwardKinematics gives every joint its own point, so joints joined by a
// link of length 0 (with joint_axes: two revolute joints at one point make a universal joint,
// three a spherical one) repeat a point. JointGroups lists the joints of each distinct point of
// the chain, base first (a prismatic joint ends its group: it moves the next joint away); the
// last group may hold the tip (a tip on its joint). ChainPoints keeps one point per group plus
// the end effector where it is a point of its own: the chain as drawn and written to files.
std::vector<std::vector<int>> JointGroups(const ArmModel& model);
Points ChainPoints(const ArmModel& model, const Points& points);
// The groups of more than one joint in words, one per line ("joints \"m1_pitch\" and
// \"m1_yaw\" act at one point (a universal joint)"); "" if every joint has its own point.
std::string JointGroupsReport(const ArmModel& model);

// The tool frame at `angles` (arms with joint_axes): the end effector (3) and the tip link's
// rotation in the world (3 by 3; ArmModel::tip_rotation in the last link's frame).
struct ToolPose {
  Eigen::Vector3d position;
  Eigen::Matrix3d rotation;
};
ToolPose ToolPoseAt(const ArmModel& model, const JointAngles& angles);

// How the base is brought back after the sweep from the end effector has moved it.
enum class FixedBaseMethod {
  // "newton": the chain is translated by u before one sweep; u solves base(u) = fixed base by
  // Newton's method (finite-difference Jacobian, Broyden updates, backtracking line search).
  kNewton,
  // "fixed_point": the predecessors' scheme: translate the chain back to the base and sweep
  // again from where it is, until the base stays within the tolerance. Converges linearly.
  kFixedPoint,
};

template <>
struct Vocabulary<FixedBaseMethod> {
  static constexpr const char* kKind = "fixed-base method";
  static constexpr NamedValue<FixedBaseMethod> kEntries[] = {
      {FixedBaseMethod::kNewton, "newton",
       "Newton's method on the base translation before one sweep (the default)"},
      {FixedBaseMethod::kFixedPoint, "fixed_point",
       "the predecessors' baseline, for comparison: translate back to the base and sweep again "
       "until the base stays; slow (linear convergence at best) and where it does not converge "
       "(arms with joint axes, as URDF arms; joint limits) the step stops unreached"},
  };
};
inline const char* FixedBaseMethodName(FixedBaseMethod method) { return NameOf(method); }
inline FixedBaseMethod ParseFixedBaseMethod(std::string_view name,
                                            const std::string& field = "method") {
  return ParseName<FixedBaseMethod>(name, field);
}

struct ArmOptions {
  FixedBaseMethod method = FixedBaseMethod::kNewton;  // see FixedBaseMethod
  // Base residual at which the solver stops, relative to the mean link length. Typical 1e-10.
  double tolerance = 1e-10;
  // Cap on the solver's iterations per step. Newton typically needs 2 to 5; the fixed-point
  // baseline needs hundreds to thousands near the edge of the workspace.
  int max_iterations = 100;
  int max_fixed_point_iterations = 100000;
  // Joint-space solves (ArmStepReport::joint_space) that stall short of the target are started
  // again up to this many times: twice from the last pose with weights that spread the motion
  // more evenly along the arm, then from random poses around it (a fixed seed). Each costs up to
  // a full solve, so a target that the limits put out of reach costs up to restarts + 1 solves.
  // 0: none. Typical 8.
  int restarts = 8;
  // Sub-steps of the sweep: the end effector's move to the target is split in this many straight
  // pieces (finer = closer to the continuous tractrix motion). Typical 1.
  int substeps = 1;
  // Targets farther from the base than (1 - edge_margin) times the reach are treated as out of
  // reach: the arm is stretched straight toward them. Typical 1e-9.
  double edge_margin = 1e-9;
  // Pointing (arms with joint_axes, method newton): an axis of the tool frame (unit, in the tip
  // link's frame, see ArmModel::tip_rotation) is turned toward a direction or a point as the end
  // effector tracks its target. The step then minimises |position miss|^2 + (weight x mean link
  // length x angular miss)^2, with the same smallest weighted joint motion; where both can be met
  // (a redundant arm inside its workspace) both are, and the step counts as reached when the
  // position is within the tolerance and the angle within angle_tolerance (rad).
  struct Pointing {
    bool enabled = false;
    Eigen::Vector3d axis = Eigen::Vector3d::UnitX();  // in the tool frame
    // The direction to point along (world, non-zero), or, with look_at, the point to look at.
    Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
    bool look_at = false;
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
    double weight = 1.0;            // > 0: mean link lengths per radian of angular miss
    double angle_tolerance = 1e-9;  // rad, > 0
  } pointing;
  // Velocity limits (arms with ArmModel::max_velocity): the time between two path
  // points (s). A step whose joint motion would exceed a limit in that time is split into as many
  // equal legs along the end effector's straight move, each taking time_step, as keep every joint
  // within its limit (ArmStepReport::velocity_legs). 0: limits ignored.
  double time_step = 0.0;
  // Things in the world the arm's links stay outside of (docs/robots.md, "Colliders"). Each link
  // is a capsule of ArmModel::link_radii about its axis. Where a step's free result (the step
  // without colliders) keeps every link outside, it is that result bit for bit; otherwise, for
  // planar and spherical arms, the step is solved again by the sweep in which every link whose
  // tractrix step would enter a collider takes the contact step instead (the least motion of its
  // trailing end that keeps it outside); for arms with joint axes (method newton, with
  // or without pointing), by the joint-space step with the capsules' clearances as
  // constraints. A 2D arm lies in the plane z = 0. Keyframed colliders (Collider::motion) move with
  // time in leader steps: TrackPath's step toward path row i spans [i, i + 1], each sub-step of its
  // sweep at its own time, the result checked where they are at i + 1 (docs/robots.md,
  // "Colliders"). Empty: none.
  std::vector<Collider> colliders;
  // Every problem (empty if valid), each naming its member ("max_iterations").
  Problems Validate() const;
  // The problems of these options on `model` besides Validate's: pointing needs joint axes, and
  // method fixed_point takes only revolute joints across links of positive length within
  // [-pi, pi] and no pointing; colliders on an arm with joint axes need method newton.
  Problems ValidateFor(const ArmModel& model) const;
};

// What the Newton fixed-base solver learned in a step, to start the next one from (continuation
// along a path: consecutive steps solve nearby problems). ArmStep fills it in the state it returns
// when Newton converged, and TrackPath passes it on. It is only a hint: ArmStep works without it
// (the first step, a state built by hand) and checks it (a start whose base residual exceeds the
// move is dropped for u = 0), so a stale one costs a sweep, never accuracy. The next step starts
// from the translations of the last steps extrapolated along the path (quadratically in the end
// effector's travel), and probes F's curvature along the last prediction error to correct its
// first Newton step (docs/robots.md, "The step"). Parts that are missing, of the wrong size or
// not finite are ignored.
struct ArmSolverMemory {
  // dim: the translation u that solved the last step (length unit); empty: none.
  Eigen::VectorXd translation;
  // dim by 0 to 2: the translations that solved the steps before the last, most recent first.
  Eigen::MatrixXd earlier_translations;
  // 1 + earlier_translations.cols() values: the length of the end effector's move (target minus
  // the end effector before the step; length unit) in the last step, then in the earlier ones.
  Eigen::VectorXd move_lengths;
  // dim: the last step's translation minus the one it was started from (length unit): where the
  // next step probes F's curvature. Empty: none.
  Eigen::VectorXd prediction_error;
  // Whether there is a memory of the right size (dim) with finite values; otherwise it is ignored.
  bool Usable(int dim) const;
};

// The arm between steps: its points (base first) and joint angles, which agree.
struct ArmState {
  Points points;
  JointAngles angles;
  ArmSolverMemory memory;  // optional (empty by default): see ArmSolverMemory
};
// The state at the model's initial angles.
ArmState InitialState(const ArmModel& model);

struct ArmStepReport {
  ArmState state;           // after the step; the base exactly at model.base, limits held
  double ee_error = 0.0;    // |end effector - target| after the step (length unit)
  double base_error = 0.0;  // the solver's last base residual before the base was re-anchored
  int iterations = 0;       // solver iterations (Newton steps or fixed-point sweeps)
  int sweeps = 0;           // sweeps from the end effector, all included
  int passes = 0;  // passes over the links (cost ~ passes * n): sweeps done together count once
  bool converged = false;  // the base residual reached the tolerance
  bool reached = false;    // converged and ee_error within the tolerance: the target was reached
  bool stretched = false;  // out of reach: the arm was stretched straight toward the target
  bool limited = false;    // a joint limit was active
  // The step was solved in joint space (docs/robots.md): always for revolute joints about axes
  // with method newton; for planar and spherical arms where the sweep found no root. The state's
  // memory is then empty.
  bool joint_space = false;
  // A far move on which one sweep found no root, tracked along the same straight line in this
  // many legs of at most half a mean link, the base held after each (docs/robots.md); 0: one
  // sweep. iterations, sweeps and passes count all of them.
  int legs = 0;
  int restarts = 0;  // joint-space solves after the first (ArmOptions::restarts)
  // With ArmOptions::pointing: the angle (rad) between the tool axis and where it should point.
  double pointing_error = 0.0;
  // With ArmOptions::time_step: the legs the step took to keep every joint within its velocity
  // limit (1: the step as asked), so the step lasted velocity_legs x time_step; 0 without.
  int velocity_legs = 0;
  // With ArmOptions::time_step: the largest joint speed over its limit in any leg (<= 1 when
  // the limits were kept).
  double velocity_ratio = 0.0;
  // With ArmOptions::colliders: the least clearance of any link's capsule from any collider after
  // the step (length unit; negative: a link is inside, by that depth); +inf without colliders.
  double clearance = std::numeric_limits<double>::infinity();
  // The step's free result would have put a link into a collider, so it was solved again by the
  // sweep with contact steps.
  bool contact = false;
  // No solve left every link outside the colliders (within 1e-12 of its length): the sweep with
  // contact steps found no root, nor did it in legs, and the other solves entered a collider. The
  // arm was held where it was (state = the step's start), reached = false.
  bool blocked = false;
  std::string BriefReport() const;
};

// Moves the end effector of the arm in `state` to `target` (dim) with the base held at
// model.base. Every link keeps its length (the points are rebuilt from the joint angles), every
// joint stays within its limits, and nothing is NaN: an unreachable target gives the nearest
// configuration the method finds and reached = false. Throws InputError on an invalid model,
// options, state or target. `time` (leader steps) places keyframed colliders (Collider::motion):
// the step spans [time, time + 1], as TrackPath's step toward path row i spans [i, i + 1]
// (docs/colliders.md, "Moving colliders"); the state must be outside them at `time`.
ArmStepReport ArmStep(const ArmModel& model, const ArmState& state,
                      const Eigen::Ref<const Eigen::VectorXd>& target, const ArmOptions& options,
                      double time = 0.0);

struct ArmTrajectory {
  // One per path point from the plain TrackPath; empty from TrackPath with a sink (the steps went
  // to the sink).
  std::vector<ArmStepReport> steps;
  long long num_steps = 0;  // steps tracked (one per path point), with or without a sink
  double max_ee_error = 0.0, max_base_error = 0.0;
  int unreached = 0;                // steps with reached = false
  double max_pointing_error = 0.0;  // rad, with ArmOptions::pointing
  // With ArmOptions::colliders: the least clearance over the steps (length unit), the steps
  // solved with contact steps, and those blocked (the arm held where it was).
  double min_clearance = std::numeric_limits<double>::infinity();
  int contact_steps = 0, blocked_steps = 0;
  long long velocity_legs = 0;  // with ArmOptions::time_step: legs of all steps
  int max_iterations = 0;
  long long total_sweeps = 0;
  long long total_passes = 0;  // passes over the links (see ArmStepReport::passes)
  double seconds = 0.0;        // wall time of TrackPath
  std::string BriefReport() const;
};

// Receives TrackPath's steps as they are produced (path row 0 first), so that a caller can stream
// them to a file or keep only what it needs: the tracking itself holds one step, not the
// trajectory.
class ArmStepSink {
 public:
  virtual ~ArmStepSink() = default;
  // The step that moved the end effector to the next path row; valid only during the call. May
  // throw: the tracking stops and the exception propagates.
  virtual void Add(const ArmStepReport& step) = 0;
};

// The sink of TrackPath's plain form: keeps every step, in `steps`.
class ArmStepRecorder : public ArmStepSink {
 public:
  void Add(const ArmStepReport& step) override { steps.push_back(step); }
  std::vector<ArmStepReport> steps;
};

// Hands every step to each of `sinks` in turn (a trajectory file and a joint CSV, say).
class ArmStepFanOut : public ArmStepSink {
 public:
  explicit ArmStepFanOut(std::vector<ArmStepSink*> sinks) : sinks_(std::move(sinks)) {}
  void Add(const ArmStepReport& step) override {
    for (ArmStepSink* sink : sinks_) sink->Add(step);
  }

 private:
  std::vector<ArmStepSink*> sinks_;
};

// Tracks `path` (m by dim targets, one per row) from the model's initial state: one ArmStep per
// row. The first step moves the end effector from its initial position to path row 0. Each step
// goes to `sink` (may be null) as it is produced; the trajectory returned has the summary
// (num_steps, errors, unreached, iterations, sweeps, passes, seconds) and no steps. Throws
// InputError on an invalid model, options or path before any step is produced.
ArmTrajectory TrackPath(const ArmModel& model, const Points& path, const ArmOptions& options,
                        ArmStepSink* sink);
// The same with every step kept in ArmTrajectory::steps.
ArmTrajectory TrackPath(const ArmModel& model, const Points& path, const ArmOptions& options);

}  // namespace flexkin
