// Tests of the generated initial curves: every link has exactly the requested chord length, the
// points lie on the intended shape, and bad parameters are refused with the field named.
#include "flexkin/curves.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>

#include "flexkin/chain.h"
#include "flexkin/error.h"
#include "test_util.h"

namespace flexkin {
namespace {

using test_util::ExpectInputError;

constexpr double kPi = 3.14159265358979323846;

// Every distance between consecutive points equals `length` to `tolerance` relative.
void ExpectChords(const Points& p, double length, double tolerance = 1e-12) {
  for (Eigen::Index i = 1; i < p.rows(); ++i) {
    const double chord = (p.row(i) - p.row(i - 1)).norm();
    EXPECT_NEAR(chord, length, tolerance * length) << "link " << i;
  }
}

// Calls `make` and checks that it throws an InputError for `field` whose message contains
// `text`.
TEST(CurveLineTest, PointsAreEquallySpacedAlongTheUnitDirection) {
  LineDef def;
  def.start = Eigen::Vector3d(1.0, -2.0, 0.5);
  def.direction = Eigen::Vector3d(3.0, 4.0, 12.0);  // length 13, not normalized
  def.links = 50;
  def.link_length = 0.3;
  const Points p = MakeLine(def);
  ASSERT_EQ(p.rows(), 51);
  ASSERT_EQ(p.cols(), 3);
  EXPECT_EQ(p.row(0), def.start.transpose());
  ExpectChords(p, 0.3);
  const Eigen::Vector3d unit = def.direction.normalized();
  for (Eigen::Index i = 1; i < p.rows(); ++i) {
    const Eigen::Vector3d d = (p.row(i) - p.row(0)).transpose();
    EXPECT_NEAR(d.cross(unit).norm(), 0.0, 1e-13) << "point " << i << " off the line";
    EXPECT_GT(d.dot(unit), 0.0);
  }
}

class CurveParabolaTest : public testing::TestWithParam<std::tuple<double, int, double>> {};

TEST_P(CurveParabolaTest, ChordsExactAndPointsOnTheParabola) {
  ParabolaDef def;
  std::tie(def.a, def.side, def.link_length) = GetParam();
  def.links = 40;
  const Points p = MakeParabola(def);
  ASSERT_EQ(p.rows(), 41);
  ASSERT_EQ(p.cols(), 2);
  EXPECT_EQ(p(0, 0), 0.0);
  EXPECT_EQ(p(0, 1), 0.0);
  ExpectChords(p, def.link_length);
  for (Eigen::Index i = 1; i < p.rows(); ++i) {
    const double x = p(i, 0), y = p(i, 1);
    EXPECT_NEAR(y, def.a * x * x, 1e-14 * std::fmax(1.0, std::fabs(y))) << "point " << i;
    // Successive points move away from the vertex on the requested side.
    EXPECT_GT(def.side * x, def.side * p(i - 1, 0)) << "point " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(CurveShapes, CurveParabolaTest,
                         testing::Combine(testing::Values(1.0, 0.0, -2.0, 1e-8, 50.0),
                                          testing::Values(1, -1),
                                          testing::Values(1e-6, 0.25, 10.0)));

TEST(CurveParabolaTest, PaperSection51HasTotalLengthFive) {
  ParabolaDef def;  // a = 1, 20 links of 0.25
  const Points p = MakeParabola(def);
  double total = 0.0;
  for (Eigen::Index i = 1; i < p.rows(); ++i) total += (p.row(i) - p.row(i - 1)).norm();
  EXPECT_NEAR(total, 5.0, 1e-13);
  // The arc length of y = x^2 from 0 to the last x exceeds the chord sum, but not by much.
  const double x = p(20, 0);
  const double arc = 0.5 * x * std::sqrt(1 + 4 * x * x) + 0.25 * std::asinh(2 * x);
  EXPECT_GT(arc, 5.0);
  EXPECT_LT(arc, 5.01);
}

TEST(CurveParabolaTest, SidesAreMirrorImages) {
  ParabolaDef right, left;
  left.side = -1;
  const Points r = MakeParabola(right), l = MakeParabola(left);
  EXPECT_EQ(l.col(0), -r.col(0));
  EXPECT_EQ(l.col(1), r.col(1));
}

TEST(CurveArcTest, ChordsExactAndPointsOnTheCircle) {
  for (bool clockwise : {false, true}) {
    ArcDef def;
    def.radius = 1.7;
    def.center = Eigen::Vector2d(0.5, -3.0);
    def.start_angle = 0.3;
    def.clockwise = clockwise;
    def.links = 200;  // winds several times around the center
    def.link_length = 0.45;
    const Points p = MakeArc(def);
    ASSERT_EQ(p.rows(), 201);
    ExpectChords(p, 0.45);
    for (Eigen::Index i = 0; i < p.rows(); ++i) {
      EXPECT_NEAR((p.row(i).transpose() - def.center).norm(), 1.7, 1e-14 * 1.7);
    }
    EXPECT_NEAR(p(0, 0), 0.5 + 1.7 * std::cos(0.3), 1e-15);
    EXPECT_NEAR(p(0, 1), -3.0 + 1.7 * std::sin(0.3), 1e-15);
    // Turning sense: the cross product of (p0 - c) and (p1 - c) is positive counterclockwise.
    const Eigen::Vector2d a = p.row(0).transpose() - def.center;
    const Eigen::Vector2d b = p.row(1).transpose() - def.center;
    EXPECT_EQ(a.x() * b.y() - a.y() * b.x() > 0.0, !clockwise);
  }
}

TEST(CurveArcTest, ChordEqualToTheDiameterIsAllowed) {
  ArcDef def;
  def.radius = 0.5;
  def.link_length = 1.0;
  def.links = 3;
  const Points p = MakeArc(def);
  ExpectChords(p, 1.0);
  EXPECT_NEAR((p.row(2) - p.row(0)).norm(), 0.0, 1e-15);  // back and forth across the circle
}

class CurveHelixTest : public testing::TestWithParam<std::tuple<double, double, double>> {};

TEST_P(CurveHelixTest, ChordsExactRadiusAndRiseConstant) {
  HelixDef def;
  std::tie(def.radius, def.pitch, def.link_length) = GetParam();
  def.center = Eigen::Vector3d(1.0, 2.0, -1.0);
  def.start_angle = -0.7;
  def.links = 60;
  const Points p = MakeHelix(def);
  ASSERT_EQ(p.rows(), 61);
  ASSERT_EQ(p.cols(), 3);
  ExpectChords(p, def.link_length);
  const double rise = p(1, 2) - p(0, 2);
  EXPECT_EQ(p(0, 2), -1.0);
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    EXPECT_NEAR(std::hypot(p(i, 0) - 1.0, p(i, 1) - 2.0), def.radius, 1e-14 * (1 + def.radius));
    if (i > 0) EXPECT_NEAR(p(i, 2) - p(i - 1, 2), rise, 1e-12 * (1 + std::fabs(p(i, 2))));
  }
  // The rise per link is pitch * (turned angle) / (2 pi), in the direction of the pitch.
  EXPECT_EQ(rise > 0.0, def.pitch > 0.0);
  EXPECT_EQ(rise == 0.0, def.pitch == 0.0);
}

INSTANTIATE_TEST_SUITE_P(
    CurveShapes, CurveHelixTest,
    testing::Values(std::make_tuple(2.0, 3.0, 1.5),      // the fig12 example
                    std::make_tuple(1.0, 0.0, 0.3),      // a circle
                    std::make_tuple(1.0, -5.0, 0.3),     // descending
                    std::make_tuple(0.01, 100.0, 7.0),   // nearly a straight line
                    std::make_tuple(1.0, 2.0, 2.236)));  // close to half a turn per link

TEST(CurveHelixTest, ClockwiseTurnsTheOtherWay) {
  HelixDef ccw, cw;
  cw.clockwise = true;
  const Points a = MakeHelix(ccw), b = MakeHelix(cw);
  EXPECT_GT(a(1, 1), 0.0);
  EXPECT_LT(b(1, 1), 0.0);
  EXPECT_EQ(a.col(2), b.col(2));
}

TEST(CurveErrorTest, BadParametersNameTheField) {
  ExpectInputError(
      [] {
        MakeLine(LineDef{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), 3, 1.0});
      },
      "direction", "nonzero");
  ExpectInputError(
      [] {
        MakeLine(LineDef{Eigen::Vector4d::Zero(), Eigen::Vector4d::Ones(), 3, 1.0});
      },
      "start", "expected 2 (planar) or 3");
  ExpectInputError(
      [] {
        MakeLine(LineDef{Eigen::Vector2d::Zero(), Eigen::Vector3d::Ones(), 3, 1.0});
      },
      "direction", "expected 2");
  ExpectInputError(
      [] {
        MakeParabola(ParabolaDef{1.0, 1, 0, 0.25});
      },
      "links", "value 0 is not valid; expected an integer from 1");
  ExpectInputError(
      [] {
        MakeParabola(ParabolaDef{1.0, 1, 20, 0.0});
      },
      "link_length", "value 0 is not valid; expected a finite number > 0");
  ExpectInputError([] { MakeParabola(ParabolaDef{1.0, 1, 20, -0.5}); }, "link_length", "-0.5");
  ExpectInputError([] { MakeParabola(ParabolaDef{NAN, 1, 20, 0.25}); }, "a", "not a finite");
  ExpectInputError([] { MakeParabola(ParabolaDef{1.0, 0, 20, 0.25}); }, "side", "+1");
  ExpectInputError([] { MakeParabola(ParabolaDef{1.0, 1, 20, INFINITY}); }, "link_length", "inf");
  ArcDef arc;
  arc.radius = 0.2;
  arc.link_length = 0.5;
  ExpectInputError([&] { MakeArc(arc); }, "radius", "expected radius >= 0.25");
  arc.radius = -1.0;
  ExpectInputError([&] { MakeArc(arc); }, "radius", "value -1 is not valid");
  arc.radius = 1.0;
  arc.center.x() = NAN;
  ExpectInputError([&] { MakeArc(arc); }, "center[0]", "not a finite");
  HelixDef helix;
  helix.radius = 0.5;
  helix.pitch = 1.0;
  helix.link_length = 1.5;  // the half-turn chord is sqrt(1 + 0.25) < 1.5
  ExpectInputError([&] { MakeHelix(helix); }, "radius", "at most half a turn");
  helix.radius = 0.0;
  ExpectInputError([&] { MakeHelix(helix); }, "radius", "expected a finite number > 0");
}

TEST(CurveErrorTest, ProblemsListsEveryBadField) {
  ArcDef def;
  def.radius = NAN;
  def.links = -3;
  def.link_length = 0.0;
  const Problems problems = CurveProblems(def);
  ASSERT_EQ(problems.size(), 3u);
  EXPECT_EQ(problems[0].field, "radius");
  EXPECT_EQ(problems[1].field, "links");
  EXPECT_EQ(problems[2].field, "link_length");
  EXPECT_TRUE(CurveProblems(ArcDef{}).empty());
  EXPECT_TRUE(CurveProblems(HelixDef{}).empty());
  EXPECT_TRUE(CurveProblems(ParabolaDef{}).empty());
  EXPECT_TRUE(CurveProblems(LineDef{}).empty());
}

TEST(CurveEqualLinkChainTest, LengthsAreExactlyTheRequestedLength) {
  ArcDef def;
  def.link_length = 0.1;
  const Chain chain = MakeEqualLinkChain(MakeArc(def), 0.1);
  ASSERT_EQ(chain.num_links(), def.links);
  for (Eigen::Index i = 0; i < chain.lengths.size(); ++i) EXPECT_EQ(chain.lengths[i], 0.1);
  EXPECT_LT(MaxRelativeLengthError(chain), 1e-14);
  // Points whose chords are not the given length are refused.
  ExpectInputError([&] { MakeEqualLinkChain(MakeArc(def), 0.1 * (1 + 1e-6)); }, "points",
                   "expected link_length");
}

// The largest documented size of every curved shape (kMaxGeneratedLinks, 10 million links of
// 0.08): accepted, and every chord within the rounding of its end points' coordinates of
// link_length (32 eps (|a| + |b|), MakeEqualLinkChain's allowance for it, without its 1e-9
// relative part). Before, the arc and the helix turned by i * dt rounded to ulp(8e5) = 1.2e-10
// rad, and their chords strayed by 1.6e-9 relative; MakeEqualLinkChain refused all three ("link
// 8017535 has length 0.0800000001295933"). About a second per shape on one core.
void ExpectLargestSizeAccepted(const Points& p, double link_length) {
  ASSERT_EQ(p.rows(), kMaxGeneratedLinks + 1);
  EXPECT_NO_THROW(MakeEqualLinkChain(p, link_length));
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  double worst = 0.0;  // |chord - L| over the allowance
  Eigen::Index at = 0;
  for (Eigen::Index i = 1; i < p.rows(); ++i) {
    const double error = std::fabs((p.row(i) - p.row(i - 1)).norm() - link_length);
    const double allowance = 32.0 * kEps * (p.row(i).norm() + p.row(i - 1).norm());
    if (error / allowance > worst) {
      worst = error / allowance;
      at = i;
    }
  }
  EXPECT_LE(worst, 1.0) << "link " << at << " of " << p.rows() - 1;
}

TEST(CurveLargestSizeTest, ArcOfTenMillionLinks) {
  ArcDef def;
  def.radius = 1.0;
  def.links = kMaxGeneratedLinks;
  def.link_length = 0.08;
  ExpectLargestSizeAccepted(MakeArc(def), def.link_length);
}

TEST(CurveLargestSizeTest, HelixOfTenMillionLinks) {
  HelixDef def;
  def.radius = 1.0;
  def.pitch = 0.5;
  def.clockwise = true;
  def.links = kMaxGeneratedLinks;
  def.link_length = 0.08;
  ExpectLargestSizeAccepted(MakeHelix(def), def.link_length);
}

TEST(CurveLargestSizeTest, ParabolaOfTenMillionLinks) {
  ParabolaDef def;  // a = 1: y reaches 8e5, its rounding alone 1.2e-10
  def.links = kMaxGeneratedLinks;
  def.link_length = 0.08;
  ExpectLargestSizeAccepted(MakeParabola(def), def.link_length);
}

TEST(CurveLargestSizeTest, DiagonalLineOfTenMillionLinks) {
  LineDef def;
  def.direction = Eigen::Vector2d(1.0, 3.0);
  def.links = kMaxGeneratedLinks;
  def.link_length = 0.08;
  ExpectLargestSizeAccepted(MakeLine(def), def.link_length);
}

// Up to 16 rad of turning an arc's points are the plain formula's, bit for bit, so the scenes
// pinned by tests/golden_test.cc (fig10: 80 links turning 4 rad) keep their points.
TEST(CurveArcTest, ShortArcsAreThePlainFormulaBitForBit) {
  ArcDef def;
  def.radius = 1.0;
  def.center = Eigen::Vector2d(0.0, 1.0);
  def.start_angle = -kPi / 2;
  def.links = 80;
  def.link_length = 0.05;
  const Points p = MakeArc(def);
  const double dt = 2.0 * std::asin(def.link_length / (2.0 * def.radius));
  for (int i = 0; i <= def.links; ++i) {
    const double t = def.start_angle + 1.0 * (i * dt);
    EXPECT_EQ(p(i, 0), def.center.x() + def.radius * std::cos(t)) << "point " << i;
    EXPECT_EQ(p(i, 1), def.center.y() + def.radius * std::sin(t)) << "point " << i;
  }
}

// Past 16 rad the angle is reduced modulo 2 pi: the points still lie on the circle, at the angle
// i dt (to 1e-15 rad where the plain formula is still that good, so the switch leaves no seam).
TEST(CurveArcTest, LongArcsStayOnTheCircleAtTheirAngle) {
  ArcDef def;
  def.radius = 2.0;
  def.links = 2000;
  def.link_length = 0.05;
  def.clockwise = true;
  const Points p = MakeArc(def);
  ExpectChords(p, def.link_length, 1e-13);  // coordinates of 2: rounding is 1e-14 of a link
  const double dt = 2.0 * std::asin(def.link_length / (2.0 * def.radius));
  for (int i = 0; i <= def.links; i += 7) {
    EXPECT_NEAR(p.row(i).norm(), def.radius, 1e-15 * def.radius) << "point " << i;
    const double t = -(i * dt);
    EXPECT_NEAR(p(i, 0), def.radius * std::cos(t), 2e-14) << "point " << i;
    EXPECT_NEAR(p(i, 1), def.radius * std::sin(t), 2e-14) << "point " << i;
  }
}

}  // namespace
}  // namespace flexkin
