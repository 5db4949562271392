#pragma once
// Arm scenes shared by the arm tests.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <random>

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

// Planar (dim 2, limits +-limit) or spherical (dim 3, bend cone `limit`) unit links, every joint
// turned by `turn` (spherical: about azimuths 0.5 j).
inline ArmModel LimitedArm(int dim, int links, double limit, double turn) {
  ArmModel model = StraightArm(dim, links, 1.0);
  if (dim == 2) {
    model.joint_min = Eigen::VectorXd::Constant(links, -limit);
    model.joint_max = Eigen::VectorXd::Constant(links, limit);
  } else {
    model.max_bend = Eigen::VectorXd::Constant(links, limit);
    for (int j = 0; j < links; ++j) model.initial.azimuth[j] = std::remainder(0.5 * j, 2.0 * M_PI);
  }
  model.initial.angle.setConstant(turn);
  return model;
}

// m targets of a LimitedArm(dim, n, limit, ...) whose joints swing beyond their limits and are
// held there: each joint a sine of amplitude up to 1.6 x the limit (random phase and rate),
// clamped into the limits (spherical: the bend, about a slowly turning random azimuth), 0.05
// rad of phase a step. Reachable by construction: end effectors of angles within the limits.
inline Points SaturatingPath(const ArmModel& model, double limit, int m, std::mt19937* rng) {
  const int n = model.num_links(), dim = model.dim;
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::VectorXd phase(n), rate(n), amplitude(n), azimuth(n);
  for (int j = 0; j < n; ++j) {
    phase[j] = 3.0 * unit(*rng);
    rate[j] = 1.0 + 0.5 * unit(*rng);
    amplitude[j] = 1.6 * limit * unit(*rng);
    azimuth[j] = 3.0 * unit(*rng);
  }
  Points path(m, dim);
  for (int i = 0; i < m; ++i) {
    const double t = 0.05 * i;
    JointAngles a = model.initial;
    for (int j = 0; j < n; ++j) {
      const double swing = amplitude[j] * std::sin(rate[j] * t + phase[j]);
      a.angle[j] = dim == 2 ? std::clamp(swing, -limit, limit) : std::min(std::abs(swing), limit);
      if (dim == 3) a.azimuth[j] = std::remainder(azimuth[j] + 0.3 * t, 2.0 * M_PI);
    }
    path.row(i) = ForwardKinematics(model, a).row(n);
  }
  return path;
}

}  // namespace flexkin
