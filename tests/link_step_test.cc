// Tests of the one-link rules: the closed-form tractrix step against the paper's eq. (23),
// against an independent ODE solution (Boost.Odeint), its fast form against its reference form,
// edge cases and invariants; the follow-the-leader step's invariants; input checking.
#include "flexkin/link_step.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <type_traits>

#include "flexkin/error.h"
#include "reference_ode.h"
#include "sequential/link_rules.h"
#include "test_util.h"

namespace flexkin {
namespace {

using test_util::Str;

template <int Dim>
using Vec = Eigen::Matrix<double, Dim, 1>;

constexpr double kEps = std::numeric_limits<double>::epsilon();

// The two internal forms, called directly so that the tests can compare them.
template <int Dim>
Vec<Dim> Fast(const Vec<Dim>& head_old, const Vec<Dim>& head_new, const Vec<Dim>& tail,
              double length) {
  Vec<Dim> out = tail;
  internal::TractrixStep<Dim>(head_old.data(), head_new.data(), out.data(), length, 1.0 / length);
  return out;
}
template <int Dim>
Vec<Dim> Reference(const Vec<Dim>& head_old, const Vec<Dim>& head_new, const Vec<Dim>& tail,
                   double length) {
  Vec<Dim> out = tail;
  internal::TractrixStepReference<Dim>(head_old.data(), head_new.data(), out.data(), length);
  return out;
}

// Deterministic uniform numbers (the std distributions differ between standard libraries).
class Random {
 public:
  explicit Random(uint64_t seed) : engine_(seed) {}
  double Uniform(double lo, double hi) {
    return lo + (hi - lo) * static_cast<double>(engine_() >> 11) * 0x1.0p-53;
  }
  template <int Dim>
  Vec<Dim> UnitVector() {
    for (;;) {
      Vec<Dim> x;
      for (int k = 0; k < Dim; ++k) x[k] = Uniform(-1.0, 1.0);
      const double n = x.norm();
      if (n > 0.1 && n <= 1.0) return x / n;
    }
  }
  // A unit vector perpendicular to the unit vector `u`.
  template <int Dim>
  Vec<Dim> Perpendicular(const Vec<Dim>& u) {
    for (;;) {
      const Vec<Dim> x = UnitVector<Dim>();
      const Vec<Dim> w = x - x.dot(u) * u;
      if (w.norm() > 0.1) return w.normalized();
    }
  }

 private:
  std::mt19937_64 engine_;
};

// Direction of the head's move relative to the link: the cosine between the move and
// tail - head_old is in [-1, -0.2] (pulling), [-0.2, 0.2] (sideways) or [0.2, 0.99] (pushing).
enum class MoveKind { kPull, kSideways, kPush };

template <int Dim>
struct LinkMove {
  Vec<Dim> head_old, head_new, tail;
  double length = 1.0;
  double p = 0.0;  // |head_new - head_old|
};

template <int Dim>
LinkMove<Dim> RandomMove(Random& random, MoveKind kind, double length, double p) {
  LinkMove<Dim> m;
  m.length = length;
  m.p = p;
  for (int k = 0; k < Dim; ++k) m.head_old[k] = length * random.Uniform(-1.0, 1.0);
  const Vec<Dim> u = random.UnitVector<Dim>();
  const Vec<Dim> w = random.Perpendicular<Dim>(u);
  double c = 0.0;
  switch (kind) {
    case MoveKind::kPull:
      c = random.Uniform(-1.0, -0.2);
      break;
    case MoveKind::kSideways:
      c = random.Uniform(-0.2, 0.2);
      break;
    case MoveKind::kPush:
      c = random.Uniform(0.2, 0.99);
      break;
  }
  const double s = std::sqrt(1.0 - c * c);
  m.tail = m.head_old + length * (c * u + s * w);
  m.head_new = m.head_old + p * u;
  return m;
}

// The head moves almost straight at the tail: tail - head_old = L (sqrt(1 - s^2) u + s w),
// with a random sideways offset s (in link lengths) and a random orientation.
template <int Dim>
LinkMove<Dim> AlmostTowardMove(Random& random, double length, double offset, double p) {
  LinkMove<Dim> m;
  m.length = length;
  m.p = p;
  for (int k = 0; k < Dim; ++k) m.head_old[k] = length * random.Uniform(-1.0, 1.0);
  const Vec<Dim> u = random.UnitVector<Dim>();
  const Vec<Dim> w = random.Perpendicular<Dim>(u);
  m.tail = m.head_old + length * (std::sqrt(1.0 - offset * offset) * u + offset * w);
  m.head_new = m.head_old + p * u;
  return m;
}

const char* KindName(MoveKind kind) {
  switch (kind) {
    case MoveKind::kPull:
      return "pull";
    case MoveKind::kSideways:
      return "sideways";
    case MoveKind::kPush:
      return "push";
  }
  return "?";
}

class DimName {
 public:
  template <class T>
  static std::string GetName(int) {
    return std::to_string(T::value) + "D";
  }
};

template <class T>
class TractrixStepTest : public ::testing::Test {};
using Dims = ::testing::Types<std::integral_constant<int, 2>, std::integral_constant<int, 3>>;
TYPED_TEST_SUITE(TractrixStepTest, Dims, DimName);

// Paper eq. (23): head at the origin pulled along +X by p, tail at (0, L) before the move.
// Evaluated in long double from the same double p and L, and checked for every ordered pair of
// axes and both signs, so that the closed form is tested without rotation rounding.
TYPED_TEST(TractrixStepTest, MatchesPaperEquation23) {
  constexpr int kDim = TypeParam::value;
  for (const double length : {1e-9, 1.0, 1e9}) {
    for (const double ratio : {0.0, 1e-8, 0.5, 1.0, 5.0, 30.0, 1000.0}) {
      const double p = ratio * length;
      const long double q = static_cast<long double>(p) / length;
      const long double x_exact = p - length * std::tanh(q);
      const long double y_exact = length / std::cosh(q);
      for (int a = 0; a < kDim; ++a) {
        for (int b = 0; b < kDim; ++b) {
          if (a == b) continue;
          for (const double sign : {1.0, -1.0}) {
            Vec<kDim> head_old = Vec<kDim>::Zero(), head_new = Vec<kDim>::Zero(),
                      tail = Vec<kDim>::Zero();
            head_new[a] = sign * p;
            tail[b] = sign * length;
            SCOPED_TRACE("L = " + Str(length) + ", p/L = " + Str(ratio) + ", pull axis " +
                         std::to_string(a) + ", link axis " + std::to_string(b) + ", sign " +
                         Str(sign));
            for (const Vec<kDim>& got : {Vec<kDim>(TractrixStep(head_old, head_new, tail, length)),
                                         Fast<kDim>(head_old, head_new, tail, length),
                                         Reference<kDim>(head_old, head_new, tail, length)}) {
              // x = p - L tanh(p/L) cancels for small p/L: its error is relative to p + L.
              EXPECT_LE(std::fabs(sign * got[a] - x_exact), 4 * kEps * (p + length));
              // y = L sech(p/L) is computed without cancellation: relative error bounded by the
              // conditioning of sech (q tanh q) plus a few roundings.
              EXPECT_LE(std::fabs(sign * got[b] - y_exact),
                        (4 + 2 * ratio) * kEps * static_cast<double>(y_exact) + 1e-300);
              for (int k = 0; k < kDim; ++k) {
                if (k != a && k != b) EXPECT_EQ(got[k], 0.0);
              }
            }
          }
        }
      }
    }
  }
}

// The closed form against the numerically integrated ODE (tail velocity along the link), for
// random pulling, sideways and pushing moves of 1e-3 to 10 link lengths, and its fast form
// against its reference (asinh/tanh/sech) form.
TYPED_TEST(TractrixStepTest, MatchesOdeReferenceForRandomMoves) {
  constexpr int kDim = TypeParam::value;
  Random random(20130917 + kDim);
  double worst_ode = 0.0, worst_forms = 0.0;
  int count = 0;
  for (const MoveKind kind : {MoveKind::kPull, MoveKind::kSideways, MoveKind::kPush}) {
    for (int i = 0; i < 80; ++i) {
      const double length = std::pow(10.0, random.Uniform(-1.0, 1.0));
      const double p = length * std::pow(10.0, random.Uniform(-3.0, 1.0));
      const LinkMove<kDim> m = RandomMove<kDim>(random, kind, length, p);
      SCOPED_TRACE(std::string(KindName(kind)) + " #" + std::to_string(i) + ": L = " + Str(length) +
                   ", p/L = " + Str(p / length));
      const Vec<kDim> ode =
          reference::ReferenceLinkStep<kDim>(m.head_old, m.head_new, m.tail, length);
      const Vec<kDim> api = TractrixStep(m.head_old, m.head_new, m.tail, length);
      const Vec<kDim> fast = Fast<kDim>(m.head_old, m.head_new, m.tail, length);
      const Vec<kDim> ref = Reference<kDim>(m.head_old, m.head_new, m.tail, length);
      EXPECT_EQ(api, fast);  // the public function is the fast kernel
      const double err_ode = std::fmax((fast - ode).norm(), (ref - ode).norm()) / length;
      const double err_forms = (fast - ref).norm() / (length + p);
      EXPECT_LE(err_ode, 1e-9);
      EXPECT_LE(err_forms, 1e-14);
      worst_ode = std::fmax(worst_ode, err_ode);
      worst_forms = std::fmax(worst_forms, err_forms);
      ++count;
    }
  }
  std::cout << "[ measured ] " << kDim << "D, " << count
            << " random moves: max |closed form - ODE| / L = " << worst_ode
            << ", max |fast - reference form| / (L + p) = " << worst_forms << "\n";
  ::testing::Test::RecordProperty("max_error_vs_ode_over_L", std::to_string(worst_ode));
  ::testing::Test::RecordProperty("max_fast_vs_reference", std::to_string(worst_forms));
}

// The head moves exactly toward the tail (the unstable equilibrium): the link translates.
// Cases where tail - head_old is exactly parallel to the move in real arithmetic, including
// lengths and moves whose products round, and moves far past the point where the continuous
// motion with an infinitesimal offset would flip the link.
TYPED_TEST(TractrixStepTest, HeadMovingExactlyTowardTheTailTranslatesTheLink) {
  constexpr int kDim = TypeParam::value;
  for (const double length : {1.0, 3.0, 0.3, 0.7, 1e-9, 1e9}) {
    for (const double ratio : {1e-3, 0.5, 1.0, 10.0, 100.0, 1e3}) {
      for (int axis = 0; axis < kDim; ++axis) {
        for (const double sign : {1.0, -1.0}) {
          const double p = ratio * length;
          Vec<kDim> head_old = Vec<kDim>::Constant(0.25 * length);
          Vec<kDim> tail = head_old, d = Vec<kDim>::Zero();
          tail[axis] += sign * length;
          d[axis] = sign * p;
          const Vec<kDim> head_new = head_old + d;
          SCOPED_TRACE("L = " + Str(length) + ", p/L = " + Str(ratio) + ", axis " +
                       std::to_string(axis) + ", sign " + Str(sign));
          const Vec<kDim> expected = tail + d;
          const double tol = 4 * kEps * (tail.cwiseAbs().maxCoeff() + p);
          EXPECT_LE((TractrixStep(head_old, head_new, tail, length) - expected).norm(), tol);
          EXPECT_LE((Reference<kDim>(head_old, head_new, tail, length) - expected).norm(), tol);
        }
      }
    }
  }
}

// The head moves exactly away from the tail: the link is pulled straight and translates.
TYPED_TEST(TractrixStepTest, HeadMovingExactlyAwayFromTheTailTranslatesTheLink) {
  constexpr int kDim = TypeParam::value;
  Random random(7);
  for (const double length : {1.0, 0.3, 1e-9, 1e9}) {
    for (const double ratio : {1e-8, 1e-3, 1.0, 10.0, 1e3}) {
      const double p = ratio * length;
      // Axis-aligned (exact) and a random direction (tail - head_old parallel to within a few
      // ulp).
      Vec<kDim> u = Vec<kDim>::Zero();
      u[kDim - 1] = 1.0;
      for (const Vec<kDim>& dir : {u, random.UnitVector<kDim>()}) {
        const Vec<kDim> head_old = length * Vec<kDim>::Constant(-0.5);
        const Vec<kDim> tail = head_old - length * dir;
        const Vec<kDim> head_new = head_old + p * dir;
        const Vec<kDim> expected = tail + p * dir;
        const double tol = 8 * kEps * (tail.cwiseAbs().maxCoeff() + p + length);
        EXPECT_LE((TractrixStep(head_old, head_new, tail, length) - expected).norm(), tol)
            << "L = " << length << ", p/L = " << ratio;
        EXPECT_LE((Reference<kDim>(head_old, head_new, tail, length) - expected).norm(), tol)
            << "L = " << length << ", p/L = " << ratio;
      }
    }
  }
}

// A pushing move with a tiny sideways offset eps L. In the axis-aligned frame the inputs are
// exact, so the analytic answer (long double) is known: phi = asinh(X0/Y0) - p/L,
// tail = head_new + L (tanh(phi), sech(phi)). The problem is well conditioned in these inputs
// (a relative change delta in Y0 moves the tail by about delta L), so a stable evaluation is
// accurate to a few eps (p + L) however small the offset. The answer is also continuous as the
// offset goes to 0: the tail is within about 2 eps e^(p/L) L of the translated position.
TYPED_TEST(TractrixStepTest, TinySidewaysOffsetInPushingMoveIsAccurateAndContinuous) {
  constexpr int kDim = TypeParam::value;
  double worst = 0.0;
  for (const double length : {1.0, 0.7, 1e-9, 1e9}) {
    for (const double ratio : {1e-3, 0.5, 1.0, 5.0, 20.0, 30.0, 33.0, 40.0, 100.0}) {
      for (const double offset : {1e-6, 1e-10, 1e-14, 0.0}) {
        const double p = ratio * length;
        const double x0 = length * std::sqrt(1.0 - offset * offset);
        const double y0 = offset * length;
        Vec<kDim> head_old = Vec<kDim>::Zero(), head_new = Vec<kDim>::Zero(),
                  tail = Vec<kDim>::Zero();
        head_new[0] = p;
        tail[0] = x0;
        tail[1] = y0;
        // Analytic, in long double, from the same double inputs.
        const long double phi = (y0 == 0.0) ? std::numeric_limits<long double>::infinity()
                                            : std::asinh(static_cast<long double>(x0) / y0) -
                                                  static_cast<long double>(p) / length;
        const long double x_exact = p + length * std::tanh(phi);
        const long double y_exact = length / std::cosh(phi);
        SCOPED_TRACE("L = " + Str(length) + ", p/L = " + Str(ratio) +
                     ", offset/L = " + Str(offset));
        for (const bool reference_form : {false, true}) {
          const Vec<kDim> got = reference_form
                                    ? Reference<kDim>(head_old, head_new, tail, length)
                                    : Vec<kDim>(TractrixStep(head_old, head_new, tail, length));
          const double err = std::hypot(static_cast<double>(got[0] - x_exact),
                                        static_cast<double>(got[1] - y_exact));
          EXPECT_LE(err, 8 * kEps * (p + length)) << (reference_form ? "reference" : "fast");
          if (!reference_form) worst = std::fmax(worst, err / (p + length));
          if (ratio <= 5.0) {
            const double from_translated = std::hypot(got[0] - (p + length), got[1]);
            EXPECT_LE(from_translated,
                      2.2 * offset * std::exp(ratio) * length + 8 * kEps * (p + length));
          }
        }
      }
    }
  }
  std::cout << "[ measured ] " << kDim
            << "D, pushing with tiny offsets: max |fast - analytic| / (p + L) = " << worst
            << " (eps = " << kEps << ")\n";
}

// The same in a rotated frame, where the offset itself is rounded: the answer must still be
// the one of the inputs as given, here checked against the reference form (which has no
// cancellation for Y0 -> 0) and the ODE.
TYPED_TEST(TractrixStepTest, TinySidewaysOffsetInRotatedFrameAgreesWithReferenceForm) {
  constexpr int kDim = TypeParam::value;
  Random random(99);
  for (const double offset : {1e-3, 1e-6, 1e-10, 1e-14}) {
    for (const double ratio : {0.5, 1.0, 5.0}) {
      const Vec<kDim> u = random.UnitVector<kDim>();
      const Vec<kDim> w = random.Perpendicular<kDim>(u);
      const double length = 1.0, p = ratio;
      const Vec<kDim> head_old = Vec<kDim>::Constant(0.1);
      const Vec<kDim> tail = head_old + std::sqrt(1 - offset * offset) * u + offset * w;
      const Vec<kDim> head_new = head_old + p * u;
      const Vec<kDim> fast = TractrixStep(head_old, head_new, tail, length);
      const Vec<kDim> ref = Reference<kDim>(head_old, head_new, tail, length);
      // Rounding of the inputs moves Y0 by about eps: a relative change eps/offset of it moves
      // the tail by up to that many link lengths times sech^2(phi) <= 1 (conditioning, not an
      // error of the method). Both forms see the same inputs and must agree far better.
      EXPECT_LE((fast - ref).norm(), 64 * kEps * (1 + p) * std::fmax(1.0, 1e-16 / offset))
          << "offset " << offset << ", p/L " << ratio;
      if (offset >= 1e-6) {
        const Vec<kDim> ode = reference::ReferenceLinkStep<kDim>(head_old, head_new, tail, length);
        // The ODE's own error (~1e-12) is amplified by up to L / Y0 near the equilibrium.
        EXPECT_LE((fast - ode).norm(), 1e-12 / offset) << "offset " << offset;
      }
    }
  }
}

// Zero displacement: the tail does not move, exactly, whatever the configuration.
TYPED_TEST(TractrixStepTest, ZeroDisplacementLeavesTheTailExactlyUnchanged) {
  constexpr int kDim = TypeParam::value;
  Random random(3);
  for (int i = 0; i < 100; ++i) {
    const double length = std::pow(10.0, random.Uniform(-9.0, 9.0));
    const LinkMove<kDim> m = RandomMove<kDim>(random, static_cast<MoveKind>(i % 3), length, 0.0);
    ASSERT_EQ(m.head_new, m.head_old);
    EXPECT_EQ(TractrixStep(m.head_old, m.head_new, m.tail, length), m.tail);
    EXPECT_EQ(Reference<kDim>(m.head_old, m.head_new, m.tail, length), m.tail);
  }
}

// Huge moves: 1e3, 1e6 and 1e20 link lengths. The link ends up aligned behind the head
// (tail = head_new - L u; sech(p/L) underflows) and keeps its length, to the rounding of
// coordinates of size |head_new| (at 1e20 L those are coarser than the link itself).
TYPED_TEST(TractrixStepTest, HugeMovesLeaveTheLinkBehindTheHead) {
  constexpr int kDim = TypeParam::value;
  Random random(11);
  for (const double length : {1e-9, 1.0, 1e9}) {
    for (const double ratio : {1e3, 1e6, 1e20}) {
      for (const MoveKind kind : {MoveKind::kPull, MoveKind::kSideways, MoveKind::kPush}) {
        const LinkMove<kDim> m = RandomMove<kDim>(random, kind, length, ratio * length);
        const Vec<kDim> u = (m.head_new - m.head_old).normalized();
        const double coordinate_rounding = 8 * kEps * (m.head_new.cwiseAbs().maxCoeff() + length);
        for (const Vec<kDim>& got :
             {Vec<kDim>(TractrixStep(m.head_old, m.head_new, m.tail, length)),
              Reference<kDim>(m.head_old, m.head_new, m.tail, length)}) {
          SCOPED_TRACE("L = " + Str(length) + ", p/L = " + Str(ratio) + ", " + KindName(kind));
          ASSERT_TRUE(got.allFinite());
          EXPECT_LE(std::fabs((got - m.head_new).norm() - length), coordinate_rounding);
          EXPECT_LE((got - (m.head_new - length * u)).norm(), coordinate_rounding);
        }
      }
    }
  }
}

// Moves far outside the fast form's safe range (denominator beyond 1e+-250) take the fallback:
// p/L = 1e60 (the link ends up behind the head) and p/L = 1e-60 (the tail moves by at most p,
// which is below the rounding of its coordinates). Also a huge ratio reached with a tiny link
// (inside the safe range, exp(-p/L) = 0).
TYPED_TEST(TractrixStepTest, ExtremeRatiosOutsideTheFastRangeAreHandled) {
  constexpr int kDim = TypeParam::value;
  Random random(13);
  struct Case {
    double length, ratio;
  };
  for (const Case c : {Case{1.0, 1e60}, Case{1.0, 1e-60}, Case{1e-30, 1e60}, Case{1e30, 1e-60},
                       Case{1e-100, 1e100}, Case{1e100, 1e-100}}) {
    for (const MoveKind kind : {MoveKind::kPull, MoveKind::kSideways, MoveKind::kPush}) {
      const double length = c.length, p = c.ratio * length;
      const LinkMove<kDim> m = RandomMove<kDim>(random, kind, length, p);
      const Vec<kDim> fast = TractrixStep(m.head_old, m.head_new, m.tail, length);
      const Vec<kDim> ref = Reference<kDim>(m.head_old, m.head_new, m.tail, length);
      SCOPED_TRACE("L = " + Str(length) + ", p/L = " + Str(c.ratio) + ", " + KindName(kind));
      ASSERT_TRUE(fast.allFinite());
      const double rounding = 8 * kEps * (m.head_new.cwiseAbs().maxCoeff() + length);
      EXPECT_LE((fast - ref).norm(), rounding);
      EXPECT_LE(std::fabs((fast - m.head_new).norm() - length), rounding);
      if (c.ratio > 1.0) {
        const Vec<kDim> u = (m.head_new - m.head_old) / p;
        EXPECT_LE((fast - (m.head_new - length * u)).norm(), rounding);
      } else {
        EXPECT_LE((fast - m.tail).norm(), p + rounding);
      }
    }
  }
}

// Where the motion dies out along a chain, moves fall to 1e-50 of a link and below, down to
// subnormal sizes: the rule computes them in its vector form, scaled (a move whose squared length
// underflows, every coordinate below 1e-162, leaves the tail where it is), without flagging the
// lane for the scalar reference form (which made such batches several times slower), and agrees
// with the reference to rounding. So do moves of 1e60 links.
TYPED_TEST(TractrixStepTest, TinyAndHugeMovesStayInTheVectorForm) {
  constexpr int kDim = TypeParam::value;
  Random random(17);
  int checked = 0;
  for (const double length : {1e-3, 1.0, 1e3}) {
    for (const double ratio : {1e-45, 1e-60, 1e-120, 1e-200, 1e-300, 1e-310, 1e60}) {
      for (const MoveKind kind : {MoveKind::kPull, MoveKind::kSideways, MoveKind::kPush}) {
        // Head at the origin, so that a move of 1e-310 L is a move and not rounded away.
        const double p = ratio * length;
        LinkMove<kDim> m = RandomMove<kDim>(random, kind, length, 1.0);
        const Vec<kDim> u = m.head_new - m.head_old;  // unit, to rounding
        m.tail -= m.head_old;
        m.head_old.setZero();
        m.head_new = p * u;
        Vec<kDim> tail = m.tail;
        const bool flagged = internal::TractrixRule<kDim>::Apply(
            m.head_old.data(), m.head_new.data(), tail.data(), length, -1.0 / length);
        const Vec<kDim> ref = Reference<kDim>(m.head_old, m.head_new, m.tail, length);
        SCOPED_TRACE("L = " + Str(length) + ", p/L = " + Str(ratio) + ", " + KindName(kind));
        EXPECT_FALSE(flagged);
        ASSERT_TRUE(tail.allFinite());
        const double rounding = 8 * kEps * (m.head_new.cwiseAbs().maxCoeff() + length);
        EXPECT_LE(std::fabs((tail - m.head_new).norm() - length), rounding);
        if (ratio < 1.0) {
          // The tail moves by at most p: below the rounding of its coordinates.
          EXPECT_LE((tail - m.tail).norm(), p + rounding);
        }
        // The reference form agrees, except for a subnormal move (1e-310 L here), whose direction
        // the reference's asinh, tanh and cosh of large arguments resolve only to a few ulps.
        if (ratio >= 1e-300) EXPECT_LE((tail - ref).norm(), rounding);
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 63);
}

// Invariants over many random inputs, manif style: identity (no move), tiny (1e-8 L) and
// random moves (1e-3 to 30 L, pulling, sideways and pushing).
enum class InputKind { kIdentity, kTiny, kRandom };

struct PropertyParam {
  int dim;
  InputKind kind;
};

void PrintTo(const PropertyParam& p, std::ostream* os) {
  *os << p.dim << "D, input kind " << static_cast<int>(p.kind);
}

std::string PropertyName(const ::testing::TestParamInfo<PropertyParam>& info) {
  const char* kind = info.param.kind == InputKind::kIdentity ? "Identity"
                     : info.param.kind == InputKind::kTiny   ? "Tiny"
                                                             : "Random";
  return std::to_string(info.param.dim) + "D" + kind;
}

class LinkStepPropertyTest : public ::testing::TestWithParam<PropertyParam> {
 protected:
  // Counts the samples that break a property and keeps the worst one, so that a broken
  // property gives one readable failure instead of thousands.
  struct Violations {
    int count = 0;
    double worst = 0.0;  // in units of the allowed bound
    std::string example;
    void Check(double value, double bound, const std::string& what) {
      if (value <= bound) return;
      ++count;
      if (value / bound > worst) {
        worst = value / bound;
        example = what + ": " + Str(value) + " > " + Str(bound);
      }
    }
  };

  template <int Dim>
  void CheckInvariants() {
    const InputKind input = GetParam().kind;
    Random random(1000 * Dim + static_cast<int>(input));
    constexpr int kSamples = 3000;
    Violations length_kept, no_faster, identity, first_order;
    double worst_length = 0.0, worst_speed = 0.0;
    for (int i = 0; i < kSamples; ++i) {
      const double length = std::pow(10.0, random.Uniform(-3.0, 3.0));
      const double p = input == InputKind::kIdentity ? 0.0
                       : input == InputKind::kTiny
                           ? 1e-8 * length
                           : length * std::pow(10.0, random.Uniform(-3.0, std::log10(30.0)));
      // Every fourth sample pushes almost straight at the tail (offset 1e-15 to 1e-6 L); for
      // random moves the move then ends near the point where the continuous motion flips the
      // link (p/L ~ asinh(1/offset)), where rounding of the offset matters most.
      LinkMove<Dim> m;
      std::string kind;
      if (i % 4 == 3) {
        const double offset = std::pow(10.0, random.Uniform(-15.0, -6.0));
        const double q = std::asinh(1.0 / offset) + random.Uniform(-3.0, 3.0);
        m = AlmostTowardMove<Dim>(random, length, offset,
                                  input == InputKind::kRandom ? q * length : p);
        kind = "almost toward the tail (offset " + Str(offset) + " L)";
      } else {
        m = RandomMove<Dim>(random, static_cast<MoveKind>(i % 4), length, p);
        kind = KindName(static_cast<MoveKind>(i % 4));
      }
      const double scale = m.head_new.cwiseAbs().maxCoeff() + m.tail.cwiseAbs().maxCoeff();
      const Vec<Dim> tractrix = TractrixStep(m.head_old, m.head_new, m.tail, length);
      const Vec<Dim> ftl = FollowTheLeaderStep(m.head_old, m.head_new, m.tail, length);
      for (const bool is_ftl : {false, true}) {
        const Vec<Dim>& got = is_ftl ? ftl : tractrix;
        const std::string what = std::string(is_ftl ? "ftl" : "tractrix") + " sample " +
                                 std::to_string(i) + ", " + kind + ", L = " + Str(length) +
                                 ", p/L = " + Str(m.p / length);
        // Length kept: the new tail is head_new + offset, so the only error is the rounding
        // of that sum (coordinates of size `scale`) and of the offset itself.
        const double length_error = std::fabs((got - m.head_new).norm() - length);
        length_kept.Check(length_error, 4 * kEps * (length + scale),
                          what + ", | |tail - head_new| - L |");
        // Never faster than the head (paper Sec. 2, dr <= dp), to rounding.
        const double excess = (got - m.tail).norm() - m.p;
        no_faster.Check(excess, 4 * kEps * (m.p + length + scale), what + ", |dtail| - |dhead|");
        if (!is_ftl) {
          worst_length = std::fmax(worst_length, length_error / (length + scale));
          worst_speed = std::fmax(worst_speed, excess / (m.p + length + scale));
        }
        if (input == InputKind::kTiny) {
          // First order: the tail moves by the projection of the head's move onto the link.
          const Vec<Dim> e = (m.head_old - m.tail).normalized();
          const Vec<Dim> expected = m.tail + (m.head_new - m.head_old).dot(e) * e;
          first_order.Check((got - expected).norm(), p * p / length + 8 * kEps * (length + scale),
                            what + ", distance from the first-order motion");
        }
      }
      if (input == InputKind::kIdentity) {
        identity.Check((tractrix - m.tail).norm(), 0.0, "tractrix sample " + std::to_string(i));
      }
    }
    EXPECT_EQ(length_kept.count, 0) << "of " << kSamples << "; worst: " << length_kept.example;
    EXPECT_EQ(no_faster.count, 0) << "of " << kSamples << "; worst: " << no_faster.example;
    EXPECT_EQ(identity.count, 0) << "tail moved without a move: " << identity.example;
    EXPECT_EQ(first_order.count, 0) << "of " << kSamples << "; worst: " << first_order.example;
    std::cout << "[ measured ] tractrix: max length error / (L + |coords|) = " << worst_length
              << ", max (|dtail| - |dhead|) / (p + L + |coords|) = " << worst_speed << "\n";
  }
};

TEST_P(LinkStepPropertyTest, LengthKeptAndTailNoFasterThanHead) {
  if (GetParam().dim == 2) {
    CheckInvariants<2>();
  } else {
    CheckInvariants<3>();
  }
}

INSTANTIATE_TEST_SUITE_P(
    AllInputs, LinkStepPropertyTest,
    ::testing::Values(PropertyParam{2, InputKind::kIdentity}, PropertyParam{2, InputKind::kTiny},
                      PropertyParam{2, InputKind::kRandom}, PropertyParam{3, InputKind::kIdentity},
                      PropertyParam{3, InputKind::kTiny}, PropertyParam{3, InputKind::kRandom}),
    PropertyName);

// Follow-the-leader: the tail goes to the nearest point of the sphere around the new head; if
// the head lands exactly on the tail the link keeps its old direction.
TYPED_TEST(TractrixStepTest, FollowTheLeaderNearestPointAndLandingOnTheTail) {
  constexpr int kDim = TypeParam::value;
  Vec<kDim> head_old = Vec<kDim>::Zero(), tail = Vec<kDim>::Zero();
  tail[1] = 2.0;
  Vec<kDim> head_new = Vec<kDim>::Zero();
  head_new[0] = 2.0;
  Vec<kDim> expected = head_new;
  expected[0] -= std::sqrt(2.0);
  expected[1] += std::sqrt(2.0);
  EXPECT_LE((FollowTheLeaderStep(head_old, head_new, tail, 2.0) - expected).norm(), 4 * kEps);
  // Landing on the tail.
  const Vec<kDim> landed = FollowTheLeaderStep(head_old, tail, tail, 2.0);
  EXPECT_LE((landed - 2.0 * tail).norm(), 4 * kEps);
}

// Bad input: a typed error naming the field.
TYPED_TEST(TractrixStepTest, RejectsInvalidInputNamingTheField) {
  constexpr int kDim = TypeParam::value;
  const Vec<kDim> zero = Vec<kDim>::Zero();
  Vec<kDim> tail = Vec<kDim>::Zero();
  tail[0] = 1.0;
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  using Rule = Vec<kDim> (*)(const Vec<kDim>&, const Vec<kDim>&, const Vec<kDim>&, double);
  for (const Rule rule :
       {static_cast<Rule>(&TractrixStep), static_cast<Rule>(&FollowTheLeaderStep)}) {
    for (const double length : {0.0, -0.0, -1.0, nan, inf, -inf}) {
      try {
        rule(zero, tail, tail, length);
        ADD_FAILURE() << "no error for length " << length;
      } catch (const InputError& e) {
        EXPECT_EQ(e.field(), "length");
        EXPECT_NE(std::string(e.what()).find("length"), std::string::npos) << e.what();
      }
    }
    for (const double bad : {nan, inf, -inf}) {
      Vec<kDim> x = zero;
      x[kDim - 1] = bad;
      const std::string k = "[" + std::to_string(kDim - 1) + "]";
      struct Args {
        Vec<kDim> head_old, head_new, tail;
        std::string field;
      };
      for (const Args& a : {Args{x, tail, tail, "head_old" + k},
                            Args{zero, x, tail, "head_new" + k}, Args{zero, tail, x, "tail" + k}}) {
        try {
          rule(a.head_old, a.head_new, a.tail, 1.0);
          ADD_FAILURE() << "no error for " << a.field << " = " << bad;
        } catch (const InputError& e) {
          EXPECT_EQ(e.field(), a.field);
          EXPECT_NE(std::string(e.what()).find(a.field), std::string::npos) << e.what();
        }
      }
    }
  }
}

}  // namespace
}  // namespace flexkin
