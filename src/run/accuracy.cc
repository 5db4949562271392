// Run's accuracy control: step doubling through the run's own pipeline (src/run/sweep_pipeline.h).
#include <algorithm>
#include <chrono>
#include <cmath>

#include "run/sweep_pipeline.h"

namespace flexkin::internal {
namespace {

using Clock = std::chrono::steady_clock;

double MaxPointDistance(const Points& a, const Points& b) {
  return (a - b).rowwise().norm().maxCoeff();
}

}  // namespace

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
  const Stepper stepper = MakeStepperUnchecked(options.method, chain);
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

}  // namespace flexkin::internal
