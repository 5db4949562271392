// Spatial arms with revolute joints about given axes (src/arm/revolute.h, docs/robots.md).
#include "arm/revolute.h"

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "arm/internal.h"
#include "chain/substep.h"
#include "flexkin/error.h"
#include "sequential/link_rules.h"

namespace flexkin::arm_internal {
namespace {

std::string Row(const char* field, int i) {
  return std::string(field) + "[" + std::to_string(i) + "]";
}

std::optional<Problem> CheckUnitRows(const Eigen::MatrixXd& m, const char* field, int n) {
  if (m.rows() != n || m.cols() != 3) {
    return Problem(field, "shape " + std::to_string(m.rows()) + " by " + std::to_string(m.cols()) +
                              " is not valid; expected " + std::to_string(n) + " by 3");
  }
  for (int i = 0; i < n; ++i) {
    if (!m.row(i).allFinite() || std::abs(m.row(i).norm() - 1.0) > 1e-9) {
      return Problem(Row(field, i), "is not a finite unit vector (norm " +
                                        FormatNumber(m.row(i).norm()) + "); expected norm 1");
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<Problem> ValidateAxes(const ArmModel& model) {
  const int n = model.num_links();
  if (model.dim != 3) return Problem("joint_axes", "only spatial arms (dim 3) have joint axes");
  if (model.max_bend.size() != 0) {
    return Problem("max_bend", "revolute joints have joint_min and joint_max instead");
  }
  std::optional<Problem> why = CheckUnitRows(model.joint_axes, "joint_axes", n);
  if (!why && model.link_directions.size() != 0) {
    why = CheckUnitRows(model.link_directions, "link_directions", n);
  }
  if (why) return why;
  if (!model.joint_types.empty() && static_cast<int>(model.joint_types.size()) != n) {
    return Problem("joint_types", "has " + std::to_string(model.joint_types.size()) +
                                      " entries; expected " + std::to_string(n) + " or none");
  }
  const Eigen::Vector4d& q = model.tip_rotation;
  if (!q.allFinite() || std::abs(q.norm() - 1.0) > 1e-9) {
    return Problem("tip_rotation", "is not a finite unit quaternion (norm " +
                                       FormatNumber(q.norm()) + "); expected (w, x, y, z), norm 1");
  }
  return std::nullopt;
}

bool Sweepable(const ArmModel& model) {
  for (int j = 0; j < model.num_links(); ++j) {
    if (model.prismatic(j) || !(model.link_lengths[j] > 0.0)) return false;
    if (Eigen::Vector3d(model.joint_axes.row(j).transpose()).cross(RestDirection(model, j)).norm() <
        1e-6) {
      return false;
    }
    if (model.joint_min.size() != 0 &&
        !(model.joint_min[j] >= -M_PI && model.joint_max[j] <= M_PI)) {
      return false;
    }
  }
  return true;
}

Eigen::Vector3d RestDirection(const ArmModel& model, int k) {
  if (model.link_directions.size() != 0) return model.link_directions.row(k).transpose();
  return model.base_direction.head<3>().normalized();
}

double AngleAbout(const Eigen::Vector3d& axis, const Eigen::Vector3d& from,
                  const Eigen::Vector3d& to) {
  const Eigen::Vector3d f = from - axis.dot(from) * axis, t = to - axis.dot(to) * axis;
  if (!(f.squaredNorm() > 0.0) || !(t.squaredNorm() > 0.0)) return 0.0;
  return std::atan2(axis.dot(f.cross(t)), f.dot(t));
}

namespace {

// The coordinate axis that `v` is (0, 1, 2 for +-x, +-y, +-z: two components exactly 0), with its
// sign in `sign`; 3 if none.
int CoordinateIndex(const Eigen::Vector3d& v, double* sign) {
  for (int k = 0; k < 3; ++k) {
    if (v[(k + 1) % 3] == 0.0 && v[(k + 2) % 3] == 0.0 && v[k] != 0.0) {
      *sign = v[k];
      return k;
    }
  }
  *sign = 1.0;
  return 3;
}

}  // namespace

AxisKinematics::AxisKinematics(const ArmModel& model) : base_(model.base.head<3>()) {
  const int n = model.num_links();
  joints_.resize(n);
  for (int j = 0; j < n; ++j) {
    Joint& joint = joints_[j];
    joint.axis = model.joint_axes.row(j).transpose();
    joint.rest = model.link_lengths[j] * RestDirection(model, j);
    joint.prismatic = model.prismatic(j);
    joint.axis_index = CoordinateIndex(joint.axis, &joint.axis_sign);
    // A unit axis with two zero components is exactly +-1 along the third (ValidateAxes allows
    // 1e-9 of slack in the norm: such an axis takes the general path).
    if (joint.axis_index < 3 && std::abs(joint.axis_sign) != 1.0) {
      joint.axis_index = 3;
      joint.axis_sign = 1.0;
    }
    joint.rest_index = CoordinateIndex(joint.rest, &joint.rest_sign);
    if (joint.rest.isZero(0.0)) joint.rest_index = -1;  // a joint at the next one's point
  }
}

void AxisKinematics::Forward(const Eigen::VectorXd& angle, Points* points, Eigen::MatrixXd* axes,
                             Eigen::Matrix3d* last) const {
  using Vec3 = Eigen::Vector3d;
  const int n = num_links();
  points->resize(n + 1, 3);
  if (axes != nullptr) axes->resize(n, 3);
  // The angles' sines and cosines, batched where the CPU allows (SinCosAll).
  thread_local std::vector<double> scratch;
  scratch.resize(2 * static_cast<size_t>(n));
  double* sn = scratch.data();
  double* cs = sn + n;
  SinCosAll(angle.data(), n, sn, cs);
  // R's columns, each its own variable (kept in registers: the switches below pick them by name,
  // as an array indexed by the joint would go through memory).
  Vec3 x = Vec3::UnitX(), y = Vec3::UnitY(), z = Vec3::UnitZ();
  // R v, for v a coordinate axis times `sign` (index 0 to 2) or general (3).
  const auto turned = [&](int index, double sign, const Vec3& v) -> Vec3 {
    switch (index) {
      case 0:
        return sign * x;
      case 1:
        return sign * y;
      case 2:
        return sign * z;
      default:
        return x * v.x() + y * v.y() + z * v.z();
    }
  };
  // R Rot(+-e_k, q): the plane rotation of the two other columns (s carries the sign).
  const auto plane = [](double c, double s, Vec3* u, Vec3* v) {
    const Vec3 u0 = *u;
    *u = c * u0 + s * *v;
    *v = c * *v - s * u0;
  };
  Vec3 p = base_;
  points->row(0) = p.transpose();
  for (int j = 0; j < n; ++j) {
    const Joint& joint = joints_[j];
    const Vec3 w = turned(joint.axis_index, joint.axis_sign, joint.axis);
    if (axes != nullptr) axes->row(j) = w.transpose();
    if (joint.prismatic) {
      // A slide along the axis: link j+1 and everything after it move by angle[j] along it.
      p += turned(3, 1.0, joint.rest) + angle[j] * w;
    } else {
      const double c = cs[j], s = joint.axis_sign * sn[j];
      switch (joint.axis_index) {
        case 0:
          plane(c, s, &y, &z);
          break;
        case 1:
          plane(c, s, &z, &x);
          break;
        case 2:
          plane(c, s, &x, &y);
          break;
        default: {
          const Vec3 a = joint.axis * (1.0 - c);
          x = c * x + s * w.cross(x) + a.x() * w;
          y = c * y + s * w.cross(y) + a.y() * w;
          z = c * z + s * w.cross(z) + a.z() * w;
        }
      }
      if (joint.rest_index >= 0) p += turned(joint.rest_index, joint.rest_sign, joint.rest);
    }
    points->row(j + 1) = p.transpose();
  }
  if (last != nullptr) *last << x, y, z;
}

Points RevoluteForward(const ArmModel& model, const Eigen::VectorXd& angle, Eigen::MatrixXd* axes,
                       Eigen::Quaterniond* last_frame) {
  Points points;
  Eigen::Matrix3d last;
  AxisKinematics(model).Forward(angle, &points, axes, &last);
  if (last_frame != nullptr) *last_frame = Eigen::Quaterniond(last).normalized();
  return points;
}

Eigen::VectorXd RevoluteInverse(const ArmModel& model, const Points& points) {
  const int n = model.num_links();
  Eigen::VectorXd angle(n);
  Eigen::Quaterniond frame = Eigen::Quaterniond::Identity();
  for (int j = 0; j < n; ++j) {
    const Eigen::Vector3d a = model.joint_axes.row(j).transpose();
    const Eigen::Vector3d d = (points.row(j + 1) - points.row(j)).transpose();
    angle[j] = AngleAbout(a, RestDirection(model, j), frame.conjugate() * d);
    frame = (frame * Eigen::Quaterniond(Eigen::AngleAxisd(angle[j], a))).normalized();
  }
  return angle;
}

RevoluteSweeper::RevoluteSweeper(const ArmModel& model, const ArmState& start,
                                 const Eigen::VectorXd& target, int substeps)
    : model_(model), start_(start), target_(target), substeps_(substeps), n_(model.num_links()) {
  for (int j = 0; j < n_; ++j) {
    axes_.push_back(model.joint_axes.row(j).transpose());
    rest_.push_back(RestDirection(model, j));
  }
  // The frames of the start, accumulated from the base as forward kinematics does.
  Eigen::Quaterniond frame = Eigen::Quaterniond::Identity();
  for (int j = 0; j < n_; ++j) {
    frame = (frame * Eigen::Quaterniond(Eigen::AngleAxisd(start.angles.angle[j], axes_[j])))
                .normalized();
    start_frames_.push_back(frame);
  }
  angle_.resize(n_);
}

SmallVec RevoluteSweeper::Evaluate(const SmallVec& u) {
  ++sweeps_;
  limited_ = false;
  const bool limits = model_.joint_min.size() > 0;
  Points p = start_.points;
  p.rowwise() += u.transpose();
  frames_ = start_frames_;
  const Eigen::Vector3d from = p.row(n_).transpose();
  double head_old[3], tail_old[3];
  for (int s = 1; s <= substeps_; ++s) {
    for (int k = 0; k < 3; ++k) head_old[k] = p(n_, k);
    Eigen::Vector3d head;
    for (int k = 0; k < 3; ++k) head[k] = internal::SubstepHead(from[k], target_[k], s, substeps_);
    p.row(n_) = head.transpose();
    for (int j = n_; j >= 1; --j) {
      const double length = model_.link_lengths[j - 1];
      double* tail = p.row(j - 1).data();
      for (int k = 0; k < 3; ++k) tail_old[k] = tail[k];
      internal::TractrixStep<3>(head_old, p.row(j).data(), tail, length, 1.0 / length);
      const Eigen::Vector3d e = (p.row(j) - p.row(j - 1)).transpose() / length;
      if (j == n_) {
        // The end-effector link: the smallest rotation from its old direction to the new one.
        const Eigen::Vector3d e_old = frames_[j - 1] * rest_[j - 1];
        frames_[j - 1] =
            (Eigen::Quaterniond::FromTwoVectors(e_old, e) * frames_[j - 1]).normalized();
      } else {
        // Joint j turns link j into link j+1 (frame j): link j's direction lies on the cone
        // frames_[j] * Rot(axis_j, -q) * rest_[j-1].
        double q = -AngleAbout(axes_[j], rest_[j - 1], frames_[j].conjugate() * e);
        if (limits) {
          const double c = ClampCircular(q, model_.joint_min[j], model_.joint_max[j]);
          limited_ |= c != q;
          q = c;
        }
        angle_[j] = q;
        frames_[j - 1] =
            (frames_[j] * Eigen::Quaterniond(Eigen::AngleAxisd(-q, axes_[j]))).normalized();
        const Eigen::Vector3d on_cone = frames_[j - 1] * rest_[j - 1];
        for (int k = 0; k < 3; ++k) tail[k] = p(j, k) - length * on_cone[k];
      }
      for (int k = 0; k < 3; ++k) head_old[k] = tail_old[k];
    }
  }
  // Joint 0 turns the base link against the fixed base frame.
  const Eigen::Vector3d e1 = (p.row(1) - p.row(0)).transpose() / model_.link_lengths[0];
  double q0 = AngleAbout(axes_[0], rest_[0], e1);
  if (limits) {
    const double c = ClampCircular(q0, model_.joint_min[0], model_.joint_max[0]);
    limited_ |= c != q0;
    q0 = c;
  }
  angle_[0] = q0;
  points_ = RevoluteForward(model_, angle_);
  return points_.row(n_).transpose() - target_;
}

}  // namespace flexkin::arm_internal
