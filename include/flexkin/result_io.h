#pragma once

#include <iosfwd>
#include <string>

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
// The same from the text of a result file. Throws InputError as ReadResultJson; for text that is
// not JSON, with an empty field and a message "line L, column C: invalid JSON: <reason>".
ResultFile ResultFromText(const std::string& json_text);

}  // namespace flexkin
