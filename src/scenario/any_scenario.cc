#include "flexkin/any_scenario.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "flexkin/dynamics.h"
#include "groom/groom_reader.h"
#include "io/json_file.h"
#include "io/scenario_kinds.h"
#include "run/sweep_pipeline.h"

namespace flexkin {
namespace {

using json = nlohmann::json;

AnyScenario Read(const std::string& text, const ScenarioReadOptions& options,
                 const std::string& directory) {
  AnyScenario out;
  json root;
  try {
    root = ParseJsonText(text);
  } catch (const InputError& e) {
    out.problems.push_back(e.problem());
    return out;
  }
  out.kind = internal::KindOf(root);
  switch (out.kind) {
    case ScenarioKind::kChain: {
      Scenario s = internal::ReadChainScenario(root, &out.problems, directory);
      if (out.problems.empty()) out.chain = std::move(s);
      break;
    }
    case ScenarioKind::kGroom: {
      GroomScenario s = internal::ReadGroomScenario(root, &out.problems, directory);
      if (out.problems.empty()) out.groom = std::move(s);
      break;
    }
    case ScenarioKind::kRobot: {
      RobotScenario s = internal::ReadRobotScenario(root, options.robot, directory, &out.problems);
      if (out.problems.empty()) out.robot = std::move(s);
      break;
    }
    case ScenarioKind::kTree: {
      TreeScenario s = internal::ReadTreeScenario(root, options.robot, directory, &out.problems);
      if (out.problems.empty()) out.tree = std::move(s);
      break;
    }
  }
  return out;
}

}  // namespace

std::string AnyScenario::Summary() const {
  if (chain) return ScenarioSummary(*chain);
  if (groom) return GroomSummary(*groom);
  if (robot) return RobotScenarioSummary(*robot);
  if (tree) return TreeSummary(*tree);
  return "";
}

void AnyScenario::ThrowIfInvalid() const { ThrowIfAny(problems); }

AnyScenario ReadScenarioText(const std::string& json_text, const ScenarioReadOptions& options) {
  return Read(json_text, options, options.robot.directory);
}

AnyScenario ReadScenarioFile(const std::string& path, const ScenarioReadOptions& options) {
  const std::string directory = options.robot.directory.empty()
                                    ? std::filesystem::path(path).parent_path().string()
                                    : options.robot.directory;
  return Read(ReadTextFile(path), options, directory);
}

namespace {

// Calls `progress` after each step of a robot's tracking.
class ArmProgress : public ArmStepSink {
 public:
  ArmProgress(const std::function<void(int64_t, int64_t)>& progress, int64_t total)
      : progress_(progress), total_(total) {}
  void Add(const ArmStepReport&) override { progress_(++done_, total_); }

 private:
  const std::function<void(int64_t, int64_t)>& progress_;
  int64_t total_, done_ = 0;
};

bool EndsWith(const std::string& s, const std::string& end) {
  return s.size() >= end.size() && s.compare(s.size() - end.size(), end.size(), end) == 0;
}

// The colliders of a dynamic chain: a scenario's, their keyframe times turned from frames (leader
// steps) into seconds, grown by the links' radius (RunOptions::link_radius, as Run grows them).
std::vector<Collider> DynamicColliders(const RunOptions& options, double frame_rate) {
  std::vector<Collider> colliders = options.colliders;
  for (Collider& c : colliders) {
    c.margin += options.link_radius;
    if (c.motion) {
      auto motion = std::make_shared<ColliderMotion>(*c.motion);
      for (BodyKeyframe& k : motion->keyframes) k.time /= frame_rate;
      c.motion = std::move(motion);
    }
  }
  return colliders;
}

// The metrics of a dynamic chain's frames, measured from frame to frame (its sub-steps are not
// seen): per frame the points' distances moved, plain and weighted by arc length, and each
// point's path.
Metrics FrameMetrics(const Chain& chain, const std::vector<Points>& frames,
                     double max_relative_length_error) {
  const Eigen::Index n = chain.num_links(), steps = static_cast<Eigen::Index>(frames.size()) - 1;
  const Eigen::VectorXd weight = internal::ArcLengthWeights(chain.lengths);
  Metrics m;
  m.l2_per_step = Eigen::VectorXd::Zero(steps);
  m.l2_weighted_per_step = Eigen::VectorXd::Zero(steps);
  m.path_length = Eigen::VectorXd::Zero(n + 1);
  for (Eigen::Index f = 1; f <= steps; ++f) {
    const Points& a = frames[static_cast<size_t>(f - 1)];
    const Points& b = frames[static_cast<size_t>(f)];
    for (Eigen::Index j = 0; j <= n; ++j) {
      const double d = (b.row(j) - a.row(j)).norm();
      m.l2_per_step[f - 1] += d;
      m.l2_weighted_per_step[f - 1] += weight[j] * d;
      m.path_length[j] += d;
    }
  }
  m.l2_total = m.l2_per_step.sum();
  m.l2_weighted_total = m.l2_weighted_per_step.sum();
  m.max_relative_length_error = max_relative_length_error;
  return m;
}

// A dynamic chain (Scenario::dynamics) into its files: SimulateChain, then the frames.
RunResult RunDynamicChain(const Scenario& s, const RunOptions& options, const RunFiles& files,
                          FrameSink* also) {
  Scenario checked;  // DynamicScenarioProblems of these options (the command line's, Python's)
  checked.dynamics = s.dynamics;
  checked.options.method = options.method;
  checked.options.substeps = options.substeps;
  checked.options.tolerance = options.tolerance;
  checked.options.colliders = options.colliders;
  ThrowIfAny(DynamicScenarioProblems(checked));
  if (const Problems problems = options.Validate(); !problems.empty()) {
    throw InputError(InScenarioFile(problems.front()));
  }
  DynamicOptions dynamics = *s.dynamics;
  dynamics.colliders = DynamicColliders(options, dynamics.frame_rate);
  const Eigen::Index frames = s.leader_steps.rows();
  // The files are opened first: a path that cannot be written fails before the run.
  std::optional<ResultFileWriter> writer;
  std::vector<FrameSink*> sinks;
  if (!files.result.empty()) {
    sinks.push_back(&writer.emplace(files.result, ResultFileFormatOfPath(files.result),
                                    MakeResultHeader(s.chain, options, s.name)));
  }
  std::optional<FramesCsvWriter> csv;
  if (!files.csv.empty()) sinks.push_back(&csv.emplace(files.csv, s.chain.dim()));
  if (also != nullptr) sinks.push_back(also);
  FrameFanOut sink(sinks);
  if (options.progress) options.progress(0, frames);

  const auto start = std::chrono::steady_clock::now();
  DynamicResult run;
  try {
    run = SimulateChain(s.chain, s.leader_steps, dynamics);
  } catch (const InputError& e) {  // the driven end in a collider: named in the scenario's terms
    Problem p = e.problem();
    if (p.field.rfind("root_path[", 0) == 0) {
      const int64_t frame = std::stoll(p.field.substr(10)) + 1;
      p.message = "frame " + std::to_string(frame) + ": " + p.message;
      p.field = "/leader";
    }
    throw InputError(p);
  }
  RunResult result;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.method = options.method;
  result.lengths = s.chain.lengths;
  result.num_steps = frames;
  result.accuracy.substeps = dynamics.substeps;
  result.accuracy.order = 0;  // no accuracy control
  result.metrics = FrameMetrics(s.chain, run.frames, run.max_relative_length_error);
  result.contacts.num_colliders = static_cast<int>(dynamics.colliders.size());
  DynamicRunReport& report = result.dynamics;
  report.enabled = true;
  report.projection = ProjectionName(dynamics.projection);
  report.frame_rate = dynamics.frame_rate;
  report.substeps = dynamics.substeps;
  report.energy = run.energy;
  report.failures = run.failures;
  report.contact_substeps = run.contact_substeps;
  report.contact_solves = run.contact_solves;
  report.contact_solve_failures = run.contact_solve_failures;

  const Eigen::VectorXd no_angles;
  for (Eigen::Index f = 0; f <= frames; ++f) {
    if (f % options.record_every != 0 && f != frames) continue;
    sink.Add(f, run.frames[static_cast<size_t>(f)], no_angles);
    ++result.recorded_frames;
    if (options.progress && f > 0 && f % 256 == 0) options.progress(f, frames);
  }
  if (writer) writer->Commit(result);
  if (csv) csv->Commit();
  if (options.progress) options.progress(frames, frames);
  return result;
}

RunResult RunChain(const Scenario& s, const RunOptions& options, const RunFiles& files,
                   FrameSink* also) {
  if (s.dynamics) return RunDynamicChain(s, options, files, also);
  return RunToFiles(s.chain, s.leader_steps, options, s.name, files, also);
}

}  // namespace

RunResult RunChainScenario(const Scenario& scenario, const RunFiles& files, FrameSink* also) {
  return RunChain(scenario, scenario.options, files, also);
}

std::string ScenarioRunReport::BriefReport() const {
  switch (kind) {
    case ScenarioKind::kChain:
      return chain.BriefReport();
    case ScenarioKind::kRobot:
      return robot.BriefReport();
    case ScenarioKind::kTree:
      return tree.BriefReport();
    case ScenarioKind::kGroom:
      break;
  }
  char line[256];
  std::snprintf(line, sizeof line,
                "groom: %s x %d thread%s, %.3f s, largest link-length error %.2g",
                strands.engine.c_str(), strands.threads, strands.threads == 1 ? "" : "s",
                strands.seconds, strands.max_length_error);
  return line;
}

ScenarioRunReport RunScenarioToFiles(const AnyScenario& scenario, const ScenarioOutputs& outputs,
                                     const std::function<void(int64_t, int64_t)>& progress) {
  scenario.ThrowIfInvalid();
  ScenarioRunReport report;
  report.kind = scenario.kind;
  switch (scenario.kind) {
    case ScenarioKind::kChain: {
      RunOptions options = scenario.chain->options;
      if (progress) options.progress = progress;
      report.chain = RunChain(*scenario.chain, options, {outputs.output, outputs.csv}, nullptr);
      break;
    }
    case ScenarioKind::kGroom: {
      if (!outputs.csv.empty()) {
        throw InputError(Problem::Invalid("csv", "\"" + outputs.csv + "\"",
                                          "none: a groom run writes a strand file only"));
      }
      if (!EndsWith(outputs.output, ".npz")) {
        throw InputError(Problem::Invalid("output", "\"" + outputs.output + "\"",
                                          "a path ending in .npz: a groom run writes a strand file "
                                          "(NumPy archive, docs/strands.md)"));
      }
      report.strands =
          RunGroomToFile(*scenario.groom, outputs.output, [&progress](int64_t done, int64_t total) {
            if (progress) progress(done, total);
            return true;
          });
      break;
    }
    case ScenarioKind::kRobot: {
      const RobotScenario& s = *scenario.robot;
      std::optional<ArmProgress> tick;
      if (progress) tick.emplace(progress, s.path.rows());
      report.robot = TrackToFiles(s, outputs.output, outputs.csv, tick ? &*tick : nullptr);
      break;
    }
    case ScenarioKind::kTree: {
      if (!outputs.csv.empty()) {
        throw InputError(Problem::Invalid("csv", "\"" + outputs.csv + "\"",
                                          "none: a tree run writes a tree result only"));
      }
      CheckTreeResultPath(outputs.output);
      report.tree = RunTree(*scenario.tree, progress);
      WriteTreeResult(outputs.output, *scenario.tree, report.tree);
      break;
    }
  }
  return report;
}

}  // namespace flexkin
