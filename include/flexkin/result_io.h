#pragma once

#include <cstdint>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "flexkin/colliders.h"
#include "flexkin/run.h"

namespace flexkin {

// Files in and out: result files (docs/result-format.md, docs/schema/result.schema.json) and frame
// CSV files.
//
// Errors: std::system_error for a file that cannot be read or written (the message has the path
// and the system's reason, e.g. "No such file or directory"); InputError for content that is not
// valid. Every writer below is all-or-nothing: it writes a temporary file in the destination's
// directory, flushes, syncs and closes it, checks every step, and only then renames it over the
// destination. On any error the temporary file is removed and an existing destination is left
// untouched.

// The identification and version of result files, written and checked by the functions below.
inline constexpr const char* kResultFormat = "flexkin-result";
inline constexpr int kResultVersion = 1;

// The formats of result files: JSON (one document, docs/result-format.md) and NumPy's .npz (a ZIP
// archive of .npy arrays and a result.json member, readable by numpy.load without flexkin).
enum class ResultFileFormat { kJson, kNpz };

// "json" or "npz".
const char* ResultFileFormatName(ResultFileFormat format);
// The format named by the extension of `path` (".json", ".npz", in any case). Throws InputError
// with `field` ("-o") naming the path and the valid extensions for any other.
ResultFileFormat ResultFileFormatOfPath(const std::string& path, const std::string& field = "path");

// What a result file says before its frames: known when a run starts.
struct ResultHeader {
  Method method = Method::kTractrix;
  int dim = 2;                // 2 or 3
  Eigen::VectorXd lengths;    // the n link lengths
  std::string scenario_name;  // written as "scenario" if not empty
  // The run's colliders (RunOptions::colliders), written as "colliders" in the scenario's form if
  // any (a file without them is written as before colliders existed).
  std::vector<Collider> colliders;
  // The links' radii (one per link; RunOptions::link_radius, a robot's capsules), written as
  // "link_radii" if given: figures draw each link as its capsule. Empty: none.
  Eigen::VectorXd link_radii;
};
// The header of a run of `chain` with `options` (its colliders and link radius included).
ResultHeader MakeResultHeader(const Chain& chain, const RunOptions& options,
                              const std::string& scenario_name = "");

// A FrameSink that hands every frame to each of `sinks` in turn (a result file, a CSV file,
// arrays).
class FrameFanOut : public FrameSink {
 public:
  explicit FrameFanOut(std::vector<FrameSink*> sinks) : sinks_(std::move(sinks)) {}
  void Add(int64_t step, const PointsRef& points, const VectorRef& link_angles) override {
    for (FrameSink* sink : sinks_) sink->Add(step, points, link_angles);
  }

 private:
  std::vector<FrameSink*> sinks_;
};

// Where a run writes as it goes: the result file (JSON or .npz by the extension of `result`,
// ResultFileFormatOfPath) and the frames CSV; an empty path writes no such file.
struct RunFiles {
  std::string result;
  std::string csv;
};

// The one call that runs a chain into files, as `flexkin run` and Python's run_scenario(output=)
// do: the frames stream to the files (and to `also`, if not null: arrays, a viewer) while the run
// records them, in bounded memory; each file is renamed into place only when the run and the file
// are complete, and removed, an existing file untouched, if either fails. Returns the run's result
// without its frames (they went to the sinks). Throws what Run and the writers throw.
RunResult RunToFiles(const Chain& chain, const Points& leader_steps, const RunOptions& options,
                     const std::string& scenario_name, const RunFiles& files,
                     FrameSink* also = nullptr);

// A FrameSink that writes a result file while the run produces its frames, in bounded memory
// (one frame and a buffer; the .npz writer keeps the frames' step numbers, 8 bytes a frame, and
// puts the link angles in an unlinked scratch file in the destination's directory until Commit):
//
//   ResultFileWriter writer(path, ResultFileFormat::kNpz, MakeResultHeader(chain, options, name));
//   RunResult result = Run(chain, leader_steps, options, &writer);
//   writer.Commit(result);
//
// All-or-nothing like every writer here: the file is written to a temporary file in the
// destination's directory, and only Commit renames it over `path`. A frame holding a non-finite
// number (or of the wrong shape, or with a step not above the previous one) is refused by Add with
// InputError naming it ("frames[f].points[i][k]"), which stops the run; destroyed without a
// successful Commit (an exception, a failed run), the writer removes its temporary file and leaves
// an existing file at `path` untouched. The JSON written parses to the same value as
// WriteResultJson's for the same result (the keys after "frames" come in another order).
class ResultFileWriter : public FrameSink {
 public:
  // Creates the temporary file: throws std::system_error if it cannot, InputError for an invalid
  // header (dim, link lengths).
  ResultFileWriter(const std::string& path, ResultFileFormat format, const ResultHeader& header);
  ~ResultFileWriter() override;
  ResultFileWriter(const ResultFileWriter&) = delete;
  ResultFileWriter& operator=(const ResultFileWriter&) = delete;

  void Add(int64_t step, const PointsRef& points, const VectorRef& link_angles) override;
  // Writes the rest of the result (num_steps, metrics, accuracy, overall report, weights, seconds;
  // its frames, if any, are ignored: they came through Add), syncs the file and renames it over
  // the destination. Throws InputError (nothing written) if `result` does not match the header
  // (method, link lengths), no frame was added, or a number is not finite; std::system_error if
  // the file cannot be written. Once only.
  void Commit(const RunResult& result);
  // Frames added so far.
  int64_t frames() const;

  class Impl;

 private:
  ResultHeader header_;
  std::unique_ptr<Impl> impl_;  // null after Commit or a failure
  int64_t frames_ = 0, last_step_ = -1;
};

// A FrameSink that writes the frames as CSV (the format of WriteFramesCsv) as they are produced,
// all-or-nothing like ResultFileWriter: Commit renames the file into place.
class FramesCsvWriter : public FrameSink {
 public:
  // `dim` is 2 or 3.
  FramesCsvWriter(const std::string& path, int dim);
  ~FramesCsvWriter() override;
  FramesCsvWriter(const FramesCsvWriter&) = delete;
  FramesCsvWriter& operator=(const FramesCsvWriter&) = delete;
  void Add(int64_t step, const PointsRef& points, const VectorRef& link_angles) override;
  void Commit();

  class Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

// Writes `result` as a result JSON document (format "flexkin-result", version 1). Doubles are
// written with 17 significant digits, so reading them back gives the same bits. Frames are
// streamed, one per line, without building the document in memory. `scenario_name` is written
// as "scenario" if not empty. Throws InputError (field "frames[f].points[i][k]" and so on)
// before writing anything if the result holds a non-finite number, which JSON cannot represent.
void WriteResultJson(const RunResult& result, std::ostream& out,
                     const std::string& scenario_name = "");
void WriteResultJson(const RunResult& result, const std::string& path,
                     const std::string& scenario_name = "");
// A whole result in either format, through ResultFileWriter, after the same check.
void WriteResultFile(const RunResult& result, const std::string& path, ResultFileFormat format,
                     const std::string& scenario_name = "");

// Writes the recorded frames as CSV: a header "step,point,x,y" (",z" in 3D), then one row per
// point per frame, leading end (point 0) first, 17 significant digits. Non-finite values are
// refused as by WriteResultJson.
void WriteFramesCsv(const RunResult& result, std::ostream& out);
void WriteFramesCsv(const RunResult& result, const std::string& path);

// The one check of a result, shared by every reader and writer of results (render, viewer and
// glTF add only their own): dim 2 or 3, at least one link, positive finite link lengths, at least
// one frame, every frame (n+1) by dim, link angles one per link or none, and every number finite.
// Stops at the first problem; its field is the member path ("frames[3].points[2][1]",
// "link_lengths[0]", "metrics.l2_total").
Problems ValidateResult(const RunResult& result, int dim);

// A result file read back.
struct ResultFile {
  RunResult result;           // method, lengths, num_steps, frames, metrics, accuracy, seconds
  int dim = 0;                // 2 or 3
  std::string scenario_name;  // "" if the file has none
  // The colliders the chain stayed outside of ("colliders", in the scenario's form; empty if the
  // file has none). Here rather than in RunResult, beside the scenario's name: like it they are
  // the run's input, known before it starts (RunOptions::colliders), which a run hands on
  // unchanged; what the run made of them is RunResult::contacts.
  std::vector<Collider> colliders;
  // The links' radii ("link_radii", one per link; empty if the file has none).
  Eigen::VectorXd link_radii;
};

// ValidateResult of the file's result, and its colliders: each passes CheckCollider and, in 2D,
// lies in the plane z = 0 as a 2D scenario's (fields "colliders[k]"). What every writer of a
// ResultFile (the result writers, the figures, the viewer, glTF) checks.
Problems ValidateResult(const ResultFile& file);

// Writes a whole ResultFile (its result, scenario name and colliders) as WriteResultFile and
// WriteResultJson write a RunResult: what reads back as the same ResultFile.
void WriteResultFile(const ResultFile& file, const std::string& path, ResultFileFormat format);
void WriteResultJson(const ResultFile& file, std::ostream& out);

// Reads a result file of either format, recognised by its content (an .npz file starts with
// "PK\x03\x04"; anything else is read as JSON): the same ResultFile as ReadResultJson gives for
// the JSON of the same result. Every size, shape, offset and checksum of an .npz file is checked:
// a malformed one throws InputError whose field names the member ("frames.npy",
// "result.json/metrics/l2_total") or the ZIP structure ("zip central directory").
ResultFile ReadResultFile(const std::string& path);

// Reads a result file written by WriteResultJson. Checks "format" and "version" and the shapes
// (every frame (n+1) by dim with n = the number of link lengths). Throws std::system_error if it
// cannot be read, InputError (field: JSON pointer) if it is not a valid result file.
ResultFile ReadResultJson(const std::string& path);
// The same from the text of a result file. Throws InputError as ReadResultJson; for text that is
// not JSON, with an empty field and a message "line L, column C: invalid JSON: <reason>".
ResultFile ResultFromText(const std::string& json_text);

// The size of a run's output, before the run: the number of recorded frames is exact (frame 0,
// every record_every-th leader step and the last), the bytes are estimates (JSON and CSV: about
// 24 bytes per number, 17 significant digits with sign, exponent and separator; npz: 8).
struct ResultSizeEstimate {
  int64_t frames = 0;
  bool link_angles = true;  // the frames carry link angles (n numbers each)
  uint64_t json_bytes = 0;
  uint64_t npz_bytes = 0;
  uint64_t csv_bytes = 0;  // the --csv frames file
  // Memory of Run's plain form, which keeps every frame (FrameRecorder), for the frames alone.
  uint64_t recorder_bytes = 0;

  uint64_t bytes(ResultFileFormat format) const;
};

ResultSizeEstimate EstimateResultSize(int num_links, int dim, int64_t num_steps,
                                      const RunOptions& options);
uint64_t EstimateResultBytes(int num_links, int dim, int64_t num_steps, const RunOptions& options,
                             ResultFileFormat format);

// A process-wide check made by every writer of flexkin just before it puts a finished output in
// place (its data on disk, before the rename over an earlier file): a check that throws leaves the
// earlier file as it was and removes the new one, and the exception propagates. The command line
// sets it so that SIGINT and SIGTERM stop a command up to that moment. Null (the default): none.
// Set it before any writing starts.
void SetBeforeOutputCommit(void (*check)());

}  // namespace flexkin
