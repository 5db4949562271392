#pragma once
// An independent solution of the contact step (world/contact.h) for the tests: IPOPT on the same
// constrained minimization, written out for spheres, the one collider whose segment distance has
// a simple gradient. Minimize |x - tail|^2 subject to |x - head|^2 = length^2 and, for each
// sphere (center c, radius r), the distance from c to the segment [head, x] >= r.
#include <Eigen/Core>
#include <vector>

namespace flexkin::peers {

struct SphereObstacle {
  Eigen::Vector3d center;
  double radius;
};

// Solved from `start` to IPOPT's tolerance 1e-14; true if IPOPT reports success.
bool IpoptContactTail(const Eigen::Vector3d& head, const Eigen::Vector3d& tail, double length,
                      const std::vector<SphereObstacle>& spheres, const Eigen::Vector3d& start,
                      Eigen::Vector3d* x);

}  // namespace flexkin::peers
