#include "flexkin/curves.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>

#include "flexkin/error.h"

namespace flexkin {
namespace {

constexpr double kPi = 3.14159265358979323846;

void CheckLinks(int links, Problems* problems) {
  if (links < 1 || links > kMaxGeneratedLinks) {
    problems->emplace_back("links", "value " + std::to_string(links) +
                                        " is not valid; expected an integer from 1 to " +
                                        std::to_string(kMaxGeneratedLinks));
  }
}

void CheckLinkLength(double link_length, Problems* problems) {
  if (!(link_length > 0.0) || !std::isfinite(link_length)) {
    problems->emplace_back("link_length", "value " + FormatNumber(link_length) +
                                              " is not valid; expected a finite number > 0");
  }
}

void CheckFinite(const char* field, double value, Problems* problems) {
  if (!std::isfinite(value)) {
    problems->emplace_back(field, "value " + FormatNumber(value) + " is not a finite number");
  }
}

void CheckFiniteVector(const char* field, const Eigen::Ref<const Eigen::VectorXd>& v,
                       Problems* problems) {
  for (Eigen::Index k = 0; k < v.size(); ++k) {
    if (!std::isfinite(v[k])) {
      problems->emplace_back(std::string(field) + "[" + std::to_string(k) + "]",
                             "value " + FormatNumber(v[k]) + " is not a finite number");
    }
  }
}

void CheckRadius(double radius, Problems* problems) {
  if (!(radius > 0.0) || !std::isfinite(radius)) {
    problems->emplace_back(
        "radius", "value " + FormatNumber(radius) + " is not valid; expected a finite number > 0");
  }
}

template <typename Def>
void ThrowFirstProblem(const Def& def) {
  ThrowIfAny(CurveProblems(def));
}

// Chord length of the parabola y = a x^2 between x0 >= 0 and x0 + u, u >= 0:
// |(u, a u (2 x0 + u))| = u sqrt(1 + (a (2 x0 + u))^2); written this way to avoid the
// cancellation in a (x1^2 - x0^2). Increasing and convex in u.
double ParabolaChord(double a, double x0, double u) {
  return u * std::hypot(1.0, a * (2.0 * x0 + u));
}

// The u > 0 with ParabolaChord(a, x0, u) = length. The chord is >= u, so u is in (0, length].
// Newton from the right end converges monotonically for a convex increasing function; the bracket
// guards against rounding, with bisection as the fallback.
double ParabolaAdvance(double a, double x0, double length) {
  double lo = 0.0, hi = length, u = length;
  for (int iter = 0; iter < 200; ++iter) {
    const double f = ParabolaChord(a, x0, u) - length;
    if (f == 0.0) return u;
    if (f > 0.0) {
      hi = u;
    } else {
      lo = u;
    }
    const double s = a * (2.0 * x0 + u);
    const double root = std::hypot(1.0, s);
    const double slope = root + u * a * s / root;  // d chord / du, >= 1
    double next = u - f / slope;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (next == u || hi - lo <= 4.0 * std::numeric_limits<double>::epsilon() * hi) break;
    u = next;
  }
  // The better end of the bracket.
  return std::fabs(ParabolaChord(a, x0, lo) - length) < std::fabs(ParabolaChord(a, x0, hi) - length)
             ? lo
             : hi;
}

// Chord of a helix between parameters t and t + dt: sqrt(4 r^2 sin^2(dt/2) + (c dt)^2), c the
// rise per radian. Increasing on [0, pi].
double HelixChord(double radius, double rise_per_radian, double dt) {
  return std::hypot(2.0 * radius * std::sin(0.5 * dt), rise_per_radian * dt);
}

}  // namespace

Problems CurveProblems(const LineDef& def) {
  Problems problems;
  if (def.start.size() != 2 && def.start.size() != 3) {
    problems.emplace_back("start", "has " + std::to_string(def.start.size()) +
                                       " coordinates; expected 2 (planar) or 3 (spatial)");
  } else if (def.direction.size() != def.start.size()) {
    problems.emplace_back("direction", "has " + std::to_string(def.direction.size()) +
                                           " coordinates; expected " +
                                           std::to_string(def.start.size()) + ", as \"start\"");
  } else {
    CheckFiniteVector("start", def.start, &problems);
    CheckFiniteVector("direction", def.direction, &problems);
    const double norm = def.direction.norm();
    if (def.direction.allFinite() && !(norm > 0.0 && std::isfinite(norm))) {
      problems.emplace_back("direction", "has length " + FormatNumber(norm) +
                                             "; expected a nonzero, finite direction vector");
    }
  }
  CheckLinks(def.links, &problems);
  CheckLinkLength(def.link_length, &problems);
  return problems;
}

Problems CurveProblems(const ParabolaDef& def) {
  Problems problems;
  CheckFinite("a", def.a, &problems);
  if (def.side != 1 && def.side != -1) {
    problems.emplace_back("side", "value " + std::to_string(def.side) +
                                      " is not valid; expected +1 (toward +x) or -1 (toward -x)");
  }
  CheckLinks(def.links, &problems);
  CheckLinkLength(def.link_length, &problems);
  return problems;
}

Problems CurveProblems(const ArcDef& def) {
  Problems problems;
  CheckRadius(def.radius, &problems);
  CheckFiniteVector("center", def.center, &problems);
  CheckFinite("start_angle", def.start_angle, &problems);
  CheckLinks(def.links, &problems);
  CheckLinkLength(def.link_length, &problems);
  if (problems.empty() && 2.0 * def.radius < def.link_length) {
    problems.emplace_back("radius",
                          "value " + FormatNumber(def.radius) + " is too small for link_length " +
                              FormatNumber(def.link_length) +
                              " (a chord cannot exceed the diameter); expected radius >= " +
                              FormatNumber(0.5 * def.link_length));
  }
  return problems;
}

Problems CurveProblems(const HelixDef& def) {
  Problems problems;
  CheckRadius(def.radius, &problems);
  CheckFinite("pitch", def.pitch, &problems);
  CheckFiniteVector("center", def.center, &problems);
  CheckFinite("start_angle", def.start_angle, &problems);
  CheckLinks(def.links, &problems);
  CheckLinkLength(def.link_length, &problems);
  if (problems.empty()) {
    const double half_turn_chord = std::hypot(2.0 * def.radius, 0.5 * def.pitch);
    if (def.link_length > half_turn_chord) {
      // Smallest radius whose half-turn chord reaches link_length.
      const double min_radius = 0.5 * std::sqrt(std::fmax(0.0, def.link_length * def.link_length -
                                                                   0.25 * def.pitch * def.pitch));
      problems.emplace_back(
          "radius", "value " + FormatNumber(def.radius) + " is too small for link_length " +
                        FormatNumber(def.link_length) + " and pitch " + FormatNumber(def.pitch) +
                        " (a link may span at most half a turn, whose chord is sqrt(4 radius^2 + "
                        "(pitch/2)^2) = " +
                        FormatNumber(half_turn_chord) +
                        "); expected radius >= " + FormatNumber(min_radius));
    }
  }
  return problems;
}

Points MakeLine(const LineDef& def) {
  ThrowFirstProblem(def);
  const Eigen::VectorXd unit = def.direction / def.direction.norm();
  Points points(def.links + 1, def.start.size());
  for (int i = 0; i <= def.links; ++i) {
    points.row(i) = (def.start + (i * def.link_length) * unit).transpose();
  }
  return points;
}

Points MakeParabola(const ParabolaDef& def) {
  ThrowFirstProblem(def);
  Points points(def.links + 1, 2);
  // Work on the +x branch (x >= 0, where the chord grows with x) and mirror for side -1.
  double x = 0.0;
  points.row(0) << 0.0, 0.0;
  for (int i = 1; i <= def.links; ++i) {
    x += ParabolaAdvance(def.a, x, def.link_length);
    points.row(i) << def.side * x, def.a * x * x;
  }
  return points;
}

Points MakeArc(const ArcDef& def) {
  ThrowFirstProblem(def);
  const double dt = 2.0 * std::asin(std::fmin(1.0, def.link_length / (2.0 * def.radius)));
  const double sign = def.clockwise ? -1.0 : 1.0;
  Points points(def.links + 1, 2);
  for (int i = 0; i <= def.links; ++i) {
    const double t = def.start_angle + sign * (i * dt);
    points.row(i) << def.center.x() + def.radius * std::cos(t),
        def.center.y() + def.radius * std::sin(t);
  }
  return points;
}

Points MakeHelix(const HelixDef& def) {
  ThrowFirstProblem(def);
  const double rise = def.pitch / (2.0 * kPi);  // per radian
  // Bisection on [0, pi], where the chord is increasing, down to adjacent doubles.
  double lo = 0.0, hi = kPi;
  while (true) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (HelixChord(def.radius, rise, mid) < def.link_length ? lo : hi) = mid;
  }
  const double dt = std::fabs(HelixChord(def.radius, rise, lo) - def.link_length) <
                            std::fabs(HelixChord(def.radius, rise, hi) - def.link_length)
                        ? lo
                        : hi;
  const double sign = def.clockwise ? -1.0 : 1.0;
  Points points(def.links + 1, 3);
  for (int i = 0; i <= def.links; ++i) {
    const double turned = i * dt;
    const double t = def.start_angle + sign * turned;
    points.row(i) << def.center.x() + def.radius * std::cos(t),
        def.center.y() + def.radius * std::sin(t), def.center.z() + rise * turned;
  }
  return points;
}

Chain MakeEqualLinkChain(const Points& points, double link_length) {
  Chain chain = MakeChain(points);
  for (Eigen::Index i = 0; i < chain.lengths.size(); ++i) {
    if (std::fabs(chain.lengths[i] - link_length) > 1e-9 * link_length) {
      throw InputError("points", "link " + std::to_string(i + 1) + " has length " +
                                     FormatNumber(chain.lengths[i]) + "; expected link_length " +
                                     FormatNumber(link_length) + " to 1e-9 relative");
    }
  }
  chain.lengths.setConstant(link_length);
  return chain;
}

}  // namespace flexkin
