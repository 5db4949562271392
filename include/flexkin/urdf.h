#pragma once
// Robot arms from and to URDF (Unified Robot Description Format) files, read with Debian's
// urdfdom (library flexkin_urdf, for the command line and the tests; docs/robots.md).
//
// A URDF is read as a serial chain from `base_link` to `tip_link` (docs/robots.md, "Any serial
// robot"): every revolute, continuous or prismatic joint on it becomes one joint of the arm, in
// order from the base, its value angle[j] the URDF joint's (rad or length); fixed joints are
// merged into the links. The arm's points are the joints' origins followed by the end effector
// (the tip link's origin, or UrdfChain::tip_offset in its frame), all at the pose where every
// joint is 0, in the frame of the URDF's root link. Link k's length is the distance from joint
// k-1's origin to joint k's (or the end effector): 0 where joints share a point (a universal or
// spherical joint, a tip on its joint); its direction at that pose is ArmModel::link_directions'
// row k-1, joint j's axis the URDF axis turned into the world frame of that pose
// (ArmModel::joint_axes; it may lie along its link: a twist joint), joint_types says which slide,
// and tip_rotation is the tip link's frame. An arm whose joints are all revolute about +z with
// links of positive length along one direction of the z = 0 plane is returned as a planar arm
// (dim 2).
//
// Threads: ArmFromUrdf may be called from several threads at once; urdfdom's process-wide error
// handler, which it replaces during a parse to quote urdfdom's reason, is held under a lock.

#include <string>
#include <vector>

#include "flexkin/arm.h"
#include "flexkin/robot_scenario.h"  // UrdfChain, RobotScenarioOptions
#include "flexkin/robot_tree.h"

namespace flexkin {

// Reads the chain from URDF text / a URDF file. Limits as written: revolute joints' [lower,
// upper] (rad, multi-turn joints beyond [-pi, pi] kept), prismatic ones' (length); continuous
// joints are unlimited (-inf, inf); velocity limits (> 0) go to ArmModel::max_velocity. The
// initial values are 0 (or the limit nearest 0). Throws InputError naming the element
// ("joint \"elbow\"", "link \"tool\"", "tip_link", "urdf") for floating or planar joints,
// closed loops (a link the child of two joints), branches without tip_link, a chain without a
// movable joint or all at one point, missing links and text that is not a URDF (with urdfdom's
// reason); a file that cannot be read throws std::system_error.
ArmModel ArmFromUrdf(const std::string& urdf_text, const UrdfChain& chain = {});
ArmModel ArmFromUrdfFile(const std::string& path, const UrdfChain& chain = {});

// A robot tree (flexkin/robot_tree.h) from URDF text / a URDF file: every joint below
// `base_link` ("" : the URDF's root link), revolute or continuous (fixed joints merged into their
// links), each after its parent, at the zero pose in the frame of the URDF's root link; limits
// as ArmFromUrdf reads them; the tools in the order asked, each the point `offset` of its link's
// frame. Throws InputError naming the element ("base_link", "tools[1].link", "joint \"elbow\"")
// for prismatic, floating or planar joints below the base, a tool link not below the base or
// below no movable joint, an axis of zero length, and what ArmFromUrdf refuses of the text; a
// file that cannot be read throws std::system_error.
RobotTree RobotTreeFromUrdf(const std::string& urdf_text, const std::string& base_link,
                            const std::vector<UrdfTool>& tools);
RobotTree RobotTreeFromUrdfFile(const std::string& path, const std::string& base_link,
                                const std::vector<UrdfTool>& tools);

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
