// Strands grown on a scalp, and the keyframed motion of the body they grow from
// (docs/groom-format.md, "Growing strands" and "Motion").
//
// The roots come from std::mt19937_64, whose sequence the C++ standard fixes, turned into doubles
// by our own (x >> 11) * 2^-53 and placed with + - * / and sqrt only (no distribution of the
// standard library, whose results are implementation-defined; no trigonometry), so a seed gives
// the same roots on every platform.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/groom.h"
#include "groom/grow_internal.h"

namespace flexkin {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kMaxGrownLinks = 1 << 20;
// Root placement gives up when, after this many candidates, fewer than 1 in kMinAcceptance of
// them fell in the region.
constexpr int64_t kGiveUpCandidates = 1000000;
constexpr int64_t kMinAcceptance = 10000;

std::string ShowVector(const Eigen::Vector3d& v) {
  return "[" + FormatNumber(v[0]) + ", " + FormatNumber(v[1]) + ", " + FormatNumber(v[2]) + "]";
}

// A double in [0, 1) from the generator's top 53 bits: the same on every platform.
double Uniform(std::mt19937_64& generator) { return double(generator() >> 11) * 0x1p-53; }

// A unit vector uniformly distributed over the sphere: a point uniform in the cube [-1, 1]^3,
// kept if it lies in the unit ball (and is not the centre), scaled to length 1.
Eigen::Vector3d UniformDirection(std::mt19937_64& generator) {
  for (;;) {
    const double x = 2.0 * Uniform(generator) - 1.0;
    const double y = 2.0 * Uniform(generator) - 1.0;
    const double z = 2.0 * Uniform(generator) - 1.0;
    const double r2 = x * x + y * y + z * z;
    if (r2 > 0.0 && r2 <= 1.0) {
      const double r = std::sqrt(r2);
      return {x / r, y / r, z / r};
    }
  }
}

// A unit vector perpendicular to the unit vector n, chosen without randomness: the coordinate
// axis least aligned with n (x before y before z in a tie) made perpendicular to n.
Eigen::Vector3d Perpendicular(const Eigen::Vector3d& n) {
  int k = 0;
  for (int i = 1; i < 3; ++i) {
    if (std::fabs(n[i]) < std::fabs(n[k])) k = i;
  }
  const Eigen::Vector3d e = Eigen::Vector3d::Unit(k);
  return (e - e.dot(n) * n).normalized();
}

void CheckVector(const Eigen::Vector3d& v, const char* field, Problems* problems) {
  if (!v.allFinite()) {
    problems->push_back(Problem::Invalid(field, ShowVector(v), "a finite vector"));
  } else if (!(v.squaredNorm() > 0.0)) {
    problems->emplace_back(field, "is zero; expected a non-zero vector", ShowVector(v),
                           "a non-zero vector");
  }
}

}  // namespace

Problems ValidateGrowSpec(const GrowSpec& spec) {
  Problems problems;
  const ScalpShape& scalp = spec.scalp;
  if (scalp.shape != "sphere" && scalp.shape != "ellipsoid") {
    problems.push_back(
        Problem::Invalid("scalp.shape", "\"" + scalp.shape + "\"", "\"sphere\" or \"ellipsoid\""));
  }
  if (!scalp.center.allFinite()) {
    problems.push_back(
        Problem::Invalid("scalp.center", ShowVector(scalp.center), "a finite point"));
  }
  bool radii_ok = true;
  for (int k = 0; k < 3; ++k) {
    const double r = scalp.radii[k];
    if (!(r > 0.0) || !std::isfinite(r)) {
      problems.push_back(Problem::Invalid("scalp.radii[" + std::to_string(k) + "]", FormatNumber(r),
                                          "a finite number > 0"));
      radii_ok = false;
    }
  }
  if (radii_ok && scalp.shape == "sphere" &&
      !(scalp.radii[0] == scalp.radii[1] && scalp.radii[1] == scalp.radii[2])) {
    problems.emplace_back("scalp.radii",
                          "value " + ShowVector(scalp.radii) +
                              " is not valid for a sphere; expected three equal radii",
                          ShowVector(scalp.radii), "three equal radii");
  }
  const bool roots_ok = spec.roots >= 1 && spec.roots <= kMaxGroomRoots;
  if (!roots_ok) {
    problems.push_back(Problem::Invalid("roots", std::to_string(spec.roots),
                                        "an integer from 1 to " + std::to_string(kMaxGroomRoots)));
  }
  const bool links_ok = spec.links >= 1 && spec.links <= kMaxGrownLinks;
  if (!links_ok) {
    problems.push_back(Problem::Invalid("links", std::to_string(spec.links),
                                        "an integer from 1 to " + std::to_string(kMaxGrownLinks)));
  }
  if (roots_ok && links_ok) {
    const int64_t points = int64_t{spec.roots} * (spec.links + 1);
    if (points > kMaxGroomPoints) {
      problems.emplace_back(
          "roots",
          "value " + std::to_string(spec.roots) + " with " + std::to_string(spec.links) +
              " links makes " + std::to_string(points) +
              " points; expected roots x (links + 1) <= " + std::to_string(kMaxGroomPoints),
          std::to_string(spec.roots), "roots x (links + 1) <= " + std::to_string(kMaxGroomPoints));
    }
  }
  if (!(spec.link_length > 0.0) || !std::isfinite(spec.link_length)) {
    problems.push_back(
        Problem::Invalid("link_length", FormatNumber(spec.link_length), "a finite number > 0"));
  }
  if (!(spec.length_variation >= 0.0 && spec.length_variation < 1.0)) {
    problems.push_back(Problem::Invalid("length_variation", FormatNumber(spec.length_variation),
                                        "a number >= 0 and < 1"));
  }
  if (!(spec.droop >= 0.0 && spec.droop <= 1.0)) {
    problems.push_back(Problem::Invalid("droop", FormatNumber(spec.droop), "a number from 0 to 1"));
  }
  CheckVector(spec.gravity, "gravity", &problems);
  CheckVector(spec.region_axis, "region_axis", &problems);
  if (!(spec.max_angle_deg > 0.0 && spec.max_angle_deg <= 180.0)) {
    problems.push_back(Problem::Invalid("max_angle_deg", FormatNumber(spec.max_angle_deg),
                                        "a number > 0 and <= 180 (degrees)"));
  }
  return problems;
}

namespace groom_internal {

void PlaceRoots(const GrowSpec& spec,
                const std::function<void(const Eigen::Vector3d& root, const Eigen::Vector3d& normal,
                                         double link_length)>& visit) {
  const Eigen::Vector3d radii = spec.scalp.radii;
  const bool ellipsoid = spec.scalp.shape == "ellipsoid";
  const double min_radius = radii.minCoeff();
  const Eigen::Vector3d axis = spec.region_axis.normalized();
  const bool whole_surface = spec.max_angle_deg >= 180.0;
  const double min_cos = std::cos(spec.max_angle_deg * (kPi / 180.0));

  std::mt19937_64 generator(spec.seed);
  int64_t candidates = 0;
  for (int i = 0; i < spec.roots; ++i) {
    // A candidate: a uniform direction u on the unit sphere, mapped to the surface point
    // center + radii .* u. The map stretches the area element by radii.prod() * g(u), g(u) =
    // |u ./ radii|, so for an ellipsoid the candidate is kept with probability
    // g(u) / max g = g(u) * min(radii): the kept points are uniform by area.
    Eigen::Vector3d u, normal;
    for (;;) {
      ++candidates;
      if (candidates > kGiveUpCandidates && candidates > kMinAcceptance * (int64_t{i} + 1)) {
        throw InputError("region", "after " + std::to_string(candidates) +
                                       " candidate roots only " + std::to_string(i) +
                                       " lay within " + FormatNumber(spec.max_angle_deg) +
                                       " degrees of the axis " + ShowVector(spec.region_axis) +
                                       "; expected a region covering at least about 1/" +
                                       std::to_string(kMinAcceptance) + " of the scalp");
      }
      u = UniformDirection(generator);
      const Eigen::Vector3d scaled = u.cwiseQuotient(radii);  // the outward normal, unscaled
      const double g = scaled.norm();
      if (ellipsoid && !(Uniform(generator) < g * min_radius)) continue;
      normal = scaled / g;
      if (whole_surface || normal.dot(axis) >= min_cos) break;
    }
    const double length =
        spec.link_length * (1.0 + spec.length_variation * (2.0 * Uniform(generator) - 1.0));
    visit(spec.scalp.center + radii.cwiseProduct(u), normal, length);
  }
}

}  // namespace groom_internal

std::vector<Points> GrowStrands(const GrowSpec& spec) {
  ThrowIfAny(ValidateGrowSpec(spec));
  const Eigen::Vector3d gravity = spec.gravity.normalized();
  std::vector<Points> strands;
  strands.reserve(spec.roots);
  groom_internal::PlaceRoots(
      spec, [&](const Eigen::Vector3d& root, const Eigen::Vector3d& normal, double length) {
        // Link j turns from the normal toward gravity by droop * theta * (j + 1) / links, in the
        // plane of the normal and gravity (`side`: gravity's part across the normal, unit).
        Eigen::Vector3d side = gravity - gravity.dot(normal) * normal;
        const double across = side.norm();
        const double theta = std::atan2(across, gravity.dot(normal));
        side = across > 1e-12 ? Eigen::Vector3d(side / across) : Perpendicular(normal);

        Points points(spec.links + 1, 3);
        Eigen::Vector3d p = root;
        points.row(0) = p.transpose();
        for (int j = 0; j < spec.links; ++j) {
          const double angle = spec.droop * theta * (j + 1) / spec.links;
          p += length * (std::cos(angle) * normal + std::sin(angle) * side);
          points.row(j + 1) = p.transpose();
        }
        strands.push_back(std::move(points));
      });
  return strands;
}

int64_t BodyMotion::num_frames() const {
  if (keyframes.empty()) return 0;
  const double duration = keyframes.back().time - keyframes.front().time;
  return static_cast<int64_t>(std::floor(duration * fps + 1e-9)) + 1;
}

double BodyMotion::TimeOf(int64_t frame) const {
  if (keyframes.empty()) return double(frame) / fps;
  const double first = keyframes.front().time, last = keyframes.back().time;
  return std::clamp(first + double(frame) / fps, first, last);
}

BodyPose BodyMotion::PoseAt(int64_t frame) const {
  if (keyframes.empty()) return {};
  return InterpolateKeyframes(keyframes, interpolation, TimeOf(frame));
}

}  // namespace flexkin
