#pragma once

#include <string>
#include <vector>

#include "flexkin/result_io.h"
#include "flexkin/robot_scenario.h"
#include "flexkin/tree_scenario.h"

namespace flexkin {

// The interactive viewer: one self-contained HTML file per result (docs/viewer.md). The page, its
// script and its style sheet are compiled into the library, and the result's frames and metrics
// are embedded in it as JSON, so the file opens offline in any current browser and fetches nothing.
// Library target flexkin_viewer.

struct ViewerOptions {
  // Page title and heading. Empty: the result's scenario name, or "flexkin result" if it has none.
  std::string title;
  // Wall time in seconds for one play-through of all frames at speed 1x (the speed control
  // scales it). > 0, at most 86400. Typical: 5 to 30.
  double playback_seconds = 10.0;
  // Start playing as soon as the page is open.
  bool autoplay = true;
  // Start again from the first frame after the last one; otherwise stop at the last one.
  bool loop = true;
  // Show the leading end's path (point 0 over all frames) at the start; the page has a toggle.
  bool show_leader_path = true;
  // Points (0 = leading end, n = trailing end) whose trails are shown at the start: the point's
  // positions from the first frame up to the current one. Each >= 0 and, checked against the
  // result by WriteViewerHtml, <= n. The page can add and remove trails.
  std::vector<int> trail_points;
  // Initial 3D view: azimuth of the viewing direction about the z axis from the x axis, degrees
  // (any finite value), and elevation above the x-y plane, degrees in [-90, 90]. Unused in 2D.
  double azimuth = -60.0;
  double elevation = 25.0;
  // Initial 3D projection: perspective if true, orthographic otherwise; the page has a toggle.
  bool perspective = false;
  // Significant digits of the embedded coordinates, in [6, 17]. 9 keeps a point to about 1e-9 of
  // the drawing's extent, far below a pixel, at about 13 bytes per coordinate; 17 is exact.
  int digits = 9;

  // Every problem (empty if valid), each naming its member ("digits").
  Problems Validate() const;
};

// Writes the viewer page for `result` to `path`, atomically (WriteFileAtomically: written whole or
// not at all, an existing file is left untouched on any error). Throws InputError, before
// writing anything, for invalid options (field "options.<name>", or "trail_points[i]" for a point
// the result does not have) or a result that cannot be shown: dim not 2 or 3 ("dim"), no frames
// ("frames"), a frame of the wrong shape or a non-finite number (e.g. "frames[3].points[2][1]",
// "metrics.l2_total", "link_lengths[0]"). Throws std::system_error if the file cannot be written.
void WriteViewerHtml(const ResultFile& result, const ViewerOptions& options,
                     const std::string& path);
// The viewer page of a robot trajectory, drawn as RobotTrajectoryAsResult makes it a chain: the
// end effector is point 0 (the leading end: its path is the one shown) and the fixed base, point
// g - 1, is marked as a support; the panel gives the method, the targets and how many were not
// reached, the end effector and the base instead of the leading and trailing ends, and no
// link-length error (the arm keeps its lengths; prismatic joints change the distances). Errors as
// above.
void WriteViewerHtml(const RobotTrajectoryFile& trajectory, const ViewerOptions& options,
                     const std::string& path);

// The viewer page of a tree result (flexkin/tree_scenario.h; docs/trees.md, "Pictures"): each link
// drawn from its parent's point, the driven points' paths where a chain's leading end's is,
// supports under the fixed points; the panel gives the method, the points, the driven and fixed
// points, the frames not reached and the largest relative link-length error against the first
// frame's lengths (per frame too), the sparklines each point's path length and the distance the
// points travel per frame. Throws InputError for invalid options, a trail point beyond the points
// ("trail_points[i]") or a tree ValidateTreeResult refuses; std::system_error if the file cannot
// be written. Written atomically.
void WriteTreeViewerHtml(const TreeResultFile& tree, const ViewerOptions& options,
                         const std::string& path);

namespace internal {
// The page of a drawing Draw (flexkin/draw.h) has checked, with options it has checked (the trail
// points against the drawing included): nothing is checked again.
void WriteViewerHtml(const CheckedDrawing& drawing, const ViewerOptions& options,
                     const std::string& path);
// The same for a tree and options Draw has checked (ValidateTreeResult, Validate, the trail
// points against the tree): nothing is checked again.
void WriteTreeViewerHtml(const TreeResultFile& tree, const ViewerOptions& options,
                         const std::string& path);
}  // namespace internal

}  // namespace flexkin
