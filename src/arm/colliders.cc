// A fixed-base arm among colliders (src/arm/colliders.h).
#include "arm/colliders.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "world/contact.h"

namespace flexkin::arm_internal {
namespace {

std::string FormatPoint(const Eigen::VectorXd& v) {
  std::string text = "[";
  for (int k = 0; k < v.size(); ++k) text += (k > 0 ? ", " : "") + FormatNumber(v[k]);
  return text + "]";
}

Eigen::Vector3d In3d(const Points& points, int i) {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (int k = 0; k < points.cols(); ++k) p[k] = points(i, k);
  return p;
}

double LinkRadius(const ArmModel& model, int k) {
  return model.link_radii.size() > 0 ? model.link_radii[k] : 0.0;
}

}  // namespace

const std::vector<Collider>& CollidersNow(const std::vector<Collider>& colliders, double time,
                                          std::vector<Collider>* storage) {
  if (!AnyMoves(colliders)) return colliders;
  *storage = CollidersAt(colliders, time);
  return *storage;
}

double SweepSkin(const ArmModel& model, const ArmOptions& options) {
  return std::max(2.0 * options.tolerance, 1e-8) * model.link_lengths.mean();
}

std::vector<Collider> SweepColliders(const ArmModel& model, const ArmOptions& options) {
  const double grow = model.max_link_radius() + 2.0 * options.tolerance * model.link_lengths.mean();
  std::vector<Collider> grown = options.colliders;
  for (Collider& c : grown) c.margin += grow;
  return grown;
}

double ArmClearance(const ArmModel& model, const Points& points,
                    const std::vector<Collider>& colliders, double* relative, int* link,
                    int* collider) {
  double least = std::numeric_limits<double>::infinity();
  double least_relative = least;
  for (int k = 0; k < model.num_links(); ++k) {
    const Eigen::Vector3d a = In3d(points, k), b = In3d(points, k + 1);
    const double r = LinkRadius(model, k);
    const double length = model.link_lengths[k];
    for (size_t c = 0; c < colliders.size(); ++c) {
      // A capsule of radius r is outside a convex set by its axis' clearance less r, inside by
      // its depth plus r (the set grown by r is convex, its signed distance the set's less r).
      const double clearance = internal::SegmentClearance(colliders[c], a, b) - r;
      least = std::min(least, clearance);
      const double rel = clearance / length;
      if (rel < least_relative) {
        least_relative = rel;
        if (link != nullptr) *link = k + 1;
        if (collider != nullptr) *collider = static_cast<int>(c);
      }
    }
  }
  if (relative != nullptr) *relative = least_relative;
  return least;
}

void CheckArmOutside(const ArmModel& model, const Points& points,
                     const std::vector<Collider>& colliders, const std::string& field,
                     double time) {
  if (colliders.empty()) return;
  double relative = 0.0;
  int link = 0, collider = 0;
  std::vector<Collider> storage;
  ArmClearance(model, points, CollidersNow(colliders, time, &storage), &relative, &link, &collider);
  if (relative >= -kArmContactSlack) return;
  const double depth = -relative * model.link_lengths[link - 1];
  const std::string when = colliders[collider].motion
                               ? " at time " + FormatNumber(time) + " of its motion"
                               : std::string();
  throw InputError(field, "link " + std::to_string(link) + " (points " + std::to_string(link - 1) +
                              " to " + std::to_string(link) +
                              ", base first) lies inside collider " + std::to_string(collider) +
                              " (" + ColliderShapeName(colliders[collider].shape) + ")" + when +
                              " by " + FormatNumber(depth) +
                              " (length unit, its capsule's radius included); expected a start "
                              "with every link outside every collider");
}

void CheckTargetOutside(const ArmModel& model, const ArmOptions& options,
                        const Eigen::VectorXd& target, const std::string& field) {
  if (options.colliders.empty()) return;
  const int n = model.num_links();
  const double skin = SweepSkin(model, options);
  const double r = LinkRadius(model, n - 1);
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  t.head(target.size()) = target;
  for (size_t c = 0; c < options.colliders.size(); ++c) {
    if (options.colliders[c].motion) continue;  // blocks the steps where it is on the target
    const double d = QuerySurface(options.colliders[c], t).distance - r;
    if (d < skin) {
      throw InputError(field, "the target " + FormatPoint(target) + " lies inside collider " +
                                  std::to_string(c) + " (" +
                                  ColliderShapeName(options.colliders[c].shape) + ") by " +
                                  FormatNumber(-d) + " (the end effector's link radius " +
                                  FormatNumber(r) + " included); expected a target at least " +
                                  FormatNumber(skin) + " outside every collider");
    }
  }
}

}  // namespace flexkin::arm_internal
