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

// The angle from point 0 of point i, i dt, as an offset from start_angle for cos and sin, sign
// applied. Up to kPlainTurn it is the plain sign * (i * dt): its rounding, at most ulp(16) / 2 =
// 1.8e-15 rad, moves a point less than the coordinates' own rounding (MakeEqualLinkChain's
// tolerance), and the curves of up to 2.5 turns (the paper's figures, the pinned golden results)
// keep their points bit for bit. Beyond, i dt (up to 3e7 rad at 10 million links) would be
// rounded by up to 2e-9 rad, the same for two neighbours only by chance: the chords would differ
// from link_length by about eps * i relative (1.6e-9 at 8 million links), so the angle is
// reduced modulo 2 pi first, from i dt = p + e held exactly (fma) and 2 pi = kTwoPiHi + kTwoPiLo,
// which leaves an angle in [-pi, pi] rounded by about 1e-16 rad however many links there are.
double TurnedAngle(int i, double dt, double sign) {
  constexpr double kPlainTurn = 16.0;
  constexpr double kTwoPiHi = 6.283185307179586;       // 2 pi rounded to double
  constexpr double kTwoPiLo = 2.4492935982947064e-16;  // 2 pi - kTwoPiHi
  const double p = i * dt;
  if (p <= kPlainTurn) return sign * p;
  const double e = std::fma(static_cast<double>(i), dt, -p);  // i dt - p, exactly
  const double k = std::nearbyint(p / kTwoPiHi);
  // p - k kTwoPiHi is below 4 in magnitude: one fma rounds it once (k < 2^23, so k kTwoPiHi is
  // held exactly inside the fma); the small terms then add their part.
  const double r = std::fma(-k, kTwoPiLo, std::fma(-k, kTwoPiHi, p)) + e;
  return sign * r;
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
    const double t = def.start_angle + TurnedAngle(i, dt, sign);
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
    const double turned = i * dt;  // the height grows with it, unreduced
    const double t = def.start_angle + TurnedAngle(i, dt, sign);
    points.row(i) << def.center.x() + def.radius * std::cos(t),
        def.center.y() + def.radius * std::sin(t), def.center.z() + rise * turned;
  }
  return points;
}

namespace {

// How far a generated chord may be from link_length (MakeEqualLinkChain).
double ChordTolerance(const Eigen::Ref<const Eigen::RowVectorXd>& a,
                      const Eigen::Ref<const Eigen::RowVectorXd>& b, double link_length) {
  // A generated point is its exact value with each coordinate rounded, a few times over (a
  // product, a sine, a sum): off by a few eps times its magnitude. The chord between two such
  // points is then off by up to about that much times |a| + |b| whatever the generator does,
  // which far from the origin outgrows any fixed fraction of the link: the parabola of 10 million
  // links of 0.08 reaches y = 6.4e5, whose rounding alone (ulp 1.2e-10) moves a chord by 1.6e-9
  // of its length. 32 eps covers those few roundings with a margin; 1e-9 relative, the bound
  // before, keeps every set of points accepted then.
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  return 1e-9 * link_length + 32.0 * kEps * (a.norm() + b.norm());
}

}  // namespace

Chain MakeEqualLinkChain(const Points& points, double link_length) {
  Chain chain = MakeChain(points);
  for (Eigen::Index i = 0; i < chain.lengths.size(); ++i) {
    const double tolerance = ChordTolerance(points.row(i), points.row(i + 1), link_length);
    if (std::fabs(chain.lengths[i] - link_length) > tolerance) {
      throw InputError("points", "link " + std::to_string(i + 1) + " has length " +
                                     FormatNumber(chain.lengths[i]) + "; expected link_length " +
                                     FormatNumber(link_length) + " to " + FormatNumber(tolerance) +
                                     " (1e-9 relative plus the rounding of its end points' "
                                     "coordinates)");
    }
  }
  chain.lengths.setConstant(link_length);
  return chain;
}

}  // namespace flexkin
