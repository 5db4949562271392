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

}  // namespace flexkin
