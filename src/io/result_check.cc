// The one check of a result: what every reader and writer of results relies on (result_io.h).
#include "io/result_check.h"

#include <cmath>
#include <optional>
#include <string>

#include "flexkin/error.h"
#include "flexkin/result_io.h"
#include "io/colliders_json.h"

namespace flexkin {
namespace {

std::string Index(const std::string& field, Eigen::Index i) {
  return field + "[" + std::to_string(i) + "]";
}

std::optional<Problem> NonFinite(const Eigen::Ref<const Eigen::VectorXd>& v,
                                 const std::string& field) {
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) {
      return Problem::Invalid(Index(field, i), FormatNumber(v[i]), "a finite number");
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<Problem> ResultHeaderProblem(const Eigen::VectorXd& lengths, int dim) {
  if (dim != 2 && dim != 3) return Problem::Invalid("dim", std::to_string(dim), "2 or 3");
  const Eigen::Index n = lengths.size();
  if (n < 1) return Problem("link_lengths", "the result has no links; expected at least one");
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!(lengths[i] > 0.0) || !std::isfinite(lengths[i])) {
      return Problem::Invalid(Index("link_lengths", i), FormatNumber(lengths[i]),
                              "a positive finite number");
    }
  }
  return std::nullopt;
}

std::optional<Problem> LinkRadiiProblem(const Eigen::VectorXd& radii, Eigen::Index n,
                                        bool pointer) {
  if (radii.size() == 0) return std::nullopt;
  const std::string field = pointer ? "/link_radii" : "link_radii";
  if (radii.size() != n) {
    return Problem(field, "has " + std::to_string(radii.size()) + " entries; expected " +
                              std::to_string(n) + ", one per link");
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!(radii[i] >= 0.0) || !std::isfinite(radii[i])) {
      return Problem::Invalid(pointer ? field + "/" + std::to_string(i) : Index(field, i),
                              FormatNumber(radii[i]), "a finite number >= 0");
    }
  }
  return std::nullopt;
}

std::optional<Problem> ResultFrameProblem(size_t f, int64_t step, const PointsRef& p,
                                          const VectorRef& link_angles, int64_t previous_step,
                                          Eigen::Index n, int dim) {
  const std::string field = Index("frames", static_cast<Eigen::Index>(f));
  if (p.rows() != n + 1 || p.cols() != dim) {
    return Problem(field + ".points", "is " + std::to_string(p.rows()) + " by " +
                                          std::to_string(p.cols()) + "; expected " +
                                          std::to_string(n + 1) + " by " + std::to_string(dim) +
                                          " (one row per point, n+1 for n links)");
  }
  for (Eigen::Index i = 0; i <= n; ++i) {
    if (auto problem = NonFinite(p.row(i).transpose(), Index(field + ".points", i))) {
      return problem;
    }
  }
  if (link_angles.size() != 0 && link_angles.size() != n) {
    return Problem(field + ".link_angles", "has " + std::to_string(link_angles.size()) +
                                               " values; expected one per link (" +
                                               std::to_string(n) + ") or none");
  }
  if (auto problem = NonFinite(link_angles, field + ".link_angles")) return problem;
  if (step < 0 || step <= previous_step) {
    return Problem(
        field + ".step",
        std::to_string(step) + " is not valid; steps must be >= 0 and increase from frame to frame",
        std::to_string(step), ">= 0 and above the previous frame's");
  }
  return std::nullopt;
}

std::optional<Problem> ResultSummaryProblem(const RunResult& r) {
  const Metrics& m = r.metrics;
  const std::pair<const char*, const Eigen::VectorXd*> vectors[] = {
      {"metrics.l2_per_step", &m.l2_per_step},
      {"metrics.l2_weighted_per_step", &m.l2_weighted_per_step},
      {"metrics.path_length", &m.path_length}};
  for (const auto& [name, v] : vectors) {
    if (auto problem = NonFinite(*v, name)) return problem;
  }
  if (r.dynamics.enabled) {
    if (auto problem = NonFinite(r.dynamics.energy, "dynamics.energy")) return problem;
    if (r.dynamics.energy.size() != r.num_steps + 1) {
      return Problem("dynamics.energy", "has " + std::to_string(r.dynamics.energy.size()) +
                                            " values; expected " + std::to_string(r.num_steps + 1) +
                                            " (one per frame, 0 to num_steps)");
    }
    if (!(std::isfinite(r.dynamics.frame_rate) && r.dynamics.frame_rate > 0.0)) {
      return Problem::Invalid("dynamics.frame_rate", FormatNumber(r.dynamics.frame_rate),
                              "a finite number > 0");
    }
  }
  const std::pair<const char*, double> numbers[] = {
      {"metrics.l2_total", m.l2_total},
      {"metrics.l2_weighted_total", m.l2_weighted_total},
      {"metrics.max_relative_length_error", m.max_relative_length_error},
      {"accuracy.tolerance", r.accuracy.tolerance},
      {"accuracy.estimated_error", r.accuracy.estimated_error},
      {"overall.constraint_violation", r.overall.constraint_violation},
      {"overall.optimality", r.overall.optimality},
      {"seconds", r.seconds}};
  for (const auto& [name, x] : numbers) {
    if (!std::isfinite(x)) return Problem::Invalid(name, FormatNumber(x), "a finite number");
  }
  return std::nullopt;
}

namespace {

std::optional<Problem> FirstProblem(const RunResult& r, int dim) {
  if (auto problem = ResultHeaderProblem(r.lengths, dim)) return problem;
  if (r.frames.empty()) {
    return Problem("frames", "the result has no frames; expected at least the initial frame");
  }
  for (size_t f = 0; f < r.frames.size(); ++f) {
    const Frame& frame = r.frames[f];
    if (auto problem =
            ResultFrameProblem(f, frame.step, frame.points, frame.link_angles,
                               f > 0 ? r.frames[f - 1].step : -1, r.lengths.size(), dim)) {
      return problem;
    }
  }
  return ResultSummaryProblem(r);
}

}  // namespace

Problems ValidateResult(const RunResult& result, int dim) {
  if (std::optional<Problem> problem = FirstProblem(result, dim)) return {*problem};
  return {};
}

Problems ValidateResult(const ResultFile& file) {
  if (std::optional<Problem> problem = FirstProblem(file.result, file.dim)) return {*problem};
  Problems problems = CollidersProblems(file.colliders, file.dim);
  if (problems.size() > 1) problems.resize(1);  // the first, as for the rest of the result
  if (problems.empty()) {
    if (auto problem = LinkRadiiProblem(file.link_radii, file.result.lengths.size())) {
      problems.push_back(*problem);
    }
  }
  return problems;
}

}  // namespace flexkin
