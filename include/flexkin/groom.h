#pragma once
// Grooms: strands grown on a body (a sphere or ellipsoid "scalp", or given one by one) and the
// keyframed rigid motion of that body, read from a groom scenario file (docs/groom-format.md,
// JSON Schema docs/schema/groom.schema.json) and run frame by frame through the strand engine
// (flexkin/strands.h) into a strand file (flexkin/strand_file.h).

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/strand_file.h"
#include "flexkin/strands.h"

namespace flexkin {

// Limits that keep a small file from asking for unbounded memory or time.
constexpr int kMaxGroomRoots = 10000000;         // roots (or explicit strands) of a groom
constexpr int64_t kMaxGroomPoints = 200000000;   // points of all strands together (24 B each)
constexpr int64_t kMaxGroomFrames = 10000000;    // frames of a motion
constexpr int64_t kMaxGroomKeyframes = 1000000;  // keyframes of a motion

// Strands grown on a scalp (all in body coordinates); docs/groom-format.md, "Growing strands".
struct GrowSpec {
  ScalpShape scalp;  // shape "sphere" (radii all equal) or "ellipsoid"
  int roots = 1000;  // number of strands, 1 .. kMaxGroomRoots
  // Roots only where the outward normal is within `max_angle_deg` of `region_axis` (a cap; 180:
  // the whole surface).
  Eigen::Vector3d region_axis = Eigen::Vector3d::UnitZ();
  double max_angle_deg = 180.0;
  int links = 32;                 // links per strand, >= 1
  double link_length = 0.005;     // > 0 (scenario units, e.g. metres)
  double length_variation = 0.0;  // in [0, 1): each strand's link length scaled by 1 + v (2u - 1)
  // Direction field: link j of a strand points along the surface normal turned toward `gravity`
  // by droop * angle(normal, gravity) * (j + 1) / links (droop in [0, 1]; 0: straight out; 1:
  // the last link along gravity).
  double droop = 0.0;
  Eigen::Vector3d gravity = -Eigen::Vector3d::UnitZ();
  uint64_t seed = 1;  // roots are placed by a seeded generator: same seed, same groom
};

// The strands of `spec`, each (links + 1) x 3, root first, in body coordinates. The same seed
// gives the same roots on every platform (std::mt19937_64, + - * / and sqrt only). Throws
// InputError naming the member ("roots", "scalp.radii[1]", ...) for an invalid spec, or "region"
// when fewer than 1 in 10,000 of the first million or more candidate roots fell in the region.
std::vector<Points> GrowStrands(const GrowSpec& spec);
// Every problem of `spec` (empty if valid), named by member path; roots x (links + 1) must not
// exceed kMaxGroomPoints.
Problems ValidateGrowSpec(const GrowSpec& spec);

struct BodyMotion {
  std::vector<BodyKeyframe> keyframes;  // at least 1
  double fps = 30.0;                    // frames per second, > 0
  // Translation interpolated linearly, rotation by slerp, in the parameter u of the segment
  // (kLinear) or 3u^2 - 2u^3 (kSmooth: at rest at every keyframe).
  KeyframeInterpolation interpolation = KeyframeInterpolation::kSmooth;

  // Frames from the first keyframe's time to the last's: floor(duration * fps + 1e-9) + 1 (0
  // without keyframes).
  int64_t num_frames() const;
  // The first keyframe's time + frame / fps, clamped to the keyframes' times.
  double TimeOf(int64_t frame) const;
  // The pose at TimeOf(frame): a keyframe's own pose at its time (and within 1e-12 of a segment
  // from it), else the translation interpolated linearly and the rotation by slerp (the shorter
  // arc) between the segment's keyframes. No keyframes: the identity.
  BodyPose PoseAt(int64_t frame) const;
};

struct GroomScenario {
  std::string name, description;
  int dim = 3;
  std::vector<Points> strands;  // body coordinates, grown or given
  ScalpShape scalp;             // for drawing ("" shape for explicit strands)
  BodyMotion motion;
  StrandOptions options;  // method, substeps, pinned, threads
  int record_every = 1;   // frames 0, e, 2e, ... and always the last
  bool float32 = true;    // precision of points.npy
};

// Reads a groom scenario (a JSON object with "groom" or "strands", and "motion";
// docs/groom-format.md) and grows its strands; every problem is collected, each named by its JSON
// pointer ("/groom/roots"), and the first is thrown as InputError. As for chain and robot
// scenario files, a file's problems are named by pointer alone (a front end prints
// "PATH: /pointer: message"); a file that cannot be read is a std::system_error naming the path.
GroomScenario ParseGroomText(const std::string& json_text);
GroomScenario LoadGroomFile(const std::string& path);
// Every problem (empty if valid), without throwing.
Problems ValidateGroomText(const std::string& json_text);
Problems ValidateGroomFile(const std::string& path);
// True if the text (or file) is a JSON object with "groom" or "strands" at the top: a groom
// scenario rather than a chain or robot one. Never throws.
bool IsGroomText(const std::string& json_text);
bool IsGroomFile(const std::string& path);
// Values given to a front end (`flexkin run` options, Python's run_groom keywords) that replace
// the scenario's; unset ones keep the file's.
struct GroomOverrides {
  std::optional<std::string> method;  // "tractrix" or "ftl": the strand engine's methods
  // Dynamic strands' projection ("overall", "tractrix", "dftl"); refused without "dynamics".
  std::optional<std::string> projection;
  std::optional<int> substeps, pinned, threads;
  std::optional<int64_t> record_every;   // >= 1
  std::optional<std::string> precision;  // "float32" or "float64"
};

// Applies `overrides` to `scenario`, each checked as the file's value is and with the same
// messages (the valid names listed, a suggestion for a near miss). Throws InputError for the
// first problem, named as the front end spells the option: "--record-every" (command_line) or
// "record_every".
void ApplyGroomOverrides(const GroomOverrides& overrides, bool command_line,
                         GroomScenario* scenario);

// One line: "3D, 10000 strands of 32 links (...), 90 frames at 30 fps, method tractrix, ...".
std::string GroomSummary(const GroomScenario& scenario);

// The header a run of `scenario` writes (frames counted with record_every).
StrandFileHeader MakeStrandFileHeader(const GroomScenario& scenario);

// Runs the groom: the strands placed at the first keyframe's pose, then one StepStrands per
// frame, recording frames 0, e, 2e, ... and the last into `writer` (which it does not commit).
// `progress(done, total)` is called now and then; returning false stops the run (InputError
// "interrupted"). Allocates nothing per frame beyond the writer's buffer.
StrandRunReport RunGroom(const GroomScenario& scenario, StrandFileWriter* writer,
                         const std::function<bool(int64_t, int64_t)>& progress = {});
// The groom run into the strand file `path` (.npz), as `flexkin run -o` and Python's run_groom
// write it: streamed, renamed into place only when complete, removed if the run fails.
StrandRunReport RunGroomToFile(const GroomScenario& scenario, const std::string& path,
                               const std::function<bool(int64_t, int64_t)>& progress = {});

}  // namespace flexkin
