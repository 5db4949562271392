#include "flexkin/any_scenario.h"

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
      Scenario s = internal::ReadChainScenario(root, &out.problems);
      if (out.problems.empty()) out.chain = std::move(s);
      break;
    }
    case ScenarioKind::kGroom: {
      GroomScenario s = internal::ReadGroomScenario(root, &out.problems);
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

}  // namespace flexkin
