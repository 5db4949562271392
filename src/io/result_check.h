#pragma once
// The one check of results (ValidateResult, flexkin/result_io.h) in its parts, for the writers that
// see a result piece by piece (the streaming writers: the header, then frame by frame, then the
// rest). Private to the library and its tests.

#include <cstdint>
#include <optional>
#include <string>

#include "flexkin/error.h"
#include "flexkin/run.h"

namespace flexkin {

// dim 2 or 3, at least one link, positive finite link lengths.
std::optional<Problem> ResultHeaderProblem(const Eigen::VectorXd& lengths, int dim);
// The links' radii: none, or one finite number >= 0 per link of `n`; named "link_radii" and
// "link_radii[i]", or as JSON pointers ("/link_radii", "/link_radii/i") for the readers.
std::optional<Problem> LinkRadiiProblem(const Eigen::VectorXd& radii, Eigen::Index n,
                                        bool pointer = false);
// Frame `f` (named "frames[f]..."): (n+1) by dim points, link angles one per link or none, every
// number finite, step >= 0 and above `previous_step` (-1 for the first frame).
std::optional<Problem> ResultFrameProblem(size_t f, int64_t step, const PointsRef& points,
                                          const VectorRef& link_angles, int64_t previous_step,
                                          Eigen::Index n, int dim);
// The rest: every number of the metrics, the accuracy report, the overall report and the
// seconds finite.
std::optional<Problem> ResultSummaryProblem(const RunResult& r);

}  // namespace flexkin
