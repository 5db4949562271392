// URDF arms from Python: flexkin.arm_from_urdf and urdf_from_arm (flexkin/urdf.h), built where
// the URDF component (flexkin_urdf, Debian's urdfdom) is.
#include "flexkin/urdf.h"

#include <string>
#include <system_error>

#include "convert.h"

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
                        const std::string& tip_link) {
  const UrdfChain chain{base_link, tip_link};
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
        py::arg("base_link") = "", py::arg("tip_link") = "", R"doc(
Reads an arm from a URDF (Unified Robot Description Format; docs/robots.md): the serial chain
from base_link to tip_link, every revolute or continuous joint one joint of the arm, fixed
joints merged into the links. Returns an ArmModel (planar where every axis is +z and the links
lie along one direction of the z = 0 plane; spatial revolute with joint_axes otherwise).

arm_from_urdf(source, *, base_link="", tip_link="")
  source: URDF text (a str whose first non-blank character is '<') or the path of a URDF file
    (any other str, or an os.PathLike such as pathlib.Path).
  base_link: the link the arm is bolted to; "" = the URDF's root link.
  tip_link: the end effector's link; "" = the one leaf below base_link.
Limits: a revolute joint's [lower, upper] (radians) cut to [-pi, pi]; continuous joints get
[-pi, pi] when any other joint has limits. The initial angles are 0 (or the limit nearest 0).
Raises InputError naming the element (field 'joint "elbow"', 'link "tool"', 'base_link',
'urdf'; after the file's path for a file) for prismatic, floating or planar joints, branches,
zero-length links, twist joints and text that is not a URDF; OSError (FileNotFoundError) with
the path for a file that cannot be read.
)doc");
  m.def(
      "urdf_from_arm",
      [](ModelObject model, const std::string& robot_name) {
        return UrdfFromArm(ModelArg(model), robot_name);
      },
      py::arg("model"), py::arg("robot_name") = "flexkin_arm", R"doc(
The URDF text of an arm with revolute joints: links "base_link", "link_1".."link_n", "tip_link";
joints "joint_0".. (revolute where the model has limits, else continuous) and the fixed
"tip_joint". arm_from_urdf of it gives the same arm back. Planar arms are written with z axes
in the z = 0 plane. Raises InputError for spherical joints (URDF has none) or an invalid model.
)doc");
}

}  // namespace flexkin::python
