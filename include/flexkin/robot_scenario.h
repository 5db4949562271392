#pragma once
// Robot scenario files (docs/robot-format.md, docs/schema/robot.schema.json) in and robot
// trajectories out: the one reader and writer that every front end (the `flexkin robot` command,
// the examples, the Python module) shares.
//
//   RobotScenarioOptions options = UrdfRobotScenarioOptions();  // flexkin/urdf.h, or {}
//   const RobotScenario s = LoadRobotScenarioFile("arm.json", options);
//   const ArmTrajectory t = TrackPath(s.model, s.path, s.options);
//   WriteRobotTrajectoryJson(s, t, "trajectory.json");
//
// or, streamed in memory that does not grow with the number of targets:
//
//   RobotTrajectoryWriter writer(s, "trajectory.json");
//   writer.Commit(TrackPath(s.model, s.path, s.options, &writer));
//
// Errors as everywhere in flexkin: InputError for content that is not valid (its field the JSON
// pointer of the value, "/arm/link_lengths/2"), std::system_error for a file that cannot be read
// or written (the message has the path and the system's reason).

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "flexkin/arm.h"
#include "flexkin/chain.h"
#include "flexkin/error.h"
#include "flexkin/result_io.h"
#include "flexkin/robot_tree.h"

namespace flexkin {

// Which part of a URDF (Unified Robot Description Format) model is the arm.
struct UrdfChain {
  std::string base_link;  // the link the arm is bolted to; "" = the URDF's root link
  std::string tip_link;   // the end effector's link; "" = the one leaf below base_link
  // The end effector: this point of the tip link's frame (length unit), e.g. a tool point beyond
  // the last joint. Zero: the tip link's origin (which may sit on the last joint).
  Eigen::Vector3d tip_offset = Eigen::Vector3d::Zero();
};

// Reads the arm of the URDF file at `path` (flexkin/urdf.h: ArmFromUrdfFile). Throws InputError
// naming the element ("base_link", "tip_link", "joint \"elbow\"") for a URDF that is not a
// valid arm, std::system_error for a file that cannot be read.
using UrdfArmLoader = std::function<ArmModel(const std::string& path, const UrdfChain& chain)>;

// Reads the robot tree of the URDF file at `path` below `base_link` with `tools` (flexkin/urdf.h:
// RobotTreeFromUrdfFile), for tree scenarios with "robot" (docs/trees.md, "Robot trees").
using UrdfTreeLoader = std::function<RobotTree(
    const std::string& path, const std::string& base_link, const std::vector<UrdfTool>& tools)>;

struct RobotScenarioOptions {
  // Reads the arm of a scenario that names a URDF file ("urdf"). Empty (the default): such
  // scenarios are refused with an InputError at "/urdf". The URDF component (flexkin_urdf,
  // flexkin/urdf.h) provides UrdfRobotScenarioOptions(), which sets it to ArmFromUrdfFile; the
  // core library does not depend on a URDF parser.
  UrdfArmLoader urdf_loader;
  // The same for robot trees (tree scenarios with "robot"); UrdfRobotScenarioOptions() sets it.
  UrdfTreeLoader urdf_tree_loader;
  // The directory that a relative "urdf" file name is taken relative to. "": the scenario file's
  // directory for LoadRobotScenarioFile and ValidateRobotScenarioFile, the working directory for
  // the *Text functions.
  std::string directory;
};

// A robot scenario file read in.
struct RobotScenario {
  std::string name;    // "name", "" if absent
  ArmModel model;      // from "arm", or from the URDF file named by "urdf"
  Points path;         // m by dim, m >= 1: the end effector's targets from "path", one per step
  ArmOptions options;  // "solver"; the defaults where it is absent
};

// Checks the JSON text of a robot scenario and builds it. Throws InputError for the first
// problem (as listed by ValidateRobotScenarioText); for text that is not JSON, the field is empty
// and the message "line L, column C: invalid JSON: <reason>". A URDF file that cannot be read
// throws std::system_error.
RobotScenario ParseRobotScenarioText(const std::string& json_text,
                                     const RobotScenarioOptions& options = {});

// Every problem found in the JSON text of a robot scenario (unknown keys with a suggestion for a
// typo, wrong types, values out of range, sizes that do not match the number of links, an arm
// the model refuses, ...), in the order checked; empty if and only if ParseRobotScenarioText
// would succeed. Each problem's field is the JSON pointer of the offending value
// ("/arm/joint_limits/max_bend/0"; "" for the whole document). Numbers are read as in scenario
// files: an integer may be written 5.0, not 5.5. A URDF arm is read with options.urdf_loader, so
// its problems are listed too; a URDF file that cannot be read throws std::system_error.
Problems ValidateRobotScenarioText(const std::string& json_text,
                                   const RobotScenarioOptions& options = {});

// The same for the file at `path`. Messages do not repeat the path; callers add it. Throw
// std::system_error if the file cannot be read.
RobotScenario LoadRobotScenarioFile(const std::string& path,
                                    const RobotScenarioOptions& options = {});
Problems ValidateRobotScenarioFile(const std::string& path,
                                   const RobotScenarioOptions& options = {});

// Whether the JSON text is a robot scenario rather than a chain scenario (docs/scenario-format.md):
// an object whose "format" is "flexkin-robot", or, without "format", one with "arm" or "urdf" and
// neither "curve" nor "leader". False for text that is not JSON. The file version throws
// std::system_error if the file cannot be read.
bool IsRobotScenarioText(const std::string& json_text);
bool IsRobotScenarioFile(const std::string& path);

// One line about a robot scenario, as `flexkin validate` prints it: "robot, 2D, 8 links, revolute
// joints (reach 0.56), 120 targets, method newton, tolerance 1e-10" (", joint limits" where it
// has some, ", 4 sub-steps" where more than one).
std::string RobotScenarioSummary(const RobotScenario& scenario);

// The identification and version of robot trajectory files.
inline constexpr const char* kRobotTrajectoryFormat = "flexkin-robot-trajectory";
inline constexpr int kRobotTrajectoryVersion = 1;

// The estimated sizes of the outputs of `scenario`: the trajectory JSON and the joint CSV, about
// 24 bytes per number (as result files) for the initial state and one step per target (joint
// angles, azimuths of spherical joints, joint quaternions in 3D, the points, the target) and
// about 300 bytes of keys and reports per step. Saturates at the largest uint64_t.
struct RobotOutputEstimate {
  uint64_t json_bytes = 0, csv_bytes = 0;
};
RobotOutputEstimate EstimateRobotOutput(const RobotScenario& scenario);

// Writes the trajectory of `scenario` (TrackPath of its model, path and options) as a trajectory
// JSON document (docs/robot-format.md, "Outputs"): the arm, the method, a summary, the initial
// state and one step per line. The path version writes atomically (a temporary file renamed over
// `path`; on any error nothing is written) and throws std::system_error if it cannot.
void WriteRobotTrajectoryJson(const RobotScenario& scenario, const ArmTrajectory& trajectory,
                              std::ostream& out);
void WriteRobotTrajectoryJson(const RobotScenario& scenario, const ArmTrajectory& trajectory,
                              const std::string& path);

// Writes the joint angles as CSV: a header "step" and a column per joint, named by
// model.joint_names where it has them (a URDF's; quoted as CSV quotes where a name holds a comma,
// a quote or a line break), else "joint_0,...,joint_{n-1}" (spatial arms with spherical joints:
// then "azimuth_0,..."), row 0 the initial angles, then one row per step, 17 significant digits.
// The path version writes atomically, as above.
void WriteRobotJointsCsv(const RobotScenario& scenario, const ArmTrajectory& trajectory,
                         std::ostream& out);
void WriteRobotJointsCsv(const RobotScenario& scenario, const ArmTrajectory& trajectory,
                         const std::string& path);

// An ArmStepSink that writes the trajectory JSON of `scenario` (the document of
// WriteRobotTrajectoryJson) while TrackPath produces its steps, in bounded memory (one step and
// a buffer):
//
//   RobotTrajectoryWriter writer(scenario, path);
//   writer.Commit(TrackPath(scenario.model, scenario.path, scenario.options, &writer));
//
// All-or-nothing: the file is written to a temporary file in the destination's directory, and
// only Commit renames it over `path`. A step holding a non-finite number (or of the wrong shape,
// or beyond the path's targets) is refused by Add with InputError naming it
// ("steps[3].points[2][1]"), which stops the tracking; destroyed without a successful Commit (an
// exception, a failed write), the writer removes its temporary file and leaves an existing file
// at `path` untouched. The JSON written parses to the same value as WriteRobotTrajectoryJson's
// for the same trajectory ("summary" comes last). `scenario` must outlive the writer. Errors
// writing throw std::system_error naming the path.
class RobotTrajectoryWriter : public ArmStepSink {
 public:
  // Creates the temporary file and writes the head (the arm, the method, the initial state).
  RobotTrajectoryWriter(const RobotScenario& scenario, const std::string& path);
  ~RobotTrajectoryWriter() override;
  RobotTrajectoryWriter(const RobotTrajectoryWriter&) = delete;
  RobotTrajectoryWriter& operator=(const RobotTrajectoryWriter&) = delete;

  void Add(const ArmStepReport& step) override;
  // Writes the summary of `trajectory` (its steps, if any, are ignored: they came through Add),
  // syncs the file and renames it over the destination. Throws InputError (nothing written) if
  // fewer steps than targets were added, the trajectory's num_steps differs, or a summary number
  // is not finite ("summary.max_ee_error"); std::system_error if the file cannot be written.
  // Once only.
  void Commit(const ArmTrajectory& trajectory);
  // Steps added so far.
  int64_t steps() const { return steps_; }

  class Impl;

 private:
  std::unique_ptr<Impl> impl_;  // null after Commit or a failure
  int64_t steps_ = 0;
};

// The same for the joint CSV of WriteRobotJointsCsv: the header and the initial angles at
// construction, a row per step, renamed into place by Commit.
class RobotJointsCsvWriter : public ArmStepSink {
 public:
  RobotJointsCsvWriter(const RobotScenario& scenario, const std::string& path);
  ~RobotJointsCsvWriter() override;
  RobotJointsCsvWriter(const RobotJointsCsvWriter&) = delete;
  RobotJointsCsvWriter& operator=(const RobotJointsCsvWriter&) = delete;

  void Add(const ArmStepReport& step) override;
  void Commit(const ArmTrajectory& trajectory);
  int64_t steps() const { return steps_; }

  class Impl;

 private:
  std::unique_ptr<Impl> impl_;
  int64_t steps_ = 0;
};

// The one call that tracks a robot scenario into files, as `flexkin robot -o --csv` and Python's
// run_robot(output=, csv=) do: the steps stream to the trajectory JSON `trajectory` and, if `csv`
// is not empty, the joint CSV (each renamed into place only when complete, removed if the tracking
// or the file fails), and to `also` if not null (arrays, an interrupt check; it sees each step
// after the files). Either path may be empty: that file is not written. Returns the trajectory
// summary (its steps went to the sinks).
ArmTrajectory TrackToFiles(const RobotScenario& scenario, const std::string& trajectory,
                           const std::string& csv, ArmStepSink* also = nullptr);

// A trajectory file (WriteRobotTrajectoryJson, RobotTrajectoryWriter) read back: what drawing
// it takes (docs/rendering.md, "Robot trajectories"). Robot order: point 0 of each state is the
// base.
struct RobotTrajectoryFile {
  std::string scenario_name;     // "scenario"; "" if none
  int dim = 2;                   // 2 or 3
  std::string method;            // the fixed-base method's name ("newton", "fixed_point")
  Eigen::VectorXd link_lengths;  // the n link lengths, base link first
  Eigen::VectorXd base;          // dim: where the base is bolted
  // "initial" and then one state per step: each g by dim, base first, one point per distinct
  // position (g = n + 1 unless joints share a point, "joint_groups").
  std::vector<Points> states;
  Points targets;             // T by dim: the end effector's target of each step
  std::vector<bool> reached;  // T: each step's "reached"
  int64_t unreached = 0;      // "summary": steps not reached, largest end-effector error,
  double max_ee_error = 0.0;  // wall time of the tracking (s)
  double seconds = 0.0;
  // "colliders" (as the scenario gave them; a keyframed one's times in steps: the state of step s
  // where its motion has it at time s), none if the file has none.
  std::vector<Collider> colliders;
  // "link_radii" (with colliders): each link's capsule radius, base link first; empty if none.
  Eigen::VectorXd link_radii;
};

// Whether the file at `path` is a robot trajectory: JSON whose top-level "format" is
// "flexkin-robot-trajectory". Reads only up to that key (the writers put it first); false for
// anything else (another format, not JSON, a file that cannot be read).
bool IsRobotTrajectoryFile(const std::string& path);
// Reads a trajectory file. Checks "format", "version", the shapes (every state g by dim, the
// same g throughout; one target of dim numbers per step) and that every number is finite.
// Throws std::system_error if it cannot be read, InputError (field: the JSON pointer,
// "/steps/3/points/2/1") if it is not a valid trajectory.
RobotTrajectoryFile ReadRobotTrajectoryFile(const std::string& path);
// The same from the text of a trajectory file (InputError as ParseRobotScenarioText for text
// that is not JSON).
RobotTrajectoryFile RobotTrajectoryFromText(const std::string& json_text);

// The trajectory as a chain result, the form the pictures and the viewer draw: one frame per
// state (step 0 the initial state, then step t after target t), its points in reverse, the end
// effector first as a chain's leading end and the base last; the link lengths the largest
// distance of each pair of neighbouring points over the states (prismatic joints change it; 1 for
// a pair that never parts); the metrics' path lengths and L2 per step from the states (no length
// error: the arm keeps its own), and the trajectory's colliders, which the pictures, animations and
// viewer then draw as a chain run's. Throws InputError for a trajectory without states or of
// mismatched shapes.
ResultFile RobotTrajectoryAsResult(const RobotTrajectoryFile& trajectory);

namespace internal {

// What Draw (flexkin/draw.h) hands the writers once it has checked the drawing and every option,
// once, where they entered the library (docs/architecture.md, "Checked once"): `result` is valid
// (ValidateResult); for a robot trajectory `trajectory` is the file and `result` its
// RobotTrajectoryAsResult, made once for every output. The internal:: writers that take it
// (flexkin/render.h, viewer.h, gltf.h) check neither again (the path's extension they still read).
struct CheckedDrawing {
  const ResultFile& result;
  const RobotTrajectoryFile* trajectory = nullptr;
};

}  // namespace internal

}  // namespace flexkin
