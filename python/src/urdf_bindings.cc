// URDF arms from Python: flexkin.arm_from_urdf and urdf_from_arm (flexkin/urdf.h), built where
// the URDF component (flexkin_urdf, Debian's urdfdom) is.
#include <string>
#include <system_error>

#include "convert.h"
#include "flexkin/urdf.h"

namespace flexkin::python {
namespace {

// A URDF source is text when it is a str whose first non-blank character is '<'; any other str,
// and any os.PathLike, names a file.
bool IsUrdfText(py::handle source) {
  if (!py::isinstance<py::str>(source)) return false;
  const std::string text = py::cast<std::string>(source);
  const size_t first = text.find_first_not_of(" \t\r\n");
  return first != std::string::npos && text[first] == '<';
}

ArmModel ArmFromUrdfArg(UrdfSource source, const std::string& base_link,
                        const std::string& tip_link, OptionalArray tip_offset) {
  UrdfChain chain;
  chain.base_link = base_link;
  chain.tip_link = tip_link;
  if (!tip_offset.is_none()) chain.tip_offset = ReadVector(tip_offset, "tip_offset", 3);
  if (IsUrdfText(source)) {
    const std::string text = py::cast<std::string>(source);
    py::gil_scoped_release release;
    return ArmFromUrdf(text, chain);
  }
  const std::string path = PathArg(source);
  if (path.empty()) {
    const std::string type = py::str(py::type::of(source).attr("__name__"));
    ThrowInput("source",
               "is a " + type + "; expected URDF text (a str starting with '<') or a path", type,
               "str or os.PathLike");
  }
  return OnFile(path, [&] { return ArmFromUrdfFile(path, chain); });
}

}  // namespace

void BindUrdf(py::module_& m) {
  m.def("arm_from_urdf", &ArmFromUrdfArg, py::arg("source"), py::kw_only(),
        py::arg("base_link") = "", py::arg("tip_link") = "", py::arg("tip_offset") = py::none(),
        R"doc(
Reads an arm from a URDF (Unified Robot Description Format; docs/robots.md): any serial chain
from base_link to tip_link. Returns an ArmModel (planar where every axis is +z and the links
lie along one direction of the z = 0 plane; spatial with joint_axes otherwise).

arm_from_urdf(source, *, base_link="", tip_link="", tip_offset=None)
  source: URDF text (a str whose first non-blank character is '<') or the path of a URDF file
    (any other str, or an os.PathLike such as pathlib.Path).
  base_link: the link the arm is bolted to; "" = the URDF's root link.
  tip_link: the end effector's link; "" = the one leaf below base_link.
  tip_offset: (3,) the end effector as a point of the tip link's frame (length unit), e.g. a
    tool point beyond the last joint; None = the tip link's origin.
Joints: every revolute, continuous or prismatic joint on the chain is one joint of the arm
(joint_types, joint_names), fixed joints are merged into the links. Joints at one point (a
universal or spherical joint built from revolute joints), twist joints (an axis along its link,
a snake's roll module) and a tip on its joint are taken, with links of length 0 between joints
that coincide (joint_groups, joint_groups_report). Limits are as written (radians, or length
unit for prismatic joints; multi-turn beyond [-pi, pi]; a continuous joint -inf..+inf); a
joint's velocity limit becomes max_velocity (used with ArmOptions.time_step). The initial
values are 0 (or the limit nearest 0).
Raises InputError naming the element (field 'joint "elbow"', 'link "tool"', 'base_link',
'urdf', 'tip_offset'; after the file's path for a file) for floating or planar joints,
closed loops, a branching URDF without tip_link, missing links and text that is not a URDF;
OSError (FileNotFoundError) with the path for a file that cannot be read.
)doc");
  m.def(
      "urdf_from_arm",
      [](ModelObject model, const std::string& robot_name) {
        return UrdfFromArm(ModelArg(model), robot_name);
      },
      py::arg("model"), py::arg("robot_name") = "flexkin_arm", R"doc(
The URDF text of an arm with revolute or prismatic joints (planar, or with joint_axes): links
"base_link", "link_1".."link_n", "tip_link"; joints "joint_0".. (revolute where the model has
limits, else continuous; prismatic joints need limits) and the fixed
"tip_joint". arm_from_urdf of it gives the same arm back. Planar arms are written with z axes
in the z = 0 plane. Raises InputError for spherical joints (URDF has none) or an invalid model.
)doc");
}

}  // namespace flexkin::python
