#include "flexkin/scenario_kind.h"

#include <string>

#include "io/json_file.h"
#include "io/scenario_kinds.h"

namespace flexkin {
namespace internal {

using json = nlohmann::json;

ScenarioKind KindOf(const json& root) {
  if (!root.is_object()) return ScenarioKind::kChain;
  if (const auto format = root.find("format"); format != root.end()) {
    if (*format == "flexkin-robot") return ScenarioKind::kRobot;
    if (*format == "flexkin-tree") return ScenarioKind::kTree;
  } else if ((root.contains("arm") || root.contains("urdf")) && !root.contains("curve") &&
             !root.contains("leader")) {
    return ScenarioKind::kRobot;
  }
  if (root.contains("tree") || root.contains("robot")) return ScenarioKind::kTree;
  if (root.contains("groom") || root.contains("strands")) return ScenarioKind::kGroom;
  return ScenarioKind::kChain;
}

}  // namespace internal

ScenarioKind ScenarioKindOfText(const std::string& json_text) {
  try {
    return internal::KindOf(ParseJsonText(json_text));
  } catch (const InputError&) {
    return ScenarioKind::kChain;
  }
}

}  // namespace flexkin
