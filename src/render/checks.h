#pragma once
// Checks of the inputs shared by every writer, and small helpers of the titles.

#include <string>

#include "flexkin/render.h"
#include "flexkin/result_io.h"
#include "flexkin/robot_scenario.h"

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
// The same for a tree result: "tree · tractrix passes · 2D · 8 points · 2 targets · 1 fixed · 13
// frames, all reached" (a robot tree's: its joints and the Gauss-Newton).
std::string TreeResultSummary(const TreeResultFile& tree);

// How a picture names and marks what it draws: a chain result's leading end and leader steps, or
// a robot trajectory's end effector, targets and fixed base (RobotTrajectoryAsResult puts the end
// effector first and the base last).
struct Look {
  std::string summary;               // the subtitle's line about the run (RunSummary)
  std::string lead = "leading end";  // point 0, whose path is drawn: "<lead>'s path"
  bool fixed_tail = false;           // the last point is a fixed base: drawn as a support
};
Look ChainLook(const ResultFile& file);
// "robot · newton · 3D · 16 links · 60 targets · 24 not reached".
Look TrajectoryLook(const RobotTrajectoryFile& trajectory);
// The look of a drawing: its trajectory's if it has one, else its chain's.
Look LookOf(const internal::CheckedDrawing& drawing);

}  // namespace flexkin::render
