// A groom run (include/flexkin/groom.h): the strands placed on the body at the first keyframe's
// pose, stepped frame by frame by the strand engine, the recorded frames streamed to a strand
// file.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "flexkin/groom.h"
#include "flexkin/result_io.h"
#include "flexkin/strand_file.h"
#include "flexkin/strands.h"
#include "flexkin/vocabulary.h"

namespace flexkin {
namespace {

// The strands in world coordinates at `pose`: p -> R p + t (in 2D the top-left block).
std::vector<Points> Placed(const std::vector<Points>& strands, int dim, const BodyPose& pose) {
  std::vector<Points> placed(strands.size());
  const Eigen::MatrixXd r = pose.rotation.topLeftCorner(dim, dim);
  const Eigen::RowVectorXd t = pose.translation.head(dim).transpose();
  for (size_t i = 0; i < strands.size(); ++i) {
    placed[i] = (strands[i] * r.transpose()).rowwise() + t;
  }
  return placed;
}

// Whether frame f of `frames` is recorded: 0, e, 2e, ... and the last.
bool Recorded(int64_t f, int64_t frames, int every) { return f % every == 0 || f == frames - 1; }

}  // namespace

StrandFileHeader MakeStrandFileHeader(const GroomScenario& scenario) {
  StrandFileHeader h;
  h.name = scenario.name;
  h.description = scenario.description;
  h.dim = scenario.dim;
  h.offsets.reserve(scenario.strands.size() + 1);
  h.offsets.push_back(0);
  for (const Points& s : scenario.strands) h.offsets.push_back(h.offsets.back() + s.rows());
  // The rest lengths as the batch measures them: of the strands placed at the first pose.
  const std::vector<Points> placed =
      Placed(scenario.strands, scenario.dim, scenario.motion.PoseAt(0));
  h.link_lengths.resize(h.num_points() - h.num_strands());
  Eigen::Index k = 0;
  for (const Points& s : placed) {
    for (Eigen::Index j = 1; j < s.rows(); ++j)
      h.link_lengths[k++] = (s.row(j) - s.row(j - 1)).norm();
  }
  h.num_frames = CountRecordedFrames(scenario.motion.num_frames() - 1, scenario.record_every);
  h.float32 = scenario.float32;
  h.fps = scenario.motion.fps;
  h.method = NameOf(scenario.options.method);
  h.substeps = scenario.options.substeps;
  h.pinned = scenario.options.pinned;
  h.record_every = scenario.record_every;
  h.scalp = scenario.scalp;
  h.body_colliders = scenario.options.body_colliders;
  h.world_colliders = scenario.options.colliders;
  h.dynamics = scenario.options.dynamics;
  for (const Eigen::VectorXd& m : scenario.options.masses) h.own_masses |= m.size() != 0;
  return h;
}

StrandRunReport RunGroom(const GroomScenario& scenario, StrandFileWriter* writer,
                         const std::function<bool(int64_t, int64_t)>& progress) {
  const BodyMotion& motion = scenario.motion;
  const int64_t frames = motion.num_frames();
  const BodyPose start = motion.PoseAt(0);
  StrandBatch batch(Placed(scenario.strands, scenario.dim, start), scenario.options, start,
                    motion.TimeOf(0));
  // The batch keeps the pinned points in body coordinates, q = R^T (p - t), which the pose maps
  // back to p only to rounding: one step to the same pose settles them (a move of a few ulps),
  // so that frame 0 is what a body that stays there keeps, bit for bit. (Not for dynamic strands,
  // for which a step is a frame of their motion: their frame 0 is the grown shape.)
  const bool dynamic = scenario.options.dynamics.has_value();
  if (!dynamic) StepStrands(&batch, start);
  const StrandFileHeader header = MakeStrandFileHeader(scenario);

  StrandRunReport report;
  report.engine = batch.engine();
  report.threads = scenario.options.threads > 0
                       ? scenario.options.threads
                       : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  // The largest relative link-length error of the recorded frames.
  Points strand;
  auto record = [&](int64_t f, const BodyPose& pose) {
    if (writer != nullptr) writer->Add(f, motion.TimeOf(f), pose, batch);
    if (dynamic) report.energy.push_back(batch.dynamics().energy);
    Eigen::Index k = 0;
    for (int i = 0; i < batch.size(); ++i) {
      batch.CopyStrand(i, &strand);
      for (Eigen::Index j = 1; j < strand.rows(); ++j, ++k) {
        const double rest = header.link_lengths[k];
        report.max_length_error =
            std::max(report.max_length_error,
                     std::abs((strand.row(j) - strand.row(j - 1)).norm() - rest) / rest);
      }
    }
  };
  record(0, start);
  using Clock = std::chrono::steady_clock;
  Clock::duration stepping{};
  for (int64_t f = 1; f < frames; ++f) {
    const BodyPose pose = motion.PoseAt(f);
    const Clock::time_point t0 = Clock::now();
    StepStrands(&batch, pose, motion.TimeOf(f));
    stepping += Clock::now() - t0;
    if (Recorded(f, frames, scenario.record_every)) record(f, pose);
    if (progress && !progress(f + 1, frames)) {
      throw InputError("interrupted", "the run was stopped at frame " + std::to_string(f + 1) +
                                          " of " + std::to_string(frames) +
                                          "; nothing was written");
    }
  }
  report.seconds = std::chrono::duration<double>(stepping).count();
  report.contact_link_steps = batch.contacts().contact_link_steps;
  report.least_clearance = batch.contacts().least_clearance;
  report.failures = batch.dynamics().failures;
  report.contact_substeps = batch.dynamics().contact_substeps;
  return report;
}

StrandRunReport RunGroomToFile(const GroomScenario& scenario, const std::string& path,
                               const std::function<bool(int64_t, int64_t)>& progress) {
  StrandFileWriter writer(path, MakeStrandFileHeader(scenario));
  const StrandRunReport report = RunGroom(scenario, &writer, progress);
  writer.Commit(report);
  return report;
}

}  // namespace flexkin
