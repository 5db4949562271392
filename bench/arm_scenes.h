#pragma once
// The arm scenes of the arm benchmarks (bench/arm_benchmark.cc, bench/arm_kdl_benchmark.cc),
// defined once.

#include <cmath>

#include "flexkin/arm.h"

namespace flexkin::bench {

// An arm of `links` unit links bent into a circular arc whose end effector is at
// `reach_fraction` of the reach from the base (in (0, 1)): an arc of total turn phi has chord
// reach * sin(phi/2) / (phi/2), solved for phi by bisection. dim 2: planar, revolute joints;
// dim 3: spherical joints, the arc in the x-y plane (every bend about azimuth 0).
inline ArmModel ArcArm(int links, double reach_fraction, int dim = 2) {
  double lo = 1e-9, hi = 2.0 * M_PI;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::sin(0.5 * mid) / (0.5 * mid) > reach_fraction ? lo : hi) = mid;
  }
  ArmModel model = StraightArm(dim, links, 1.0);
  model.initial.angle.setConstant(lo / links);
  return model;
}

}  // namespace flexkin::bench
