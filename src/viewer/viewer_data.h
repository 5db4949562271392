#pragma once

#include <string>
#include <vector>

#include "flexkin/tree_scenario.h"
#include "flexkin/viewer.h"

namespace flexkin::viewer_internal {

// Everything the page would show must be a finite number and every frame (n+1) by dim (the
// library's check of results); the trail points must be points of the chain. Throws InputError as
// WriteViewerHtml (include/flexkin/viewer.h) for a result that cannot be shown.
void CheckResult(const ResultFile& result, const ViewerOptions& options);

// The data the viewer page shows, as one line of JSON (layout in viewer.js, loadData): the
// result's frames as one flat array of coordinates, per-frame steps and link-length errors, the
// metrics and the page options. Strings have '<', '>' and '&' escaped as \u003c and so on, so the
// text can sit inside a <script> element without closing it. `result` and `options` are valid
// (CheckResult and ViewerOptions::Validate; checked once, by the caller).
// `robot`: the trajectory that `result` was made from (RobotTrajectoryAsResult), whose facts go
// into a "robot" object (method, targets, unreached, max_ee_error) that the page shows instead of
// the chain's (and "links", the arm's n); null for a chain result.
// "link_radii": the links' radii (one per link, link i from point i to point i + 1), with the
// coordinates' `digits`, where the result has them; the page draws the links as their capsules.
// `tree`: the tree result that `result` was made from (TreeAsViewerResult), whose topology goes
// into a "tree" object (parents; link_points, the point each link ends at, link k of `result`
// ending at link_points[k]; targets; fixed; not_reached, the frames not reached; looks, for each
// pointing goal its target index and the points it looked at, frames 1 to F-1) and whose links
// give each frame's length error; null for a chain result.
std::string ViewerDataJson(const ResultFile& result, const ViewerOptions& options,
                           const RobotTrajectoryFile* robot = nullptr,
                           const TreeResultFile* tree = nullptr);

// The points other than the root, in index order: link k of a tree's viewer result ends at the
// k-th of them.
std::vector<int> TreeLinkPoints(const TreeResultFile& tree);

// Per link k of TreeLinkPoints: 1 where it slides (the tree's `sliding`: a robot tree's prismatic
// joint), else 0.
std::vector<char> TreeSlidingLinks(const TreeResultFile& tree);

// A checked tree result (ValidateTreeResult) as the result the viewer page shows: frame f at step
// f; link k's length that of the link ending at TreeLinkPoints(tree)[k] in the first frame (a
// sliding link's, which is not checked against it, its longest over the frames, or the smallest
// positive double if it never opens); the metrics of the tree's motion from frame to frame (each
// point's path length, L2 per frame: the sum of the points' distances, L2 total, the largest
// relative link-length error of the links that do not slide).
ResultFile TreeAsViewerResult(const TreeResultFile& tree);

}  // namespace flexkin::viewer_internal
