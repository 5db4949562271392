#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "flexkin/chain.h"

namespace flexkin {

// Leader motions expanded into leader steps: an m by dim list of the successive targets of the
// leading end (point 0), NOT including its start, as Run() takes them. Between two targets the
// leading end moves in a straight line.

// Upper bound on the number of leader steps a motion may expand to (80 MB of targets in 3D).
inline constexpr int64_t kMaxLeaderSteps = 10'000'000;

// The targets as given, after checking them: `path` must be m by `dim` with m >= 1 and finite
// values. Throws InputError naming `field` ("path[i][k]" style suffixes) otherwise.
Points ExplicitPath(const Points& path, int dim, const std::string& field = "path");

// One straight pull by `pull` (dim values, any length, zero allowed) from `start` (dim values,
// the leading end's position) split into `steps` equal leader steps: row k-1 is
// start + (k / steps) pull, and the last row is exactly start + pull. Returns steps by dim.
// Throws InputError ("steps", "pull", "start") if steps is not in [1, kMaxLeaderSteps], the sizes
// differ or are not 2 or 3, or a value is not finite.
Points SplitPull(const Eigen::VectorXd& start, const Eigen::VectorXd& pull, int64_t steps);

// The polyline start -> path[0] -> path[1] -> ... with each straight segment split into
// ceil(length / max_step) equal steps, so that no step is longer than `max_step` (to a relative
// 1e-12, so that a segment of exactly k max_step, up to rounding, takes k steps and not k + 1).
// Every vertex of `path` is a target, exactly as given; a zero-length segment adds no step.
// `start` has dim values, `path` is m by dim (m >= 1), `max_step` > 0 in the same length unit.
// Returns the targets, (total steps) by dim; zero rows if the whole path has zero length.
// Throws InputError ("max_step", "path", "start") on bad sizes, non-finite values, max_step <= 0
// or more than kMaxLeaderSteps steps.
Points ResamplePath(const Eigen::VectorXd& start, const Points& path, double max_step);

}  // namespace flexkin
