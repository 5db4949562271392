#include "flexkin/run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>

#include "chain/substep.h"
#include "flexkin/error.h"
#include "overall/step.h"

namespace flexkin {
namespace {

using Clock = std::chrono::steady_clock;

void ValidateLeaderSteps(const Points& steps, int dim) {
  if (steps.rows() < 1) throw InputError("leader_steps", "is empty; give at least one target");
  if (steps.cols() != dim) {
    throw InputError("leader_steps", "targets have " + std::to_string(steps.cols()) +
                                         " coordinates; the chain is " + std::to_string(dim) + "D");
  }
  for (Eigen::Index i = 0; i < steps.rows(); ++i) {
    for (Eigen::Index k = 0; k < steps.cols(); ++k) {
      if (!std::isfinite(steps(i, k))) {
        throw InputError("leader_steps[" + std::to_string(i) + "][" + std::to_string(k) + "]",
                         "is not a finite number");
      }
    }
  }
}

// Arc-length weights of the trapezoid rule for eq. (6): half of each adjacent link.
Eigen::VectorXd ArcLengthWeights(const Eigen::VectorXd& lengths) {
  const Eigen::Index n = lengths.size();
  Eigen::VectorXd w = Eigen::VectorXd::Zero(n + 1);
  w.head(n) += 0.5 * lengths;
  w.tail(n) += 0.5 * lengths;
  return w;
}

// Angle in [0, pi] between each link (trailing -> leading end) and the unit vector `direction`.
Eigen::VectorXd LinkAngles(const Points& points, const Eigen::VectorXd& direction) {
  if (direction.size() == 0) return {};
  const Eigen::Index n = points.rows() - 1;
  Eigen::VectorXd angles(n);
  for (Eigen::Index i = 1; i <= n; ++i) {
    const Eigen::VectorXd link = (points.row(i - 1) - points.row(i)).transpose();
    const double along = link.dot(direction);
    const double across = (link - along * direction).norm();
    angles[i - 1] = std::atan2(across, along);  // accurate near 0 and pi, unlike acos
  }
  return angles;
}

double MaxPointDistance(const Points& a, const Points& b) {
  return (a - b).rowwise().norm().maxCoeff();
}

// Step doubling: runs the whole path with k and 2k sub-steps side by side and takes the largest
// difference over all leader steps; for a method of order q the error of the finer run is about
// that difference / (2^q - 1) (Richardson). Doubles until the estimate meets the tolerance or the
// finer run would exceed max_substeps (the last round then uses max_substeps and max/2).
AccuracyReport ChooseSubsteps(const Chain& chain, const Points& leader_steps,
                              const RunOptions& options) {
  AccuracyReport report;
  report.enabled = true;
  report.tolerance = options.tolerance;
  report.max_substeps = options.max_substeps;
  report.order = MethodOrder(options.method);
  const Stepper stepper = MakeStepper(options.method, chain);
  for (int fine = std::min(2 * options.substeps, options.max_substeps);;
       fine = std::min(2 * fine, options.max_substeps)) {
    const int coarse = std::max(1, fine / 2);
    Points coarse_points = chain.points, fine_points = chain.points;
    double diff = 0.0;
    for (Eigen::Index s = 0; s < leader_steps.rows(); ++s) {
      const Eigen::VectorXd target = leader_steps.row(s).transpose();
      MoveLeader(stepper, target, coarse, &coarse_points);
      MoveLeader(stepper, target, fine, &fine_points);
      diff = std::fmax(diff, MaxPointDistance(coarse_points, fine_points));
    }
    const double ratio = static_cast<double>(fine) / coarse;
    report.substeps = fine;
    report.estimated_error = diff / (std::pow(ratio, report.order) - 1.0);
    report.met = report.estimated_error <= options.tolerance;
    if (report.met || fine == options.max_substeps) return report;
  }
}

// Adds one overall solve to the run's summary.
void Record(const OverallReport& report, int64_t step, int substep, OverallRunReport* summary) {
  ++summary->solves;
  summary->iterations += report.iterations;
  summary->max_iterations = std::max(summary->max_iterations, report.iterations);
  summary->constraint_violation =
      std::fmax(summary->constraint_violation, report.constraint_violation);
  summary->optimality = std::fmax(summary->optimality, report.optimality);
  if (!report.converged()) {
    if (summary->failures == 0) {
      summary->first_failure = "leader step " + std::to_string(step) + ", sub-step " +
                               std::to_string(substep) + ": " + report.BriefReport();
    }
    ++summary->failures;
  }
}

std::string Format(const char* fmt, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, x);
  return buf;
}

}  // namespace

Problems RunOptions::Validate() const {
  Problems problems;
  if (substeps < 1) {
    problems.emplace_back("substeps", std::to_string(substeps) + " is not valid; must be >= 1",
                          std::to_string(substeps), ">= 1");
  }
  if (record_every < 1) {
    problems.emplace_back("record_every",
                          std::to_string(record_every) + " is not valid; must be >= 1",
                          std::to_string(record_every), ">= 1");
  }
  if (!(tolerance >= 0.0) || !std::isfinite(tolerance)) {
    problems.emplace_back("tolerance",
                          FormatNumber(tolerance) +
                              " is not valid; must be a finite number >= 0 (0 turns accuracy "
                              "control off)",
                          FormatNumber(tolerance), "a finite number >= 0");
  } else if (tolerance > 0.0 && MethodOrder(method) == 0) {
    problems.emplace_back("tolerance",
                          std::string("accuracy control is available for the tractrix and ftl "
                                      "methods; with \"") +
                              MethodName(method) + "\" set it to 0 and choose the sub-steps",
                          FormatNumber(tolerance), "0 with this method");
  }
  if (tolerance > 0.0 && max_substeps < 2) {
    problems.emplace_back("max_substeps",
                          std::to_string(max_substeps) +
                              " is not valid; accuracy control compares two runs and needs "
                              "max_substeps >= 2",
                          std::to_string(max_substeps), ">= 2");
  } else if (max_substeps < substeps && substeps >= 1) {
    problems.emplace_back("max_substeps",
                          std::to_string(max_substeps) + " is not valid; must be >= substeps (" +
                              std::to_string(substeps) + ")",
                          std::to_string(max_substeps), ">= substeps");
  }
  if (method == Method::kOverall) AppendNested("overall", overall.Validate(), &problems);
  return problems;
}

namespace {

// Moves the chain by one sub-step with the run's method: the sequential link rule of a stepper, or
// the overall solve in a workspace reused by every sub-step (the chain, the head and the options
// are checked once, before the run).
class ChainMover {
 public:
  ChainMover(const Chain& chain, const RunOptions& options, RunResult* result)
      : lengths_(chain.lengths), options_(options), result_(result) {
    if (options.method == Method::kOverall) {
      internal::CheckOverallOptionsForChain(options.overall, chain.dim());
      workspace_.emplace();
    } else {
      stepper_ = MakeStepper(options.method, chain);
    }
  }
  void Step(const Eigen::VectorXd& head, int64_t step, int substep, Points* points) {
    if (!stepper_) {
      internal::OverallStepUnchecked(lengths_, head, options_.overall, points, &*workspace_,
                                     &report_);
      Record(report_, step, substep, &result_->overall);
    } else {
      MoveLeader(*stepper_, head, 1, points);
    }
  }

 private:
  const Eigen::VectorXd& lengths_;
  const RunOptions& options_;
  RunResult* result_;
  std::optional<Stepper> stepper_;
  std::optional<OverallWorkspace> workspace_;
  OverallReport report_;
};

// The metrics of a run (paper eq. 6 and Sec. 3.2), accumulated sub-step by sub-step.
class MetricsAccumulator {
 public:
  MetricsAccumulator(const Eigen::VectorXd& lengths, int64_t num_steps, Metrics* m)
      : lengths_(lengths), weights_(ArcLengthWeights(lengths)), m_(m) {
    m->l2_per_step.resize(num_steps);
    m->l2_weighted_per_step.resize(num_steps);
    m->path_length = Eigen::VectorXd::Zero(lengths.size() + 1);
    moved_.resize(lengths.size() + 1);
  }
  void BeginStep() { moved_.setZero(); }
  void AddSubstep(const Points& before, const Points& after) {
    moved_ += (after - before).rowwise().norm();
  }
  void EndStep(int64_t s, const Points& points) {
    m_->path_length += moved_;
    m_->l2_per_step[s] = moved_.sum();
    m_->l2_weighted_per_step[s] = moved_.dot(weights_);
    for (Eigen::Index i = 1; i <= lengths_.size(); ++i) {
      const double length = (points.row(i) - points.row(i - 1)).norm();
      m_->max_relative_length_error = std::fmax(
          m_->max_relative_length_error, std::fabs(length - lengths_[i - 1]) / lengths_[i - 1]);
    }
  }
  void Finish() {
    m_->l2_total = m_->l2_per_step.sum();
    m_->l2_weighted_total = m_->l2_weighted_per_step.sum();
  }

 private:
  const Eigen::VectorXd& lengths_;
  const Eigen::VectorXd weights_;
  Metrics* m_;
  Eigen::VectorXd moved_;
};

// The direction of the first leader step that moves: that of frame 0's link angles.
Eigen::VectorXd FirstDirection(const Points& start, const Points& leader_steps) {
  Eigen::VectorXd from = start.row(0).transpose();
  for (Eigen::Index s = 0; s < leader_steps.rows(); ++s) {
    const Eigen::VectorXd d = leader_steps.row(s).transpose() - from;
    if (d.norm() > 0.0) return d.normalized();
    from = leader_steps.row(s).transpose();
  }
  return {};
}

}  // namespace

void FrameRecorder::Add(int64_t step, const Points& points, const Eigen::VectorXd& link_angles) {
  frames.push_back({step, points, link_angles});
}

RunResult Run(const Chain& chain, const Points& leader_steps, const RunOptions& options,
              FrameSink* sink) {
  ValidateChain(chain);
  ValidateLeaderSteps(leader_steps, chain.dim());
  ThrowIfAny(options.Validate());
  const auto start_time = Clock::now();

  RunResult result;
  result.method = options.method;
  result.lengths = chain.lengths;
  result.num_steps = leader_steps.rows();
  result.accuracy.order = MethodOrder(options.method);
  result.accuracy.substeps = options.substeps;
  if (options.method == Method::kOverall) result.weights = options.overall.weights;
  ChainMover mover(chain, options, &result);
  if (options.tolerance > 0.0) result.accuracy = ChooseSubsteps(chain, leader_steps, options);
  const int substeps = result.accuracy.substeps;
  MetricsAccumulator metrics(chain.lengths, result.num_steps, &result.metrics);

  Eigen::VectorXd direction = FirstDirection(chain.points, leader_steps);
  Points points = chain.points, before;
  sink->Add(0, points, LinkAngles(points, direction));
  auto last_report = Clock::now();
  // Buffers of the loop, sized once: a leader step allocates nothing but its recorded frame.
  Eigen::VectorXd head(chain.dim()), start(chain.dim()), target(chain.dim());
  for (int64_t s = 0; s < result.num_steps; ++s) {
    start = points.row(0).transpose();
    target = leader_steps.row(s).transpose();
    if ((target - start).norm() > 0.0) direction = (target - start).normalized();
    // One sub-step at a time (the heads MoveLeader would use), so that the metrics see the
    // motion at the resolution it is computed.
    metrics.BeginStep();
    for (int j = 1; j <= substeps; ++j) {
      for (int k = 0; k < chain.dim(); ++k) {
        head[k] = internal::SubstepHead(start[k], target[k], j, substeps);
      }
      before = points;
      mover.Step(head, s + 1, j, &points);
      metrics.AddSubstep(before, points);
    }
    metrics.EndStep(s, points);
    const int64_t done = s + 1;
    if (done % options.record_every == 0 || done == result.num_steps) {
      sink->Add(done, points, LinkAngles(points, direction));
    }
    if (options.progress && Clock::now() - last_report > std::chrono::milliseconds(100)) {
      options.progress(done, result.num_steps);
      last_report = Clock::now();
    }
  }
  if (options.progress) options.progress(result.num_steps, result.num_steps);
  metrics.Finish();
  result.seconds = std::chrono::duration<double>(Clock::now() - start_time).count();
  return result;
}

RunResult Run(const Chain& chain, const Points& leader_steps, const RunOptions& options) {
  FrameRecorder recorder;
  RunResult result = Run(chain, leader_steps, options, &recorder);
  result.frames = std::move(recorder.frames);
  return result;
}

std::string RunResult::BriefReport() const {
  std::ostringstream out;
  out << MethodName(method) << ": " << lengths.size() << " links, " << num_steps
      << " leader steps x " << accuracy.substeps << " sub-steps, max relative length error "
      << Format("%.3g", metrics.max_relative_length_error) << ", L2 total "
      << Format("%.10g", metrics.l2_total) << " (arc-length weighted "
      << Format("%.10g", metrics.l2_weighted_total) << ")";
  if (method == Method::kOverall) {
    out << ", overall solver: " << overall.solves - overall.failures << "/" << overall.solves
        << " steps converged, " << overall.iterations << " iterations (at most "
        << overall.max_iterations << " per step)";
    if (overall.failures > 0) out << ", FIRST FAILURE " << overall.first_failure;
  }
  if (accuracy.enabled) {
    out << ", estimated error " << Format("%.3g", accuracy.estimated_error)
        << (accuracy.met ? " (tolerance met)" : " (TOLERANCE NOT MET)");
  }
  out << ", " << Format("%.3g", seconds) << " s";
  return out.str();
}

std::string RunResult::FullReport() const {
  std::ostringstream out;
  out << BriefReport() << "\n";
  out << "  recorded frames: " << frames.size() << "\n";
  out << "  path length per point (leading end first):";
  const Eigen::Index n = metrics.path_length.size();
  // Long chains: print about 20 evenly spaced points so the profile fits on a screen.
  const Eigen::Index stride = std::max<Eigen::Index>(1, n / 20);
  for (Eigen::Index j = 0; j < n; j += stride) {
    out << (j % (8 * stride) == 0 ? "\n    " : " ") << "[" << j << "] "
        << Format("%.6g", metrics.path_length[j]);
  }
  if ((n - 1) % stride != 0)
    out << " [" << n - 1 << "] " << Format("%.6g", metrics.path_length[n - 1]);
  out << "\n";
  if (!frames.empty() && frames.back().link_angles.size() > 0) {
    const Eigen::VectorXd& a = frames.back().link_angles;
    out << "  final link angles to the pull, degrees: first " << Format("%.4g", a[0] * 180 / M_PI)
        << ", largest " << Format("%.4g", a.maxCoeff() * 180 / M_PI) << ", last "
        << Format("%.4g", a[a.size() - 1] * 180 / M_PI) << "\n";
  }
  return out.str();
}

}  // namespace flexkin
