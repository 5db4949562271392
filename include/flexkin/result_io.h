#pragma once

#include <functional>
#include <iosfwd>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "flexkin/run.h"

namespace flexkin {

// Files in and out: result files (docs/result-format.md, docs/schema/result.schema.json), frame
// CSV files, and the JSON reading and atomic writing they and scenario files share.
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

// Parses JSON text. Throws InputError: for a syntax error with an empty field and a message that
// starts "line L, column C: " and gives the reason; for a number too large for a double (1e999)
// with the JSON pointer of the value as field.
nlohmann::json ParseJsonText(const std::string& text);

// Reads and parses the file at `path`; throws std::system_error if it cannot be read and
// InputError as ParseJsonText.
nlohmann::json ReadJsonFile(const std::string& path);

// Creates or replaces the file at `path` with what `write` puts into the stream, atomically (see
// above). If `write` throws, the exception propagates after the clean-up. A new file gets the
// usual mode (0666 less the process umask); a replaced file keeps its mode.
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

// Writes `result` as a result JSON document (format "flexkin-result", version 1). Doubles are
// written with 17 significant digits, so reading them back gives the same bits. Frames are
// streamed, one per line, without building the document in memory. `scenario_name` is written
// as "scenario" if not empty. Throws InputError (field "frames[f].points[i][k]" and so on)
// before writing anything if the result holds a non-finite number, which JSON cannot represent.
void WriteResultJson(const RunResult& result, std::ostream& out,
                     const std::string& scenario_name = "");
void WriteResultJson(const RunResult& result, const std::string& path,
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
};

// Reads a result file written by WriteResultJson. Checks "format" and "version" and the shapes
// (every frame (n+1) by dim with n = the number of link lengths). Throws std::system_error if it
// cannot be read, InputError (field: JSON pointer) if it is not a valid result file.
ResultFile ReadResultJson(const std::string& path);
// The same from a parsed document.
ResultFile ResultFromJson(const nlohmann::json& json);

}  // namespace flexkin
