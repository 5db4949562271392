#pragma once
// The run's pipeline for the per-link rules (src/run/sweep_pipeline.cc) and its accuracy control
// (src/run/accuracy.cc): internal to Run (flexkin/run.h), which checks every input once before.

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "chain/substep.h"
#include "flexkin/run.h"
#include "sequential/sweep.h"
#include "sequential/whole_chain.h"

namespace flexkin::internal {

// Arc-length weights of the trapezoid rule for eq. (6): half of each adjacent link.
Eigen::VectorXd ArcLengthWeights(const Eigen::VectorXd& lengths);

// Moves a chain through the leader steps of a run, every sub-step of every leader step a sweep,
// in chunks of sweeps through the traced engines (src/sequential/sweep.h) with one set of buffers:
//  - on the wavefront, where the CPU has one and the chain has 8 links or more: the sweeps of
//    successive sub-steps and leader steps in flight together, the metrics measured in the lanes;
//  - else the one-pass loop, sub-step by sub-step, with the metrics of each leader step summed as
//    the reference order does (bit for bit the results of the sub-step by sub-step run).
// Tractrix and follow-the-leader (the rules the engines have); and min_rotation and
// min_joint_angle where the CPU has the whole-chain engine's kernel (WholeChainOnSimd,
// sequential/whole_chain.h), which measures the metrics as the wavefront does.
// With static colliders (a per-link rule only), each link's rule step is kept outside them in the
// engines as ContactSweep keeps it: the one-pass loop's results are the sub-step by sub-step
// run's bit for bit; the wavefront's are the free run's bit for bit where no link comes near a
// collider, else the contact sweep's up to its exp's rounding as the contact steps amplify it
// (docs/colliders.md, "On the SIMD engine").
class SweepPipeline {
 public:
  // `start` is the chain's initial configuration; `metrics` (may be null) receives the metrics.
  SweepPipeline(const Stepper& stepper, const Points& start, const Points& leader_steps,
                int substeps, Metrics* metrics);
  // The same with static colliders (none: `colliders` empty), which must outlive the pipeline.
  SweepPipeline(const Stepper& stepper, const Points& start, const Points& leader_steps,
                int substeps, Metrics* metrics, const std::vector<Collider>& colliders);

  // What the colliders did so far.
  const ContactStats& contacts() const { return contact_.stats; }

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
          heads_[static_cast<size_t>(count) * dim_ + k] = SubstepHead(from, to[k], j, substeps_);
        }
        uint8_t flag = 0;
        sweep_step_[count] = step_;
        if (j == substeps_) {
          flag = SweepTrace::kStepEnd;
          if (record(step_ + 1)) flag |= SweepTrace::kCapture, ++captures;
          ++step_;
          substep_ = 0;
        }
        flags_[count++] = flag;
        if ((exact_ && j == substeps_) || captures == max_slots_) break;
      }
      if (!exact_ && !whole_chain_ && captures > static_cast<int>(slots_.size())) {
        AddSlots(captures);
      }
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
  void AddSlots(int count);
  void Sweep(int count);
  // The end of leader step s in the one-pass loop: the metrics of the step from the distances
  // each point moved, in the reference order.
  void EndStep(int64_t s);
  static void Capture(void* context, int64_t sweep, int slot);

 private:
  const Stepper& stepper_;
  const Points& leader_steps_;
  const int substeps_, n_, dim_;
  const bool whole_chain_;  // a whole-chain rule (its kernel captures from the chain itself)
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
  std::array<double*, SweepTrace::kMaxSlots> slot_ptrs_;
  SweepTrace trace_;
  SweepContact contact_;
  WholeChainWork whole_chain_work_;
  std::function<void(int64_t, const Points&)> on_frame_;
};

// Step doubling: runs the whole path with k and 2k sub-steps and takes the largest difference
// over all leader steps; for a method of order q the error of the finer run is about that
// difference / (2^q - 1) (Richardson). Doubles until the estimate meets the tolerance or the
// finer run would exceed max_substeps (the last round then uses max_substeps and max/2). Both
// runs go through the run's own pipeline, a block of leader steps at a time: the coarse run's
// configurations after each step of the block are kept and compared with the fine run's.
AccuracyReport ChooseSubsteps(const Chain& chain, const Points& leader_steps,
                              const RunOptions& options);

// Whether Run takes `method` through the sweep pipeline on this CPU.
bool Pipelined(Method method);

// Run without the pipeline: every method one sub-step at a time (MoveLeader or the overall
// step), the metrics measured after each sub-step. Run's own path for the methods the pipeline
// does not take, and the reference the pipeline is tested and benchmarked against.
RunResult RunSubstepBySubstep(const Chain& chain, const Points& leader_steps,
                              const RunOptions& options, FrameSink* sink);

}  // namespace flexkin::internal
