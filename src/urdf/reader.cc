// A serial arm from a URDF (include/flexkin/urdf.h), parsed by urdfdom.
#include <console_bridge/console.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <system_error>
#include <tuple>
#include <utility>
#include <vector>

#include "arm/internal.h"
#include "flexkin/error.h"
#include "flexkin/urdf.h"

namespace flexkin {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();

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

// Collects what urdfdom reports while parsing, to name the element in our message.
class Collect : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR && first.empty()) first = text;
  }
  std::string first;
};

// Refuses joints that form a cycle (each link of it the child of the one before, none of them under
// the root), read with TinyXML as urdfdom reads them: urdfdom accepts such a cycle, or fails later
// with its links holding each other (never freed), and no walk up from them ends. Also refuses a
// link that is the child of two joints (a closed loop; urdfdom keeps the last of them and would
// read it as a tree).
void RefuseJointCycles(const std::string& text) {
  TiXmlDocument doc;
  doc.Parse(text.c_str());
  const TiXmlElement* robot = doc.Error() ? nullptr : doc.FirstChildElement("robot");
  if (!robot) return;  // urdfdom says what is wrong
  struct Up {
    std::string link, joint;  // the parent link and the joint to it
  };
  std::map<std::string, Up> up;  // child link -> its parent
  for (const TiXmlElement* j = robot->FirstChildElement("joint"); j;
       j = j->NextSiblingElement("joint")) {
    const TiXmlElement* parent = j->FirstChildElement("parent");
    const TiXmlElement* child = j->FirstChildElement("child");
    const char* parent_link = parent ? parent->Attribute("link") : nullptr;
    const char* child_link = child ? child->Attribute("link") : nullptr;
    const char* name = j->Attribute("name");
    if (!parent_link || !child_link || !name) continue;  // urdfdom refuses the joint
    const auto [at, fresh] = up.emplace(child_link, Up{parent_link, name});
    if (!fresh) {
      const std::string joint = name;
      const auto [first, second] = std::minmax(at->second.joint, joint);
      throw InputError("link " + Quote(child_link),
                       "is the child of joints " + Quote(first) + " and " + Quote(second) +
                           ": a closed loop; flexkin arms are serial chains (each link the "
                           "child of one joint): remove one of them");
    }
  }
  std::set<std::string> reaches_root;  // links known to lie under a link without a parent
  for (const auto& [link, unused] : up) {
    std::vector<std::string> path;
    for (auto at = up.find(link); at != up.end() && !reaches_root.count(at->first);
         at = up.find(at->second.link)) {
      path.push_back(at->first);
      if (path.size() > up.size()) {
        throw InputError("link " + Quote(at->first),
                         "is its own ancestor: joint " + Quote(at->second.joint) +
                             " and the joints above it form a cycle; expected a tree (each "
                             "joint's parent link nearer the root)");
      }
    }
    reaches_root.insert(path.begin(), path.end());
  }
}

// Refuses text that is not UTF-8 (XML's encoding here), naming the first bad byte. TinyXML, which
// urdfdom and RefuseJointCycles parse with, trusts a lead byte's length: a multi-byte sequence cut
// off by the end of the text makes it read past the end (found by the urdf fuzzer).
void RefuseInvalidUtf8(const std::string& text) {
  const auto* p = reinterpret_cast<const unsigned char*>(text.data());
  const size_t n = text.size();
  for (size_t i = 0; i < n;) {
    const unsigned char c = p[i];
    size_t len = 0;
    uint32_t min = 0, code = 0;
    if (c < 0x80) {
      ++i;
      continue;
    } else if ((c & 0xE0) == 0xC0) {
      len = 2, min = 0x80, code = c & 0x1F;
    } else if ((c & 0xF0) == 0xE0) {
      len = 3, min = 0x800, code = c & 0x0F;
    } else if ((c & 0xF8) == 0xF0) {
      len = 4, min = 0x10000, code = c & 0x07;
    }
    bool valid = len > 0 && i + len <= n;
    for (size_t k = 1; valid && k < len; ++k) {
      valid = (p[i + k] & 0xC0) == 0x80;
      code = (code << 6) | (p[i + k] & 0x3F);
    }
    // No overlong forms, no surrogates, nothing past U+10FFFF.
    valid = valid && code >= min && code <= 0x10FFFF && !(code >= 0xD800 && code <= 0xDFFF);
    if (!valid) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02X", c);
      throw InputError("urdf", std::string("byte ") + std::to_string(i) + " (" + hex +
                                   ") is not valid UTF-8; expected UTF-8 text (XML)");
    }
    i += len;
  }
}

urdf::ModelInterfaceSharedPtr Parse(const std::string& text) {
  RefuseInvalidUtf8(text);
  RefuseJointCycles(text);
  // console_bridge's handler is global: one parse at a time.
  static std::mutex mutex;
  Collect collect;
  urdf::ModelInterfaceSharedPtr robot;
  {
    const std::lock_guard<std::mutex> lock(mutex);
    console_bridge::useOutputHandler(&collect);
    console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_ERROR);
    try {
      robot = urdf::parseURDF(text);
    } catch (...) {
      robot = nullptr;
    }
    console_bridge::restorePreviousOutputHandler();
    console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
  }
  if (!robot || !robot->getRoot()) {
    throw InputError("urdf",
                     "is not a valid URDF document (urdfdom: " +
                         (collect.first.empty() ? std::string("no root link") : collect.first) +
                         "); check the XML, that every joint names existing parent and "
                         "child links, that no link has two parents (a closed loop) and "
                         "that revolute and prismatic joints have <limit>");
  }
  return robot;
}

// A movable joint's axis in its own frame; InputError (`field` the joint) where it is zero.
Eigen::Vector3d JointAxis(const urdf::Joint& joint, const std::string& field) {
  const Eigen::Vector3d axis(joint.axis.x, joint.axis.y, joint.axis.z);
  if (!(axis.norm() > 0.0) || !axis.allFinite()) {
    throw InputError(field, "axis is zero; expected a direction");
  }
  return axis;
}

// A joint's limits as written, [lower, upper] (rad, or length for prismatic joints); none for a
// continuous joint or one without <limit>. InputError where lower > upper.
std::optional<std::pair<double, double>> JointRange(const urdf::Joint& joint,
                                                    const std::string& field) {
  if (joint.type == urdf::Joint::CONTINUOUS || !joint.limits) return std::nullopt;
  const double lo = joint.limits->lower, hi = joint.limits->upper;
  if (!(lo <= hi)) {
    throw InputError(field, "limit lower " + FormatNumber(lo) + " > upper " + FormatNumber(hi) +
                                "; expected lower <= upper");
  }
  return std::make_pair(lo, hi);
}

}  // namespace

// The radius of a link's collision geometry: the largest radius of its cylinders and spheres (a
// link's capsule about its axis), 0 where it has none (boxes and meshes are not read as radii).
double CollisionRadius(const urdf::LinkConstSharedPtr& link) {
  double radius = 0.0;
  if (!link) return radius;
  std::vector<urdf::CollisionSharedPtr> all = link->collision_array;
  if (all.empty() && link->collision) all.push_back(link->collision);
  for (const urdf::CollisionSharedPtr& c : all) {
    if (!c || !c->geometry) continue;
    double r = 0.0;
    if (c->geometry->type == urdf::Geometry::CYLINDER) {
      r = static_cast<const urdf::Cylinder&>(*c->geometry).radius;
    } else if (c->geometry->type == urdf::Geometry::SPHERE) {
      r = static_cast<const urdf::Sphere&>(*c->geometry).radius;
    }
    if (std::isfinite(r) && r > radius) radius = r;
  }
  return radius;
}

ArmModel ArmFromUrdf(const std::string& text, const UrdfChain& chain) {
  const urdf::ModelInterfaceSharedPtr robot = Parse(text);
  auto find = [&](const std::string& name, const char* field) {
    const urdf::LinkConstSharedPtr link = robot->getLink(name);
    if (!link)
      throw InputError(field,
                       "link " + Quote(name) + " is not in the URDF; expected one of its links");
    return link;
  };
  if (!chain.tip_offset.allFinite()) {
    throw InputError("tip_offset", "is not finite; expected a point of the tip link's frame");
  }
  const urdf::LinkConstSharedPtr base =
      chain.base_link.empty() ? robot->getRoot() : find(chain.base_link, "base_link");
  const urdf::LinkConstSharedPtr tip =
      chain.tip_link.empty() ? nullptr : find(chain.tip_link, "tip_link");
  // The base link's pose in the world, joints above it at 0.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  for (urdf::LinkConstSharedPtr link = base; link->parent_joint; link = link->getParent()) {
    pose = Transform(link->parent_joint->parent_to_joint_origin_transform) * pose;
  }
  // Walk down the chain at the zero pose: joint origins, world axes, types and limits.
  std::vector<Eigen::Vector3d> origins, axes;
  std::vector<std::string> names;
  std::vector<JointType> types;
  std::vector<double> lower, upper, speed, radii;
  bool any_limits = false, any_speed = false;
  for (const urdf::JointConstSharedPtr& joint : ChainJoints(*robot, base, tip)) {
    const std::string field = "joint " + Quote(joint->name);
    pose = pose * Transform(joint->parent_to_joint_origin_transform);
    const double radius = CollisionRadius(robot->getLink(joint->child_link_name));
    if (joint->type == urdf::Joint::FIXED) {
      // A fixed joint merges its child into the link of the last movable joint above it.
      if (!radii.empty()) radii.back() = std::max(radii.back(), radius);
      continue;
    }
    if (joint->type == urdf::Joint::FLOATING || joint->type == urdf::Joint::PLANAR) {
      throw InputError(field, std::string("has type ") +
                                  (joint->type == urdf::Joint::FLOATING ? "floating" : "planar") +
                                  ", which a fixed-base serial arm cannot have (flexkin takes "
                                  "revolute, continuous, prismatic and fixed joints); start the "
                                  "arm below it (base_link = its child link) or make it fixed");
    }
    if (joint->type != urdf::Joint::REVOLUTE && joint->type != urdf::Joint::CONTINUOUS &&
        joint->type != urdf::Joint::PRISMATIC) {
      throw InputError(field,
                       "has an unknown type; expected revolute, continuous, prismatic "
                       "or fixed");
    }
    const Eigen::Vector3d axis = JointAxis(*joint, field);
    origins.push_back(pose.translation());
    axes.push_back((pose.linear() * axis).normalized());
    names.push_back(joint->name);
    const bool prismatic = joint->type == urdf::Joint::PRISMATIC;
    types.push_back(prismatic ? JointType::kPrismatic : JointType::kRevolute);
    // Limits as written: continuous joints have none; revolute ones may span several turns.
    double lo = -kInf, hi = kInf, v = kInf;
    if (const auto range = JointRange(*joint, field)) {
      std::tie(lo, hi) = *range;
      any_limits = true;
    }
    // A velocity limit of 0 (or none) is taken as no limit, as URDF writers use it.
    if (joint->limits && joint->limits->velocity > 0.0 && std::isfinite(joint->limits->velocity)) {
      v = joint->limits->velocity;
      any_speed = true;
    }
    lower.push_back(lo);
    upper.push_back(hi);
    speed.push_back(v);
    radii.push_back(radius);
  }
  const int n = static_cast<int>(origins.size());
  if (n == 0) {
    throw InputError("urdf",
                     "the chain from the base link to the tip link has no revolute, "
                     "continuous or prismatic joint");
  }
  origins.push_back(pose * chain.tip_offset);  // the end effector
  ArmModel model;
  model.dim = 3;
  model.base = origins[0];
  model.link_lengths.resize(n);
  model.joint_axes.resize(n, 3);
  model.link_directions.resize(n, 3);
  model.joint_types = types;
  model.joint_names = names;
  // The tool frame (the tip link's) in the last link's frame, which is the world's at zero.
  const Eigen::Quaterniond tool(pose.linear());
  model.tip_rotation << tool.w(), tool.x(), tool.y(), tool.z();
  Eigen::Vector3d last_direction = Eigen::Vector3d::UnitX();
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d v = origins[k + 1] - origins[k];
    // Joints at one point (a universal or spherical joint, a tip on its joint): length 0.
    const bool zero = !(v.norm() > 1e-12 * std::max(1.0, origins[k].norm()));
    model.link_lengths[k] = zero ? 0.0 : v.norm();
    if (!zero) last_direction = v.normalized();
    model.link_directions.row(k) = (zero ? axes[k].unitOrthogonal() : last_direction).transpose();
    model.joint_axes.row(k) = axes[k].transpose();
  }
  if (!(model.link_lengths.sum() > 0.0)) {
    throw InputError("tip_link",
                     "every joint of the chain and the end effector are at one "
                     "point; expected a chain of positive length (or a tip_offset)");
  }
  // The base direction: the first link of positive length.
  for (int k = n - 1; k >= 0; --k) {
    if (model.link_lengths[k] > 0.0)
      model.base_direction = model.link_directions.row(k).transpose();
  }
  model.initial.angle = Eigen::VectorXd::Zero(n);
  if (any_limits) {
    model.joint_min = Eigen::Map<Eigen::VectorXd>(lower.data(), n);
    model.joint_max = Eigen::Map<Eigen::VectorXd>(upper.data(), n);
    for (int j = 0; j < n; ++j) model.initial.angle[j] = std::clamp(0.0, lower[j], upper[j]);
  }
  if (any_speed) model.max_velocity = Eigen::Map<Eigen::VectorXd>(speed.data(), n);
  // Link k+1 (from joint k to the next) is joint k's child link (with what fixed joints merge into
  // it): its collision cylinder's or sphere's radius. None anywhere: no radii.
  if (*std::max_element(radii.begin(), radii.end()) > 0.0) {
    model.link_radii = Eigen::Map<Eigen::VectorXd>(radii.data(), n);
  }
  // A planar arm: every joint revolute about +z within [-pi, pi] (or continuous), every link of
  // positive length along one direction of the z = 0 plane, and the tool frame the last link's.
  bool planar = std::abs(model.base[2]) == 0.0 &&
                (model.tip_rotation - Eigen::Vector4d(1, 0, 0, 0)).norm() <= 1e-12;
  for (int k = 0; k < n && planar; ++k) {
    planar = types[k] == JointType::kRevolute && model.link_lengths[k] > 0.0 &&
             (model.joint_axes.row(k) - Eigen::RowVector3d::UnitZ()).norm() <= 1e-12 &&
             (model.link_directions.row(k) - model.link_directions.row(0)).norm() <= 1e-12 &&
             model.link_directions(k, 2) == 0.0 &&
             (!any_limits || (std::isinf(lower[k]) && std::isinf(upper[k])) ||
              (lower[k] >= -kPi && upper[k] <= kPi));
  }
  if (planar) {
    model.dim = 2;
    model.base = model.base.head<2>().eval();
    model.base_direction = model.base_direction.head<2>().eval();
    model.joint_axes.resize(0, 0);
    model.link_directions.resize(0, 0);
    model.joint_types.clear();
    // (joint_names are kept: they name the planar joints too)
    if (any_limits) {  // continuous joints of a planar arm: the whole circle
      model.joint_min = model.joint_min.cwiseMax(-kPi);
      model.joint_max = model.joint_max.cwiseMin(kPi);
    }
  }
  // The model built from the file: its problem is the file's, named "urdf" with the member.
  if (const Problems problems = model.Validate(); !problems.empty()) {
    throw InputError("urdf", problems.front().Text());
  }
  return model;
}

namespace {
std::string ReadUrdfText(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    throw std::system_error(std::make_error_code(std::errc::no_such_file_or_directory),
                            "cannot read URDF '" + path + "'");
  }
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}
}  // namespace

ArmModel ArmFromUrdfFile(const std::string& path, const UrdfChain& chain) {
  return ArmFromUrdf(ReadUrdfText(path), chain);
}

RobotTree RobotTreeFromUrdf(const std::string& text, const std::string& base_link,
                            const std::vector<UrdfTool>& tools) {
  const urdf::ModelInterfaceSharedPtr robot = Parse(text);
  urdf::LinkConstSharedPtr base = robot->getRoot();
  if (!base_link.empty()) {
    base = robot->getLink(base_link);
    if (!base) {
      throw InputError("base_link", "link " + Quote(base_link) +
                                        " is not in the URDF; expected one of its links");
    }
  }
  Eigen::Isometry3d base_pose = Eigen::Isometry3d::Identity();
  for (urdf::LinkConstSharedPtr link = base; link->parent_joint; link = link->getParent()) {
    base_pose = Transform(link->parent_joint->parent_to_joint_origin_transform) * base_pose;
  }
  RobotTree tree;
  tree.base = base_pose.translation();
  std::vector<Eigen::Vector3d> origins, axes;
  std::vector<double> lower, upper;
  struct LinkAt {
    Eigen::Isometry3d pose;  // at the zero pose
    int joint;               // the last movable joint above it (-1: none)
  };
  std::map<std::string, LinkAt> links;
  // Depth first from the base, each joint after its parent.
  std::vector<std::pair<urdf::LinkConstSharedPtr, LinkAt>> stack{{base, {base_pose, -1}}};
  while (!stack.empty()) {
    auto [link, at] = stack.back();
    stack.pop_back();
    links.emplace(link->name, at);
    for (auto c = link->child_joints.rbegin(); c != link->child_joints.rend(); ++c) {
      const urdf::JointConstSharedPtr& joint = *c;
      const urdf::LinkConstSharedPtr child = robot->getLink(joint->child_link_name);
      if (!child) continue;  // urdfdom refuses such a joint
      const std::string field = "joint " + Quote(joint->name);
      LinkAt next{at.pose * Transform(joint->parent_to_joint_origin_transform), at.joint};
      if (joint->type != urdf::Joint::FIXED) {
        if (joint->type != urdf::Joint::REVOLUTE && joint->type != urdf::Joint::CONTINUOUS &&
            joint->type != urdf::Joint::PRISMATIC) {
          const char* type = joint->type == urdf::Joint::FLOATING ? "floating"
                             : joint->type == urdf::Joint::PLANAR ? "planar"
                                                                  : "unknown";
          throw InputError(field, std::string("has type ") + type +
                                      "; robot trees take revolute, continuous, prismatic and "
                                      "fixed joints; make it fixed or start the tree below it "
                                      "(base_link)");
        }
        const Eigen::Vector3d axis = JointAxis(*joint, field);
        const auto range = JointRange(*joint, field);
        const double lo = range ? range->first : -kInf, hi = range ? range->second : kInf;
        origins.push_back(next.pose.translation());
        axes.push_back((next.pose.linear() * axis).normalized());
        lower.push_back(lo);
        upper.push_back(hi);
        tree.joint_names.push_back(joint->name);
        tree.joint_parents.push_back(at.joint);
        tree.prismatic.push_back(joint->type == urdf::Joint::PRISMATIC ? 1 : 0);
        next.joint = static_cast<int>(tree.joint_parents.size()) - 1;
      }
      stack.push_back({child, next});
    }
  }
  const int n = static_cast<int>(origins.size());
  if (n == 0) {
    throw InputError("base_link",
                     "link " + Quote(base->name) +
                         " has no revolute, continuous or prismatic joint below it; expected "
                         "the link a robot tree is bolted to");
  }
  tree.origins.resize(n, 3);
  tree.axes.resize(n, 3);
  tree.joint_min.resize(n);
  tree.joint_max.resize(n);
  tree.initial.resize(n);
  for (int j = 0; j < n; ++j) {
    tree.origins.row(j) = origins[j].transpose();
    tree.axes.row(j) = axes[j].transpose();
    tree.joint_min[j] = lower[j];
    tree.joint_max[j] = upper[j];
    tree.initial[j] = std::clamp(0.0, lower[j], upper[j]);
  }
  for (size_t k = 0; k < tools.size(); ++k) {
    const std::string field = "tools[" + std::to_string(k) + "]";
    const UrdfTool& want = tools[k];
    const auto at = links.find(want.link);
    if (at == links.end()) {
      throw InputError(field + ".link", "link " + Quote(want.link) +
                                            (robot->getLink(want.link)
                                                 ? " is not below base link " + Quote(base->name)
                                                 : std::string(" is not in the URDF")) +
                                            "; expected a link below the base");
    }
    if (at->second.joint < 0) {
      throw InputError(field + ".link",
                       "link " + Quote(want.link) +
                           " is below no revolute, continuous or prismatic joint; expected "
                           "a link that the joints move");
    }
    if (!want.offset.allFinite()) {
      throw InputError(field + ".offset", "is not finite; expected a point of the link's frame");
    }
    if (!(want.axis.norm() > 0.0) || !want.axis.allFinite()) {
      throw InputError(field + ".axis",
                       "is zero or not finite; expected a direction in the "
                       "link's frame");
    }
    RobotTree::Tool tool;
    tool.link = want.link;
    tool.joint = at->second.joint;
    tool.point = at->second.pose * want.offset;
    tool.frame = at->second.pose.linear();
    tool.axis = want.axis.normalized();
    tree.tools.push_back(tool);
  }
  if (const Problems problems = tree.Validate(); !problems.empty()) {
    throw InputError("urdf", problems.front().Text());
  }
  return tree;
}

RobotTree RobotTreeFromUrdfFile(const std::string& path, const std::string& base_link,
                                const std::vector<UrdfTool>& tools) {
  return RobotTreeFromUrdf(ReadUrdfText(path), base_link, tools);
}

}  // namespace flexkin
