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
  return options;
}

}  // namespace flexkin
