#pragma once
// Robot arms from and to URDF (Unified Robot Description Format) files, read with Debian's
// urdfdom (library flexkin_urdf, for the command line and the tests; docs/robots.md).
//
// A URDF is read as a serial chain from `base_link` to `tip_link`: every revolute or continuous
// joint on it becomes one joint of the arm, fixed joints are merged into the links, and the arm's
// points are the revolute joints' origins followed by the tip link's origin, all at the pose
// where every joint angle is 0. So link k's length is the distance from joint k-1's origin to
// joint k's (or the tip's), its direction at that pose is ArmModel::link_directions' row k-1,
// and joint j's axis is the URDF axis turned into the world frame of that pose
// (ArmModel::joint_axes, see include/flexkin/arm.h). An arm whose axes are all +z and whose
// links all lie along one direction of the z = 0 plane is returned as a planar arm (dim 2).

#include <string>

#include "flexkin/arm.h"
#include "flexkin/robot_scenario.h"  // UrdfChain, RobotScenarioOptions

namespace flexkin {

// Reads the chain from URDF text / a URDF file. Limits: a revolute joint's [lower, upper] (rad)
// is cut to [-pi, pi]; continuous joints get [-pi, pi] when any other joint has limits. The
// initial angles are 0 (or the limit nearest 0). Throws InputError naming the element
// ("joint \"elbow\"", "link \"tool\"", "urdf") for prismatic, floating or planar joints,
// branches, zero-length links, twist joints (axis along the link they turn), missing links
// and text that is not a URDF; a file that cannot be read throws std::system_error.
ArmModel ArmFromUrdf(const std::string& urdf_text, const UrdfChain& chain = {});
ArmModel ArmFromUrdfFile(const std::string& path, const UrdfChain& chain = {});

// A URDF of the arm (links "base_link", "link_1".."link_n", "tip_link"; joints "joint_0".. and
// the fixed "tip_joint"), with every joint revolute (limits given) or continuous; ArmFromUrdf
// of it gives the same arm back. Planar arms are written with z axes in the z = 0 plane.
// Throws InputError for spherical joints (URDF has none) or an invalid model.
std::string UrdfFromArm(const ArmModel& model, const std::string& robot_name = "flexkin_arm");

// Options of the robot scenario reader (flexkin/robot_scenario.h) that read "urdf" arms with
// ArmFromUrdfFile: LoadRobotScenarioFile(path, UrdfRobotScenarioOptions()). The core library has
// no URDF parser; this is how the front ends that link flexkin_urdf plug it in.
RobotScenarioOptions UrdfRobotScenarioOptions();

}  // namespace flexkin
