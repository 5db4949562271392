#pragma once
// Strand result files: every strand's points at every recorded frame of a groom run, as a NumPy
// .npz archive that numpy reads without flexkin (docs/strands.md, "The strand file"):
//
//   points.npy            (F, P, dim) float32 or float64: every strand's points, strand i in rows
//                         offsets[i] .. offsets[i+1]-1, its root first
//   offsets.npy           (S+1,) int64
//   link_lengths.npy      (P-S,) float64: strand i's links at offsets[i]-i .. offsets[i+1]-i-2
//   frames.npy            (F,) int64: the frame number of each recorded frame (0: the start)
//   times.npy             (F,) float64: seconds
//   body_rotation.npy     (F, 3, 3) float64, body_translation.npy (F, 3) float64: the body pose
//   groom.json            the run's description (name, method, substeps, pinned, scalp, the
//                         colliders when there are any, report)
//
// The writer streams: it holds one frame, never the run, and writes the file whole or not at all
// (an existing file is left as it was on any failure). The reader reads frame by frame.

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "flexkin/strands.h"
#include "flexkin/vocabulary.h"

namespace flexkin {

// The body the strands grow from, as far as drawing it goes.
struct ScalpShape {
  std::string shape;  // "sphere", "ellipsoid" or "" (none: explicit strands)
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // body coordinates
  Eigen::Vector3d radii = Eigen::Vector3d::Zero();   // semi-axes along body x, y, z
};

// The precision of a strand file's points ("record"/"precision" of a groom, --precision,
// precision= in Python), named once.
enum class StrandPrecision { kFloat32, kFloat64 };

template <>
struct Vocabulary<StrandPrecision> {
  static constexpr const char* kKind = "precision";
  static constexpr NamedValue<StrandPrecision> kEntries[] = {
      {StrandPrecision::kFloat32, "float32", "4-byte points: half the file, ~1e-7 relative"},
      {StrandPrecision::kFloat64, "float64", "8-byte points, as computed"},
  };
};

// "float32" or "float64".
inline const char* PrecisionName(bool float32) {
  return NameOf(float32 ? StrandPrecision::kFloat32 : StrandPrecision::kFloat64);
}

// Everything of a strand file but its frames.
struct StrandFileHeader {
  std::string name, description;
  int dim = 3;                   // 2 or 3
  std::vector<int64_t> offsets;  // S+1 entries, offsets[0] = 0, strictly increasing by >= 2
  Eigen::VectorXd link_lengths;  // P - S entries
  int64_t num_frames = 0;        // F, known before the first frame is written
  bool float32 = true;           // points stored as float32 ("<f4") or float64 ("<f8")
  double fps = 30.0;             // frames per second of the motion
  std::string method = "tractrix";
  int substeps = 1, pinned = 1, record_every = 1;
  ScalpShape scalp;
  // The run's colliders (StrandOptions): those moving with the body, in body coordinates (a
  // groom's scalp among them unless it said "scalp_collider": false), and those fixed in the
  // world. Written only when there are any.
  std::vector<Collider> body_colliders, world_colliders;
  // Dynamic strands (StrandOptions::dynamics): the projection, gravity, damping and wind (a
  // constant wind; keyframed wind is not written). Written as "dynamics" only when set.
  std::optional<DynamicOptions> dynamics;
  // Dynamic strands with their own masses (StrandOptions::masses; not written themselves):
  // "dynamics": {"own_masses": true}.
  bool own_masses = false;

  int num_strands() const { return static_cast<int>(offsets.empty() ? 0 : offsets.size() - 1); }
  int64_t num_points() const { return offsets.empty() ? 0 : offsets.back(); }
};

// How the strands of a file moved, for titles and reports: "dynamic, projection dftl" for dynamic
// strands, else the method ("tractrix").
std::string StrandMotionName(const StrandFileHeader& header);

// One recorded frame.
struct StrandFrame {
  int64_t frame = 0;  // frame number of the motion
  double time = 0.0;  // seconds
  BodyPose pose;
  // P by dim, row-major: strand i's points are rows offsets[i] .. offsets[i+1]-1. In a file of
  // float32 the values read back are the float32 ones, widened.
  Points points;
};

// What the run reports at the end, stored in groom.json under "report".
struct StrandRunReport {
  double max_length_error = 0.0;  // largest |link length - rest length| / rest length, all frames
  double seconds = 0.0;           // wall time of the stepping
  std::string engine;             // "avx512", "avx2" or "scalar"
  int threads = 1;
  // With colliders: the contact link steps and the least clearance of a link near one, relative
  // to its length (StrandContacts; +inf: none came near). Written only with colliders.
  int64_t contact_link_steps = 0;
  double least_clearance = std::numeric_limits<double>::infinity();
  // Dynamic strands: the strands' energy at each recorded frame (StrandDynamics::energy; frame 0
  // NaN, written null), the overall projection's non-converged strand sub-steps and its contact
  // sub-steps. Written only for dynamic strands.
  std::vector<double> energy;
  int64_t failures = 0, contact_substeps = 0;
};

class StrandFileWriter {
 public:
  // Starts writing `path` (ending in .npz). Throws InputError for an invalid header (field
  // "header.<member>") and std::system_error if the file cannot be created.
  StrandFileWriter(const std::string& path, const StrandFileHeader& header);
  ~StrandFileWriter();  // without Commit: nothing is left behind, an earlier file is untouched
  StrandFileWriter(const StrandFileWriter&) = delete;
  StrandFileWriter& operator=(const StrandFileWriter&) = delete;

  // Frame `index` (0 .. F-1, in order) with its pose and the batch's points. Throws InputError
  // for a non-finite point ("frames[i].points[j][k]") and std::system_error for a failed write.
  void Add(const StrandFrame& frame);
  // The same, the points read straight from the batch (no copy of the whole frame).
  void Add(int64_t frame_number, double time, const BodyPose& pose, const StrandBatch& batch);
  // Ends the file: every frame written (else InputError "frames"), the report in groom.json, then
  // synced and renamed into place.
  void Commit(const StrandRunReport& report);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class StrandFileReader {
 public:
  // Opens and checks a strand file (every structure against the file's size). Throws
  // std::system_error if it cannot be read, InputError naming the member if it is not a valid
  // strand file.
  explicit StrandFileReader(const std::string& path);
  ~StrandFileReader();
  StrandFileReader(const StrandFileReader&) = delete;
  StrandFileReader& operator=(const StrandFileReader&) = delete;

  const StrandFileHeader& header() const;
  const StrandRunReport& report() const;
  // The poses, frame numbers and times of all frames (small: read at open).
  const std::vector<StrandFrame>& frame_info() const;  // points left empty

  // The next frame in order (false after the last). `out->points` is resized to P by dim.
  bool Next(StrandFrame* out);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// True if the file at `path` looks like a strand file (an npz with points.npy and groom.json),
// for `flexkin render` to tell it from a chain result. Never throws.
bool IsStrandFile(const std::string& path);

}  // namespace flexkin
