#include "arm_metrics.h"

#include <Eigen/Geometry>
#include <cmath>

#include "flexkin/error.h"

namespace flexkin::peers {

Eigen::VectorXd JointMotionStep(const ArmModel& model, const JointAngles& from,
                                const JointAngles& to) {
  const int n = model.num_links();
  if (from.angle.size() != n || to.angle.size() != n) {
    throw InputError("angles", "must have one angle per link, " + std::to_string(n));
  }
  Eigen::VectorXd motion(n);
  if (model.dim == 2) {
    for (int j = 0; j < n; ++j) {
      // remainder() wraps the difference into [-pi, pi].
      motion[j] = std::fabs(std::remainder(to.angle[j] - from.angle[j], 2.0 * M_PI));
    }
    return motion;
  }
  const Eigen::MatrixXd a = JointQuaternions(model, from), b = JointQuaternions(model, to);
  for (int j = 0; j < n; ++j) {
    const Eigen::Quaterniond qa(a(j, 0), a(j, 1), a(j, 2), a(j, 3));
    const Eigen::Quaterniond qb(b(j, 0), b(j, 1), b(j, 2), b(j, 3));
    motion[j] = qa.angularDistance(qb);
  }
  return motion;
}

Eigen::VectorXd TotalJointMotion(const ArmModel& model, const JointAngles& start,
                                 const std::vector<JointAngles>& steps) {
  Eigen::VectorXd total = Eigen::VectorXd::Zero(model.num_links());
  const JointAngles* previous = &start;
  for (const JointAngles& angles : steps) {
    total += JointMotionStep(model, *previous, angles);
    previous = &angles;
  }
  return total;
}

std::vector<JointAngles> AnglesOf(const ArmTrajectory& trajectory) {
  std::vector<JointAngles> angles;
  angles.reserve(trajectory.steps.size());
  for (const ArmStepReport& step : trajectory.steps) angles.push_back(step.state.angles);
  return angles;
}

}  // namespace flexkin::peers
