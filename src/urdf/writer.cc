// A URDF of an arm (include/flexkin/urdf.h): one revolute or continuous joint per arm joint,
// every origin without rotation, so that the URDF's zero pose is the arm's.
#include <cstdio>
#include <sstream>

#include "arm/revolute.h"
#include "flexkin/error.h"
#include "flexkin/urdf.h"

namespace flexkin {
namespace {

// Three numbers with 17 significant digits: reading them back gives the same doubles.
std::string Triple(const Eigen::Vector3d& v) {
  char text[128];
  std::snprintf(text, sizeof(text), "%.17g %.17g %.17g", v[0], v[1], v[2]);
  return text;
}

std::string Number(double x) {
  char text[40];
  std::snprintf(text, sizeof(text), "%.17g", x);
  return text;
}

std::string XmlEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '&')
      out += "&amp;";
    else if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

// The tool frame's rotation as URDF's fixed-axis roll, pitch, yaw (R = Rz(yaw) Ry(pitch) Rx(roll)).
std::string TipRpy(const ArmModel& model) {
  const Eigen::Vector4d& t = model.tip_rotation;
  if (model.dim == 2 || (t - Eigen::Vector4d(1, 0, 0, 0)).norm() == 0.0) return "0 0 0";
  const Eigen::Matrix3d r = Eigen::Quaterniond(t[0], t[1], t[2], t[3]).toRotationMatrix();
  const Eigen::Vector3d ypr = r.eulerAngles(2, 1, 0);
  return Triple(Eigen::Vector3d(ypr[2], ypr[1], ypr[0]));
}

}  // namespace

std::string UrdfFromArm(const ArmModel& model, const std::string& robot_name) {
  Problems problems;
  AppendNested("model", model.Validate(), &problems);
  ThrowIfAny(problems);
  if (model.joint() == ArmJoint::kSpherical) {
    throw InputError("model.joint_axes",
                     "is empty: spherical joints have no URDF form; expected revolute joints "
                     "(a planar arm, or joint_axes)");
  }
  const int n = model.num_links();
  const bool planar = model.dim == 2;
  auto axis = [&](int j) {
    return planar ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d(model.joint_axes.row(j).transpose());
  };
  auto direction = [&](int k) {
    if (!planar) return arm_internal::RestDirection(model, k);
    const Eigen::Vector2d d = model.base_direction.normalized();
    return Eigen::Vector3d(d[0], d[1], 0.0);
  };
  const Eigen::Vector3d base = planar ? Eigen::Vector3d(model.base[0], model.base[1], 0.0)
                                      : Eigen::Vector3d(model.base.head<3>());
  std::ostringstream out;
  out << "<?xml version=\"1.0\"?>\n"
      << "<!-- Written by flexkin (UrdfFromArm): " << n << " joints, docs/robots.md. -->\n"
      << "<robot name=\"" << XmlEscape(robot_name) << "\">\n  <link name=\"base_link\"/>\n";
  for (int j = 0; j < n; ++j) out << "  <link name=\"link_" << j + 1 << "\"/>\n";
  out << "  <link name=\"tip_link\"/>\n";
  for (int j = 0; j < n; ++j) {
    const bool prismatic = model.prismatic(j);
    const bool limited = model.joint_min.size() > 0 &&
                         (std::isfinite(model.joint_min[j]) || std::isfinite(model.joint_max[j]));
    if (limited && !(std::isfinite(model.joint_min[j]) && std::isfinite(model.joint_max[j]))) {
      throw InputError("model.joint_min[" + std::to_string(j) + "]",
                       "a limit on one side only has no URDF form; expected both finite, or "
                       "both infinite (a continuous joint)");
    }
    if (prismatic && !limited) {
      throw InputError("model.joint_min[" + std::to_string(j) + "]",
                       "a prismatic joint without limits has no URDF form; expected limits");
    }
    const double speed = model.max_velocity.size() > 0 && std::isfinite(model.max_velocity[j])
                             ? model.max_velocity[j]
                             : 0.0;  // 0: no limit (ArmFromUrdf)
    const Eigen::Vector3d origin =
        j == 0 ? base : Eigen::Vector3d(model.link_lengths[j - 1] * direction(j - 1));
    out << "  <joint name=\"joint_" << j << "\" type=\""
        << (prismatic ? "prismatic"
            : limited ? "revolute"
                      : "continuous")
        << "\">\n"
        << "    <parent link=\"" << (j == 0 ? "base_link" : "link_" + std::to_string(j)) << "\"/>\n"
        << "    <child link=\"link_" << j + 1 << "\"/>\n"
        << "    <origin xyz=\"" << Triple(origin) << "\" rpy=\"0 0 0\"/>\n"
        << "    <axis xyz=\"" << Triple(axis(j)) << "\"/>\n";
    if (limited) {
      out << "    <limit lower=\"" << Number(model.joint_min[j]) << "\" upper=\""
          << Number(model.joint_max[j]) << "\" effort=\"0\" velocity=\"" << Number(speed)
          << "\"/>\n";
    } else if (speed > 0.0) {
      out << "    <limit effort=\"0\" velocity=\"" << Number(speed) << "\"/>\n";
    }
    out << "  </joint>\n";
  }
  out << "  <joint name=\"tip_joint\" type=\"fixed\">\n    <parent link=\"link_" << n << "\"/>\n"
      << "    <child link=\"tip_link\"/>\n"
      << "    <origin xyz=\"" << Triple(model.link_lengths[n - 1] * direction(n - 1)) << "\" rpy=\""
      << TipRpy(model) << "\"/>\n"
      << "  </joint>\n</robot>\n";
  return out.str();
}

}  // namespace flexkin
