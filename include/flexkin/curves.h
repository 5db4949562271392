#pragma once

#include <Eigen/Core>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/error.h"
#include "flexkin/vocabulary.h"

namespace flexkin {

// The values of a "curve" object's "turn" (arc, helix) and "side" (parabola), named once for the
// scenario files (io/scenario_sections.cc) and Python's curve generators (keywords of the same
// names): ArcDef::clockwise and HelixDef::clockwise are `turn == CurveTurn::kCw`,
// ParabolaDef::side is +1 for CurveSide::kPlusX and -1 for kMinusX.
enum class CurveTurn { kCcw, kCw };
enum class CurveSide { kPlusX, kMinusX };
template <>
struct Vocabulary<CurveTurn> {
  static constexpr const char* kKind = "turn";
  static constexpr NamedValue<CurveTurn> kEntries[] = {
      {CurveTurn::kCcw, "ccw", "counterclockwise: the angle grows along the chain"},
      {CurveTurn::kCw, "cw", "clockwise: the angle shrinks along the chain"},
  };
};
template <>
struct Vocabulary<CurveSide> {
  static constexpr const char* kKind = "side";
  static constexpr NamedValue<CurveSide> kEntries[] = {
      {CurveSide::kPlusX, "+x", "from the vertex toward +x"},
      {CurveSide::kMinusX, "-x", "from the vertex toward -x"},
  };
};

// Generated initial curves. Each one is sampled so that every link has the same chord length
// `link_length` (to rounding, a few times 1e-16 times the coordinates' magnitude over the link
// length, up to kMaxGeneratedLinks: arcs and helices reduce their angle modulo 2 pi exactly, so
// their chords do not degrade as the angle grows),
// with point 0 the leading end. The field names are those of the scenario file's "curve" object
// (docs/scenario-format.md), so errors name the same field in C++ and in JSON. Lengths are in the
// caller's unit, angles in radians.

// Upper bound on `links` for every generated curve: 10 million links already take 240 MB in 3D.
inline constexpr int kMaxGeneratedLinks = 10'000'000;

// A straight line: point i = start + i * link_length * direction / |direction|, i = 0..links.
struct LineDef {
  Eigen::VectorXd start = Eigen::Vector2d::Zero();       // leading end; 2 or 3 values
  Eigen::VectorXd direction = Eigen::Vector2d::UnitX();  // toward the trailing end; any nonzero
                                                         // length; same size as `start`
  int links = 10;                                        // >= 1
  double link_length = 0.1;                              // > 0
};

// The parabola y = a x^2, from the vertex (0, 0) (the leading end) toward +x or -x. Successive
// points are at chord distance `link_length` (paper Sec. 5.1: a = 1, 20 links of 0.25).
struct ParabolaDef {
  double a = 1.0;             // curvature at the vertex is 2a; any finite value (0 gives a line)
  int side = +1;              // +1: the points go toward +x; -1: toward -x
  int links = 20;             // >= 1
  double link_length = 0.25;  // > 0
};

// A circular arc: point i = center + radius (cos t_i, sin t_i), t_i = start_angle +- i dt, with
// dt = 2 asin(link_length / (2 radius)) so that every chord is link_length. The arc may wind
// more than once around the center.
struct ArcDef {
  double radius = 1.0;  // > 0 and >= link_length / 2
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  double start_angle = 0.0;  // radians, of point 0, from +x about center
  bool clockwise = false;    // false: the angle grows along the chain
  int links = 10;            // >= 1
  double link_length = 0.1;  // > 0
};

// A circular helix about an axis parallel to z: point i =
// center + (radius cos t_i, radius sin t_i, pitch / (2 pi) * i dt), t_i = start_angle +- i dt,
// where dt solves the chord equation 4 radius^2 sin^2(dt/2) + (pitch dt / (2 pi))^2 =
// link_length^2. A link may span at most half a turn (dt <= pi).
struct HelixDef {
  double radius = 1.0;  // > 0
  double pitch = 1.0;   // rise along +z per full turn (2 pi radians), length unit; negative
                        // descends; 0 makes a circle
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // axis point at the height of point 0
  double start_angle = 0.0;                          // radians, of point 0, from +x about the axis
  bool clockwise = false;    // seen from +z; false: the angle grows along the chain
  int links = 20;            // >= 1
  double link_length = 1.5;  // > 0 and <= sqrt(4 radius^2 + (pitch / 2)^2)
};

// Every problem with a definition, each an InputError whose field is the member's name
// ("radius", "links", ...) and whose message gives the value and the valid range. Empty if valid.
Problems CurveProblems(const LineDef& def);
Problems CurveProblems(const ParabolaDef& def);
Problems CurveProblems(const ArcDef& def);
Problems CurveProblems(const HelixDef& def);

// The points, (links + 1) by dim (dim = start.size() for a line, 2 for a parabola or arc, 3 for
// a helix). Throw the first of CurveProblems(def) if there is one.
Points MakeLine(const LineDef& def);
Points MakeParabola(const ParabolaDef& def);
Points MakeArc(const ArcDef& def);
Points MakeHelix(const HelixDef& def);

// Like MakeChain, but every link length is exactly `link_length` instead of the distance between
// the points, which differs from it by rounding. For points from the generators above.
// Throws InputError (field "points") if any chord differs from `link_length` by more than
// 1e-9 relative plus 32 eps (|a| + |b|), a and b its end points (the rounding of their
// coordinates, which far from the origin outgrows a fixed fraction of the link), or as MakeChain
// does.
Chain MakeEqualLinkChain(const Points& points, double link_length);

}  // namespace flexkin
