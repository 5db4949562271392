// The colliders' geometry (flexkin/colliders.h): every query is done in the collider's own frame,
// where each shape is symmetric about its axes, and brought back to the world by its pose.
#include "flexkin/colliders.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "world/contact.h"
#include "world/mesh_collider.h"

namespace flexkin {
namespace {

using Eigen::Vector3d;

std::string Num(double x) {
  std::ostringstream out;
  out.precision(17);
  out << x;
  return out.str();
}

// A query in the collider's frame: the point p and the result, all local.
SurfaceQuery Sphere(double radius, const Vector3d& p) {
  SurfaceQuery q;
  const double r = p.norm();
  q.normal = r > 0.0 ? Vector3d(p / r) : Vector3d::UnitZ();
  q.nearest = radius * q.normal;
  q.distance = r - radius;
  return q;
}

SurfaceQuery HalfSpace(const Vector3d& p) {
  SurfaceQuery q;
  q.nearest = Vector3d(p.x(), p.y(), 0.0);
  q.normal = Vector3d::UnitZ();
  q.distance = p.z();
  return q;
}

SurfaceQuery Capsule(double radius, double half_length, const Vector3d& p) {
  const Vector3d axis_point(0.0, 0.0, std::clamp(p.z(), -half_length, half_length));
  SurfaceQuery q = Sphere(radius, p - axis_point);
  if (p == axis_point) q.normal = Vector3d::UnitX();  // on the axis: any radial direction
  q.nearest = axis_point + radius * q.normal;
  return q;
}

SurfaceQuery Cylinder(double radius, double half_length, const Vector3d& p) {
  SurfaceQuery q;
  const double rho = std::sqrt(p.x() * p.x() + p.y() * p.y());  // hypot: several times slower
  const Vector3d radial = rho > 0.0 ? Vector3d(p.x() / rho, p.y() / rho, 0.0) : Vector3d::UnitX();
  const double side = rho - radius;                   // > 0 beyond the side
  const double cap = std::fabs(p.z()) - half_length;  // > 0 beyond a cap
  const double up = p.z() >= 0.0 ? 1.0 : -1.0;
  if (side <= 0.0 && cap <= 0.0) {
    // Inside: the nearer of the side and the cap.
    if (side >= cap) {
      q.distance = side;
      q.normal = radial;
      q.nearest = Vector3d(radius * radial.x(), radius * radial.y(), p.z());
    } else {
      q.distance = cap;
      q.normal = Vector3d(0.0, 0.0, up);
      q.nearest = Vector3d(p.x(), p.y(), up * half_length);
    }
    return q;
  }
  if (cap <= 0.0) {  // beside the side
    q.distance = side;
    q.normal = radial;
    q.nearest = Vector3d(radius * radial.x(), radius * radial.y(), p.z());
  } else if (side <= 0.0) {  // above or below a cap
    q.distance = cap;
    q.normal = Vector3d(0.0, 0.0, up);
    q.nearest = Vector3d(p.x(), p.y(), up * half_length);
  } else {  // beyond the rim
    q.nearest = Vector3d(radius * radial.x(), radius * radial.y(), up * half_length);
    q.distance = std::sqrt(side * side + cap * cap);
    q.normal = (p - q.nearest) / q.distance;
  }
  return q;
}

SurfaceQuery Box(const Vector3d& half, const Vector3d& p) {
  SurfaceQuery q;
  const Vector3d beyond = p.cwiseAbs() - half;  // > 0 beyond a face
  if ((beyond.array() <= 0.0).all()) {
    // Inside: the nearest face.
    int axis = 0;
    for (int k = 1; k < 3; ++k) axis = beyond[k] > beyond[axis] ? k : axis;
    const double sign = p[axis] >= 0.0 ? 1.0 : -1.0;
    q.distance = beyond[axis];
    q.nearest = p;
    q.nearest[axis] = sign * half[axis];
    q.normal = sign * Vector3d::Unit(axis);
    return q;
  }
  q.nearest = p.cwiseMax(-half).cwiseMin(half);
  q.distance = (p - q.nearest).norm();
  q.normal = (p - q.nearest) / q.distance;
  return q;
}

// Ellipse and ellipsoid: the nearest point of the surface to y, for semi-axes e sorted e0 >= e1
// (>= e2) and y in the first quadrant (octant), after D. Eberly, "Distance from a point to an
// ellipse, an ellipsoid, or a hyperellipsoid" (Geometric Tools, 2013). The nearest point is
// x_i = r_i y_i / (s + r_i) with r_i = (e_i / e_last)^2, s the root of the monotone function
// sum_i (r_i z_i / (s + r_i))^2 - 1 (z_i = y_i / e_i), bracketed as there. The root is found
// by Newton's method kept inside the bracket (a step that leaves it, or shrinks less than half
// the step before last, is a bisection instead): f is convex and decreasing on s > -r_last, so
// from the left of the root Newton's iterates rise to it monotonically and quadratically. It
// stops when a step or the bracket is within 2^-52 of s + r_last (s + r_i >= s + r_last > 0,
// r_last = 1, the least of the denominators): each x_i is then within an ulp or so of its own
// rounding. (Bisection to the last bit of s took over a thousand halvings where s is near 0,
// which is every point near the surface, and about 55 with this stop: the ellipsoid's queries
// were most of a contact step's time.) Zero components of y are the cases where the root lies on
// a boundary of the bracket and the problem drops a dimension.
template <size_t N>
double EllipseRoot(const std::array<double, N>& r, const std::array<double, N>& z, double g) {
  std::array<double, N> n;
  for (size_t i = 0; i < N; ++i) n[i] = r[i] * z[i];
  double lo = z[N - 1] - 1.0, hi = 0.0;
  if (g >= 0.0) {
    double scale = 0.0, sum = 0.0;
    for (size_t i = 0; i < N; ++i) scale = std::fmax(scale, std::fabs(n[i]));
    for (size_t i = 0; i < N; ++i) sum += (n[i] / scale) * (n[i] / scale);
    hi = scale * std::sqrt(sum) - 1.0;
  }
  double s = 0.5 * (lo + hi), step = hi - lo, before = step;
  for (int iteration = 0; iteration < 400; ++iteration) {
    double f = -1.0, slope = 0.0;
    for (size_t i = 0; i < N; ++i) {
      const double inv = 1.0 / (s + r[i]), ratio = n[i] * inv, term = ratio * ratio;
      f += term;
      slope -= 2.0 * term * inv;
    }
    if (f == 0.0) break;
    (f > 0.0 ? lo : hi) = s;
    const double tolerance = 0x1p-52 * (lo + r[N - 1]);
    if (hi - lo <= tolerance) return 0.5 * (lo + hi);
    double next = s - f / slope;
    if (!(next > lo && next < hi) || std::fabs(next - s) > 0.5 * std::fabs(before)) {
      next = 0.5 * (lo + hi);
    }
    before = step;
    step = next - s;
    s = next;
    if (std::fabs(step) <= tolerance) break;
  }
  return s;
}

void NearestOnEllipse(double e0, double e1, double y0, double y1, double* x0, double* x1) {
  if (y1 > 0.0) {
    if (y0 > 0.0) {
      const double z0 = y0 / e0, z1 = y1 / e1, g = z0 * z0 + z1 * z1 - 1.0;
      if (g != 0.0) {
        const double r0 = (e0 / e1) * (e0 / e1);
        const double s = EllipseRoot<2>({r0, 1.0}, {z0, z1}, g);
        *x0 = r0 * y0 / (s + r0);
        *x1 = y1 / (s + 1.0);
      } else {
        *x0 = y0;
        *x1 = y1;
      }
    } else {
      *x0 = 0.0;
      *x1 = e1;
    }
    return;
  }
  const double numer0 = e0 * y0, denom0 = e0 * e0 - e1 * e1;
  if (numer0 < denom0) {
    const double xde0 = numer0 / denom0;
    *x0 = e0 * xde0;
    *x1 = e1 * std::sqrt(1.0 - xde0 * xde0);
  } else {
    *x0 = e0;
    *x1 = 0.0;
  }
}

void NearestOnEllipsoid(const std::array<double, 3>& e, const std::array<double, 3>& y,
                        std::array<double, 3>* x) {
  if (y[2] > 0.0) {
    if (y[1] > 0.0) {
      if (y[0] > 0.0) {
        const std::array<double, 3> z = {y[0] / e[0], y[1] / e[1], y[2] / e[2]};
        const double g = z[0] * z[0] + z[1] * z[1] + z[2] * z[2] - 1.0;
        if (g != 0.0) {
          const std::array<double, 3> r = {(e[0] / e[2]) * (e[0] / e[2]),
                                           (e[1] / e[2]) * (e[1] / e[2]), 1.0};
          const double s = EllipseRoot<3>(r, z, g);
          for (int i = 0; i < 3; ++i) (*x)[i] = r[i] * y[i] / (s + r[i]);
        } else {
          *x = y;
        }
      } else {
        (*x)[0] = 0.0;
        NearestOnEllipse(e[1], e[2], y[1], y[2], &(*x)[1], &(*x)[2]);
      }
    } else if (y[0] > 0.0) {
      (*x)[1] = 0.0;
      NearestOnEllipse(e[0], e[2], y[0], y[2], &(*x)[0], &(*x)[2]);
    } else {
      *x = {0.0, 0.0, e[2]};
    }
    return;
  }
  // y on the plane of the two longer axes: the nearest point may leave it (a point inside, near
  // the long axes), else the problem is the ellipse of those axes.
  const double denom0 = e[0] * e[0] - e[2] * e[2], denom1 = e[1] * e[1] - e[2] * e[2];
  const double numer0 = e[0] * y[0], numer1 = e[1] * y[1];
  if (numer0 < denom0 && numer1 < denom1) {
    const double xde0 = numer0 / denom0, xde1 = numer1 / denom1;
    const double discr = 1.0 - xde0 * xde0 - xde1 * xde1;
    if (discr > 0.0) {
      *x = {e[0] * xde0, e[1] * xde1, e[2] * std::sqrt(discr)};
      return;
    }
  }
  (*x)[2] = 0.0;
  NearestOnEllipse(e[0], e[1], y[0], y[1], &(*x)[0], &(*x)[1]);
}

SurfaceQuery Ellipsoid(const Vector3d& semi_axes, const Vector3d& p) {
  // Axes sorted longest first, the point reflected into the first octant.
  std::array<int, 3> order = {0, 1, 2};
  std::sort(order.begin(), order.end(), [&](int a, int b) { return semi_axes[a] > semi_axes[b]; });
  std::array<double, 3> e, y, x;
  for (int i = 0; i < 3; ++i) {
    e[i] = semi_axes[order[i]];
    y[i] = std::fabs(p[order[i]]);
  }
  NearestOnEllipsoid(e, y, &x);
  SurfaceQuery q;
  Vector3d gradient;
  for (int i = 0; i < 3; ++i) {
    const int axis = order[i];
    const double sign = p[axis] >= 0.0 ? 1.0 : -1.0;
    q.nearest[axis] = sign * x[i];
    gradient[axis] = q.nearest[axis] / (e[i] * e[i]);
  }
  q.normal = gradient.normalized();
  double inside = 0.0;
  for (int k = 0; k < 3; ++k) inside += (p[k] / semi_axes[k]) * (p[k] / semi_axes[k]);
  q.distance = (p - q.nearest).norm() * (inside < 1.0 ? -1.0 : 1.0);
  return q;
}

}  // namespace

const char* ColliderShapeName(ColliderShape shape) {
  switch (shape) {
    case ColliderShape::kSphere:
      return "sphere";
    case ColliderShape::kEllipsoid:
      return "ellipsoid";
    case ColliderShape::kCapsule:
      return "capsule";
    case ColliderShape::kCylinder:
      return "cylinder";
    case ColliderShape::kBox:
      return "box";
    case ColliderShape::kHalfSpace:
      return "half_space";
    case ColliderShape::kMesh:
      return "mesh";
  }
  return "?";
}

namespace {

// The query in the collider's own frame (`p` = its pose's inverse applied to the world point),
// its margin not yet applied: distance, nearest point and normal in that frame.
SurfaceQuery LocalQuery(const Collider& c, const Vector3d& p) {
  SurfaceQuery q;
  switch (c.shape) {
    case ColliderShape::kSphere:
      q = Sphere(c.radius, p);
      break;
    case ColliderShape::kEllipsoid:
      q = Ellipsoid(c.extents, p);
      break;
    case ColliderShape::kCapsule:
      q = Capsule(c.radius, c.half_length, p);
      break;
    case ColliderShape::kCylinder:
      q = Cylinder(c.radius, c.half_length, p);
      break;
    case ColliderShape::kBox:
      q = Box(c.extents, p);
      break;
    case ColliderShape::kHalfSpace:
      q = HalfSpace(p);
      break;
    case ColliderShape::kMesh:  // its frame scaled: distances scale with it
      q = internal::MeshSurface(*c.mesh, p / c.scale);
      q.distance *= c.scale;
      q.nearest *= c.scale;
      break;
  }
  return q;
}

}  // namespace

SurfaceQuery QuerySurface(const Collider& c, const Vector3d& x) {
  return internal::QuerySurface(c, c.pose.inverse(Eigen::Isometry), x);
}

namespace internal {

SurfaceQuery QuerySurface(const Collider& c, const Eigen::Isometry3d& to_local, const Vector3d& x) {
  SurfaceQuery q = LocalQuery(c, to_local * x);
  q.nearest = c.pose * q.nearest;
  q.normal = c.pose.linear() * q.normal;
  if (c.margin != 0.0) {
    q.distance -= c.margin;
    q.nearest += c.margin * q.normal;
  }
  return q;
}

double SurfaceDistance(const Collider& c, const Eigen::Isometry3d& to_local, const Vector3d& x) {
  return LocalQuery(c, to_local * x).distance - c.margin;
}

}  // namespace internal

std::vector<Problem> CheckCollider(const Collider& c, const std::string& field) {
  std::vector<Problem> problems;
  // A JSON pointer's children ("/c/radius", "/c/extents/1") or a member path's ("c.radius",
  // "c.extents[1]").
  const bool pointer = !field.empty() && field[0] == '/';
  const auto child = [&](const std::string& name, int index = -1) {
    std::string path = field + (pointer ? "/" : ".") + name;
    if (index >= 0) {
      path += pointer ? "/" + std::to_string(index) : "[" + std::to_string(index) + "]";
    }
    return path;
  };
  const auto positive = [&](const std::string& name, double value, int index = -1) {
    if (!(std::isfinite(value) && value > 0.0)) {
      problems.push_back(Problem::Invalid(child(name, index), Num(value), "a finite number > 0"));
    }
  };
  const auto non_negative = [&](const std::string& name, double value) {
    if (!(std::isfinite(value) && value >= 0.0)) {
      problems.push_back(Problem::Invalid(child(name), Num(value), "a finite number >= 0"));
    }
  };
  switch (c.shape) {
    case ColliderShape::kSphere:
      positive("radius", c.radius);
      break;
    case ColliderShape::kCapsule:
      positive("radius", c.radius);
      non_negative("half_length", c.half_length);
      break;
    case ColliderShape::kCylinder:
      positive("radius", c.radius);
      positive("half_length", c.half_length);
      break;
    case ColliderShape::kEllipsoid:
    case ColliderShape::kBox:
      for (int k = 0; k < 3; ++k) positive("extents", c.extents[k], k);
      break;
    case ColliderShape::kHalfSpace:
      break;
    case ColliderShape::kMesh:
      positive("scale", c.scale);
      if (c.mesh == nullptr || c.mesh->bvh == nullptr) {
        problems.emplace_back(child("mesh"),
                              "is not set; expected a mesh made by MakeColliderMesh or "
                              "ReadColliderMeshFile");
      }
      break;
  }
  non_negative("margin", c.margin);
  const Eigen::Matrix3d r = c.pose.linear();
  if (!r.allFinite() || !c.pose.translation().allFinite()) {
    problems.emplace_back(child("pose"), "has a value that is not a finite number");
  } else if ((r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-12 ||
             r.determinant() < 0.0) {
    problems.emplace_back(child("pose"),
                          "is not a rotation (orthonormal, determinant +1) and a translation");
  }
  if (c.motion) {
    const std::vector<BodyKeyframe>& keys = c.motion->keyframes;
    const std::string motion = child("motion");
    const auto key = [&](size_t k, const char* name) {
      return motion + (pointer ? "/keyframes/" + std::to_string(k) + "/" + name
                               : ".keyframes[" + std::to_string(k) + "]." + name);
    };
    if (keys.empty()) {
      problems.emplace_back(motion + (pointer ? "/keyframes" : ".keyframes"),
                            "is empty; expected at least 1 keyframe", "[]", "at least 1 keyframe");
    }
    for (size_t k = 0; k < keys.size(); ++k) {
      const BodyPose& p = keys[k].pose;
      if (!std::isfinite(keys[k].time)) {
        problems.push_back(Problem::Invalid(key(k, "time"), Num(keys[k].time), "a finite number"));
      } else if (k > 0 && std::isfinite(keys[k - 1].time) && !(keys[k].time > keys[k - 1].time)) {
        problems.push_back(Problem::Invalid(key(k, "time"), Num(keys[k].time),
                                            "a time above " + Num(keys[k - 1].time) +
                                                ", the keyframe before's (strictly increasing)"));
      }
      if (!p.rotation.allFinite() || !p.translation.allFinite()) {
        problems.emplace_back(key(k, "pose"), "has a value that is not a finite number");
      } else if ((p.rotation.transpose() * p.rotation - Eigen::Matrix3d::Identity())
                         .cwiseAbs()
                         .maxCoeff() > 1e-9 ||
                 p.rotation.determinant() < 0.0) {
        problems.emplace_back(key(k, "pose"),
                              "is not a rotation (orthonormal, determinant +1) and a translation");
      }
    }
  }
  return problems;
}

BodyPose BodyPose::FromQuaternion(double w, double x, double y, double z,
                                  const Eigen::Vector3d& translation) {
  const double norm = std::sqrt(w * w + x * x + y * y + z * z);
  if (!(norm > 0.0) || !std::isfinite(norm)) {
    throw InputError("quaternion", "must be finite and not zero");
  }
  w /= norm, x /= norm, y /= norm, z /= norm;
  BodyPose pose;
  pose.rotation << 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
      2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x), 2 * (x * z - w * y),
      2 * (y * z + w * x), 1 - 2 * (x * x + y * y);
  pose.translation = translation;
  return pose;
}

BodyPose BodyPose::Planar(double angle, double tx, double ty) {
  BodyPose pose;
  const double c = std::cos(angle), s = std::sin(angle);
  pose.rotation << c, -s, 0, s, c, 0, 0, 0, 1;
  pose.translation << tx, ty, 0.0;
  return pose;
}

BodyPose InterpolateKeyframes(const std::vector<BodyKeyframe>& keyframes,
                              KeyframeInterpolation interpolation, double t) {
  if (keyframes.empty()) return {};
  // The segment [k - 1, k] holding t: the first keyframe whose time is not below t.
  const auto after = std::lower_bound(
      keyframes.begin(), keyframes.end(), t,
      [](const BodyKeyframe& keyframe, double time) { return keyframe.time < time; });
  if (after == keyframes.end()) return keyframes.back().pose;
  if (after == keyframes.begin() || after->time == t) return after->pose;
  const BodyKeyframe& a = *(after - 1);
  const BodyKeyframe& b = *after;
  const double u = (t - a.time) / (b.time - a.time);
  // Within 1e-12 of a keyframe (the rounding of first + frame / fps) the keyframe itself.
  if (u <= 1e-12) return a.pose;
  if (u >= 1.0 - 1e-12) return b.pose;
  const double s = interpolation == KeyframeInterpolation::kLinear ? u : u * u * (3.0 - 2.0 * u);

  // A part that does not change between the keyframes stays exactly as it is (a body that rests
  // moves nothing; a pure turn does not shift, a pure shift does not turn).
  const Eigen::Vector3d translation =
      a.pose.translation == b.pose.translation
          ? a.pose.translation
          : Eigen::Vector3d((1.0 - s) * a.pose.translation + s * b.pose.translation);
  if (a.pose.rotation == b.pose.rotation) {
    BodyPose pose = a.pose;
    pose.translation = translation;
    return pose;
  }
  const Eigen::Quaterniond qa = Eigen::Quaterniond(a.pose.rotation).normalized();
  Eigen::Quaterniond qb = Eigen::Quaterniond(b.pose.rotation).normalized();
  double d = qa.coeffs().dot(qb.coeffs());
  if (d < 0.0) {  // q and -q are the same rotation: take the shorter arc
    qb.coeffs() = -qb.coeffs();
    d = -d;
  }
  Eigen::Vector4d q;  // (x, y, z, w), Eigen's order
  if (d > 1.0 - 1e-12) {
    q = (1.0 - s) * qa.coeffs() + s * qb.coeffs();
  } else {
    const double angle = std::acos(d);
    const double sin_angle = std::sin(angle);
    q = (std::sin((1.0 - s) * angle) / sin_angle) * qa.coeffs() +
        (std::sin(s * angle) / sin_angle) * qb.coeffs();
  }
  return BodyPose::FromQuaternion(q[3], q[0], q[1], q[2], translation);
}

Collider ColliderAt(const Collider& collider, double time) {
  if (!collider.motion) return collider;
  Collider at = collider;
  at.motion = nullptr;
  const BodyPose carried =
      InterpolateKeyframes(collider.motion->keyframes, collider.motion->interpolation, time);
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  frame.linear() = carried.rotation;
  frame.translation() = carried.translation;
  at.pose = frame * collider.pose;
  return at;
}

std::vector<Collider> CollidersAt(const std::vector<Collider>& colliders, double time) {
  std::vector<Collider> at;
  at.reserve(colliders.size());
  for (const Collider& c : colliders) at.push_back(ColliderAt(c, time));
  return at;
}

bool AnyMoves(const std::vector<Collider>& colliders) {
  for (const Collider& c : colliders) {
    if (c.motion) return true;
  }
  return false;
}

}  // namespace flexkin
