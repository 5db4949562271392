#include "flexkin/link_step.h"

#include <cmath>
#include <cstdio>
#include <string>

#include "flexkin/error.h"
#include "sequential/link_rules.h"

namespace flexkin {
namespace {

template <class Vec>
void CheckFinite(const Vec& x, const char* field) {
  for (int k = 0; k < x.size(); ++k) {
    if (!std::isfinite(x[k])) {
      throw InputError(std::string(field) + "[" + std::to_string(k) + "]",
                       "value " + FormatNumber(x[k]) + " is not a finite number");
    }
  }
}

template <int Dim, class Vec>
Vec Apply(void (*rule)(const double*, const double*, double*, double, double), const Vec& head_old,
          const Vec& head_new, const Vec& tail, double length) {
  CheckFinite(head_old, "head_old");
  CheckFinite(head_new, "head_new");
  CheckFinite(tail, "tail");
  if (!(length > 0.0) || !std::isfinite(length)) {
    throw InputError("length",
                     "link length " + FormatNumber(length) + " is not a positive finite number");
  }
  Vec out = tail;
  rule(head_old.data(), head_new.data(), out.data(), length, 1.0 / length);
  return out;
}

}  // namespace

Eigen::Vector2d TractrixStep(const Eigen::Vector2d& head_old, const Eigen::Vector2d& head_new,
                             const Eigen::Vector2d& tail, double length) {
  return Apply<2>(internal::TractrixStep<2>, head_old, head_new, tail, length);
}
Eigen::Vector3d TractrixStep(const Eigen::Vector3d& head_old, const Eigen::Vector3d& head_new,
                             const Eigen::Vector3d& tail, double length) {
  return Apply<3>(internal::TractrixStep<3>, head_old, head_new, tail, length);
}
Eigen::Vector2d FollowTheLeaderStep(const Eigen::Vector2d& head_old,
                                    const Eigen::Vector2d& head_new, const Eigen::Vector2d& tail,
                                    double length) {
  return Apply<2>(internal::FollowTheLeaderStep<2>, head_old, head_new, tail, length);
}
Eigen::Vector3d FollowTheLeaderStep(const Eigen::Vector3d& head_old,
                                    const Eigen::Vector3d& head_new, const Eigen::Vector3d& tail,
                                    double length) {
  return Apply<3>(internal::FollowTheLeaderStep<3>, head_old, head_new, tail, length);
}

}  // namespace flexkin
