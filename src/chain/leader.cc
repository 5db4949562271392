#include "flexkin/leader.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "flexkin/error.h"

namespace flexkin {
namespace {

void CheckVector(const Eigen::VectorXd& v, int dim, const std::string& field) {
  if (v.size() != dim) {
    throw InputError(field, "has " + std::to_string(v.size()) + " coordinates; expected " +
                                std::to_string(dim) + " (the chain's dimension)");
  }
  for (Eigen::Index k = 0; k < v.size(); ++k) {
    if (!std::isfinite(v[k])) {
      throw InputError(field + "[" + std::to_string(k) + "]",
                       "value " + FormatNumber(v[k]) + " is not a finite number");
    }
  }
}

void CheckDim(Eigen::Index dim, const std::string& field) {
  if (dim != 2 && dim != 3) {
    throw InputError(
        field, "has " + std::to_string(dim) + " coordinates; expected 2 (planar) or 3 (spatial)");
  }
}

// A segment of `length` needs ceil(length / max_step) steps; the relative slack keeps a segment
// whose length is k max_step up to rounding at k steps. Returns a double so that huge counts
// can be rejected before converting.
double StepsFor(double length, double max_step) {
  const double ratio = length / max_step;
  return std::ceil(ratio * (1.0 - 1e-12));
}

}  // namespace

Points ExplicitPath(const Points& path, int dim, const std::string& field) {
  if (path.rows() < 1) throw InputError(field, "is empty; expected at least one target");
  if (path.cols() != dim) {
    throw InputError(field, "targets have " + std::to_string(path.cols()) +
                                " coordinates; expected " + std::to_string(dim) +
                                " (the chain's dimension)");
  }
  if (path.rows() > kMaxLeaderSteps) {
    throw InputError(field, "has " + std::to_string(path.rows()) + " targets; expected at most " +
                                std::to_string(kMaxLeaderSteps));
  }
  for (Eigen::Index i = 0; i < path.rows(); ++i) {
    CheckVector(path.row(i).transpose(), dim, field + "[" + std::to_string(i) + "]");
  }
  return path;
}

Points SplitPull(const Eigen::VectorXd& start, const Eigen::VectorXd& pull, int64_t steps) {
  CheckDim(start.size(), "start");
  const int dim = static_cast<int>(start.size());
  CheckVector(start, dim, "start");
  CheckVector(pull, dim, "pull");
  if (steps < 1 || steps > kMaxLeaderSteps) {
    throw InputError("steps", "value " + std::to_string(steps) +
                                  " is not valid; expected an integer from 1 to " +
                                  std::to_string(kMaxLeaderSteps));
  }
  Points targets(steps, dim);
  for (int64_t k = 1; k <= steps; ++k) {
    targets.row(k - 1) = (start + (static_cast<double>(k) / steps) * pull).transpose();
  }
  targets.row(steps - 1) = (start + pull).transpose();
  return targets;
}

Points ResamplePath(const Eigen::VectorXd& start, const Points& path, double max_step) {
  CheckDim(start.size(), "start");
  const int dim = static_cast<int>(start.size());
  CheckVector(start, dim, "start");
  ExplicitPath(path, dim, "path");
  if (!(max_step > 0.0) || !std::isfinite(max_step)) {
    throw InputError("max_step", "value " + FormatNumber(max_step) +
                                     " is not valid; expected a finite number > 0");
  }
  // First pass: count, so that the result is allocated once and huge counts are refused early.
  double total = 0.0;
  Eigen::VectorXd from = start;
  for (Eigen::Index i = 0; i < path.rows(); ++i) {
    const Eigen::VectorXd to = path.row(i).transpose();
    total += StepsFor((to - from).norm(), max_step);
    from = to;
  }
  if (!(total <= static_cast<double>(kMaxLeaderSteps))) {
    throw InputError("max_step", "value " + FormatNumber(max_step) + " splits the path into " +
                                     FormatNumber(total) + " steps; expected at most " +
                                     std::to_string(kMaxLeaderSteps) + " (use a larger max_step)");
  }
  Points targets(static_cast<Eigen::Index>(total), dim);
  Eigen::Index row = 0;
  from = start;
  for (Eigen::Index i = 0; i < path.rows(); ++i) {
    const Eigen::VectorXd to = path.row(i).transpose();
    const int64_t count = static_cast<int64_t>(StepsFor((to - from).norm(), max_step));
    for (int64_t k = 1; k < count; ++k) {
      // Interpolate from the segment's start so the error does not accumulate along it.
      targets.row(row++) = (from + (static_cast<double>(k) / count) * (to - from)).transpose();
    }
    if (count > 0) targets.row(row++) = path.row(i);
    from = to;
  }
  return targets;
}

}  // namespace flexkin
