#include "snake_urdfs.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace flexkin::snakes {
namespace {

constexpr double kPi = 3.14159265358979323846;

// 17 significant digits: the double read back is the double written.
std::string Num(double x) {
  if (x == 0.0) return "0";  // also -0
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", x);
  return buffer;
}

std::string Triple(const Eigen::Vector3d& v) {
  return Num(v[0]) + " " + Num(v[1]) + " " + Num(v[2]);
}

// URDF's fixed-axis roll, pitch, yaw (R = Rz(yaw) Ry(pitch) Rx(roll)) of a rotation matrix.
Eigen::Vector3d Rpy(const Eigen::Matrix3d& r) {
  const double pitch = std::atan2(-r(2, 0), std::hypot(r(0, 0), r(1, 0)));
  return Eigen::Vector3d(std::atan2(r(2, 1), r(2, 2)), pitch, std::atan2(r(1, 0), r(0, 0)));
}

Eigen::Matrix3d FromRpy(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy[2], Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy[1], Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy[0], Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

enum class Kind { kRevolute, kContinuous, kPrismatic, kFixed };

struct Joint {
  std::string name;
  Kind kind = Kind::kFixed;
  std::string parent, child;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  double lower = 0.0, upper = 0.0, velocity = 2.0;
};

// Collects links and joints (in the order added) and writes the URDF document.
class UrdfWriter {
 public:
  UrdfWriter(std::string robot, std::string comment)
      : robot_(std::move(robot)), comment_(std::move(comment)) {}

  void Link(const std::string& name) { links_.push_back(name); }
  void Add(const Joint& joint) { joints_.push_back(joint); }

  std::string Text() const {
    std::ostringstream out;
    out << "<?xml version=\"1.0\"?>\n";
    out << "<!-- " << comment_ << " -->\n";
    out << "<robot name=\"" << robot_ << "\">\n";
    for (const std::string& link : links_) out << "  <link name=\"" << link << "\"/>\n";
    for (const Joint& j : joints_) {
      static const char* const kTypes[] = {"revolute", "continuous", "prismatic", "fixed"};
      out << "  <joint name=\"" << j.name << "\" type=\"" << kTypes[static_cast<int>(j.kind)]
          << "\">\n";
      out << "    <parent link=\"" << j.parent << "\"/>\n";
      out << "    <child link=\"" << j.child << "\"/>\n";
      out << "    <origin xyz=\"" << Triple(j.xyz) << "\" rpy=\"" << Triple(j.rpy) << "\"/>\n";
      if (j.kind != Kind::kFixed) {
        out << "    <axis xyz=\"" << Triple(j.axis) << "\"/>\n";
        out << "    <limit";
        if (j.kind != Kind::kContinuous) {
          out << " lower=\"" << Num(j.lower) << "\" upper=\"" << Num(j.upper) << "\"";
        }
        out << " effort=\"10\" velocity=\"" << Num(j.velocity) << "\"/>\n";
      }
      out << "  </joint>\n";
    }
    out << "</robot>\n";
    return out.str();
  }

 private:
  std::string robot_, comment_;
  std::vector<std::string> links_;
  std::vector<Joint> joints_;
};

Joint Revolute(const std::string& name, const std::string& parent, const std::string& child,
               const Eigen::Vector3d& xyz, const Eigen::Vector3d& axis, double limit) {
  Joint j;
  j.name = name;
  j.kind = Kind::kRevolute;
  j.parent = parent;
  j.child = child;
  j.xyz = xyz;
  j.axis = axis;
  j.lower = -limit;
  j.upper = limit;
  return j;
}

Joint Fixed(const std::string& name, const std::string& parent, const std::string& child,
            const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy = Eigen::Vector3d::Zero()) {
  Joint j;
  j.name = name;
  j.parent = parent;
  j.child = child;
  j.xyz = xyz;
  j.rpy = rpy;
  return j;
}

void CheckModules(int modules) {
  if (modules < 1) throw std::invalid_argument("a snake needs at least one module");
}

std::string Index(const std::string& prefix, int i) { return prefix + "_" + std::to_string(i); }

const Eigen::Vector3d kX = Eigen::Vector3d::UnitX(), kY = Eigen::Vector3d::UnitY(),
                      kZ = Eigen::Vector3d::UnitZ();

}  // namespace

std::string PitchYawSnakeUrdf(int modules) {
  CheckModules(modules);
  const double length = kSnakeModuleLength;
  UrdfWriter urdf("pitch_yaw_snake_" + std::to_string(modules),
                  "Written by flexkin's testing/snake_urdfs.cc: PitchYawSnakeUrdf(" +
                      std::to_string(modules) + ")");
  urdf.Link("base_link");
  std::string parent = "base_link";
  Eigen::Matrix3d bracket_rotation = Eigen::Matrix3d::Identity();
  for (int i = 0; i < modules; ++i) {
    const std::string housing = Index("housing", i), bracket = Index("bracket", i);
    urdf.Link(housing);
    Joint joint = Revolute(Index("joint", i), parent, housing, Eigen::Vector3d::Zero(),
                           i % 2 == 0 ? kY : kZ, 1.2);
    if (i > 0) {
      // Half a module beyond the bracket's origin along the housing's x, in the bracket's frame,
      // and the bracket's rotation undone.
      joint.xyz = bracket_rotation.transpose() * Eigen::Vector3d(0.5 * length, 0.0, 0.0);
      joint.rpy = Rpy(bracket_rotation.transpose());
    }
    urdf.Add(joint);
    if (i + 1 < modules) {
      urdf.Link(bracket);
      const Eigen::Vector3d rpy(0.11 + 0.013 * i, -0.07 + 0.011 * (i % 5), 0.05 - 0.009 * (i % 7));
      urdf.Add(
          Fixed(Index("mount", i), housing, bracket, Eigen::Vector3d(0.5 * length, 0.0, 0.0), rpy));
      bracket_rotation = FromRpy(rpy);
      parent = bracket;
    } else {
      urdf.Link("tip_link");
      urdf.Add(Fixed("tip_joint", housing, "tip_link", Eigen::Vector3d::Zero(), {0.3, -0.2, 0.25}));
    }
  }
  return urdf.Text();
}

std::string UniversalSnakeUrdf(int modules) {
  CheckModules(modules);
  const double length = kSnakeModuleLength;
  UrdfWriter urdf("universal_snake_" + std::to_string(modules),
                  "Written by flexkin's testing/snake_urdfs.cc: UniversalSnakeUrdf(" +
                      std::to_string(modules) + ")");
  urdf.Link("base_link");
  std::string parent = "base_link";
  for (int i = 0; i < modules; ++i) {
    const std::string cross = Index("cross", i), link = Index("link", i);
    urdf.Link(cross);
    urdf.Link(link);
    const Eigen::Vector3d start(i == 0 ? 0.0 : length, 0.0, 0.0);
    urdf.Add(Revolute(Index("pitch", i), parent, cross, start, kY, 1.0));
    urdf.Add(Revolute(Index("yaw", i), cross, link, Eigen::Vector3d::Zero(), kZ, 1.0));
    parent = link;
  }
  urdf.Link("tip_link");
  urdf.Add(Fixed("tip_joint", parent, "tip_link", Eigen::Vector3d(length, 0.0, 0.0)));
  return urdf.Text();
}

std::string RollSnakeUrdf(int modules) {
  CheckModules(modules);
  const double length = kSnakeModuleLength;
  UrdfWriter urdf("roll_snake_" + std::to_string(modules),
                  "Written by flexkin's testing/snake_urdfs.cc: RollSnakeUrdf(" +
                      std::to_string(modules) + ")");
  urdf.Link("base_link");
  std::string parent = "base_link";
  for (int i = 0; i < modules; ++i) {
    const std::string pitch_link = Index("pitch_link", i), yaw_link = Index("yaw_link", i),
                      roll_link = Index("roll_link", i);
    urdf.Link(pitch_link);
    urdf.Link(yaw_link);
    urdf.Link(roll_link);
    const Eigen::Vector3d start(i == 0 ? 0.0 : 0.3 * length, 0.0, 0.0);
    urdf.Add(Revolute(Index("pitch", i), parent, pitch_link, start, kY, 1.0));
    urdf.Add(Revolute(Index("yaw", i), pitch_link, yaw_link, {0.4 * length, 0.0, 0.0}, kZ, 1.0));
    urdf.Add(Revolute(Index("roll", i), yaw_link, roll_link, {0.3 * length, 0.0, 0.0}, kX, 2.5));
    parent = roll_link;
  }
  urdf.Link("tip_link");
  urdf.Add(Fixed("tip_joint", parent, "tip_link", Eigen::Vector3d(0.3 * length, 0.0, 0.0)));
  return urdf.Text();
}

std::string PrismaticArmUrdf() {
  UrdfWriter urdf("prismatic_arm",
                  "Written by flexkin's testing/snake_urdfs.cc: PrismaticArmUrdf()");
  for (const char* link :
       {"base_link", "turret", "upper_arm", "forearm", "slide", "wrist", "flange", "tip_link"}) {
    urdf.Link(link);
  }
  Joint base = Revolute("base_yaw", "base_link", "turret", Eigen::Vector3d::Zero(), kZ, 2.8);
  base.velocity = 1.5;
  urdf.Add(base);
  urdf.Add(Revolute("shoulder", "turret", "upper_arm", {0.0, 0.0, 0.1}, kY, 1.5));
  urdf.Add(Revolute("elbow", "upper_arm", "forearm", {0.3, 0.0, 0.0}, kY, 2.0));
  Joint extension = Revolute("extension", "forearm", "slide", {0.2, 0.0, 0.0}, kX, 0.0);
  extension.kind = Kind::kPrismatic;
  extension.lower = 0.0;
  extension.upper = 0.3;
  extension.velocity = 0.5;
  urdf.Add(extension);
  urdf.Add(Revolute("wrist_pitch", "slide", "wrist", {0.1, 0.0, 0.0}, kY, 1.8));
  urdf.Add(Revolute("wrist_roll", "wrist", "flange", {0.05, 0.0, 0.0}, kX, 3.0));
  urdf.Add(Fixed("tool_joint", "flange", "tip_link", {0.03, 0.0, 0.0}, {0.0, 0.5 * kPi, 0.0}));
  return urdf.Text();
}

Eigen::Vector3d PrismaticToolOffset() { return Eigen::Vector3d(0.0, 0.0, 0.08); }

std::string MultiTurnArmUrdf() {
  UrdfWriter urdf("multi_turn_arm",
                  "Written by flexkin's testing/snake_urdfs.cc: MultiTurnArmUrdf()");
  for (const char* link : {"base_link", "l1", "l2", "l3", "l4", "l5", "l6", "tip_link"}) {
    urdf.Link(link);
  }
  const Eigen::Vector3d step(0.1, 0.0, 0.0);
  Joint turntable = Revolute("turntable", "base_link", "l1", Eigen::Vector3d::Zero(), kZ, 0.0);
  turntable.kind = Kind::kContinuous;
  urdf.Add(turntable);
  urdf.Add(Revolute("shoulder", "l1", "l2", step, kY, 1.2));
  urdf.Add(Revolute("twist_1", "l2", "l3", step, kZ, 2.0 * kPi));
  urdf.Add(Revolute("elbow", "l3", "l4", step, kY, 1.2));
  Joint roll = Revolute("roll", "l4", "l5", step, kX, 0.0);
  roll.kind = Kind::kContinuous;
  urdf.Add(roll);
  urdf.Add(Revolute("wrist", "l5", "l6", step, kZ, 2.0 * kPi));
  urdf.Add(Fixed("tip_joint", "l6", "tip_link", step));
  return urdf.Text();
}

std::vector<SnakeDesign> AllSnakeDesigns(int modules) {
  return {{"pitch_yaw", PitchYawSnakeUrdf(modules), Eigen::Vector3d::Zero()},
          {"universal", UniversalSnakeUrdf(modules), Eigen::Vector3d::Zero()},
          {"roll", RollSnakeUrdf(modules), Eigen::Vector3d::Zero()},
          {"prismatic", PrismaticArmUrdf(), PrismaticToolOffset()},
          {"multi_turn", MultiTurnArmUrdf(), Eigen::Vector3d::Zero()}};
}

void BendInitial(ArmModel* model, double pitch_per_joint, double yaw_per_joint,
                 double roll_per_joint) {
  const int n = model->num_links();
  if (model->joint_axes.rows() != n) {
    throw std::invalid_argument("BendInitial: the model has no joint axes");
  }
  model->initial.angle = Eigen::VectorXd::Zero(n);
  model->initial.azimuth.resize(0);
  const bool limits = model->joint_min.size() == n && model->joint_max.size() == n;
  for (int j = 0; j < n; ++j) {
    const Eigen::Vector3d axis = model->joint_axes.row(j).transpose();
    double angle = 0.0;
    if (model->prismatic(j)) {
      angle = limits && std::isfinite(model->joint_min[j]) && std::isfinite(model->joint_max[j])
                  ? 0.5 * (model->joint_min[j] + model->joint_max[j])
                  : 0.0;
    } else if (std::abs(axis.y()) > 0.99) {
      angle = pitch_per_joint;
    } else if (std::abs(axis.z()) > 0.99) {
      angle = yaw_per_joint;
    } else if (std::abs(axis.x()) > 0.99) {
      angle = roll_per_joint;
    }
    if (limits) angle = std::clamp(angle, model->joint_min[j], model->joint_max[j]);
    model->initial.angle[j] = angle;
  }
}

Points CircleThrough(const Eigen::Vector3d& start, const Eigen::Vector3d& u,
                     const Eigen::Vector3d& v, double radius, int steps, double turns) {
  const Eigen::Vector3d centre = start - radius * u;
  Points path(steps, 3);
  for (int k = 0; k < steps; ++k) {
    const double theta = 2.0 * kPi * turns * (k + 1) / steps;
    path.row(k) = (centre + radius * (std::cos(theta) * u + std::sin(theta) * v)).transpose();
  }
  return path;
}

Points LineTo(const Eigen::Vector3d& start, const Eigen::Vector3d& end, int steps) {
  Points path(steps, 3);
  for (int k = 0; k < steps; ++k) {
    const double t = static_cast<double>(k + 1) / steps;
    path.row(k) = ((1.0 - t) * start + t * end).transpose();
  }
  return path;
}

}  // namespace flexkin::snakes
