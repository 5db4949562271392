#include "kdl_urdf_peer.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_lma.hpp>
#include <kdl/chainiksolverpos_nr.hpp>
#include <kdl/chainiksolvervel_pinv.hpp>
#include <kdl/frames.hpp>
#include <kdl/segment.hpp>
#include <kdl/tree.hpp>
#include <kdl/treefksolverpos_recursive.hpp>
#include <kdl_parser/kdl_parser.hpp>
#include <limits>
#include <memory>
#include <stdexcept>

#include "kdl_counting_fk.h"

namespace flexkin::peers {
namespace {

using Clock = std::chrono::steady_clock;

Eigen::Vector3d FromKdl(const KDL::Vector& v) { return Eigen::Vector3d(v.x(), v.y(), v.z()); }

Eigen::Matrix3d FromKdl(const KDL::Rotation& r) {
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) m(i, k) = r(i, k);
  }
  return m;
}

KDL::Rotation ToKdl(const Eigen::Matrix3d& m) {
  return KDL::Rotation(m(0, 0), m(0, 1), m(0, 2), m(1, 0), m(1, 1), m(1, 2), m(2, 0), m(2, 1),
                       m(2, 2));
}

// The angle (rad) of the rotation taking a to b.
double AngleBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::Quaterniond(a).angularDistance(Eigen::Quaterniond(b));
}

// The one leaf of the tree below `root` (kdl_parser's tree has a segment per link).
std::string OnlyLeafBelow(const KDL::Tree& tree, const std::string& root) {
  std::string leaf;
  auto element = tree.getSegment(root);
  while (true) {
    const auto& children = GetTreeElementChildren(element->second);
    if (children.empty()) return element->first;
    if (children.size() > 1) {
      throw std::runtime_error("kdl_urdf_peer: link \"" + element->first +
                               "\" branches; name the tip link");
    }
    element = children.front();
  }
}

}  // namespace

KdlUrdfChain KdlChainFromUrdf(const std::string& urdf_text, const std::string& base_link,
                              const std::string& tip_link, const Eigen::Vector3d& tip_offset) {
  KDL::Tree tree;
  if (!kdl_parser::treeFromString(urdf_text, tree)) {
    throw std::runtime_error("kdl_parser could not read the URDF");
  }
  const std::string base = base_link.empty() ? tree.getRootSegment()->first : base_link;
  if (tree.getSegment(base) == tree.getSegments().end()) {
    throw std::runtime_error("kdl_urdf_peer: no link \"" + base + "\"");
  }
  const std::string tip = tip_link.empty() ? OnlyLeafBelow(tree, base) : tip_link;
  KdlUrdfChain result;
  if (!tree.getChain(base, tip, result.chain)) {
    throw std::runtime_error("kdl_urdf_peer: no chain from \"" + base + "\" to \"" + tip + "\"");
  }
  result.chain.addSegment(
      KDL::Segment("flexkin_tool_point", KDL::Joint(KDL::Joint::None),
                   KDL::Frame(KDL::Vector(tip_offset[0], tip_offset[1], tip_offset[2]))));
  for (unsigned s = 0; s < result.chain.getNrOfSegments(); ++s) {
    const KDL::Joint& joint = result.chain.getSegment(s).getJoint();
    if (joint.getType() == KDL::Joint::None) continue;
    result.joint_segments.push_back(static_cast<int>(s));
    result.joint_names.push_back(joint.getName());
  }
  return result;
}

KDL::JntArray KdlJointArray(const Eigen::VectorXd& angle) {
  KDL::JntArray q(static_cast<unsigned>(angle.size()));
  q.data = angle;
  return q;
}

Eigen::VectorXd AnglesOfJointArray(const KDL::JntArray& q) { return q.data; }

KdlUrdfPose KdlUrdfForward(const KdlUrdfChain& chain, const KDL::JntArray& q) {
  const int n = chain.num_joints();
  if (static_cast<int>(q.rows()) != n) {
    throw std::invalid_argument("KdlUrdfForward: " + std::to_string(q.rows()) +
                                " joint values for " + std::to_string(n) + " joints");
  }
  KDL::ChainFkSolverPos_recursive fk(chain.chain);
  // frames[s]: the frame at the tip of segment s (the child link's frame of its joint).
  std::vector<KDL::Frame> frames(chain.chain.getNrOfSegments());
  if (fk.JntToCart(q, frames) < 0) throw std::runtime_error("KDL forward kinematics failed");
  KdlUrdfPose pose;
  pose.points.resize(n + 1, 3);
  for (int j = 0; j < n; ++j) {
    const int s = chain.joint_segments[j];
    // The joint's origin in its parent link's frame (kdl_parser's joints carry it), taken to the
    // base by the parent link's frame: the tip of segment s - 1, or the base for s = 0.
    const KDL::Vector origin = chain.chain.getSegment(s).getJoint().JointOrigin();
    const KDL::Vector world = s == 0 ? origin : frames[s - 1] * origin;
    pose.points.row(j) = FromKdl(world).transpose();
  }
  pose.points.row(n) = FromKdl(frames.back().p).transpose();
  pose.tip_rotation = FromKdl(frames.back().M);
  return pose;
}

const char* KdlUrdfSolverName(KdlUrdfSolver solver) {
  return solver == KdlUrdfSolver::kNewtonPinv ? "kdl_nr_pinv" : "kdl_lma";
}

KdlUrdfTrajectory TrackUrdfPathWithKdl(const KdlUrdfChain& chain, const Eigen::VectorXd& start,
                                       const Points& path, KdlUrdfSolver solver,
                                       const KdlUrdfOptions& options,
                                       const std::vector<Eigen::Matrix3d>& target_rotations) {
  const int n = chain.num_joints();
  if (start.size() != n) {
    throw std::invalid_argument("TrackUrdfPathWithKdl: start has " + std::to_string(start.size()) +
                                " values for " + std::to_string(n) + " joints");
  }
  if (path.cols() != 3 || path.rows() < 1 || !path.allFinite()) {
    throw std::invalid_argument("TrackUrdfPathWithKdl: path must be m >= 1 rows of 3 numbers");
  }
  const bool pointing = !target_rotations.empty();
  if (pointing && static_cast<Eigen::Index>(target_rotations.size()) != path.rows()) {
    throw std::invalid_argument("TrackUrdfPathWithKdl: one target rotation per path row");
  }

  // The solvers made once for the path, as a controller makes them; LMA needs no velocity solver.
  CountingFk fk(chain.chain);
  std::unique_ptr<KDL::ChainIkSolverVel_pinv> pinv;
  std::unique_ptr<KDL::ChainIkSolverPos> ik;
  KDL::ChainIkSolverPos_LMA* lma = nullptr;
  if (solver == KdlUrdfSolver::kNewtonPinv) {
    pinv = std::make_unique<KDL::ChainIkSolverVel_pinv>(chain.chain, options.pinv_eps);
    ik = std::make_unique<KDL::ChainIkSolverPos_NR>(chain.chain, fk, *pinv, options.max_iterations,
                                                    options.tolerance);
  } else {
    Eigen::Matrix<double, 6, 1> weights;
    const double w = pointing ? options.rotation_weight : 0.0;
    weights << 1.0, 1.0, 1.0, w, w, w;
    auto owned = std::make_unique<KDL::ChainIkSolverPos_LMA>(
        chain.chain, weights, options.tolerance, options.max_iterations, options.lma_eps_joints);
    lma = owned.get();
    ik = std::move(owned);
  }

  KdlUrdfTrajectory result;
  KDL::JntArray q = KdlJointArray(start);
  double total_iterations = 0.0;
  // Outside the timed solve: the goal's orientation (NR, position only, holds the current one;
  // LMA's weights ignore it) and the end effector read back from the answer.
  KDL::ChainFkSolverPos_recursive check_fk(chain.chain);
  for (Eigen::Index i = 0; i < path.rows(); ++i) {
    KDL::Frame current;
    if (!pointing && lma == nullptr) check_fk.JntToCart(q, current);
    const KDL::Vector target(path(i, 0), path(i, 1), path(i, 2));
    // Position only: hold the orientation (NR needs one; LMA's weights ignore it).
    const KDL::Frame goal(pointing ? ToKdl(target_rotations[i]) : current.M, target);
    KdlUrdfStep step;
    KDL::JntArray out(q.rows());
    fk.calls = 0;
    const Clock::time_point t0 = Clock::now();
    step.status = ik->CartToJnt(q, goal, out);
    step.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    step.iterations = lma != nullptr ? lma->lastNrOfIter : fk.calls - 1;
    step.status_name = ik->strError(step.status);
    step.angles = out.data;
    const bool finite = out.data.allFinite();
    if (finite) {
      KDL::Frame reached;
      check_fk.JntToCart(out, reached);
      step.end_effector = FromKdl(reached.p);
      step.tip_rotation = FromKdl(reached.M);
      step.ee_error = (step.end_effector - path.row(i).transpose()).norm();
      if (pointing) step.angle_error = AngleBetween(step.tip_rotation, target_rotations[i]);
      q = out;  // the next start; a failed solve with non-finite joints keeps the last ones
    } else {
      step.ee_error = step.angle_error = std::numeric_limits<double>::infinity();
    }
    step.reached = step.status >= 0 && finite && step.ee_error <= 2.0 * options.tolerance &&
                   (!pointing || step.angle_error <= options.angle_tolerance);
    result.max_ee_error = std::fmax(result.max_ee_error, step.ee_error);
    result.max_angle_error = std::fmax(result.max_angle_error, step.angle_error);
    result.unreached += step.reached ? 0 : 1;
    result.max_iterations = std::max(result.max_iterations, step.iterations);
    total_iterations += step.iterations;
    result.seconds += step.seconds;
    result.steps.push_back(std::move(step));
  }
  result.mean_iterations = total_iterations / static_cast<double>(path.rows());
  return result;
}

KdlUrdfTree KdlTreeFromUrdf(const std::string& urdf_text) {
  KdlUrdfTree out;
  if (!kdl_parser::treeFromString(urdf_text, out.tree)) {
    throw std::runtime_error("kdl_parser could not read the URDF");
  }
  out.joint_names.resize(out.tree.getNrOfJoints());
  for (const auto& [name, element] : out.tree.getSegments()) {
    const KDL::Segment& segment = GetTreeElementSegment(element);
    if (segment.getJoint().getType() != KDL::Joint::None) {
      out.joint_names.at(GetTreeElementQNr(element)) = segment.getJoint().getName();
    }
  }
  return out;
}

KDL::JntArray KdlTreeJoints(const KdlUrdfTree& tree, const std::vector<std::string>& names,
                            const Eigen::VectorXd& angles) {
  KDL::JntArray q(tree.num_joints());
  for (int i = 0; i < tree.num_joints(); ++i) {
    for (size_t j = 0; j < names.size(); ++j) {
      if (names[j] == tree.joint_names[i]) q(i) = angles[static_cast<Eigen::Index>(j)];
    }
  }
  return q;
}

KdlLinkPose KdlTreeLinkPose(const KdlUrdfTree& tree, const KDL::JntArray& q,
                            const std::string& link) {
  KDL::TreeFkSolverPos_recursive fk(tree.tree);
  KDL::Frame frame;
  if (fk.JntToCart(q, frame, link) < 0) throw std::runtime_error("KDL has no link " + link);
  return {FromKdl(frame.M), FromKdl(frame.p)};
}

std::string KdlTreeChildLink(const KdlUrdfTree& tree, const std::string& joint) {
  for (const auto& [name, element] : tree.tree.getSegments()) {
    if (GetTreeElementSegment(element).getJoint().getName() == joint) return name;
  }
  return "";
}

}  // namespace flexkin::peers
