#include "flexkin/any_scenario.h"

#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>

#include "groom/groom_reader.h"
#include "io/json_file.h"
#include "io/scenario_kinds.h"

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
  }
  return out;
}

}  // namespace

std::string AnyScenario::Summary() const {
  if (chain) return ScenarioSummary(*chain);
  if (groom) return GroomSummary(*groom);
  if (robot) return RobotScenarioSummary(*robot);
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

}  // namespace

std::string ScenarioRunReport::BriefReport() const {
  switch (kind) {
    case ScenarioKind::kChain:
      return chain.BriefReport();
    case ScenarioKind::kRobot:
      return robot.BriefReport();
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
      const Scenario& s = *scenario.chain;
      RunOptions options = s.options;
      if (progress) options.progress = progress;
      report.chain =
          RunToFiles(s.chain, s.leader_steps, options, s.name, {outputs.output, outputs.csv});
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
  }
  return report;
}

}  // namespace flexkin
