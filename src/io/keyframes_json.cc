// The keyframes of a rigid motion in files (io/json_values.h, JsonReader::ReadKeyframes): a
// groom's "motion" (docs/groom-format.md) and a chain scenario's moving collider's "motion"
// (docs/scenario-format.md), one form and one set of messages for both.

#include <cmath>
#include <string>

#include "io/json_values.h"

namespace flexkin::json_internal {
namespace {

constexpr double kPi = 3.14159265358979323846;

const char* const kRotationExpected =
    "an object {\"axis\": [x, y, z], \"angle_deg\": a} or {\"quaternion\": [w, x, y, z]}";

}  // namespace

std::optional<std::pair<std::vector<BodyKeyframe>, KeyframeInterpolation>>
JsonReader::ReadKeyframes(const json& motion, const std::string& ptr, int dim,
                          const char* time_unit, int64_t max_keyframes) {
  const size_t before = problems.size();
  KeyframeInterpolation interpolation = KeyframeInterpolation::kSmooth;
  if (const json* v = Find(motion, "interpolation")) {
    if (const auto name = Choice(*v, ptr + "/interpolation", {"smooth", "linear"})) {
      interpolation =
          *name == "linear" ? KeyframeInterpolation::kLinear : KeyframeInterpolation::kSmooth;
    }
  }
  const std::string expected = "an array of at least 1 keyframe {\"time\": t, ...}";
  const json* list = Required(motion, ptr, "keyframes", expected);
  if (list == nullptr) return std::nullopt;
  const std::string lp = ptr + "/keyframes";
  if (!list->is_array()) {
    TypeProblem(*list, lp, expected);
    return std::nullopt;
  }
  if (list->empty()) {
    Add(lp, "has 0 keyframes; expected " + expected, "[]", expected);
    return std::nullopt;
  }
  if (list->size() > size_t(max_keyframes)) {
    Add(lp, "has " + std::to_string(list->size()) + " keyframes; expected at most " +
                std::to_string(max_keyframes));
    return std::nullopt;
  }
  std::vector<BodyKeyframe> keyframes;
  std::optional<double> previous;  // the last keyframe's time, if it could be read
  for (size_t k = 0; k < list->size(); ++k) {
    const std::string kp = lp + "/" + std::to_string(k);
    std::optional<BodyKeyframe> keyframe = ReadKeyframe((*list)[k], kp, dim, time_unit);
    const json* time = (*list)[k].is_object() ? Find((*list)[k], "time") : nullptr;
    std::optional<double> t;
    if (time != nullptr && time->is_number() && std::isfinite(time->get<double>())) {
      t = time->get<double>();
    }
    if (t && previous && !(*t > *previous)) {
      Add(kp + "/time",
          "value " + ShowJson(*time) + " is not above " + FormatNumber(*previous) +
              ", the time of " + lp + "/" + std::to_string(k - 1) +
              "/time; expected keyframe times that increase "
              "strictly",
          ShowJson(*time), "a time > " + FormatNumber(*previous));
    }
    previous = t;
    if (keyframe) keyframes.push_back(std::move(*keyframe));
  }
  if (problems.size() != before) return std::nullopt;
  return std::make_pair(std::move(keyframes), interpolation);
}

std::optional<BodyKeyframe> JsonReader::ReadKeyframe(const json& v, const std::string& ptr, int dim,
                                                     const char* time_unit) {
  if (!ExpectObject(v, ptr,
                    "an object {\"time\": t, \"translation\": [...], \"rotation\": {...}} (3D) "
                    "or {\"time\": t, \"translation\": [x, y], \"angle_deg\": a} (2D)")) {
    return std::nullopt;
  }
  CheckKeys(v, ptr, {"time", "translation", "rotation", "angle_deg"});
  const size_t before = problems.size();
  const auto number = [this](const json& x, const std::string& p) {
    return Number(x, p, Range::kAny);
  };
  BodyKeyframe keyframe;
  Require(v, ptr, "time", std::string("a finite number (") + time_unit + ")", number,
          &keyframe.time);
  Eigen::VectorXd translation = Eigen::Vector3d::Zero();
  Optional(
      v, ptr, "translation",
      [this, dim](const json& x, const std::string& p) { return Vector(x, p, dim); }, &translation);
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  t.head(translation.size()) = translation;
  if (dim == 2 && Find(v, "rotation")) {
    Add(ptr + "/rotation",
        "is only valid in 3D scenarios; a 2D keyframe turns about z by \"angle_deg\"");
  }
  if (dim == 3 && Find(v, "angle_deg")) {
    Add(ptr + "/angle_deg", "is only valid in 2D scenarios; a 3D keyframe turns by \"rotation\": " +
                                std::string(kRotationExpected));
  }
  std::optional<Eigen::Quaterniond> rotation;
  if (dim != 2) {
    if (const json* r = Find(v, "rotation")) rotation = ReadRotation(*r, ptr + "/rotation");
  }
  double angle_deg = 0.0;
  if (dim != 3) Optional(v, ptr, "angle_deg", number, &angle_deg);
  if (problems.size() != before) return std::nullopt;
  if (dim == 2) {
    keyframe.pose = BodyPose::Planar(angle_deg * (kPi / 180.0), t[0], t[1]);
  } else {
    const Eigen::Quaterniond q = rotation.value_or(Eigen::Quaterniond::Identity());
    keyframe.pose = BodyPose::FromQuaternion(q.w(), q.x(), q.y(), q.z(), t);
  }
  return keyframe;
}

std::optional<Eigen::Quaterniond> JsonReader::ReadRotation(const json& r, const std::string& ptr) {
  if (!ExpectObject(r, ptr, kRotationExpected)) return std::nullopt;
  CheckKeys(r, ptr, {"axis", "angle_deg", "quaternion"});
  const size_t before = problems.size();
  if (const json* q = Find(r, "quaternion")) {
    for (const char* key : {"axis", "angle_deg"}) {
      if (Find(r, key)) {
        Add(ptr + "/" + key,
            "is not valid with \"quaternion\"; give axis and angle_deg, or "
            "quaternion, not both");
      }
    }
    const std::string qp = ptr + "/quaternion";
    const char* expected = "an array of 4 numbers [w, x, y, z], not all zero";
    if (!q->is_array()) {
      TypeProblem(*q, qp, expected);
      return std::nullopt;
    }
    if (q->size() != 4) {
      Add(qp,
          "value " + ShowJson(*q) + " has " + std::to_string(q->size()) +
              (q->size() == 1 ? " number" : " numbers") + "; expected " + expected,
          ShowJson(*q), expected);
      return std::nullopt;
    }
    Eigen::Vector4d c;
    for (int k = 0; k < 4; ++k) {
      if (const auto x = Number((*q)[k], qp + "/" + std::to_string(k), Range::kAny)) c[k] = *x;
    }
    if (problems.size() != before) return std::nullopt;
    if (!(c.squaredNorm() > 0.0) || !std::isfinite(c.squaredNorm())) {
      Add(qp, "value " + ShowJson(*q) + " is not valid; expected " + expected, ShowJson(*q),
          expected);
      return std::nullopt;
    }
    c.normalize();
    return Eigen::Quaterniond(c[0], c[1], c[2], c[3]);
  }
  Eigen::VectorXd axis = Eigen::Vector3d::UnitZ();
  double angle_deg = 0.0;
  Require(
      r, ptr, "axis", "an array of 3 numbers, not all zero (the axis of the rotation)",
      [this](const json& x, const std::string& p) { return Vector(x, p, 3); }, &axis);
  Require(
      r, ptr, "angle_deg", "a finite number (degrees)",
      [this](const json& x, const std::string& p) { return Number(x, p, Range::kAny); },
      &angle_deg);
  if (problems.size() != before) return std::nullopt;
  if (!(axis.squaredNorm() > 0.0) || !std::isfinite(axis.squaredNorm())) {
    Add(ptr + "/axis", "is zero; expected a non-zero vector", ShowJson(r["axis"]),
        "a non-zero vector");
    return std::nullopt;
  }
  return Eigen::Quaterniond(
      Eigen::AngleAxisd(angle_deg * (kPi / 180.0), Eigen::Vector3d(axis.normalized())));
}

}  // namespace flexkin::json_internal
