#pragma once
// Arm scenes shared by the arm tests.

#include <Eigen/Core>
#include <cmath>

#include "flexkin/arm.h"

namespace flexkin {

// A planar arm of `links` unit links bent into an arc (every joint turned by `turn`, rad).
inline ArmModel Arc(int links, double turn) {
  ArmModel model = StraightArm(2, links, 1.0);
  model.initial.angle.setConstant(turn);
  return model;
}

// m targets on a circle of radius `radius` through the end effector's start, the last one back
// at the start.
inline Points Circle(const ArmModel& model, double radius, int m) {
  const Points start = ForwardKinematics(model, model.initial);
  const Eigen::VectorXd ee = start.row(model.num_links()).transpose();
  Points path(m, model.dim);
  for (int i = 0; i < m; ++i) {
    const double a = 2.0 * M_PI * (i + 1) / m;
    Eigen::VectorXd p = ee;
    p[0] += radius * (std::cos(a) - 1.0);
    p[1] += radius * std::sin(a);
    path.row(i) = p.transpose();
  }
  return path;
}

// A pitch/yaw snake of unit links: joint axes alternately y and z, limits +-0.6 rad, gently
// curled (0.15 and 0.1 rad).
inline ArmModel RevoluteSnake(int links) {
  ArmModel m = StraightArm(3, links, 1.0);
  m.initial.azimuth.resize(0);
  m.joint_axes.resize(links, 3);
  for (int j = 0; j < links; ++j) {
    m.joint_axes.row(j) = j % 2 == 0 ? Eigen::RowVector3d::UnitY() : Eigen::RowVector3d::UnitZ();
    m.initial.angle[j] = j % 2 == 0 ? 0.15 : 0.1;
  }
  m.joint_min = Eigen::VectorXd::Constant(links, -0.6);
  m.joint_max = Eigen::VectorXd::Constant(links, 0.6);
  return m;
}

}  // namespace flexkin
