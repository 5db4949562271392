// Fixed-base arms and end-effector paths of the tests and benchmarks (scenes/scenes.h).
#include <algorithm>
#include <cmath>

#include "scenes/scenes.h"

namespace flexkin::scenes {

ArmModel ArcArm(int dim, int links, double turn, double azimuth) {
  ArmModel model = StraightArm(dim, links, 1.0);
  model.initial.angle.setConstant(turn);
  if (dim == 3) model.initial.azimuth.setConstant(azimuth);
  return model;
}

double ArcTurnForReach(int links, double reach_fraction) {
  double lo = 1e-9, hi = 2.0 * M_PI;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::sin(0.5 * mid) / (0.5 * mid) > reach_fraction ? lo : hi) = mid;
  }
  return lo / links;
}

ArmModel CurledArm(int dim, int links, double turn) {
  if (dim == 2) return ArcArm(2, links, turn);
  ArmModel model = StraightArm(dim, links, 1.0);
  model.initial.angle.setConstant(std::abs(turn));
  for (int j = 0; j < links; ++j) {
    model.initial.azimuth[j] = 0.3 * j - M_PI * std::floor(0.3 * j / M_PI);
  }
  return model;
}

ArmModel RevoluteSnake(int links) {
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

ArmModel LimitedArm(int dim, int links, double limit, double turn) {
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

Points CircleOfTargets(const ArmModel& model, double radius, int count, CircleTilt tilt,
                       int turns) {
  const Points start = ForwardKinematics(model, model.initial);
  const Eigen::VectorXd ee = start.row(model.num_links()).transpose();
  Points path(count, model.dim);
  for (int i = 0; i < count; ++i) {
    const double a = 2.0 * M_PI * turns * (i + 1) / count;
    const double sine = radius * std::sin(a);
    Eigen::VectorXd p = ee;
    p[0] += radius * (std::cos(a) - 1.0);
    if (model.dim == 2 || tilt != CircleTilt::kTilted45) {
      p[1] += sine;
    } else {
      p[1] += sine * std::sqrt(0.5);
    }
    if (model.dim == 3 && tilt == CircleTilt::kRising) p[2] += 0.5 * sine;
    if (model.dim == 3 && tilt == CircleTilt::kTilted45) p[2] += sine * std::sqrt(0.5);
    path.row(i) = p.transpose();
  }
  return path;
}

Points SaturatingPath(const ArmModel& model, double limit, int count, std::mt19937* rng) {
  const int n = model.num_links(), dim = model.dim;
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::VectorXd phase(n), rate(n), amplitude(n), azimuth(n);
  for (int j = 0; j < n; ++j) {
    phase[j] = 3.0 * unit(*rng);
    rate[j] = 1.0 + 0.5 * unit(*rng);
    amplitude[j] = 1.6 * limit * unit(*rng);
    azimuth[j] = 3.0 * unit(*rng);
  }
  Points path(count, dim);
  for (int i = 0; i < count; ++i) {
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

}  // namespace flexkin::scenes
