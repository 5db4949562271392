#include "kdl_peer.h"

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_lma.hpp>
#include <kdl/chainiksolverpos_nr.hpp>
#include <kdl/chainiksolvervel_pinv.hpp>
#include <kdl/frames.hpp>
#include <kdl/segment.hpp>
#include <memory>

#include "flexkin/error.h"
#include "kdl_counting_fk.h"

namespace flexkin::peers {
namespace {

using Clock = std::chrono::steady_clock;

KDL::Vector ToKdl(const Eigen::VectorXd& v) {
  return KDL::Vector(v[0], v[1], v.size() > 2 ? v[2] : 0.0);
}

void CheckModel(const ArmModel& model) {
  Problems problems;
  AppendNested("arm", model.Validate(), &problems);
  ThrowIfAny(problems);
  if (model.has_limits()) {
    throw InputError("arm.joint_limits",
                     "KDL's NR and LMA solvers have no joint limits; remove the limits to compare");
  }
}

}  // namespace

const char* KdlSolverName(KdlSolver solver) {
  return solver == KdlSolver::kNewtonPinv ? "kdl_nr_pinv" : "kdl_lma";
}

Problems KdlOptions::Validate() const {
  Problems problems;
  if (!(tolerance > 0.0 && tolerance < 1.0)) {
    problems.push_back(Problem::Invalid("tolerance", FormatNumber(tolerance), "in (0, 1)"));
  }
  if (max_iterations < 1) {
    problems.push_back(Problem::Invalid("max_iterations", std::to_string(max_iterations), ">= 1"));
  }
  if (!(pinv_eps > 0.0)) {
    problems.push_back(Problem::Invalid("pinv_eps", FormatNumber(pinv_eps), "> 0"));
  }
  if (!(lma_eps_joints > 0.0)) {
    problems.push_back(Problem::Invalid("lma_eps_joints", FormatNumber(lma_eps_joints), "> 0"));
  }
  return problems;
}

int KdlJointsPerLink(const ArmModel& model) { return model.dim == 2 ? 1 : 2; }

KDL::Chain KdlChain(const ArmModel& model) {
  CheckModel(model);
  KDL::Rotation base_rotation;
  if (model.dim == 2) {
    base_rotation =
        KDL::Rotation::RotZ(std::atan2(model.base_direction[1], model.base_direction[0]));
  } else {
    // As flexkin's base frame: the smallest rotation taking x to the base direction.
    const Eigen::Quaterniond q = Eigen::Quaterniond::FromTwoVectors(
        Eigen::Vector3d::UnitX(), model.base_direction.head<3>().normalized());
    base_rotation = KDL::Rotation::Quaternion(q.x(), q.y(), q.z(), q.w());
  }
  KDL::Chain chain;
  chain.addSegment(
      KDL::Segment(KDL::Joint(KDL::Joint::None), KDL::Frame(base_rotation, ToKdl(model.base))));
  for (int k = 0; k < model.num_links(); ++k) {
    const KDL::Frame link(KDL::Vector(model.link_lengths[k], 0.0, 0.0));
    if (model.dim == 2) {
      chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::RotZ), link));
    } else {
      chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::RotZ), KDL::Frame::Identity()));
      chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::RotY), link));
    }
  }
  return chain;
}

KDL::JntArray KdlJoints(const ArmModel& model, const JointAngles& angles) {
  const int n = model.num_links();
  if (angles.angle.size() != n || (model.dim == 3 && angles.azimuth.size() != n)) {
    throw InputError("angles",
                     "must have one angle (and in 3D one azimuth) per link, " + std::to_string(n));
  }
  KDL::JntArray q(static_cast<unsigned>(n * KdlJointsPerLink(model)));
  if (model.dim == 2) {
    for (int j = 0; j < n; ++j) q(j) = angles.angle[j];
    return q;
  }
  // Spatial: the universal joint that points each link where flexkin's joint points it, read from
  // the points: link j's direction in the frame after joint j - 1 is Rz(qz) Ry(qy) x =
  // (cos qz cos qy, sin qz cos qy, -sin qy).
  const Points points = ForwardKinematics(model, angles);
  const KDL::Chain chain = KdlChain(model);
  KDL::Rotation frame = chain.getSegment(0).getFrameToTip().M;  // the base frame
  for (int j = 0; j < n; ++j) {
    const Eigen::Vector3d link = (points.row(j + 1) - points.row(j)).transpose();
    const KDL::Vector d = frame.Inverse(KDL::Vector(link[0], link[1], link[2]));
    const double qz = std::atan2(d.y(), d.x());
    const double qy = std::atan2(-d.z(), std::hypot(d.x(), d.y()));
    q(2 * j) = qz;
    q(2 * j + 1) = qy;
    frame = frame * KDL::Rotation::RotZ(qz) * KDL::Rotation::RotY(qy);
  }
  return q;
}

Points KdlPoints(const ArmModel& model, const KDL::Chain& chain, const KDL::JntArray& q) {
  KDL::ChainFkSolverPos_recursive fk(chain);
  std::vector<KDL::Frame> frames(chain.getNrOfSegments());
  if (fk.JntToCart(q, frames) < 0) throw std::runtime_error("KDL forward kinematics failed");
  const int n = model.num_links(), per_link = KdlJointsPerLink(model);
  Points points(n + 1, model.dim);
  for (int k = 0; k <= n; ++k) {
    const KDL::Vector& p = frames[static_cast<size_t>(k * per_link)].p;
    for (int c = 0; c < model.dim; ++c) points(k, c) = p(c);
  }
  return points;
}

KdlTrajectory TrackPathWithKdl(const ArmModel& model, const Points& path, KdlSolver solver,
                               const KdlOptions& options) {
  const KDL::Chain chain = KdlChain(model);
  Problems problems;
  AppendNested("options", options.Validate(), &problems);
  ThrowIfAny(problems);
  if (path.rows() < 1 || path.cols() != model.dim || !path.allFinite()) {
    throw InputError(
        "path", "must be at least one row of " + std::to_string(model.dim) + " finite coordinates");
  }
  const double scale = model.reach() / model.num_links();  // mean link length
  const double tolerance = options.tolerance * scale;

  // The solvers made once for the path, as a controller makes them; LMA needs no velocity solver.
  CountingFk fk(chain);
  std::unique_ptr<KDL::ChainIkSolverVel_pinv> pinv;
  std::unique_ptr<KDL::ChainIkSolverPos> ik;
  KDL::ChainIkSolverPos_LMA* lma = nullptr;
  if (solver == KdlSolver::kNewtonPinv) {
    pinv = std::make_unique<KDL::ChainIkSolverVel_pinv>(chain, options.pinv_eps);
    ik = std::make_unique<KDL::ChainIkSolverPos_NR>(chain, fk, *pinv, options.max_iterations,
                                                    tolerance);
  } else {
    Eigen::Matrix<double, 6, 1> weights;
    weights << 1.0, 1.0, 1.0, 0.0, 0.0, 0.0;  // position only
    auto owned = std::make_unique<KDL::ChainIkSolverPos_LMA>(
        chain, weights, tolerance, options.max_iterations, options.lma_eps_joints);
    lma = owned.get();
    ik = std::move(owned);
  }

  KdlTrajectory result;
  KDL::JntArray q = KdlJoints(model, model.initial);
  double total_iterations = 0;
  // Outside the timed solve: the goal's orientation (NR holds the current one; LMA ignores it,
  // weight 0), and reading the answer back into points and flexkin's angles.
  KDL::ChainFkSolverPos_recursive goal_fk(chain);
  for (Eigen::Index i = 0; i < path.rows(); ++i) {
    KDL::Frame current;
    if (lma == nullptr) goal_fk.JntToCart(q, current);
    KDL::Frame goal(current.M, ToKdl(path.row(i).transpose()));
    KdlStepReport step;
    step.q.resize(q.rows());
    fk.calls = 0;
    const Clock::time_point start = Clock::now();
    step.status = ik->CartToJnt(q, goal, step.q);
    step.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    step.iterations = lma != nullptr ? lma->lastNrOfIter : fk.calls - 1;
    step.status_name = ik->strError(step.status);
    step.points = KdlPoints(model, chain, step.q);
    step.angles = JointAnglesFromPoints(model, step.points);
    step.ee_error = (step.points.row(model.num_links()) - path.row(i)).norm();
    step.reached = step.status >= 0 && step.q.data.allFinite() && step.ee_error <= 2.0 * tolerance;
    // A failed solve keeps its last joints as the next start only when they are finite.
    if (step.q.data.allFinite()) q = step.q;
    result.max_ee_error = std::fmax(result.max_ee_error, step.ee_error);
    result.unreached += step.reached ? 0 : 1;
    result.max_iterations = std::fmax(result.max_iterations, step.iterations);
    total_iterations += step.iterations;
    result.seconds += step.seconds;
    result.steps.push_back(std::move(step));
  }
  result.mean_iterations = total_iterations / static_cast<double>(path.rows());
  return result;
}

}  // namespace flexkin::peers
