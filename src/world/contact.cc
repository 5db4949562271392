// A link against the colliders (src/world/contact.h, docs/colliders.md).
#include "world/contact.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include "world/mesh_collider.h"

namespace flexkin::internal {
namespace {

using Eigen::Vector3d;

// The closest points of the segments [p, q] and [r, s]: parameters (t, u) of p + t (q - p) and
// r + u (s - r) in [0, 1], minimizing the distance (the convex quadratic in (t, u) on the unit
// square: its minimum on an edge when the interior one is outside).
double SegmentSegmentDistance(const Vector3d& p, const Vector3d& q, const Vector3d& r,
                              const Vector3d& s, double* t_out = nullptr, double* u_out = nullptr) {
  const Vector3d d1 = q - p, d2 = s - r, w = p - r;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(w);
  double t = 0.0, u = 0.0;
  if (t_out != nullptr) *t_out = 0.0;
  if (u_out != nullptr) *u_out = 0.0;
  if (a == 0.0 && e == 0.0) return w.norm();
  if (a == 0.0) {
    u = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(w);
    if (e == 0.0) {
      t = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      t = denom > 0.0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      u = (b * t + f) / e;
      if (u < 0.0) {
        u = 0.0;
        t = std::clamp(-c / a, 0.0, 1.0);
      } else if (u > 1.0) {
        u = 1.0;
        t = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  double distance = (p + t * d1 - (r + u * d2)).norm();
  // Nearly parallel segments (the angle between them below about 0.01): a e - b^2 cancels, and the
  // (t, u) above may lie anywhere along the flat valley of the distance, by up to the segments'
  // tilt times their length more than its least value. That least value is then on an edge of
  // the square (an end against the other segment; the interior is flat to within the rounding),
  // and each edge's least value is a well-conditioned point-segment distance.
  if (a > 0.0 && e > 0.0) {
    const double b = d1.dot(d2);
    if (a * e - b * b <= 1e-4 * a * e) {
      const auto edge = [&](double te, double ue) {
        const double d = (p + te * d1 - (r + ue * d2)).norm();
        if (d < distance) distance = d, t = te, u = ue;
      };
      edge(0.0, std::clamp(f / e, 0.0, 1.0));                // p against [r, s]
      edge(1.0, std::clamp((f + b) / e, 0.0, 1.0));          // q against [r, s]
      edge(std::clamp(-d1.dot(w) / a, 0.0, 1.0), 0.0);       // r against [p, q]
      edge(std::clamp((b - d1.dot(w)) / a, 0.0, 1.0), 1.0);  // s against [p, q]
    }
  }
  if (t_out != nullptr) *t_out = t;
  if (u_out != nullptr) *u_out = u;
  return distance;
}

// The minimum of the signed distance along [a, b] by golden-section search (the function is
// convex), with the ends (the collider's margin included): the least of the values evaluated.
//
// Given a finite `threshold`, it answers only whether that minimum lies below it, from the same
// evaluations in the same order, stopping as soon as they tell: it returns a value below the
// threshold if the minimum is, else one above it. The result is the least of the values evaluated
// (the golden-section pair always holds the least interior value so far, and the ends are in the
// minimum), so one below the threshold answers yes. The function is convex, so on the bracket
// [lo, hi] with its inner pair x1 < x2 it lies above the chord of (x1, x2) extended beyond them,
// and between them above the larger of the chords (lo, x1) and (x2, hi) extended: the least of
// these bounds the minimum from below, and a bound above the threshold, by a margin of 1e-12 of
// the values' scale (the queries' rounding, which the golden-section ratios amplify at most
// threefold), answers no. Near the threshold it runs to the end as the full search.
double ConvexMinimumAlong(const Collider& c, const Vector3d& a, const Vector3d& b,
                          double threshold = -std::numeric_limits<double>::infinity()) {
  const Eigen::Isometry3d to_local = c.pose.inverse(Eigen::Isometry);
  const auto f = [&](double t) { return SurfaceDistance(c, to_local, a + t * (b - a)); };
  const bool stop_early = std::isfinite(threshold);
  const double f0 = f(0.0);
  if (f0 < threshold || a == b) return f0;
  const double f_end = f(1.0);
  if (f_end < threshold) return f_end;
  const double scale = (b - a).norm() + std::fabs(f0) + std::fabs(f_end) + std::fabs(threshold);
  const double margin = 1e-12 * scale;
  constexpr double kInvPhi = 0.6180339887498949;
  double lo = 0.0, hi = 1.0, f_lo = f0, f_hi = f_end;
  double x1 = hi - kInvPhi * (hi - lo), x2 = lo + kInvPhi * (hi - lo);
  double f1 = f(x1);
  if (f1 < threshold) return f1;
  double f2 = f(x2);
  if (f2 < threshold) return f2;
  // A lower bound of the minimum on [lo, hi] from the four values there.
  const auto lower_bound = [&]() {
    // The chord of (x1, x2), extended to lo and to hi.
    const double s12 = (f2 - f1) / (x2 - x1);
    double bound = std::min({f1, f2, f1 + s12 * (lo - x1), f2 + s12 * (hi - x2)});
    // Between x1 and x2: above max(left, right), the chords of (lo, x1) and (x2, hi) extended;
    // the least of that maximum on [x1, x2] is at an end or where they cross.
    const double left_slope = (f1 - f_lo) / (x1 - lo), right_slope = (f_hi - f2) / (hi - x2);
    const auto left = [&](double t) { return f1 + left_slope * (t - x1); };
    const auto right = [&](double t) { return f2 + right_slope * (t - x2); };
    double inner = std::min(std::max(left(x1), right(x1)), std::max(left(x2), right(x2)));
    if (right_slope > left_slope) {
      const double cross =
          (f1 - f2 + right_slope * x2 - left_slope * x1) / (right_slope - left_slope);
      if (cross > x1 && cross < x2) inner = std::min(inner, left(cross));
    }
    return std::min(bound, inner);
  };
  for (int i = 0; i < 90 && hi - lo > 1e-15; ++i) {
    if (stop_early) {
      const double bound = lower_bound();
      if (std::isfinite(bound) && bound > threshold + margin) return bound;
    }
    if (f1 <= f2) {
      hi = x2;
      f_hi = f2;
      x2 = x1;
      f2 = f1;
      x1 = hi - kInvPhi * (hi - lo);
      f1 = f(x1);
      if (f1 < threshold) return f1;
    } else {
      lo = x1;
      f_lo = f1;
      x1 = x2;
      f1 = f2;
      x2 = lo + kInvPhi * (hi - lo);
      f2 = f(x2);
      if (f2 < threshold) return f2;
    }
  }
  return std::min({f1, f2, f0, f_end});
}

}  // namespace

double SegmentClearance(const Collider& c, const Vector3d& a, const Vector3d& b) {
  switch (c.shape) {
    case ColliderShape::kSphere: {
      const Vector3d center = c.pose.translation(), ab = b - a;
      const double ab2 = ab.squaredNorm();
      const double t = ab2 > 0.0 ? std::clamp((center - a).dot(ab) / ab2, 0.0, 1.0) : 0.0;
      return (a + t * ab - center).norm() - (c.radius + c.margin);
    }
    case ColliderShape::kCapsule: {
      const Vector3d axis = c.pose.linear().col(2) * c.half_length;
      const Vector3d center = c.pose.translation();
      return SegmentSegmentDistance(a, b, center - axis, center + axis) - (c.radius + c.margin);
    }
    case ColliderShape::kHalfSpace: {
      const Vector3d up = c.pose.linear().col(2), origin = c.pose.translation();
      return std::min(up.dot(a - origin), up.dot(b - origin)) - c.margin;
    }
    case ColliderShape::kEllipsoid:
    case ColliderShape::kCylinder:
    case ColliderShape::kBox:
      return ConvexMinimumAlong(c, a, b);  // the margin is in QuerySurface's distances
    case ColliderShape::kMesh: {           // not convex: world/mesh_collider.h, in the mesh's frame
      const Eigen::Isometry3d to_local = c.pose.inverse(Eigen::Isometry);
      return c.scale *
                 MeshSegmentClearance(*c.mesh, to_local * a / c.scale, to_local * b / c.scale) -
             c.margin;
    }
  }
  return 0.0;
}

namespace {

// Whether a link's least signed distance to an ellipsoid, a cylinder or a box, less its margin,
// lies below `threshold`, where that is known without the search: 1 yes, 0 no, -1 not known.
//
// The shape's gauge rho is the factor by which it must grow to reach x (|x_i / a_i| for the
// ellipsoid, max_i |x_i| / e_i for the box, the greater of the radial and the axial ratio for
// the cylinder): K = {rho <= 1}, convex and symmetric about its centre, and the link in the
// shape's frame scaled axis by axis (su, sv) is a segment along which rho is convex and closed
// form. With r_in and r_out the radii of a ball about the centre within K and of one holding it,
// the signed distance s of a point at gauge rho lies between (rho - 1) r_in and (rho - 1) r_out:
// - outside (rho > 1): K plus a ball of r lies in (1 + r / r_in) K, and the point lies in K plus
//   the ball of s, so rho <= 1 + s / r_in; and rho K = K + (rho - 1) K lies in K plus the ball
//   of (rho - 1) r_out;
// - inside: rho K plus the ball of (1 - rho) r_in lies in rho K + (1 - rho) K = K, and the
//   boundary point x / rho on the ray from the centre is |x| (1 - rho) / rho <= (1 - rho) r_out
//   away.
// Both bounds grow with rho. So the link's least s is at most the upper bound at any point of it
// (at its least gauge, for one) and at least the lower bound at its least gauge, which
// is exact for the ellipsoid (a quadratic's minimum) and the box (the least of a piecewise linear
// function: an end or where two of its six lines cross) and for the cylinder: the greater of two
// convex functions of t (the radial ratio, the root of a quadratic, and the axial one, a line's
// absolute value) is least at an end, at the least of the one that is the greater there, or
// where they cross, and each of these is a candidate. `guard` covers the gauge's rounding (a few
// ulps of |su| + |sv|) in units of s; for the cylinder also a crossing's, whose root is well
// conditioned where it is the least (the two slopes are of opposite signs there): its error in
// the gauge is a few ulps of (|su| + |sv|)^2.
//
// With `band` > 0 a link whose least s is certainly below threshold + band is answered yes (it
// may be clear by less than the band); a no is still certain.
int KnownBelow(const Collider& c, const Vector3d& a, const Vector3d& b, double threshold,
               double band = 0.0) {
  const Eigen::Matrix3d& rotation = c.pose.linear();
  Vector3d scale;  // the gauge's axis by axis
  double r_in = 0.0, r_out = 0.0;
  switch (c.shape) {
    case ColliderShape::kEllipsoid:
      scale = c.extents.cwiseInverse();
      r_in = c.extents.minCoeff();
      r_out = c.extents.maxCoeff();
      break;
    case ColliderShape::kBox:
      scale = c.extents.cwiseInverse();
      r_in = c.extents.minCoeff();
      r_out = c.extents.norm();
      break;
    case ColliderShape::kCylinder:
      if (!(c.half_length > 0.0)) return -1;  // a flat disc: the search
      scale = Vector3d(1.0 / c.radius, 1.0 / c.radius, 1.0 / c.half_length);
      r_in = std::min(c.radius, c.half_length);
      r_out = std::hypot(c.radius, c.half_length);
      break;
    default:
      return -1;
  }
  const Vector3d su = (rotation.transpose() * (a - c.pose.translation())).cwiseProduct(scale);
  const Vector3d sv = (rotation.transpose() * (b - a)).cwiseProduct(scale);
  double rho = std::numeric_limits<double>::infinity(), at = 0.0;  // the least gauge, where
  if (c.shape == ColliderShape::kEllipsoid) {
    const double vv = sv.squaredNorm();
    at = vv > 0.0 ? std::clamp(-su.dot(sv) / vv, 0.0, 1.0) : 0.0;
    rho = (su + at * sv).norm();
  } else if (c.shape == ColliderShape::kBox) {
    const auto gauge = [&](double t) { return (su + t * sv).cwiseAbs().maxCoeff(); };
    rho = gauge(0.0);
    if (const double end = gauge(1.0); end < rho) rho = end, at = 1.0;
    std::array<double, 6> offset, slope;
    for (int i = 0; i < 3; ++i) {
      offset[2 * i] = su[i], slope[2 * i] = sv[i];
      offset[2 * i + 1] = -su[i], slope[2 * i + 1] = -sv[i];
    }
    for (int j = 0; j < 6; ++j) {
      for (int k = j + 1; k < 6; ++k) {
        if (slope[j] == slope[k]) continue;
        const double t = (offset[k] - offset[j]) / (slope[j] - slope[k]);
        if (t > 0.0 && t < 1.0) {
          if (const double g = gauge(t); g < rho) rho = g, at = t;
        }
      }
    }
  } else {
    // The greater of the radial ratio (the root of a quadratic) and the axial one (a line's
    // absolute value): candidates at the ends, at each one's least and where they cross.
    const auto gauge = [&](double t) {
      const Vector3d x = su + t * sv;
      return std::max(std::sqrt(x.x() * x.x() + x.y() * x.y()), std::fabs(x.z()));
    };
    std::array<double, 6> candidates{0.0, 1.0, -1.0, -1.0, -1.0, -1.0};
    const double vxy = sv.x() * sv.x() + sv.y() * sv.y();
    const double uv = su.x() * sv.x() + su.y() * sv.y();
    if (vxy > 0.0) candidates[2] = -uv / vxy;
    if (sv.z() != 0.0) candidates[3] = -su.z() / sv.z();
    // |xy|^2 = z^2: qa t^2 + qb t + qc = 0.
    const double qa = vxy - sv.z() * sv.z(), qb = 2.0 * (uv - su.z() * sv.z());
    const double qc = su.x() * su.x() + su.y() * su.y() - su.z() * su.z();
    if (qa != 0.0) {
      const double disc = qb * qb - 4.0 * qa * qc;
      if (disc >= 0.0) {
        const double q = -0.5 * (qb + std::copysign(std::sqrt(disc), qb));
        candidates[4] = q / qa;
        if (q != 0.0) candidates[5] = qc / q;
      }
    } else if (qb != 0.0) {
      candidates[4] = -qc / qb;
    }
    for (double t : candidates) {
      if (t >= 0.0 && t <= 1.0) {
        if (const double g = gauge(t); g < rho) rho = g, at = t;
      }
    }
  }
  const double upper = rho >= 1.0 ? (rho - 1.0) * r_out : (rho - 1.0) * r_in;
  const double lower = rho >= 1.0 ? (rho - 1.0) * r_in : (rho - 1.0) * r_out;
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  const double reach = 1.0 + su.norm() + sv.norm();
  const double guard = 8.0 * kEps *
                       (r_out * (c.shape == ColliderShape::kCylinder ? reach * reach : reach) +
                        c.margin + std::fabs(threshold));
  if (upper - c.margin < threshold + band - guard) return 1;
  if (lower - c.margin > threshold + guard) return 0;
  // Within the band, the distance of the point of least gauge, an upper bound of the least (the
  // bisection's last steps, at the queries' rounding, where the bounds from the gauge are loose
  // by r_out / r_in).
  if (band > 0.0 && lower - c.margin < threshold + band &&
      SurfaceDistance(c, c.pose.inverse(Eigen::Isometry), a + at * (b - a)) < threshold + band) {
    return 1;
  }
  return -1;
}

}  // namespace

bool SegmentClearanceBelow(const Collider& c, const Vector3d& a, const Vector3d& b,
                           double threshold, double band) {
  switch (c.shape) {
    case ColliderShape::kEllipsoid:
    case ColliderShape::kCylinder:
    case ColliderShape::kBox:
      if (const int known = KnownBelow(c, a, b, threshold, band); known >= 0) return known == 1;
      return ConvexMinimumAlong(c, a, b, threshold) < threshold;
    default:
      return SegmentClearance(c, a, b) < threshold;
  }
}

double SegmentClearance(const std::vector<Collider>& colliders, const Vector3d& a,
                        const Vector3d& b) {
  double least = std::numeric_limits<double>::infinity();
  for (const Collider& c : colliders) least = std::min(least, SegmentClearance(c, a, b));
  return least;
}

double BoundingRadius(const Collider& c) {
  double radius = 0.0;
  switch (c.shape) {
    case ColliderShape::kHalfSpace:
      return 0.0;
    case ColliderShape::kSphere:
      radius = c.radius;
      break;
    case ColliderShape::kCapsule:
      radius = c.half_length + c.radius;
      break;
    case ColliderShape::kCylinder:
      radius = std::hypot(c.half_length, c.radius);
      break;
    case ColliderShape::kBox:
      radius = c.extents.norm();
      break;
    case ColliderShape::kEllipsoid:
      radius = c.extents.maxCoeff();
      break;
    case ColliderShape::kMesh:  // the ball about its frame's origin that holds every vertex
      radius = c.scale * c.mesh->radius;
      break;
  }
  return radius + c.margin;
}

double DistanceLowerBound(const Collider& c, const Vector3d& x) {
  if (c.shape == ColliderShape::kHalfSpace) {
    return c.pose.linear().col(2).dot(x - c.pose.translation()) - c.margin;
  }
  return (x - c.pose.translation()).norm() - BoundingRadius(c);
}

SegmentContact NearestOnSegment(const Collider& c, const Vector3d& a, const Vector3d& b) {
  SegmentContact contact;
  const Vector3d ab = b - a;
  switch (c.shape) {
    case ColliderShape::kSphere: {
      const double ab2 = ab.squaredNorm();
      contact.s = ab2 > 0.0 ? std::clamp((c.pose.translation() - a).dot(ab) / ab2, 0.0, 1.0) : 0.0;
      break;
    }
    case ColliderShape::kCapsule: {
      const Vector3d axis = c.pose.linear().col(2) * c.half_length;
      const Vector3d center = c.pose.translation();
      SegmentSegmentDistance(a, b, center - axis, center + axis, &contact.s);
      break;
    }
    case ColliderShape::kHalfSpace: {
      const Vector3d up = c.pose.linear().col(2);
      contact.s = up.dot(b) < up.dot(a) ? 1.0 : 0.0;
      break;
    }
    case ColliderShape::kEllipsoid:
    case ColliderShape::kCylinder:
    case ColliderShape::kBox:
    case ColliderShape::kMesh: {
      // The signed distance of a convex set is convex along the segment: its slope there, the
      // normal's component along ab, does not decrease; its zero by bisection to the last bit.
      // A mesh's need not be: the least of 33 samples along the segment brackets the minimum
      // bisected (the nearest part of the link to the mesh, to the samples' resolution of its
      // features; a link that passes two bumps is linearized at the nearer).
      const Eigen::Isometry3d to_local = c.pose.inverse(Eigen::Isometry);
      const auto slope = [&](double s) {
        return QuerySurface(c, to_local, a + s * ab).normal.dot(ab);
      };
      double lo = 0.0, hi = 1.0;
      if (c.shape == ColliderShape::kMesh) {
        constexpr int kSamples = 32;
        int best = 0;
        double least = std::numeric_limits<double>::infinity();
        for (int k = 0; k <= kSamples; ++k) {
          const double d = SurfaceDistance(c, to_local, a + (double(k) / kSamples) * ab);
          if (d < least) least = d, best = k;
        }
        lo = double(std::max(best - 1, 0)) / kSamples;
        hi = double(std::min(best + 1, kSamples)) / kSamples;
      }
      if (slope(lo) >= 0.0) {
        contact.s = lo;
      } else if (slope(hi) <= 0.0) {
        contact.s = hi;
      } else {
        for (int i = 0; i < 64; ++i) {
          const double mid = 0.5 * (lo + hi);
          if (mid <= lo || mid >= hi) break;
          (slope(mid) < 0.0 ? lo : hi) = mid;
        }
        contact.s = 0.5 * (lo + hi);
      }
      break;
    }
  }
  const Vector3d p = a + contact.s * ab;
  const SurfaceQuery at = QuerySurface(c, p);
  contact.clearance = at.distance;
  contact.normal = at.normal;
  return contact;
}

namespace {

// The finest angle step of the march past a mesh (radians): at most about 3,000 steps round a
// half circle, whatever the mesh's detail.
constexpr double kMeshLeastStep = 1e-3;

// The directions from the head: d(theta, psi) = cos(theta) d0 + sin(theta) (cos(psi) e1 +
// sin(psi) e2), theta the angle from d0 (the direction of the old tail).
struct Directions {
  Vector3d d0, e1, e2;
  Vector3d At(double theta, double psi) const {
    return std::cos(theta) * d0 + std::sin(theta) * (std::cos(psi) * e1 + std::sin(psi) * e2);
  }
};

class TailSearch {
 public:
  TailSearch(const Vector3d& head, double length, const std::vector<Collider>& colliders,
             const Directions& dirs)
      : head_(head), length_(length), colliders_(colliders), dirs_(dirs) {
    // A mesh may block the half circle again after another collider is passed.
    for (const Collider& c : colliders) {
      if (c.shape == ColliderShape::kMesh) rounds_ = std::numeric_limits<size_t>::max() - 1;
    }
    // The thread's buffer (ContactTail does not call itself): no allocation a contact step.
    thread_local std::vector<HeadAgainst> heads;
    heads.assign(colliders.size(), HeadAgainst{});
    heads_ = &heads;
  }

  Vector3d Tail(double theta, double psi) const { return head_ + length_ * dirs_.At(theta, psi); }
  bool Blocks(const Collider& c, double theta, double psi) const {
    if (c.shape == ColliderShape::kMesh) {
      // The head is outside: the crossings say it. Its depths are sampled (midpoints, the end)
      // where SegmentClearance samples others: a quarter of the slack keeps what this test lets
      // through within the slack as SegmentClearance measures it.
      const Eigen::Isometry3d& to_local = ToLocal(static_cast<size_t>(&c - colliders_.data()));
      return MeshSegmentEnters(*c.mesh, to_local * head_ / c.scale,
                               to_local * Tail(theta, psi) / c.scale,
                               (c.margin - 0.25 * kContactSlack * length_) / c.scale);
    }
    // SegmentClearance's answer, from a golden-section search stopped where it is known for the
    // shapes that take one. Allowed is never above the slack's threshold, so a link within the
    // slack is clear whatever the head's own depth allows.
    const size_t k = static_cast<size_t>(&c - colliders_.data());
    const double allowed = Allowed(k);
    if (c.shape == ColliderShape::kEllipsoid || c.shape == ColliderShape::kCylinder ||
        c.shape == ColliderShape::kBox) {
      // Without the search where the link leaves the collider from the head: the signed distance
      // is convex along the link, and the head's normal (the outward normal at its nearest
      // surface point) is a subgradient of it at the head, so where the link's direction has a
      // positive component along it, the distance only grows from the head's own, which is not
      // below `allowed`: the search's answer (its first value, the head's, is not below, and
      // none after it is). The component must exceed the normal's rounding; a link near the
      // tangent plane takes the search.
      const HeadAgainst& head = (*heads_)[k];
      if (head.distance >= allowed && head.normal.dot(dirs_.At(theta, psi)) > 1e-12) return false;
    }
    // A link within the slack above `allowed` may be held (the bisection's last steps, where
    // only the search could tell, at the queries' rounding): the exit angle is then larger by
    // at most what keeps the link that much clearer, and a link let through is still certain.
    return SegmentClearanceBelow(c, head_, Tail(theta, psi), allowed, kContactSlack * length_);
  }

  // Mesh k's world-to-mesh transform (its pose's inverse), computed when first needed.
  const Eigen::Isometry3d& ToLocal(size_t k) const {
    if (to_local_.empty()) to_local_.resize(colliders_.size());
    if (!to_local_[k]) to_local_[k] = colliders_[k].pose.inverse(Eigen::Isometry);
    return *to_local_[k];
  }

  // What a link may lie inside convex collider k: the slack, or, where the rounding of an earlier
  // contact step left the head itself inside by a hair more, twice the head's depth, so that the
  // directions leading out of the collider are not held against the link. Computed when first
  // needed (a collider the link does not reach never needs it).
  // The head's own distance and normal are kept for Blocks.
  double Allowed(size_t k) const {
    HeadAgainst& head = (*heads_)[k];
    if (std::isnan(head.allowed)) {
      const Collider& c = colliders_[k];
      head.allowed = -kContactSlack * length_;
      const SurfaceQuery at = QuerySurface(c, head_);
      head.distance = at.distance;
      head.normal = at.normal;
      const double depth = std::fmin(at.distance, SegmentClearance(c, head_, head_));
      if (depth > -1e-9 * length_) head.allowed = std::fmin(head.allowed, 2.0 * depth);
    }
    return head.allowed;
  }

  // The least angle theta along the half great circle psi at which no collider blocks the link
  // (+inf if none). Each collider, convex, blocks the directions of a spherically convex set seen
  // from the head (outside it), within an open hemisphere: along the half circle from a direction
  // it blocks, it blocks an arc and then never again. So the colliders are passed one after
  // another, each by bisection to the last bit, at most once each.
  double ExitAngle(double psi) const {
    double theta = 0.0;
    for (size_t round = 0; round <= rounds_; ++round) {
      const Collider* blocking = nullptr;
      for (const Collider& c : colliders_) {
        if (Blocks(c, theta, psi)) {
          blocking = &c;
          break;
        }
      }
      if (blocking == nullptr) return theta;
      double lo = theta, hi = M_PI;
      if (blocking->shape == ColliderShape::kMesh) {
        // Not convex: along the half circle it may block several arcs. Marched from theta in
        // steps finer than its features seen from the head to the first direction it leaves
        // free, then bisected back (docs/colliders.md, "Meshes").
        const double step = std::clamp(0.5 * blocking->mesh->feature * blocking->scale / length_,
                                       kMeshLeastStep, M_PI / 32.0);
        for (;;) {
          hi = std::min(M_PI, lo + step);
          if (!Blocks(*blocking, hi, psi)) break;
          if (hi >= M_PI) return std::numeric_limits<double>::infinity();
          lo = hi;
        }
      } else if (Blocks(*blocking, hi, psi)) {
        // The opposite direction blocked too: a head on the surface (to the rounding) whose old
        // direction and its opposite both graze it, within the slack. The blocked set is then
        // the surface's tangent half-space of directions, and the half circle leaves it between
        // its ends: the first of a few samples that is free brackets the exit.
        bool free = false;
        for (int k = 1; k < 8 && !free; ++k) {
          hi = theta + k * (M_PI - theta) / 8.0;
          free = !Blocks(*blocking, hi, psi);
        }
        if (!free) return std::numeric_limits<double>::infinity();
      }
      for (;;) {
        const double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi) break;
        (Blocks(*blocking, mid, psi) ? lo : hi) = mid;
      }
      theta = hi;
    }
    return std::numeric_limits<double>::infinity();
  }

 private:
  const Vector3d& head_;
  const double length_;
  const std::vector<Collider>& colliders_;
  const Directions& dirs_;
  size_t rounds_ = colliders_.size();  // each convex collider is passed at most once
  // Per collider: the least clearance a link may have (Allowed; NaN until computed), and the
  // head's distance and outward normal there.
  struct HeadAgainst {
    double allowed = std::numeric_limits<double>::quiet_NaN();
    double distance = 0.0;
    Vector3d normal = Vector3d::Zero();
  };
  std::vector<HeadAgainst>* heads_ = nullptr;
  mutable std::vector<std::optional<Eigen::Isometry3d>> to_local_;  // per mesh: ToLocal
};

// The least exit angle near *psi (a sample no larger than its neighbours kStep away, whose exit
// angle is *theta): golden-section search, then Newton's method on the central differences'
// slope. Golden-section search places the minimum to about the square root of the rounding (the
// function is flat there: its values cannot tell closer); the slope can, to about 1e-10. A
// Newton step is kept unless it raises the exit angle beyond the rounding.
void RefineExit(const TailSearch& search, double step, double* psi, double* theta) {
  constexpr double kInvPhi = 0.6180339887498949;
  double lo = *psi - step, hi = *psi + step;
  double p1 = hi - kInvPhi * (hi - lo), p2 = lo + kInvPhi * (hi - lo);
  double t1 = search.ExitAngle(p1), t2 = search.ExitAngle(p2);
  for (int i = 0; i < 60 && hi - lo > 1e-13; ++i) {
    if (t1 <= t2) {
      hi = p2, p2 = p1, t2 = t1;
      p1 = hi - kInvPhi * (hi - lo);
      t1 = search.ExitAngle(p1);
    } else {
      lo = p1, p1 = p2, t1 = t2;
      p2 = lo + kInvPhi * (hi - lo);
      t2 = search.ExitAngle(p2);
    }
  }
  if (t1 < *theta) *theta = t1, *psi = p1;
  if (t2 < *theta) *theta = t2, *psi = p2;
  constexpr double kH = 2e-6;
  for (int i = 0; i < 4; ++i) {
    const double minus = search.ExitAngle(*psi - kH), plus = search.ExitAngle(*psi + kH);
    const double slope = (plus - minus) / (2.0 * kH);
    const double curvature = (plus - 2.0 * *theta + minus) / (kH * kH);
    if (!(curvature > 0.0) || !std::isfinite(slope)) break;
    const double move = std::clamp(-slope / curvature, -step, step);
    const double moved_psi = *psi + move, moved_theta = search.ExitAngle(moved_psi);
    if (!(moved_theta <= *theta + 4e-16 * (1.0 + *theta))) break;
    *theta = moved_theta;
    *psi = moved_psi;
    if (std::fabs(move) < 1e-12) break;
  }
}

// A sphere blocks, from a head outside it, a circular cone of directions about the direction u
// of its centre (docs/colliders.md, "One sphere"): of half-angle asin(r / D) when the link
// reaches the tangent points (L >= sqrt(D^2 - r^2)), else of the angle at which the link's end
// lies on the sphere, cos = (D^2 + L^2 - r^2) / (2 L D). The nearest direction outside the cone
// to d0, inside it, lies on the great circle through u and d0, at the cone's angle from u. Sets
// *x to the link's end in that direction; false if the head is inside the sphere (beyond the
// slack).
bool SphereExit(int dim, const Collider& sphere, const Vector3d& head, const Vector3d& d0,
                double length, double widen, Vector3d* x) {
  const Vector3d to_center = sphere.pose.translation() - head;
  const double distance = to_center.norm(), r = sphere.radius + sphere.margin;
  // A head on the surface (a contact step put it there, to the last bits, or a root): the cone
  // is the half-space of directions into the sphere; its boundary, the tangent plane.
  if (!(distance > r) && (r - distance > kContactSlack * length || !(distance > 0.0))) {
    return false;
  }
  const Vector3d u = to_center / distance;
  const double tangent = distance > r ? std::sqrt((distance - r) * (distance + r)) : 0.0;
  double cos_a, sin_a;
  if (distance <= r) {
    sin_a = 1.0;
    cos_a = 0.0;
  } else if (length >= tangent) {
    sin_a = r / distance;
    cos_a = tangent / distance;
  } else {
    cos_a = std::clamp((distance * distance + length * length - r * r) / (2.0 * length * distance),
                       -1.0, 1.0);
    sin_a = std::sqrt((1.0 - cos_a) * (1.0 + cos_a));
  }
  if (widen != 0.0) {
    const double a = std::atan2(sin_a, cos_a) + widen;
    cos_a = std::cos(a);
    sin_a = std::sin(a);
  }
  Vector3d w = d0 - d0.dot(u) * u;
  const double w_norm = w.norm();
  if (w_norm > 1e-300) {
    w /= w_norm;
  } else if (dim == 2) {
    w = Vector3d(-u.y(), u.x(), 0.0);
  } else {
    const Vector3d helper = std::fabs(u.x()) < 0.9 ? Vector3d::UnitX() : Vector3d::UnitY();
    w = u.cross(helper).normalized();
  }
  *x = head + length * (cos_a * u + sin_a * w);
  return true;
}

}  // namespace

bool ContactTail(int dim, const Vector3d& head, const Vector3d& tail, double length,
                 const std::vector<Collider>& colliders, Vector3d* x, double* clearance) {
  Directions dirs;
  const Vector3d from_head = tail - head;
  const double distance = from_head.norm();
  dirs.d0 = distance > 0.0 ? Vector3d(from_head / distance) : Vector3d::UnitX();
  if (dim == 2) {
    dirs.e1 = Vector3d(-dirs.d0.y(), dirs.d0.x(), 0.0);
    dirs.e2 = Vector3d::Zero();
  } else {
    // Any orthonormal pair across d0.
    const Vector3d helper = std::fabs(dirs.d0.x()) < 0.9 ? Vector3d::UnitX() : Vector3d::UnitY();
    dirs.e1 = dirs.d0.cross(helper).normalized();
    dirs.e2 = dirs.d0.cross(dirs.e1);
  }
  // One sphere blocking the old direction, and its exit clear of the others: closed form.
  const Collider* only = nullptr;
  int blocking = 0;
  const bool spheres = std::all_of(colliders.begin(), colliders.end(), [](const Collider& c) {
    return c.shape == ColliderShape::kSphere;
  });
  // Spheres within the link's reach from the head (with a margin for the rounding): the others
  // block nothing, and a link from the head is clearer of them than of one it touches.
  thread_local std::vector<const Collider*> within;
  if (spheres) {
    // TailSearch::Blocks for spheres, without its queries: the head's depth is its segment
    // clearance at the head, |head - centre| - r (Allowed).
    const Vector3d end = head + length * dirs.d0;
    within.clear();
    for (const Collider& c : colliders) {
      const double reach = (c.radius + c.margin + length) * (1.0 + 1e-9);
      if ((c.pose.translation() - head).squaredNorm() > reach * reach) continue;
      within.push_back(&c);
      const double depth = SegmentClearance(c, head, head);
      double allowed = -kContactSlack * length;
      if (depth > -1e-9 * length) allowed = std::fmin(allowed, 2.0 * depth);
      if (SegmentClearance(c, head, end) < allowed) ++blocking, only = &c;
    }
  }
  const TailSearch search(head, length, colliders, dirs);
  if (!spheres) {
    for (const Collider& c : colliders) {
      if (search.Blocks(c, 0.0, 0.0)) ++blocking, only = &c;
    }
  }
  if (blocking == 1 && only->shape == ColliderShape::kSphere) {
    // On the cone's boundary to the last bits; widened by a few ulps of the angle if rounding
    // leaves the link inside by more than the slack.
    for (double widen : {0.0, 1e-15, 1e-14, 1e-13}) {
      Vector3d candidate;
      if (!SphereExit(dim, *only, head, dirs.d0, length, widen, &candidate)) break;
      double least = std::numeric_limits<double>::infinity();
      if (spheres) {
        for (const Collider* c : within)
          least = std::min(least, SegmentClearance(*c, head, candidate));
      } else {
        least = SegmentClearance(colliders, head, candidate);
      }
      if (least >= -kContactSlack * length) {
        *x = candidate;
        if (clearance != nullptr) *clearance = least;
        return true;
      }
    }
  }
  double best_theta = std::numeric_limits<double>::infinity(), best_psi = 0.0;
  if (dim == 2) {
    // The two ways round.
    for (double psi : {0.0, M_PI}) {
      const double theta = search.ExitAngle(psi);
      if (theta < best_theta) best_theta = theta, best_psi = psi;
    }
  } else {
    // The exit angle over the directions of departure, sampled.
    constexpr int kSamples = 32;
    constexpr double kStep = 2.0 * M_PI / kSamples;
    std::array<double, kSamples> sampled;
    for (int k = 0; k < kSamples; ++k) sampled[k] = search.ExitAngle(k * kStep);
    // Every local minimum of the samples is refined (a box's or a cylinder's blocked region has
    // one per face near the old direction, whose values can be close).
    for (int k = 0; k < kSamples; ++k) {
      const double here = sampled[k];
      if (!std::isfinite(here) || here > sampled[(k + 1) % kSamples] ||
          here > sampled[(k + kSamples - 1) % kSamples]) {
        continue;
      }
      double psi = k * kStep, theta = here;
      if (theta > 0.0) RefineExit(search, kStep, &psi, &theta);
      if (theta < best_theta) best_theta = theta, best_psi = psi;
    }
  }
  if (!std::isfinite(best_theta)) return false;
  *x = search.Tail(best_theta, best_psi);
  if (clearance != nullptr) *clearance = SegmentClearance(colliders, head, *x);
  return true;
}

void SettleTail(int dim, const Vector3d& head, double length,
                const std::vector<Collider>& colliders, Vector3d* tail) {
  Vector3d lifted = *tail;
  for (const Collider& c : colliders) {
    const SurfaceQuery q = QuerySurface(c, lifted);
    if (q.distance < 0.0 && q.distance > -1e-9 * length) lifted -= q.distance * q.normal;
  }
  if (lifted == *tail) return;
  lifted = head + (length / (lifted - head).norm()) * (lifted - head);
  if (dim == 2) lifted.z() = 0.0;
  if (SegmentClearance(colliders, head, lifted) >= SegmentClearance(colliders, head, *tail)) {
    *tail = lifted;
  }
}

}  // namespace flexkin::internal
