// Joint angles <-> link points of a fixed-base arm (include/flexkin/arm.h), the model's checks
// and the joint-limit projections the solver uses.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "arm/anchor.h"
#include "arm/internal.h"
#include "arm/revolute.h"
#include "flexkin/arm.h"
#include "flexkin/error.h"

namespace flexkin {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();

// x mapped to (-pi, pi] by a multiple of 2 pi.
double Wrap(double x) {
  if (x > -kPi && x <= kPi) return x;  // what remainder gives, without its cost
  const double r = std::remainder(x, 2.0 * kPi);
  return r <= -kPi ? r + 2.0 * kPi : r;
}

std::string Indexed(const char* field, int i) {
  return std::string(field) + "[" + std::to_string(i) + "]";
}

std::optional<Problem> CheckVector(const Eigen::VectorXd& v, const char* field, int size) {
  if (v.size() != size) {
    return Problem(field,
                   "has " + std::to_string(v.size()) + " values; expected " + std::to_string(size));
  }
  for (int i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) {
      return Problem::Invalid(Indexed(field, i), FormatNumber(v[i]), "a finite number");
    }
  }
  return std::nullopt;
}

// The base frame: the smallest rotation taking the world x axis to the base direction.
Eigen::Quaterniond BaseFrame(const ArmModel& model) {
  return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitX(),
                                            model.base_direction.head<3>().normalized());
}

// The rotation of a spherical joint in the frame of the link before it (see JointAngles).
Eigen::Quaterniond LocalRotation(double bend, double azimuth) {
  const double s = std::sin(0.5 * bend);
  return Eigen::Quaterniond(std::cos(0.5 * bend), 0.0, -std::sin(azimuth) * s,
                            std::cos(azimuth) * s);
}

void CheckAngles(const ArmModel& model, const JointAngles& angles, const char* field) {
  const int n = model.num_links();
  const bool spherical = model.joint() == ArmJoint::kSpherical;
  std::optional<Problem> why = CheckVector(angles.angle, "angle", n);
  if (!why && spherical) why = CheckVector(angles.azimuth, "azimuth", n);
  if (!why && !spherical && angles.azimuth.size() != 0) {
    why = Problem("azimuth", "revolute joints have no azimuths; expected none");
  }
  if (why) {
    Problems problems;
    AppendNested(field, {*why}, &problems);
    ThrowIfAny(problems);
  }
}

}  // namespace

namespace arm_internal {

void CheckModel(const ArmModel& model) { ThrowIfAny(model.Validate()); }

double ClampCircular(double theta, double lo, double hi) {
  if (theta >= lo && theta <= hi) return theta;
  return std::abs(Wrap(theta - lo)) <= std::abs(Wrap(theta - hi)) ? lo : hi;
}

bool ClampToLimits(const ArmModel& model, JointAngles* angles) {
  bool changed = false;
  for (int j = 0; j < model.joint_min.size(); ++j) {
    // With joint axes the limits are an interval of the line (multi-turn, prismatic); otherwise
    // of the circle.
    const double c = model.has_axes()
                         ? std::clamp(angles->angle[j], model.joint_min[j], model.joint_max[j])
                         : ClampCircular(angles->angle[j], model.joint_min[j], model.joint_max[j]);
    changed |= c != angles->angle[j];
    angles->angle[j] = c;
  }
  for (int j = 0; j < model.max_bend.size(); ++j) {
    if (angles->angle[j] > model.max_bend[j]) {
      angles->angle[j] = model.max_bend[j];
      changed = true;
    }
  }
  return changed;
}

bool ClampDirection(int dim, const double* reference, double lo, double hi, double* dir) {
  if (dim == 2) {
    const double cross = reference[0] * dir[1] - reference[1] * dir[0];
    const double dot = reference[0] * dir[0] + reference[1] * dir[1];
    const double theta = std::atan2(cross, dot);
    const double c = ClampCircular(theta, lo, hi);
    if (c == theta) return false;
    const double cs = std::cos(c), sn = std::sin(c);
    dir[0] = cs * reference[0] - sn * reference[1];
    dir[1] = sn * reference[0] + cs * reference[1];
    return true;
  }
  const Eigen::Map<const Eigen::Vector3d> ref(reference);
  Eigen::Map<Eigen::Vector3d> d(dir);
  const double dot = ref.dot(d);
  Eigen::Vector3d w = d - dot * ref;
  const double angle = std::atan2(w.norm(), dot);
  if (angle <= hi) return false;
  if (!(w.squaredNorm() > 0.0)) w = ref.unitOrthogonal();  // exact reversal: any side will do
  d = std::cos(hi) * ref + std::sin(hi) * w.normalized();
  return true;
}

}  // namespace arm_internal

// The checks of an arm model in independent sections, each giving its first problem: Validate lists
// one problem per section, so a model with a bad base and bad limits hears of both. The dimension
// and the links come first; nothing else can be checked without them.
namespace {

std::optional<Problem> ShapeProblem(const ArmModel& m) {
  const int dim = m.dim;
  const Eigen::VectorXd& link_lengths = m.link_lengths;
  if (dim != 2 && dim != 3) {
    return Problem("dim", "value " + std::to_string(dim) + " is not 2 or 3", std::to_string(dim),
                   "2 or 3");
  }
  const int n = m.num_links();
  if (n < 1) return Problem("link_lengths", "the arm has no links; expected at least 1");
  // With joint axes a link may have length 0 (joints at one point, a tip on its joint).
  const bool zero_ok = m.has_axes();
  for (int i = 0; i < n; ++i) {
    if (!(link_lengths[i] > 0.0 || (zero_ok && link_lengths[i] == 0.0)) ||
        !std::isfinite(link_lengths[i])) {
      const char* expected = zero_ok ? "a finite number >= 0" : "a positive finite number";
      return Problem(Indexed("link_lengths", i),
                     "value " + FormatNumber(link_lengths[i]) + " is not " + expected,
                     FormatNumber(link_lengths[i]), expected);
    }
  }
  if (!(link_lengths.sum() > 0.0)) {
    return Problem("link_lengths", "every link has length 0; expected a positive total length");
  }
  return std::nullopt;
}

std::optional<Problem> BaseProblem(const ArmModel& m) {
  const int dim = m.dim;
  const Eigen::VectorXd &base = m.base, &base_direction = m.base_direction;
  std::optional<Problem> why = CheckVector(base, "base", dim);
  if (!why) why = CheckVector(base_direction, "base_direction", dim);
  if (why) return why;
  if (!(base_direction.squaredNorm() > 0.0)) {
    return Problem("base_direction", "is zero; expected a non-zero vector");
  }
  return std::nullopt;
}

std::optional<Problem> AxesProblem(const ArmModel& m) {
  if (m.has_axes() || m.link_directions.size() != 0) {
    if (!m.has_axes()) {
      return Problem("link_directions", "only arms with joint_axes have link directions");
    }
    return arm_internal::ValidateAxes(m);
  }
  return std::nullopt;
}

std::optional<Problem> LimitsProblem(const ArmModel& m) {
  const int n = m.num_links();
  const Eigen::VectorXd &joint_min = m.joint_min, &joint_max = m.joint_max, &max_bend = m.max_bend;
  const auto has_axes = [&m] { return m.has_axes(); };
  std::optional<Problem> why;
  const bool revolute = m.joint() == ArmJoint::kRevolute;
  if (revolute) {
    if (max_bend.size() != 0) {
      return Problem("max_bend", "revolute joints have joint_min and joint_max instead");
    }
    if (joint_min.size() != joint_max.size()) {
      return Problem("joint_max", "joint_min and joint_max differ in size");
    }
    if (joint_min.size() != 0 && has_axes()) {
      // As written: multi-turn, continuous (infinite) or prismatic (length) limits.
      if (joint_min.size() != n) {
        return Problem("joint_min", "has " + std::to_string(joint_min.size()) +
                                        " values; expected " + std::to_string(n));
      }
      for (int j = 0; j < n; ++j) {
        if (!(joint_min[j] <= joint_max[j]) || joint_min[j] == kInf || joint_max[j] == -kInf) {
          return Problem(Indexed("joint_min", j),
                         "limits [" + FormatNumber(joint_min[j]) + ", " +
                             FormatNumber(joint_max[j]) +
                             "] are not valid; expected min <= max (-inf and inf: no limit)");
        }
      }
    } else if (joint_min.size() != 0) {
      if ((why = CheckVector(joint_min, "joint_min", n))) return why;
      if ((why = CheckVector(joint_max, "joint_max", n))) return why;
      for (int j = 0; j < n; ++j) {
        if (!(joint_min[j] >= -kPi && joint_min[j] <= joint_max[j] && joint_max[j] <= kPi)) {
          return Problem(Indexed("joint_min", j),
                         "limits [" + FormatNumber(joint_min[j]) + ", " +
                             FormatNumber(joint_max[j]) +
                             "] rad are not valid; expected -pi <= min <= max <= pi");
        }
      }
    }
  } else {
    if (joint_min.size() != 0 || joint_max.size() != 0) {
      return Problem("joint_min", "spherical joints have max_bend instead");
    }
    if (max_bend.size() != 0) {
      if ((why = CheckVector(max_bend, "max_bend", n))) return why;
      for (int j = 0; j < n; ++j) {
        if (!(max_bend[j] > 0.0 && max_bend[j] <= kPi)) {
          return Problem(Indexed("max_bend", j),
                         "value " + FormatNumber(max_bend[j]) +
                             " rad is not valid; expected 0 < max_bend <= pi",
                         FormatNumber(max_bend[j]), "0 < max_bend <= pi");
        }
      }
    }
  }
  return std::nullopt;
}

// The link radii: none, or n finite values >= 0.
std::optional<Problem> RadiiProblem(const ArmModel& m) {
  const Eigen::VectorXd& r = m.link_radii;
  if (r.size() == 0) return std::nullopt;
  if (r.size() != m.num_links()) {
    return Problem("link_radii", "has " + std::to_string(r.size()) + " values; expected " +
                                     std::to_string(m.num_links()) + " (one per link) or none");
  }
  for (int k = 0; k < r.size(); ++k) {
    if (!(r[k] >= 0.0 && std::isfinite(r[k]))) {
      return Problem::Invalid(Indexed("link_radii", k), FormatNumber(r[k]),
                              "a finite radius >= 0 (length unit)");
    }
  }
  return std::nullopt;
}

std::optional<Problem> NamesAndVelocityProblem(const ArmModel& m) {
  const int n = m.num_links();
  const bool revolute = m.joint() == ArmJoint::kRevolute;
  const auto& joint_names = m.joint_names;
  const Eigen::VectorXd& max_velocity = m.max_velocity;
  if (!joint_names.empty() && static_cast<int>(joint_names.size()) != n) {
    return Problem("joint_names", "has " + std::to_string(joint_names.size()) +
                                      " names; expected " + std::to_string(n) + " or none");
  }
  if (max_velocity.size() != 0) {
    if (!revolute) {
      return Problem("max_velocity", "spherical joints have no velocity limits; expected none");
    }
    if (max_velocity.size() != n) {
      return Problem("max_velocity", "has " + std::to_string(max_velocity.size()) +
                                         " values; expected " + std::to_string(n) + " or none");
    }
    for (int j = 0; j < n; ++j) {
      if (!(max_velocity[j] > 0.0)) {
        return Problem(Indexed("max_velocity", j),
                       "value " + FormatNumber(max_velocity[j]) +
                           " is not valid; expected a speed > 0 (inf: no limit)",
                       FormatNumber(max_velocity[j]), "> 0");
      }
    }
  }
  return std::nullopt;
}

// After LimitsProblem found nothing: the initial angles are checked against the limits.
std::optional<Problem> InitialProblem(const ArmModel& m) {
  const int n = m.num_links();
  const bool revolute = m.joint() == ArmJoint::kRevolute;
  const auto& initial = m.initial;
  const Eigen::VectorXd &joint_min = m.joint_min, &joint_max = m.joint_max, &max_bend = m.max_bend;
  const auto has_axes = [&m] { return m.has_axes(); };
  std::optional<Problem> why = CheckVector(initial.angle, "initial.angle", n);
  if (!why && !revolute) why = CheckVector(initial.azimuth, "initial.azimuth", n);
  if (!why && revolute && initial.azimuth.size() != 0) {
    why = Problem("initial.azimuth", "revolute joints have no azimuths; expected none");
  }
  if (why) return why;
  for (int j = 0; j < n; ++j) {
    const double a = initial.angle[j];
    // With joint axes the limits alone bound the angles (multi-turn joints, prismatic ones).
    const bool ok = has_axes() || (revolute ? a >= -kPi && a <= kPi : a >= 0.0 && a <= kPi);
    if (!ok) {
      const char* expected = revolute ? "-pi <= angle <= pi" : "0 <= bend angle <= pi";
      return Problem(Indexed("initial.angle", j),
                     "value " + FormatNumber(a) + " rad is not valid; expected " + expected,
                     FormatNumber(a), expected);
    }
    const bool inside = revolute ? joint_min.size() == 0 || (a >= joint_min[j] && a <= joint_max[j])
                                 : max_bend.size() == 0 || a <= max_bend[j];
    if (!inside) {
      return Problem(Indexed("initial.angle", j),
                     "value " + FormatNumber(a) +
                         " rad is outside the joint's limits; the initial angles must be within "
                         "them",
                     FormatNumber(a), "within the joint's limits");
    }
  }
  return std::nullopt;
}

}  // namespace

Problems ArmModel::Validate() const {
  if (std::optional<Problem> shape = ShapeProblem(*this)) return {*shape};
  Problems problems;
  const auto add = [&problems](std::optional<Problem> p) {
    if (p) problems.push_back(std::move(*p));
  };
  add(BaseProblem(*this));
  add(AxesProblem(*this));
  std::optional<Problem> limits = LimitsProblem(*this);
  const bool limits_ok = !limits;
  add(std::move(limits));
  add(NamesAndVelocityProblem(*this));
  add(RadiiProblem(*this));
  if (limits_ok) add(InitialProblem(*this));
  return problems;
}

std::optional<Problem> ArmModel::FirstProblem() const {
  const Problems problems = Validate();
  if (problems.empty()) return std::nullopt;
  return problems.front();
}

ArmModel StraightArm(int dim, int links, double link_length) {
  ArmModel model;
  model.dim = dim;
  model.link_lengths = Eigen::VectorXd::Constant(links, link_length);
  model.base = Eigen::VectorXd::Zero(dim);
  model.base_direction = Eigen::VectorXd::Unit(dim, 0);
  model.initial.angle = Eigen::VectorXd::Zero(links);
  if (dim == 3) model.initial.azimuth = Eigen::VectorXd::Zero(links);
  return model;
}

Points ForwardKinematics(const ArmModel& model, const JointAngles& angles) {
  arm_internal::CheckModel(model);
  CheckAngles(model, angles, "angles");
  return arm_internal::ForwardUnchecked(model, angles);
}

JointAngles JointAnglesFromPoints(const ArmModel& model, const Points& points) {
  arm_internal::CheckModel(model);
  const int n = model.num_links();
  if (points.rows() != n + 1 || points.cols() != model.dim) {
    throw InputError("points", "shape " + std::to_string(points.rows()) + " by " +
                                   std::to_string(points.cols()) + " is not valid; expected " +
                                   std::to_string(n + 1) + " by " + std::to_string(model.dim));
  }
  if (!points.allFinite()) throw InputError("points", "a value is not a finite number");
  if (model.has_axes() && !arm_internal::Sweepable(model)) {
    throw InputError("model",
                     "has twist, prismatic or coincident joints (or limits beyond "
                     "[-pi, pi]), whose values the points do not determine; keep the "
                     "joint angles (ArmState::angles) instead");
  }
  return arm_internal::AnglesUnchecked(model, points);
}

namespace arm_internal {

void Atan2All(const double* y, const double* x, int count, double* out, bool batched) {
#if FLEXKIN_HAVE_WAVEFRONT
  if (batched && HasAvx2Fma()) {
    internal::Atan2Avx2(y, x, count, out);
    return;
  }
#endif
  for (int i = 0; i < count; ++i) out[i] = std::atan2(y[i], x[i]);
}

void SinCosAll(const double* a, int count, double* s, double* c, bool batched) {
#if FLEXKIN_HAVE_WAVEFRONT
  if (batched && HasAvx2Fma()) {
    internal::SinCosAvx2(a, count, s, c);
    return;
  }
#endif
  for (int i = 0; i < count; ++i) {
    s[i] = std::sin(a[i]);
    c[i] = std::cos(a[i]);
  }
}

Points ForwardUnchecked(const ArmModel& model, const JointAngles& angles) {
  const int n = model.num_links();
  Points points(n + 1, model.dim);
  points.row(0) = model.base.transpose();
  if (model.dim == 2) {
    // The headings (sequential sums), their sines and cosines (independent: batched where the
    // CPU allows), then the points (sequential sums).
    Eigen::VectorXd scratch(3 * n);
    double* heading = scratch.data();
    double* sn = heading + n;
    double* cs = sn + n;
    double h = std::atan2(model.base_direction[1], model.base_direction[0]);
    for (int j = 0; j < n; ++j) heading[j] = h += angles.angle[j];
    SinCosAll(heading, n, sn, cs);
    for (int j = 0; j < n; ++j) {
      const double l = model.link_lengths[j];
      points(j + 1, 0) = points(j, 0) + l * cs[j];
      points(j + 1, 1) = points(j, 1) + l * sn[j];
    }
    return points;
  }
  if (model.has_axes()) return RevoluteForward(model, angles.angle);
  Eigen::Quaterniond frame = BaseFrame(model);
  for (int j = 0; j < n; ++j) {
    frame = (frame * LocalRotation(angles.angle[j], angles.azimuth[j])).normalized();
    const Eigen::Vector3d d = frame * Eigen::Vector3d::UnitX();
    points.row(j + 1) = points.row(j) + model.link_lengths[j] * d.transpose();
  }
  return points;
}

JointAngles AnglesUnchecked(const ArmModel& model, const Points& points, Points* rebuilt) {
  const int n = model.num_links();
  JointAngles angles;
  angles.angle.resize(n);
  // Each angle is measured against the frame that forward kinematics accumulates, with the same
  // operations, so FK reproduces every direction to rounding without drift along the arm.
  if (model.dim == 2) {
    // Each link's direction (independent: batched where the CPU allows), then the angles
    // against the accumulated heading (sequential).
    Eigen::VectorXd scratch(2 * n);
    double* dx = scratch.data();
    double* dy = dx + n;
    for (int j = 0; j < n; ++j) {
      dx[j] = points(j + 1, 0) - points(j, 0);
      dy[j] = points(j + 1, 1) - points(j, 1);
    }
    double* direction = angles.angle.data();
    Atan2All(dy, dx, n, direction);
    double heading = std::atan2(model.base_direction[1], model.base_direction[0]);
    for (int j = 0; j < n; ++j) {
      const double theta = (dx[j] == 0.0 && dy[j] == 0.0) ? 0.0 : Wrap(direction[j] - heading);
      angles.angle[j] = theta;
      heading += theta;
    }
    if (rebuilt != nullptr) *rebuilt = ForwardUnchecked(model, angles);
    return angles;
  }
  if (model.has_axes()) {
    angles.angle = RevoluteInverse(model, points);
    if (rebuilt != nullptr) *rebuilt = ForwardUnchecked(model, angles);
    return angles;
  }
  angles.azimuth.resize(n);
  Eigen::Quaterniond frame = BaseFrame(model);
  if (rebuilt != nullptr) {
    rebuilt->resize(n + 1, 3);
    rebuilt->row(0) = model.base.transpose();
  }
  for (int j = 0; j < n; ++j) {
    const Eigen::Vector3d d = (points.row(j + 1) - points.row(j)).transpose();
    const Eigen::Vector3d v = frame.conjugate() * d;
    const double side = std::hypot(v.y(), v.z());
    angles.angle[j] = std::atan2(side, v.x());
    angles.azimuth[j] = side > 0.0 ? std::atan2(v.z(), v.y()) : 0.0;
    frame = (frame * LocalRotation(angles.angle[j], angles.azimuth[j])).normalized();
    if (rebuilt != nullptr) {
      // ForwardUnchecked's operations on the same frame: the same points, bit for bit.
      const Eigen::Vector3d e = frame * Eigen::Vector3d::UnitX();
      rebuilt->row(j + 1) = rebuilt->row(j) + model.link_lengths[j] * e.transpose();
    }
  }
  return angles;
}

}  // namespace arm_internal

Eigen::MatrixXd JointQuaternions(const ArmModel& model, const JointAngles& angles) {
  arm_internal::CheckModel(model);
  CheckAngles(model, angles, "angles");
  const int n = model.num_links();
  Eigen::MatrixXd q(n, 4);
  for (int j = 0; j < n; ++j) {
    if (model.dim == 2) {
      q.row(j) << std::cos(0.5 * angles.angle[j]), 0.0, 0.0, std::sin(0.5 * angles.angle[j]);
    } else if (model.prismatic(j)) {
      q.row(j) << 1.0, 0.0, 0.0, 0.0;  // a slide turns nothing
    } else if (model.has_axes()) {
      const double s = std::sin(0.5 * angles.angle[j]);
      q.row(j) << std::cos(0.5 * angles.angle[j]), s * model.joint_axes.row(j);
    } else {
      const Eigen::Quaterniond r = LocalRotation(angles.angle[j], angles.azimuth[j]);
      q.row(j) << r.w(), r.x(), r.y(), r.z();
    }
  }
  return q;
}

bool WithinLimits(const ArmModel& model, const JointAngles& angles, double slack) {
  for (int j = 0; j < model.joint_min.size(); ++j) {
    if (!(angles.angle[j] >= model.joint_min[j] - slack &&
          angles.angle[j] <= model.joint_max[j] + slack)) {
      return false;
    }
  }
  for (int j = 0; j < model.max_bend.size(); ++j) {
    if (!(angles.angle[j] <= model.max_bend[j] + slack)) return false;
  }
  return true;
}

namespace {

// Whether joint j shares its point with what follows it (the next joint, or the tip after the
// last joint): a link of length 0 that no slide stretches.
bool JoinsNext(const ArmModel& model, int j) {
  return model.link_lengths[j] == 0.0 && !model.prismatic(j);
}

}  // namespace

std::vector<std::vector<int>> JointGroups(const ArmModel& model) {
  arm_internal::CheckModel(model);
  std::vector<std::vector<int>> groups;
  for (int j = 0; j < model.num_links(); ++j) {
    if (j == 0 || !JoinsNext(model, j - 1)) groups.emplace_back();
    groups.back().push_back(j);
  }
  return groups;
}

Points ChainPoints(const ArmModel& model, const Points& points) {
  const std::vector<std::vector<int>> groups = JointGroups(model);
  const int n = model.num_links();
  if (points.rows() != n + 1 || points.cols() != model.dim) {
    throw InputError("points", "shape " + std::to_string(points.rows()) + " by " +
                                   std::to_string(points.cols()) + " is not valid; expected " +
                                   std::to_string(n + 1) + " by " + std::to_string(model.dim));
  }
  // The tip is a point of its own unless the last group reaches it (a tip on its joint).
  const bool tip_apart = !JoinsNext(model, n - 1);
  Points chain(groups.size() + (tip_apart ? 1 : 0), model.dim);
  for (size_t g = 0; g < groups.size(); ++g) chain.row(g) = points.row(groups[g].front());
  if (tip_apart) chain.row(groups.size()) = points.row(n);
  return chain;
}

std::string JointGroupsReport(const ArmModel& model) {
  std::string out;
  auto name = [&](int j) {
    return static_cast<int>(model.joint_names.size()) == model.num_links()
               ? "\"" + model.joint_names[j] + "\""
               : std::to_string(j);
  };
  const int n = model.num_links();
  for (const std::vector<int>& group : JointGroups(model)) {
    const bool with_tip = group.back() == n - 1 && JoinsNext(model, n - 1);
    if (group.size() < 2 && !with_tip) continue;
    std::string line = group.size() == 1 ? "joint " : "joints ";
    for (size_t i = 0; i < group.size(); ++i) {
      line += (i == 0 ? "" : i + 1 == group.size() ? " and " : ", ") + name(group[i]);
    }
    line += group.size() == 1 ? " acts" : " act";
    if (with_tip) {
      line += group.size() == 1 ? " at the end effector (it turns the tool frame only)"
                                : " at the end effector (they turn the tool frame only)";
    } else {
      line += " at one point";
    }
    if (group.size() == 2) line += " (a universal joint)";
    if (group.size() == 3) line += " (a spherical joint)";
    out += line + "\n";
  }
  return out;
}

ToolPose ToolPoseAt(const ArmModel& model, const JointAngles& angles) {
  arm_internal::CheckModel(model);
  CheckAngles(model, angles, "angles");
  if (!model.has_axes()) {
    throw InputError("model",
                     "has no joint axes; the tool frame is defined for arms with "
                     "joint_axes (URDF arms)");
  }
  Eigen::Quaterniond last;
  const Points points = arm_internal::RevoluteForward(model, angles.angle, nullptr, &last);
  const Eigen::Vector4d& t = model.tip_rotation;
  ToolPose pose;
  pose.position = points.row(model.num_links()).transpose();
  pose.rotation = (last * Eigen::Quaterniond(t[0], t[1], t[2], t[3])).toRotationMatrix();
  return pose;
}

ArmState InitialState(const ArmModel& model) {
  ArmState state;
  state.points = ForwardKinematics(model, model.initial);
  state.angles = model.initial;
  return state;
}

}  // namespace flexkin
