// A serial arm from a URDF (include/flexkin/urdf.h), parsed by urdfdom.
#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <sstream>
#include <system_error>
#include <vector>

#include "arm/internal.h"
#include "flexkin/error.h"
#include "flexkin/urdf.h"

namespace flexkin {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string Quote(const std::string& s) { return "\"" + s + "\""; }

Eigen::Isometry3d Transform(const urdf::Pose& pose) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translate(Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z));
  t.rotate(Eigen::Quaterniond(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z)
               .normalized());
  return t;
}

// The joints from `base` down to `tip`, parent first.
std::vector<urdf::JointConstSharedPtr> ChainJoints(const urdf::ModelInterface& robot,
                                                   const urdf::LinkConstSharedPtr& base,
                                                   urdf::LinkConstSharedPtr tip) {
  std::vector<urdf::JointConstSharedPtr> joints;
  if (!tip) {
    tip = base;
    while (!tip->child_links.empty()) {
      if (tip->child_links.size() > 1) {
        throw InputError(
            "link " + Quote(tip->name),
            "has " + std::to_string(tip->child_links.size()) +
                " child links: the URDF branches; name the end effector's link (tip_link)");
      }
      tip = tip->child_links[0];
    }
  }
  for (urdf::LinkConstSharedPtr link = tip; link != base; link = link->getParent()) {
    if (!link->parent_joint || !link->getParent()) {
      throw InputError("tip_link", "link " + Quote(tip->name) + " is not below base link " +
                                       Quote(base->name) +
                                       "; expected a link of the chain under it");
    }
    joints.insert(joints.begin(), link->parent_joint);
  }
  (void)robot;
  return joints;
}

}  // namespace

ArmModel ArmFromUrdf(const std::string& text, const UrdfChain& chain) {
  console_bridge::setLogLevel(
      console_bridge::CONSOLE_BRIDGE_LOG_NONE);  // errors are ours to report
  const urdf::ModelInterfaceSharedPtr robot = urdf::parseURDF(text);
  if (!robot || !robot->getRoot()) {
    throw InputError("urdf",
                     "is not a valid URDF document (urdfdom could not parse it: check the XML, "
                     "that every joint names existing parent and child links and that "
                     "revolute joints have <limit>)");
  }
  auto find = [&](const std::string& name, const char* field) {
    const urdf::LinkConstSharedPtr link = robot->getLink(name);
    if (!link)
      throw InputError(field,
                       "link " + Quote(name) + " is not in the URDF; expected one of its links");
    return link;
  };
  const urdf::LinkConstSharedPtr base =
      chain.base_link.empty() ? robot->getRoot() : find(chain.base_link, "base_link");
  const urdf::LinkConstSharedPtr tip =
      chain.tip_link.empty() ? nullptr : find(chain.tip_link, "tip_link");
  // The base link's pose in the world, joints above it at 0.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  for (urdf::LinkConstSharedPtr link = base; link->parent_joint; link = link->getParent()) {
    pose = Transform(link->parent_joint->parent_to_joint_origin_transform) * pose;
  }
  // Walk down the chain at the zero pose: joint origins, world axes and limits.
  std::vector<Eigen::Vector3d> origins, axes;
  std::vector<std::string> names;
  std::vector<double> lower, upper;
  bool any_limits = false;
  for (const urdf::JointConstSharedPtr& joint : ChainJoints(*robot, base, tip)) {
    const std::string field = "joint " + Quote(joint->name);
    pose = pose * Transform(joint->parent_to_joint_origin_transform);
    if (joint->type == urdf::Joint::FIXED) continue;
    if (joint->type != urdf::Joint::REVOLUTE && joint->type != urdf::Joint::CONTINUOUS) {
      throw InputError(field,
                       "has a type other than revolute, continuous or fixed (prismatic, floating "
                       "or planar); flexkin arms have revolute joints only");
    }
    const Eigen::Vector3d axis(joint->axis.x, joint->axis.y, joint->axis.z);
    if (!(axis.norm() > 0.0) || !axis.allFinite())
      throw InputError(field, "axis is zero; expected a direction");
    origins.push_back(pose.translation());
    axes.push_back((pose.linear() * axis).normalized());
    names.push_back(joint->name);
    double lo = -kPi, hi = kPi;
    if (joint->type == urdf::Joint::REVOLUTE && joint->limits) {
      if (!(joint->limits->lower <= joint->limits->upper)) {
        throw InputError(field, "limit lower " + FormatNumber(joint->limits->lower) + " > upper " +
                                    FormatNumber(joint->limits->upper) +
                                    "; expected lower <= upper");
      }
      lo = std::max(-kPi, joint->limits->lower);
      hi = std::min(kPi, joint->limits->upper);
      if (!(lo <= hi))
        throw InputError(field, "limits lie outside [-pi, pi] rad; expected an overlap with it");
      any_limits = true;
    }
    lower.push_back(lo);
    upper.push_back(hi);
  }
  const int n = static_cast<int>(origins.size());
  if (n == 0)
    throw InputError("urdf", "the chain from the base link to the tip link has no revolute joint");
  origins.push_back(pose.translation());  // the tip
  ArmModel model;
  model.dim = 3;
  model.base = origins[0];
  model.link_lengths.resize(n);
  model.joint_axes.resize(n, 3);
  model.link_directions.resize(n, 3);
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d v = origins[k + 1] - origins[k];
    if (!(v.norm() > 1e-12 * std::max(1.0, origins[k].norm()))) {
      throw InputError(k + 1 < n ? "joint " + Quote(names[k + 1]) : "tip_link",
                       "its origin coincides with joint " + Quote(names[k]) +
                           "'s: a zero-length link; flexkin needs links of positive length");
    }
    model.link_lengths[k] = v.norm();
    model.link_directions.row(k) = v.normalized().transpose();
    model.joint_axes.row(k) = axes[k].transpose();
    if (axes[k].cross(v.normalized()).norm() < 1e-6) {
      throw InputError("joint " + Quote(names[k]),
                       "axis lies along the link it turns (a pure twist); "
                       "flexkin arms need axes across their links");
    }
  }
  model.base_direction = model.link_directions.row(0).transpose();
  model.initial.angle = Eigen::VectorXd::Zero(n);
  if (any_limits) {
    model.joint_min = Eigen::Map<Eigen::VectorXd>(lower.data(), n);
    model.joint_max = Eigen::Map<Eigen::VectorXd>(upper.data(), n);
    for (int j = 0; j < n; ++j)
      model.initial.angle[j] = arm_internal::ClampCircular(0.0, lower[j], upper[j]);
  }
  // A planar arm: every axis +z, every link along one direction of the z = 0 plane.
  bool planar = std::abs(model.base[2]) == 0.0;
  for (int k = 0; k < n && planar; ++k) {
    planar = (model.joint_axes.row(k) - Eigen::RowVector3d::UnitZ()).norm() <= 1e-12 &&
             (model.link_directions.row(k) - model.link_directions.row(0)).norm() <= 1e-12 &&
             model.link_directions(k, 2) == 0.0;
  }
  if (planar) {
    model.dim = 2;
    model.base = model.base.head<2>().eval();
    model.base_direction = model.base_direction.head<2>().eval();
    model.joint_axes.resize(0, 0);
    model.link_directions.resize(0, 0);
  }
  // The model built from the file: its problem is the file's, named "urdf" with the member.
  if (const Problems problems = model.Validate(); !problems.empty()) {
    throw InputError("urdf", problems.front().Text());
  }
  return model;
}

ArmModel ArmFromUrdfFile(const std::string& path, const UrdfChain& chain) {
  std::ifstream in(path);
  if (!in) {
    throw std::system_error(std::make_error_code(std::errc::no_such_file_or_directory),
                            "cannot read URDF '" + path + "'");
  }
  std::stringstream text;
  text << in.rdbuf();
  return ArmFromUrdf(text.str(), chain);
}

}  // namespace flexkin
