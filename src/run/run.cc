#include "flexkin/run.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>

#include "chain/substep.h"
#include "flexkin/error.h"
#include "overall/contact_step.h"
#include "overall/step.h"
#include "run/follow_path.h"
#include "run/sweep_pipeline.h"
#include "sequential/rule_table.h"
#include "sequential/sweep.h"
#include "world/contact.h"

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

// An upper bound of the path's length between running lengths `from` and `to` (to >= from),
// with a margin for the rounding of the sums.
inline double TravelUpper(double from, double to) {
  return (to - from) * (1.0 + 1e-12) + 1e-14 * to;
}

// With colliders: the chain starts outside every one, and the leading end's path (straight
// from the start through every target) never enters one.
void CheckOutsideColliders(const Chain& chain, const Points& leader_steps,
                           const std::vector<Collider>& colliders) {
  const int dim = chain.dim();
  const auto at = [dim](const auto& row) {
    return Eigen::Vector3d(row(0), row(1), dim == 3 ? row(2) : 0.0);
  };
  const double shortest = chain.lengths.minCoeff();
  const auto depth_text = [](double clearance) { return FormatNumber(-clearance); };
  // travelled[s]: the length of the leading end's path over its first s moves.
  std::vector<double> travelled(static_cast<size_t>(leader_steps.rows()) + 1, 0.0);
  for (Eigen::Index s = 0; s < leader_steps.rows(); ++s) {
    const Eigen::Vector3d from = at(s == 0 ? chain.points.row(0) : leader_steps.row(s - 1));
    travelled[s + 1] = travelled[s] + (at(leader_steps.row(s)) - from).norm();
  }
  for (size_t c = 0; c < colliders.size(); ++c) {
    std::string name =
        "colliders[" + std::to_string(c) + "] (" + ColliderShapeName(colliders[c].shape) + ")";
    if (colliders[c].margin > 0.0) {
      name += " grown by the link radius " + FormatNumber(colliders[c].margin);
    }
    // A moving collider where its motion has it at the start (time 0); its path is checked
    // sub-step by sub-step during the run (ChainMover::PlaceColliders).
    const Collider collider = ColliderAt(colliders[c], 0.0);
    if (colliders[c].motion) name += " at time 0 of its motion";
    for (Eigen::Index i = 0; i < chain.points.rows(); ++i) {
      const double clearance = QuerySurface(collider, at(chain.points.row(i))).distance;
      if (clearance < -internal::kContactSlack * shortest) {
        throw InputError("points[" + std::to_string(i) + "]",
                         "lies inside " + name + " by " + depth_text(clearance) +
                             "; the chain must start outside every collider");
      }
    }
    for (Eigen::Index i = 1; i < chain.points.rows(); ++i) {
      const double clearance = internal::SegmentClearance(collider, at(chain.points.row(i - 1)),
                                                          at(chain.points.row(i)));
      if (clearance < -internal::kContactSlack * chain.lengths[i - 1]) {
        throw InputError("points[" + std::to_string(i) + "]",
                         "link " + std::to_string(i) + " (points " + std::to_string(i - 1) +
                             " to " + std::to_string(i) + ") passes through " + name + ", " +
                             depth_text(clearance) +
                             " deep; the chain must start outside every collider");
      }
    }
    if (colliders[c].motion) continue;
    // A stretch of the path shorter than its start's distance from the collider (a lower bound
    // of it) cannot enter it: measured exactly only where it comes nearer (the same verdicts,
    // with one bound and a binary search over the path's running length for many short moves).
    const auto point = [&](Eigen::Index s) {  // the leading end before move s
      return s == 0 ? at(chain.points.row(0)) : at(leader_steps.row(s - 1));
    };
    for (Eigen::Index s = 0; s < leader_steps.rows();) {
      const Eigen::Vector3d from = point(s);
      const double bound = internal::DistanceLowerBound(colliders[c], from);
      // The moves s..e-1 travel travelled[e] - travelled[s] (within the rounding of the sums).
      const double* first = travelled.data() + s;
      const double* end = travelled.data() + travelled.size();
      const double* last = std::upper_bound(
          first + 1, end, bound, [&](double b, double t) { return !(TravelUpper(*first, t) < b); });
      if (last - first > 1) {  // moves s..e-2 are clear
        s += (last - first) - 1;
        continue;
      }
      const Eigen::Vector3d to = at(leader_steps.row(s));
      const double clearance = internal::SegmentClearance(colliders[c], from, to);
      if (clearance < -internal::kContactSlack * shortest) {
        throw InputError("leader_steps[" + std::to_string(s) + "]",
                         "the leading end's path to this target enters " + name + ", " +
                             depth_text(clearance) +
                             " deep; the path must stay outside every collider");
      }
      ++s;
    }
  }
}

// Angle in [0, pi] between each link (trailing -> leading end) and the unit vector `direction`,
// into `angles`, as atan2(|across|, along) (accurate near 0 and pi, unlike acos), the atan2s a
// batch at a time (internal::Atan2OfSqrt). `across2` is scratch; both are sized n once: nothing
// is allocated per frame.
void LinkAngles(const Points& points, const Eigen::VectorXd& direction, Eigen::VectorXd* angles,
                Eigen::VectorXd* across2) {
  const Eigen::Index n = points.rows() - 1, dim = points.cols();
  if (direction.size() == 0) {
    angles->resize(0);
    return;
  }
  angles->resize(n);
  across2->resize(n);
  for (Eigen::Index i = 1; i <= n; ++i) {
    double link[3], along = 0.0;
    for (Eigen::Index k = 0; k < dim; ++k) {
      link[k] = points(i - 1, k) - points(i, k);
      along += link[k] * direction[k];
    }
    double sum = 0.0;
    for (Eigen::Index k = 0; k < dim; ++k) {
      const double c = link[k] - along * direction[k];
      sum += c * c;
    }
    (*angles)[i - 1] = along;
    (*across2)[i - 1] = sum;
  }
  internal::Atan2OfSqrt(across2->data(), angles->data(), n, angles->data());
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

// Moves the chain by one sub-step with the run's method: the sequential link rule of a stepper, or
// the overall solve in a workspace reused by every sub-step (the chain, the head and the options
// are checked once, before the run).
class ChainMover {
 public:
  ChainMover(const Chain& chain, const Points& leader_steps, const RunOptions& options,
             int substeps, RunResult* result)
      : lengths_(chain.lengths),
        options_(options),
        result_(result),
        moving_(AnyMoves(options.colliders)),
        posed_(moving_ ? options.colliders : std::vector<Collider>()),
        substeps_(substeps),
        shortest_(chain.lengths.minCoeff()) {
    if (options.method == Method::kFollowPath) {
      follow_path_.emplace(chain, leader_steps, colliders());
    } else if (options.method == Method::kOverall) {
      internal::CheckOverallOptionsForChain(options.overall, chain.dim());
      workspace_.emplace();
    } else {
      stepper_ = internal::MakeStepperUnchecked(options.method, chain);
    }
  }
  void Step(const Eigen::VectorXd& head, int64_t step, int substep, Points* points) {
    if (moving_) PlaceColliders(head, step, substep);
    if (follow_path_) {
      follow_path_->Step(head, step, points);
    } else if (!stepper_ && !options_.colliders.empty()) {
      internal::OverallContactStep(lengths_, head, options_.overall, colliders(), points,
                                   &*workspace_, &contact_state_, &report_, &contacts_);
      Record(report_, step, substep, &result_->overall);
      result_->contacts.contact_link_steps = contacts_.contact_link_steps;
      result_->contacts.least_clearance = contacts_.least_clearance;
    } else if (!options_.colliders.empty()) {
      internal::ContactSweep(stepper_->method, stepper_->dim, head.data(), stepper_->lengths.data(),
                             stepper_->inv_lengths.data(), static_cast<int>(lengths_.size()),
                             points->data(), colliders(), &contacts_);
      result_->contacts.contact_link_steps = contacts_.contact_link_steps;
      result_->contacts.least_clearance = contacts_.least_clearance;
    } else if (!stepper_) {
      internal::OverallStepUnchecked(lengths_, head, options_.overall, points, &*workspace_,
                                     &report_);
      Record(report_, step, substep, &result_->overall);
    } else {
      MoveLeader(*stepper_, head, 1, points);
    }
  }
  // The keyframed colliders at the time of sub-step `substep` of leader step `step` (1-based):
  // step - 1 + substep / substeps (docs/colliders.md, "Moving colliders"); and the leading end,
  // which no rule moves aside, outside each of them (follow_path measures instead).
  void PlaceColliders(const Eigen::VectorXd& head, int64_t step, int substep) {
    const double time = double(step - 1) + double(substep) / double(substeps_);
    const Eigen::Vector3d lead(head[0], head[1], head.size() == 3 ? head[2] : 0.0);
    for (size_t c = 0; c < posed_.size(); ++c) {
      if (!options_.colliders[c].motion) continue;
      posed_[c] = ColliderAt(options_.colliders[c], time);
      if (follow_path_) continue;
      const double clearance = QuerySurface(posed_[c], lead).distance;
      if (clearance < -internal::kContactSlack * shortest_) {
        throw InputError("leader_steps[" + std::to_string(step - 1) + "]",
                         "colliders[" + std::to_string(c) + "] (" +
                             ColliderShapeName(posed_[c].shape) +
                             ", moving) reaches the leading end at sub-step " +
                             std::to_string(substep) + " of this leader step (time " +
                             FormatNumber(time) + "), " + FormatNumber(-clearance) +
                             " deep; the leading end must stay outside every collider "
                             "at every sub-step");
      }
    }
  }
  // The colliders as the current sub-step has them.
  const std::vector<Collider>& colliders() const { return moving_ ? posed_ : options_.colliders; }
  // After leader step `step` (1-based): the follow_path report.
  void EndStep(int64_t step, const Points& points) {
    if (follow_path_) follow_path_->EndStep(step, points, result_);
  }

 private:
  const Eigen::VectorXd& lengths_;
  const RunOptions& options_;
  RunResult* result_;
  const bool moving_;            // some collider has a motion
  std::vector<Collider> posed_;  // then every collider at the current sub-step's time
  const int substeps_;
  const double shortest_;  // link
  std::optional<Stepper> stepper_;
  std::optional<OverallWorkspace> workspace_;
  std::optional<internal::FollowPathMover> follow_path_;
  OverallReport report_;
  internal::ContactStats contacts_;
  internal::OverallContactState contact_state_;
};

// The metrics of a run (paper eq. 6 and Sec. 3.2), accumulated sub-step by sub-step.
class MetricsAccumulator {
 public:
  MetricsAccumulator(const Eigen::VectorXd& lengths, int64_t num_steps, Metrics* m)
      : lengths_(lengths), weights_(internal::ArcLengthWeights(lengths)), m_(m) {
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

// The direction of leader step `s` (0-based) if it moves, else of the last one before it that
// moves, into `direction`; `fallback` (the first direction) if none does.
void StepDirection(const Points& start, const Points& leader_steps, int64_t s,
                   const Eigen::VectorXd& fallback, Eigen::VectorXd* direction) {
  for (; s >= 0; --s) {
    *direction = leader_steps.row(s).transpose();
    *direction -= (s == 0 ? start.row(0) : leader_steps.row(s - 1)).transpose();
    if (direction->norm() > 0.0) {
      direction->normalize();
      return;
    }
  }
  *direction = fallback;
}

// The options with the colliders grown by the links' radius (RunOptions::link_radius).
RunOptions WithLinkRadius(const RunOptions& given) {
  RunOptions options = given;
  for (Collider& c : options.colliders) c.margin += given.link_radius;
  return options;
}

// Run, through the sweep pipeline where `pipeline` and the method has one.
RunResult RunOn(const Chain& chain, const Points& leader_steps, const RunOptions& given,
                FrameSink* sink, bool pipeline) {
  ValidateChain(chain);
  ValidateLeaderSteps(leader_steps, chain.dim());
  ThrowIfAny(given.Validate());
  const RunOptions grown = given.link_radius > 0.0 ? WithLinkRadius(given) : RunOptions();
  const RunOptions& options = given.link_radius > 0.0 ? grown : given;
  // follow_path keeps every point on the head's path: it measures the clearances (negative where
  // the path enters a collider) rather than requiring them.
  if (!options.colliders.empty() && options.method != Method::kFollowPath) {
    CheckOutsideColliders(chain, leader_steps, options.colliders);
  }
  const auto start_time = Clock::now();

  RunResult result;
  result.method = options.method;
  result.lengths = chain.lengths;
  result.num_steps = leader_steps.rows();
  result.contacts.num_colliders = static_cast<int>(options.colliders.size());
  result.accuracy.order = MethodOrder(options.method);
  result.accuracy.substeps = options.substeps;
  if (options.method == Method::kOverall) result.weights = options.overall.weights;
  if (options.method == Method::kFollowPath) {
    result.path.enabled = true;
    result.path.clearance.resize(leader_steps.rows());
    result.path.tip_error.resize(leader_steps.rows());
    result.path.deviation.resize(leader_steps.rows());
  }
  if (options.tolerance > 0.0)
    result.accuracy = internal::ChooseSubsteps(chain, leader_steps, options);
  const int substeps = result.accuracy.substeps;
  const int64_t num_steps = result.num_steps;

  const Eigen::VectorXd first_direction = FirstDirection(chain.points, leader_steps);
  Eigen::VectorXd angles, across2;  // reused by every frame
  const auto add_frame = [&](int64_t step, const Points& points, const Eigen::VectorXd& direction) {
    if (options.link_angles) LinkAngles(points, direction, &angles, &across2);
    sink->Add(step, points, angles);
    ++result.recorded_frames;
    if (step == num_steps) result.final_link_angles = angles;
  };
  add_frame(0, chain.points, first_direction);
  const auto recorded = [&](int64_t done) {
    return done % options.record_every == 0 || done == num_steps;
  };
  auto last_report = Clock::now();
  const auto report_progress = [&](int64_t done) {
    if (options.progress && Clock::now() - last_report > std::chrono::milliseconds(100)) {
      options.progress(done, num_steps);
      last_report = Clock::now();
    }
  };

  // Static colliders go through the pipeline with the per-link rules (the engines take their
  // contact steps); moving ones, and the whole-chain rules with colliders, sub-step by sub-step.
  const bool piped_colliders =
      !AnyMoves(options.colliders) && internal::RuleRunsOn(options.method, internal::kSweepsEngine);
  if (pipeline && internal::Pipelined(options.method) &&
      (options.colliders.empty() || piped_colliders)) {
    const Stepper stepper = internal::MakeStepperUnchecked(options.method, chain);
    internal::SweepPipeline pipeline(stepper, chain.points, leader_steps, substeps, &result.metrics,
                                     options.colliders);
    Eigen::VectorXd direction = first_direction;
    const auto on_frame = [&](int64_t done, const Points& points) {
      if (options.link_angles) {
        StepDirection(chain.points, leader_steps, done - 1, first_direction, &direction);
      }
      add_frame(done, points, direction);
    };
    if (options.progress) pipeline.after_chunk = report_progress;
    pipeline.Advance(num_steps, recorded, on_frame);
    if (!options.colliders.empty()) {
      result.contacts.contact_link_steps = pipeline.contacts().contact_link_steps;
      result.contacts.least_clearance = pipeline.contacts().least_clearance;
    }
  } else {
    ChainMover mover(chain, leader_steps, options, substeps, &result);
    MetricsAccumulator metrics(chain.lengths, num_steps, &result.metrics);
    Eigen::VectorXd direction = first_direction;
    Points points = chain.points, before;
    // Buffers of the loop, sized once: a leader step allocates nothing but its recorded frame.
    Eigen::VectorXd head(chain.dim()), start(chain.dim()), target(chain.dim());
    for (int64_t s = 0; s < num_steps; ++s) {
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
      mover.EndStep(s + 1, points);
      if (recorded(s + 1)) add_frame(s + 1, points, direction);
      report_progress(s + 1);
    }
  }
  if (options.progress) options.progress(num_steps, num_steps);
  result.metrics.l2_total = result.metrics.l2_per_step.sum();
  result.metrics.l2_weighted_total = result.metrics.l2_weighted_per_step.sum();
  result.seconds = std::chrono::duration<double>(Clock::now() - start_time).count();
  return result;
}

}  // namespace

namespace internal {

// Per-link rules go through the sweep pipeline (sweeps engine, wavefront), and the whole-chain
// rules where their kernel runs.
bool Pipelined(Method method) {
  return RuleRunsOn(method, kSweepsEngine) ||
         (RuleRunsOn(method, kWholeChainEngine) && WholeChainOnSimd());
}

RunResult RunSubstepBySubstep(const Chain& chain, const Points& leader_steps,
                              const RunOptions& options, FrameSink* sink) {
  return RunOn(chain, leader_steps, options, sink, false);
}

}  // namespace internal

RunResult Run(const Chain& chain, const Points& leader_steps, const RunOptions& options,
              FrameSink* sink) {
  return RunOn(chain, leader_steps, options, sink, true);
}

RunResult Run(const Chain& chain, const Points& leader_steps, const RunOptions& options) {
  FrameRecorder recorder;
  // One allocation for the frames (Run checks the inputs and refuses bad ones).
  if (chain.points.size() > 0 && options.record_every >= 1) {
    recorder.frames.Reserve(CountRecordedFrames(leader_steps.rows(), options.record_every),
                            chain.points.rows(), chain.dim(), options.link_angles);
  }
  RunResult result = Run(chain, leader_steps, options, &recorder);
  result.frames = std::move(recorder.frames);
  return result;
}

}  // namespace flexkin
