#pragma once
// Checks of the inputs shared by every writer, and small helpers of the titles.

#include <string>

#include "flexkin/result_io.h"

namespace flexkin::render {

// Throws InputError if `file` cannot be drawn: no frames, a dimension other than 2 or 3, a
// frame of the wrong shape, or a non-finite number ("frames[f].points[i][k]").
void CheckDrawable(const ResultFile& file);
// Adds the problem "width: 0 is not valid; expected an integer from 64 to 8192" if `value` is
// outside [lo, hi].
void CheckRange(const char* field, double value, double lo, double hi, bool integer,
                Problems* problems);

// The title's first line: `title`, else the scenario's name, else "flexkin result".
std::string MainTitle(const ResultFile& file, const std::string& title);
// "tractrix · 20 links · 2650 leader steps".
std::string RunSummary(const ResultFile& file);

}  // namespace flexkin::render
