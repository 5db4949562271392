#pragma once

#include <string>

#include "flexkin/viewer.h"

namespace flexkin::viewer_internal {

// The data the viewer page shows, as one line of JSON (layout in viewer.js, loadData): the
// result's frames as one flat array of coordinates, per-frame steps and link-length errors, the
// metrics and the page options. Strings have '<', '>' and '&' escaped as \u003c and so on, so the
// text can sit inside a <script> element without closing it. Throws InputError as
// WriteViewerHtml (include/flexkin/viewer.h) for a result that cannot be shown; `options` must be
// valid.
// `robot`: the trajectory that `result` was made from (RobotTrajectoryAsResult), whose facts go
// into a "robot" object (method, targets, unreached, max_ee_error) that the page shows instead of
// the chain's (and "links", the arm's n); null for a chain result.
std::string ViewerDataJson(const ResultFile& result, const ViewerOptions& options,
                           const RobotTrajectoryFile* robot = nullptr);

}  // namespace flexkin::viewer_internal
