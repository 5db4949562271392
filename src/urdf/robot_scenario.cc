// The URDF component's loader for the robot scenario reader (flexkin/robot_scenario.h), which
// itself knows no URDF parser.
#include "flexkin/robot_scenario.h"

#include <string>

#include "flexkin/urdf.h"

namespace flexkin {

RobotScenarioOptions UrdfRobotScenarioOptions() {
  RobotScenarioOptions options;
  options.urdf_loader = [](const std::string& path, const UrdfChain& chain) {
    return ArmFromUrdfFile(path, chain);
  };
  options.urdf_tree_loader = [](const std::string& path, const std::string& base_link,
                                const std::vector<UrdfTool>& tools) {
    return RobotTreeFromUrdfFile(path, base_link, tools);
  };
  return options;
}

}  // namespace flexkin
