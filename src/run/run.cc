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
#include "overall/step.h"
#include "sequential/rule_table.h"
#include "sequential/sweep.h"

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

double MaxPointDistance(const Points& a, const Points& b) {
  return (a - b).rowwise().norm().maxCoeff();
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
  ChainMover(const Chain& chain, const RunOptions& options, RunResult* result)
      : lengths_(chain.lengths), options_(options), result_(result) {
    if (options.method == Method::kOverall) {
      internal::CheckOverallOptionsForChain(options.overall, chain.dim());
      workspace_.emplace();
    } else {
      stepper_ = internal::MakeStepperUnchecked(options.method, chain);
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

// Moves a chain through the leader steps of a run, every sub-step of every leader step a sweep,
// in chunks of sweeps through the traced engines (src/sequential/sweep.h) with one set of buffers:
//  - on the wavefront, where the CPU has one and the chain has 8 links or more: the sweeps of
//    successive sub-steps and leader steps in flight together, the metrics measured in the lanes;
//  - else the one-pass loop, sub-step by sub-step, with the metrics of each leader step summed as
//    the reference order does (bit for bit the results of the sub-step by sub-step run).
// Tractrix and follow-the-leader (the rules the engines have).
class SweepPipeline {
 public:
  // `start` is the chain's initial configuration; `metrics` (may be null) receives the metrics.
  SweepPipeline(const Stepper& stepper, const Points& start, const Points& leader_steps,
                int substeps, Metrics* metrics)
      : stepper_(stepper),
        leader_steps_(leader_steps),
        substeps_(substeps),
        n_(static_cast<int>(stepper.lengths.size())),
        dim_(stepper.dim),
        exact_(internal::WavefrontLanes() == 1 || n_ < 8),
        points_(start),
        metrics_(metrics),
        start_head_(start.row(0).transpose()) {
    // Chunks of about 2^22 link-steps (a few milliseconds: progress stays live), at most 4096
    // sweeps; capture slots for at most 64 MiB of configurations.
    // A multiple of 16 sweeps, so that the wavefront's groups fill.
    chunk_ = static_cast<int>(std::clamp<int64_t>((int64_t{1} << 22) / (n_ + 1), 64, 4096)) & ~15;
    const int64_t frame_bytes = int64_t{8} * (n_ + 1) * dim_;
    max_slots_ = static_cast<int>(
        std::clamp<int64_t>((int64_t{64} << 20) / frame_bytes, 1, internal::SweepTrace::kMaxSlots));
    heads_.resize(static_cast<size_t>(chunk_) * dim_);
    flags_.resize(chunk_);
    sweep_step_.resize(chunk_);
    if (metrics_ != nullptr) {
      const int64_t m = leader_steps.rows();
      metrics_->l2_per_step = Eigen::VectorXd::Zero(m);
      metrics_->l2_weighted_per_step = Eigen::VectorXd::Zero(m);
      metrics_->path_length = Eigen::VectorXd::Zero(n_ + 1);
      if (exact_) {
        moved_ = Eigen::VectorXd::Zero(n_ + 1);
      } else {
        sweep_l2_.resize(chunk_);
        sweep_l2w_.resize(chunk_);
      }
    }
    if (metrics_ == nullptr) {
      // Without metrics the engines still measure, into scratch never read (which costs little).
      if (exact_) {
        scratch_moved_ = Eigen::VectorXd::Zero(n_ + 1);
      } else {
        scratch_l2_.resize(chunk_);
        scratch_l2w_.resize(chunk_);
        scratch_path_.assign(n_ + 1, 0.0);
      }
    }
    slot_ptrs_.fill(nullptr);
    weights_ = ArcLengthWeights(stepper.lengths);
    trace_.Prepare(stepper.lengths.data(), stepper.inv_lengths.data(), weights_.data(), n_);
    trace_.flags = flags_.data();
    trace_.context = this;
    trace_.capture = &SweepPipeline::Capture;
    trace_.slots = slot_ptrs_.data();
  }

  // Leader steps done.
  int64_t step() const { return step_; }

  // Advances to `end_step` leader steps done. After each leader step `done` for which
  // record(done) is true, on_frame(done, points) gets the configuration (valid during the call).
  template <class Record, class OnFrame>
  void Advance(int64_t end_step, const Record& record, const OnFrame& on_frame) {
    on_frame_ = [&on_frame](int64_t step, const Points& points) { on_frame(step, points); };
    while (step_ < end_step) {
      // The chunk: heads and flags of its sweeps. The one-pass loop's chunks end with a leader
      // step (whose metrics are then summed); no chunk captures more than the slots hold.
      int count = 0, captures = 0;
      while (count < chunk_ && step_ < end_step) {
        const int j = ++substep_;
        const auto to = leader_steps_.row(step_);
        for (int k = 0; k < dim_; ++k) {
          const double from = step_ == 0 ? start_head_[k] : leader_steps_(step_ - 1, k);
          heads_[static_cast<size_t>(count) * dim_ + k] =
              internal::SubstepHead(from, to[k], j, substeps_);
        }
        uint8_t flag = 0;
        sweep_step_[count] = step_;
        if (j == substeps_) {
          flag = internal::SweepTrace::kStepEnd;
          if (record(step_ + 1)) flag |= internal::SweepTrace::kCapture, ++captures;
          ++step_;
          substep_ = 0;
        }
        flags_[count++] = flag;
        if ((exact_ && j == substeps_) || captures == max_slots_) break;
      }
      if (!exact_ && captures > static_cast<int>(slots_.size())) AddSlots(captures);
      Sweep(count);
      if (after_chunk) after_chunk(step_);
    }
    on_frame_ = nullptr;
  }

  // The configuration now.
  const Points& points() const { return points_; }

  // Called with the leader steps done after each chunk (a few milliseconds of work); may be empty.
  std::function<void(int64_t)> after_chunk;

 private:
  void AddSlots(int count) {
    while (static_cast<int>(slots_.size()) < count) {
      slots_.emplace_back(n_ + 1, dim_);
      slot_ptrs_[slots_.size() - 1] = slots_.back().data();
    }
  }

  void Sweep(int count) {
    const double* lengths = stepper_.lengths.data();
    const double* inv_lengths = stepper_.inv_lengths.data();
    if (exact_) {
      trace_.moved = metrics_ != nullptr ? moved_.data() : scratch_moved_.data();
      internal::TracedSweepsScalar(stepper_.method, dim_, heads_.data(), count, lengths,
                                   inv_lengths, n_, points_.data(), &trace_);
      if (metrics_ != nullptr && flags_[count - 1] & internal::SweepTrace::kStepEnd) {
        EndStep(sweep_step_[count - 1]);
      }
      return;
    }
    trace_.moved = nullptr;
    trace_.sweep_l2 = metrics_ != nullptr ? sweep_l2_.data() : scratch_l2_.data();
    trace_.sweep_l2w = metrics_ != nullptr ? sweep_l2w_.data() : scratch_l2w_.data();
    trace_.path_length = metrics_ != nullptr ? metrics_->path_length.data() : scratch_path_.data();
    internal::TracedSweepsWavefront(stepper_.method, dim_, heads_.data(), count, lengths,
                                    inv_lengths, n_, points_.data(), &trace_);
    if (metrics_ != nullptr) {
      for (int i = 0; i < count; ++i) {
        metrics_->l2_per_step[sweep_step_[i]] += sweep_l2_[i];
        metrics_->l2_weighted_per_step[sweep_step_[i]] += sweep_l2w_[i];
      }
      metrics_->max_relative_length_error = trace_.max_length_error;
    }
  }

  // The end of leader step s in the one-pass loop: the metrics of the step from the distances
  // each point moved, in the reference order.
  void EndStep(int64_t s) {
    Metrics* m = metrics_;
    m->path_length += moved_;
    m->l2_per_step[s] = moved_.sum();
    m->l2_weighted_per_step[s] = moved_.dot(weights_);
    for (int i = 1; i <= n_; ++i) {
      const double length = (points_.row(i) - points_.row(i - 1)).norm();
      m->max_relative_length_error =
          std::fmax(m->max_relative_length_error,
                    std::fabs(length - stepper_.lengths[i - 1]) / stepper_.lengths[i - 1]);
    }
    moved_.setZero();
  }

  static void Capture(void* context, int64_t sweep, int slot) {
    auto* self = static_cast<SweepPipeline*>(context);
    self->on_frame_(self->sweep_step_[sweep] + 1, slot < 0 ? self->points_ : self->slots_[slot]);
  }

 private:
  const Stepper& stepper_;
  const Points& leader_steps_;
  const int substeps_, n_, dim_;
  const bool exact_;
  Points points_;
  Metrics* metrics_;
  const Eigen::VectorXd start_head_;  // the leading end's initial position
  int chunk_ = 0, max_slots_ = 1;
  int64_t step_ = 0;  // leader steps done
  int substep_ = 0;   // sub-steps of leader step step_ done
  std::vector<double> heads_;
  std::vector<uint8_t> flags_;
  std::vector<int64_t> sweep_step_;
  std::vector<double> sweep_l2_, sweep_l2w_;
  std::vector<double> scratch_l2_, scratch_l2w_, scratch_path_;
  Eigen::VectorXd weights_, moved_, scratch_moved_;
  std::vector<Points> slots_;
  std::array<double*, internal::SweepTrace::kMaxSlots> slot_ptrs_;
  internal::SweepTrace trace_;
  std::function<void(int64_t, const Points&)> on_frame_;
};

// Step doubling: runs the whole path with k and 2k sub-steps and takes the largest difference
// over all leader steps; for a method of order q the error of the finer run is about that
// difference / (2^q - 1) (Richardson). Doubles until the estimate meets the tolerance or the
// finer run would exceed max_substeps (the last round then uses max_substeps and max/2). Both
// runs go through the run's own pipeline, a block of leader steps at a time: the coarse run's
// configurations after each step of the block are kept and compared with the fine run's.
AccuracyReport ChooseSubsteps(const Chain& chain, const Points& leader_steps,
                              const RunOptions& options) {
  AccuracyReport report;
  report.enabled = true;
  report.tolerance = options.tolerance;
  report.max_substeps = options.max_substeps;
  report.order = MethodOrder(options.method);
  const Stepper stepper = internal::MakeStepperUnchecked(options.method, chain);
  const int64_t num_steps = leader_steps.rows();
  // Blocks of at most 32 MiB of configurations.
  const int64_t block =
      std::clamp<int64_t>((int64_t{32} << 20) / (int64_t{8} * chain.points.size()), 1, num_steps);
  std::vector<Points> kept(static_cast<size_t>(block), Points(chain.points.rows(), chain.dim()));
  const auto every_step = [](int64_t) { return true; };
  for (int fine = std::min(2 * options.substeps, options.max_substeps);;
       fine = std::min(2 * fine, options.max_substeps)) {
    const int coarse = std::max(1, fine / 2);
    SweepPipeline coarse_run(stepper, chain.points, leader_steps, coarse, nullptr);
    SweepPipeline fine_run(stepper, chain.points, leader_steps, fine, nullptr);
    // While the sub-steps are chosen no leader step of the run is done: progress (0, total),
    // about every 0.1 s, so that a caller can still show life or stop the run (by throwing).
    auto last = Clock::now();  // lives as long as the pipelines that report through it
    if (options.progress) {
      const auto report = [&options, &last, num_steps](int64_t) {
        if (Clock::now() - last > std::chrono::milliseconds(100)) {
          options.progress(0, num_steps);
          last = Clock::now();
        }
      };
      coarse_run.after_chunk = report;
      fine_run.after_chunk = report;
    }
    double diff = 0.0;
    for (int64_t first = 0; first < num_steps; first += block) {
      const int64_t end = std::min(num_steps, first + block);
      coarse_run.Advance(end, every_step, [&](int64_t done, const Points& points) {
        kept[static_cast<size_t>(done - 1 - first)] = points;
      });
      fine_run.Advance(end, every_step, [&](int64_t done, const Points& points) {
        diff =
            std::fmax(diff, MaxPointDistance(kept[static_cast<size_t>(done - 1 - first)], points));
      });
    }
    const double ratio = static_cast<double>(fine) / coarse;
    report.substeps = fine;
    report.estimated_error = diff / (std::pow(ratio, report.order) - 1.0);
    report.met = report.estimated_error <= options.tolerance;
    if (report.met || fine == options.max_substeps) return report;
  }
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

// Per-link rules go through the sweep pipeline (sweeps engine, wavefront).
bool Pipelined(Method method) { return internal::RuleRunsOn(method, internal::kSweepsEngine); }

}  // namespace

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
  if (options.tolerance > 0.0) result.accuracy = ChooseSubsteps(chain, leader_steps, options);
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

  if (Pipelined(options.method)) {
    const Stepper stepper = internal::MakeStepperUnchecked(options.method, chain);
    SweepPipeline pipeline(stepper, chain.points, leader_steps, substeps, &result.metrics);
    Eigen::VectorXd direction = first_direction;
    const auto on_frame = [&](int64_t done, const Points& points) {
      if (options.link_angles) {
        StepDirection(chain.points, leader_steps, done - 1, first_direction, &direction);
      }
      add_frame(done, points, direction);
    };
    if (options.progress) pipeline.after_chunk = report_progress;
    pipeline.Advance(num_steps, recorded, on_frame);
  } else {
    ChainMover mover(chain, options, &result);
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
