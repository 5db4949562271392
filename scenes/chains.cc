// Chains and leader paths of the tests and benchmarks (scenes/scenes.h).
#include <cmath>

#include "flexkin/curves.h"
#include "scenes/scenes.h"

namespace flexkin::scenes {

Chain PaperParabola() {
  const ParabolaDef def;  // a = 1, toward +x, 20 links of 0.25
  return MakeEqualLinkChain(MakeParabola(def), def.link_length);
}

Points PaperParabolaByBisection() {
  Points p(21, 2);
  p.row(0) << 0.0, 0.0;
  for (int i = 1; i <= 20; ++i) {
    double lo = p(i - 1, 0), hi = lo + 0.25;
    for (int it = 0; it < 200; ++it) {
      const double mid = 0.5 * (lo + hi);
      (std::hypot(mid - p(i - 1, 0), mid * mid - p(i - 1, 1)) < 0.25 ? lo : hi) = mid;
    }
    p.row(i) << lo, lo * lo;
  }
  return p;
}

Eigen::Vector2d PaperPull(double distance) {
  return Eigen::Vector2d(distance / std::sqrt(2.0), distance / std::sqrt(2.0));
}

Points CurvedPoints(int dim, int links, double radius, double turn) {
  Points p(links + 1, dim);
  for (int i = 0; i <= links; ++i) {
    const double a = turn * i;
    p(i, 0) = radius * std::cos(a);
    p(i, 1) = radius * std::sin(a);
    if (dim == 3) p(i, 2) = 0.02 * radius * i + 0.01 * radius * std::sin(3.0 * a);
  }
  return p;
}

Chain CurvedChain(int dim, int links, double radius, double turn) {
  return MakeChain(CurvedPoints(dim, links, radius, turn));
}

Points StraightPull(const Eigen::VectorXd& start, const Eigen::VectorXd& direction, double distance,
                    int steps) {
  Points targets(steps, start.size());
  for (int s = 1; s <= steps; ++s) {
    targets.row(s - 1) = (start + (distance * s / steps) * direction).transpose();
  }
  return targets;
}

Chain RandomSmoothChain(int dim, int links, double bend, std::mt19937* rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Chain chain;
  chain.points.resize(links + 1, dim);
  chain.points.row(0).setZero();
  chain.lengths.resize(links);
  Eigen::VectorXd direction = Eigen::VectorXd::Zero(dim);
  direction[0] = 1.0;
  for (int i = 1; i <= links; ++i) {
    Eigen::VectorXd turn(dim);
    for (int k = 0; k < dim; ++k) turn[k] = unit(*rng);
    turn -= turn.dot(direction) * direction;
    direction = (direction + bend * turn).normalized();
    chain.lengths[i - 1] = 1.0 + 0.5 * unit(*rng);
    chain.points.row(i) = chain.points.row(i - 1) + chain.lengths[i - 1] * direction.transpose();
  }
  return chain;
}

Chain Helix(int links) {
  HelixDef def;
  def.radius = 1.0;
  def.pitch = 0.5;
  def.links = links;
  def.link_length = 0.25;
  return MakeEqualLinkChain(MakeHelix(def), def.link_length);
}

Chain Coil(int links) {
  Points p(links + 1, 3);
  for (int i = 0; i <= links; ++i) p.row(i) << std::cos(0.3 * i), std::sin(0.3 * i), 0.05 * i;
  return MakeChain(p);
}

}  // namespace flexkin::scenes
