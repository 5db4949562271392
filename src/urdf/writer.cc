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
      << "<!-- Written by flexkin (UrdfFromArm): " << n << " revolute joints, docs/robots.md. -->\n"
      << "<robot name=\"" << XmlEscape(robot_name) << "\">\n  <link name=\"base_link\"/>\n";
  for (int j = 0; j < n; ++j) out << "  <link name=\"link_" << j + 1 << "\"/>\n";
  out << "  <link name=\"tip_link\"/>\n";
  for (int j = 0; j < n; ++j) {
    const bool limited = model.joint_min.size() > 0;
    const Eigen::Vector3d origin =
        j == 0 ? base : Eigen::Vector3d(model.link_lengths[j - 1] * direction(j - 1));
    out << "  <joint name=\"joint_" << j << "\" type=\"" << (limited ? "revolute" : "continuous")
        << "\">\n"
        << "    <parent link=\"" << (j == 0 ? "base_link" : "link_" + std::to_string(j)) << "\"/>\n"
        << "    <child link=\"link_" << j + 1 << "\"/>\n"
        << "    <origin xyz=\"" << Triple(origin) << "\" rpy=\"0 0 0\"/>\n"
        << "    <axis xyz=\"" << Triple(axis(j)) << "\"/>\n";
    if (limited) {
      out << "    <limit lower=\"" << Number(model.joint_min[j]) << "\" upper=\""
          << Number(model.joint_max[j]) << "\" effort=\"0\" velocity=\"0\"/>\n";
    }
    out << "  </joint>\n";
  }
  out << "  <joint name=\"tip_joint\" type=\"fixed\">\n    <parent link=\"link_" << n << "\"/>\n"
      << "    <child link=\"tip_link\"/>\n"
      << "    <origin xyz=\"" << Triple(model.link_lengths[n - 1] * direction(n - 1))
      << "\" rpy=\"0 0 0\"/>\n"
      << "  </joint>\n</robot>\n";
  return out.str();
}

}  // namespace flexkin
