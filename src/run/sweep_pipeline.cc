// The run's sweep pipeline (src/run/sweep_pipeline.h).
#include "run/sweep_pipeline.h"

#include <algorithm>
#include <cmath>

#include "chain/denormals.h"
#include "sequential/rule_table.h"

namespace flexkin::internal {

// Arc-length weights of the trapezoid rule for eq. (6): half of each adjacent link.
Eigen::VectorXd ArcLengthWeights(const Eigen::VectorXd& lengths) {
  const Eigen::Index n = lengths.size();
  Eigen::VectorXd w = Eigen::VectorXd::Zero(n + 1);
  w.head(n) += 0.5 * lengths;
  w.tail(n) += 0.5 * lengths;
  return w;
}

SweepPipeline::SweepPipeline(const Stepper& stepper, const Points& start,
                             const Points& leader_steps, int substeps, Metrics* metrics)
    : stepper_(stepper),
      leader_steps_(leader_steps),
      substeps_(substeps),
      n_(static_cast<int>(stepper.lengths.size())),
      dim_(stepper.dim),
      whole_chain_(RuleRunsOn(stepper.method, kWholeChainEngine)),
      exact_(!whole_chain_ && (WavefrontLanes() == 1 || n_ < 8)),
      points_(start),
      metrics_(metrics),
      start_head_(start.row(0).transpose()) {
  // Chunks of about 2^22 link-steps (a few milliseconds: progress stays live), at most 4096
  // sweeps; capture slots for at most 64 MiB of configurations.
  // A multiple of 16 sweeps, so that the wavefront's groups fill.
  chunk_ = static_cast<int>(std::clamp<int64_t>((int64_t{1} << 22) / (n_ + 1), 64, 4096)) & ~15;
  const int64_t frame_bytes = int64_t{8} * (n_ + 1) * dim_;
  max_slots_ = static_cast<int>(
      std::clamp<int64_t>((int64_t{64} << 20) / frame_bytes, 1, SweepTrace::kMaxSlots));
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
  if (whole_chain_) {
    whole_chain_work_.Prepare(stepper.method, dim_, stepper.lengths.data(), weights_.data(), n_,
                              chunk_);
  }
}

SweepPipeline::SweepPipeline(const Stepper& stepper, const Points& start,
                             const Points& leader_steps, int substeps, Metrics* metrics,
                             const std::vector<Collider>& colliders)
    : SweepPipeline(stepper, start, leader_steps, substeps, metrics) {
  if (colliders.empty()) return;
  contact_.colliders = &colliders;
  trace_.contact = &contact_;
}

void SweepPipeline::AddSlots(int count) {
  while (static_cast<int>(slots_.size()) < count) {
    slots_.emplace_back(n_ + 1, dim_);
    slot_ptrs_[slots_.size() - 1] = slots_.back().data();
  }
}

void SweepPipeline::Sweep(int count) {
  const double* lengths = stepper_.lengths.data();
  const double* inv_lengths = stepper_.inv_lengths.data();
  if (exact_) {
    trace_.moved = metrics_ != nullptr ? moved_.data() : scratch_moved_.data();
    TracedSweepsScalar(stepper_.method, dim_, heads_.data(), count, lengths, inv_lengths, n_,
                       points_.data(), &trace_);
    if (metrics_ != nullptr && flags_[count - 1] & SweepTrace::kStepEnd) {
      EndStep(sweep_step_[count - 1]);
    }
    return;
  }
  trace_.moved = nullptr;
  trace_.sweep_l2 = metrics_ != nullptr ? sweep_l2_.data() : scratch_l2_.data();
  trace_.sweep_l2w = metrics_ != nullptr ? sweep_l2w_.data() : scratch_l2w_.data();
  trace_.path_length = metrics_ != nullptr ? metrics_->path_length.data() : scratch_path_.data();
  if (whole_chain_) {
    TracedWholeChainSweeps(heads_.data(), count, lengths, inv_lengths, points_.data(),
                           &whole_chain_work_, &trace_);
  } else {
    TracedSweepsWavefront(stepper_.method, dim_, heads_.data(), count, lengths, inv_lengths, n_,
                          points_.data(), &trace_);
  }
  if (metrics_ != nullptr) {
    for (int i = 0; i < count; ++i) {
      metrics_->l2_per_step[sweep_step_[i]] += sweep_l2_[i];
      metrics_->l2_weighted_per_step[sweep_step_[i]] += sweep_l2w_[i];
    }
    metrics_->max_relative_length_error = trace_.max_length_error;
  }
}

void SweepPipeline::EndStep(int64_t s) {
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

void SweepPipeline::Capture(void* context, int64_t sweep, int slot) {
  auto* self = static_cast<SweepPipeline*>(context);
  // The sink is the caller's code: it runs in the caller's floating-point mode.
  const CallerFloatingPointMode caller_mode;
  self->on_frame_(self->sweep_step_[sweep] + 1, slot < 0 ? self->points_ : self->slots_[slot]);
}

}  // namespace flexkin::internal
