// The strand engine with colliders (flexkin/strands.h, docs/colliders.md): no free point or link
// inside a collider after any frame, lengths kept, a batch that touches nothing stepped exactly as
// without colliders, strands that touch equal to the single chain's contact sweep, the same
// result on every engine and thread count, and the refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "collider_test_util.h"
#include "flexkin/groom.h"
#include "flexkin/run.h"
#include "flexkin/strands.h"
#include "run/sweep_pipeline.h"
#include "strands/strand_engine.h"
#include "world/contact.h"

namespace flexkin {
namespace {

using collider_test::CapsuleBetween;
using collider_test::Sphere;
using Eigen::Vector3d;

// Strands lying close over the unit sphere (circle in 2D): each link turns a little away from
// the surface (radial component 0.1 to 0.25 of the link), so every point is farther from the
// centre than the one before, yet near enough that a turning body drags them through it.
std::vector<Points> LyingStrands(int count, int dim, int links, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> radial(0.1, 0.25), length(0.03, 0.06);
  std::vector<Points> strands;
  for (int s = 0; s < count; ++s) {
    Points p(links + 1, dim);
    Eigen::VectorXd root(dim), tangent(dim);
    for (int k = 0; k < dim; ++k) root[k] = normal(rng), tangent[k] = normal(rng);
    root.normalize();
    if (dim == 3 && root[2] < -0.3) root[2] = -root[2];  // clear of a neck below
    p.row(0) = root.transpose();
    for (int i = 1; i <= links; ++i) {
      const Eigen::VectorXd out = p.row(i - 1).transpose().normalized();
      Eigen::VectorXd t = tangent - tangent.dot(out) * out;
      t.normalize();
      const double a = radial(rng);
      const Eigen::VectorXd dir = a * out + std::sqrt(1.0 - a * a) * t;
      p.row(i) = p.row(i - 1) + length(rng) * dir.transpose();
      tangent = t;
    }
    strands.push_back(p);
  }
  return strands;
}

// The body turns back and forth about a tilted axis (about z in 2D) and shifts a little.
BodyPose TurningPose(int frame, int dim) {
  const double t = 0.15 * frame;
  const double angle = 1.2 * std::sin(t);
  if (dim == 2) return BodyPose::Planar(angle, 0.05 * std::sin(0.5 * t), 0.0);
  const Vector3d axis = Vector3d(0.3, 0.2, 1.0).normalized();
  return BodyPose::FromQuaternion(std::cos(angle / 2), std::sin(angle / 2) * axis[0],
                                  std::sin(angle / 2) * axis[1], std::sin(angle / 2) * axis[2],
                                  Vector3d(0.05 * std::sin(0.5 * t), 0.0, 0.0));
}

Vector3d At(const Points& p, int i) {
  return Vector3d(p(i, 0), p(i, 1), p.cols() == 3 ? p(i, 2) : 0.0);
}

// The least distance from the segment [a, b] to the point set f measures, by ternary search on
// the segment's parameter (the distance to a convex set is convex along a segment): the test's
// own measure, independent of the library's closed forms.
template <class Distance>
double LeastAlong(const Vector3d& a, const Vector3d& b, Distance f) {
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 200; ++i) {
    const double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
    if (f(a + m1 * (b - a)) < f(a + m2 * (b - a))) {
      hi = m2;
    } else {
      lo = m1;
    }
  }
  return std::min({f(a), f(b), f(a + 0.5 * (lo + hi) * (b - a))});
}

// The signed distance of x to a sphere or capsule placed in the world: |x - centre| - r, or the
// distance to the axis segment - r.
double Signed(const Collider& c, const Vector3d& x) {
  if (c.shape == ColliderShape::kSphere) return (x - c.pose.translation()).norm() - c.radius;
  const Vector3d axis = c.pose.linear().col(2) * c.half_length;
  const Vector3d p = c.pose.translation() - axis, q = c.pose.translation() + axis;
  const double t = std::clamp((x - p).dot(q - p) / (q - p).squaredNorm(), 0.0, 1.0);
  return (x - (p + t * (q - p))).norm() - c.radius;
}

// The colliders placed at the body's pose (body colliders) or as they are (world).
std::vector<Collider> Placed(const std::vector<Collider>& body, const BodyPose& pose, int dim) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  if (dim == 2) {
    m.linear().topLeftCorner<2, 2>() = pose.rotation.topLeftCorner<2, 2>();
    m.translation().head<2>() = pose.translation.head<2>();
  } else {
    m.linear() = pose.rotation;
    m.translation() = pose.translation;
  }
  std::vector<Collider> out = body;
  for (Collider& c : out) c.pose = m * c.pose;
  return out;
}

// The least clearance of strand `s`'s free links (after `pinned` - 1), relative to each link's
// length, over `colliders`.
double LeastClearance(const Points& p, int pinned, const std::vector<Collider>& colliders) {
  double least = std::numeric_limits<double>::infinity();
  for (int i = pinned; i < p.rows(); ++i) {
    const Vector3d a = At(p, i - 1), b = At(p, i);
    for (const Collider& c : colliders) {
      const double d = LeastAlong(a, b, [&](const Vector3d& x) { return Signed(c, x); });
      least = std::min(least, d / (b - a).norm());
    }
  }
  return least;
}

struct Case {
  int dim, substeps, pinned;
  const char* engine;
};

class StrandColliders : public ::testing::TestWithParam<Case> {};

// A scalp of radius 1 with the strands lying over it and, in 3D, a neck capsule below; the body
// turns for 40 frames. After every frame: no free link inside either (beyond 1e-12 of its
// length), every length kept to 1e-12, and many contact steps taken (the free strands cut
// through the scalp: the case is not vacuous).
TEST_P(StrandColliders, NothingEntersTheBodyAndLengthsAreKept) {
  const Case c = GetParam();
  const std::vector<Points> strands = LyingStrands(40, c.dim, 12, 7);
  StrandOptions options;
  options.substeps = c.substeps;
  options.pinned = c.pinned;
  options.threads = 2;
  options.body_colliders = {Sphere(Vector3d::Zero(), 1.0)};
  if (c.dim == 3) {
    options.body_colliders.push_back(
        CapsuleBetween(Vector3d(0, 0, -0.95), Vector3d(0, 0, -1.8), 0.35));
  }
  StrandBatch batch(strands, options);
  StrandBatch free(strands, [&] {
    StrandOptions o = options;
    o.body_colliders.clear();
    return o;
  }());
  if (!internal::SetStrandEngine(&batch, c.engine)) GTEST_SKIP() << "no " << c.engine << " here";
  ASSERT_TRUE(internal::SetStrandEngine(&free, c.engine));
  double free_least = std::numeric_limits<double>::infinity();
  for (int f = 1; f <= 40; ++f) {
    const BodyPose pose = TurningPose(f, c.dim);
    StepStrands(&batch, pose);
    StepStrands(&free, pose);
    const std::vector<Collider> placed = Placed(options.body_colliders, pose, c.dim);
    for (int s = 0; s < batch.size(); ++s) {
      const Points p = batch.strand(s);
      ASSERT_GE(LeastClearance(p, c.pinned, placed), -1e-12) << "frame " << f << " strand " << s;
      for (int i = 1; i < p.rows(); ++i) {
        const double rest = (strands[s].row(i) - strands[s].row(i - 1)).norm();
        ASSERT_NEAR((p.row(i) - p.row(i - 1)).norm(), rest, 1e-12 * rest);
      }
      free_least = std::min(free_least, LeastClearance(free.strand(s), c.pinned, placed));
    }
  }
  EXPECT_LT(free_least, -0.05) << "the strands without colliders should cut through the body";
  EXPECT_GT(batch.contacts().contact_link_steps, 100);
  EXPECT_GE(batch.contacts().least_clearance, -1e-13);
}

INSTANTIATE_TEST_SUITE_P(Cases, StrandColliders,
                         ::testing::Values(Case{3, 1, 1, "scalar"}, Case{3, 1, 1, "avx2"},
                                           Case{3, 1, 1, "avx512"}, Case{3, 3, 1, "avx2"},
                                           Case{3, 1, 2, "scalar"}, Case{2, 1, 1, "scalar"},
                                           Case{2, 2, 1, "avx2"}, Case{2, 1, 1, "avx512"}),
                         [](const auto& info) {
                           return std::to_string(info.param.dim) + "d_substeps" +
                                  std::to_string(info.param.substeps) + "_pinned" +
                                  std::to_string(info.param.pinned) + "_" + info.param.engine;
                         });

// Colliders that nothing comes near change nothing: bit for bit the batch without them, on
// every engine (world colliders with sub-steps; body colliders with one sub-step: with more, the
// pinned points follow the body's own motion between frames, flexkin/strands.h).
TEST(StrandCollidersTest, FarCollidersChangeNoBit) {
  for (const char* engine : {"scalar", "avx2", "avx512"}) {
    for (int substeps : {1, 2}) {
      const std::vector<Points> strands = LyingStrands(37, 3, 9, 3);
      StrandOptions options;
      options.substeps = substeps;
      StrandBatch plain(strands, options);
      options.colliders = {Sphere(Vector3d(50, 0, 0), 1.0)};
      if (substeps == 1) {
        options.body_colliders = {CapsuleBetween(Vector3d(0, 0, -40), Vector3d(0, 0, -60), 1.0)};
      }
      StrandBatch with(strands, options);
      if (!internal::SetStrandEngine(&plain, engine)) continue;
      ASSERT_TRUE(internal::SetStrandEngine(&with, engine));
      for (int f = 1; f <= 30; ++f) {
        StepStrands(&plain, TurningPose(f, 3));
        StepStrands(&with, TurningPose(f, 3));
      }
      for (int s = 0; s < plain.size(); ++s) {
        ASSERT_TRUE(plain.strand(s) == with.strand(s))
            << engine << " substeps " << substeps << " strand " << s << "\n"
            << plain.strand(s) << "\n\n"
            << with.strand(s);
      }
      EXPECT_EQ(with.contacts().contact_link_steps, 0);
    }
  }
}

// Colliders out of every strand's reach (a block's leading ends further from their bounds than
// the strands are long) are not measured: with the scalp's contacts, a batch with three such
// capsules beside it steps every strand as the scalp alone does, bit for bit, on every engine.
TEST(StrandCollidersTest, CollidersOutOfReachChangeNoBitBesideContacts) {
  const std::vector<Points> strands = LyingStrands(40, 3, 12, 5);
  for (const char* engine : {"scalar", "avx2", "avx512"}) {
    StrandOptions options;
    options.body_colliders = {Sphere(Vector3d::Zero(), 1.0)};
    StrandBatch scalp(strands, options);
    options.body_colliders.push_back(CapsuleBetween(Vector3d(0, 0, -4), Vector3d(0, 0, -6), 1.0));
    options.body_colliders.push_back(CapsuleBetween(Vector3d(5, 0, 0), Vector3d(7, 0, 1), 0.5));
    options.colliders = {CapsuleBetween(Vector3d(0, -5, 0), Vector3d(0, -7, 1), 0.5)};
    StrandBatch more(strands, options);
    if (!internal::SetStrandEngine(&scalp, engine)) continue;
    ASSERT_TRUE(internal::SetStrandEngine(&more, engine));
    for (int f = 1; f <= 30; ++f) {
      StepStrands(&scalp, TurningPose(f, 3));
      StepStrands(&more, TurningPose(f, 3));
    }
    EXPECT_GT(more.contacts().contact_link_steps, 100) << engine;
    EXPECT_EQ(more.contacts().contact_link_steps, scalp.contacts().contact_link_steps) << engine;
    for (int s = 0; s < scalp.size(); ++s) {
      ASSERT_TRUE(scalp.strand(s) == more.strand(s)) << engine << " strand " << s;
    }
  }
}

// A strand whose root is moved as a point past a world sphere is the single chain run with the
// same collider (Run with RunOptions::colliders, the contact sweep), on the scalar engine bit
// for bit.
TEST(StrandCollidersTest, AStrandIsItsChainsContactRun) {
  Points chain(9, 3);
  for (int i = 0; i <= 8; ++i) chain.row(i) << -0.25 * i, 0.02 * i, 0.0;
  const Collider post = Sphere(Vector3d(-0.4, -0.4, 0.0), 0.25);
  // The root moves down, dragging the strand's tail round the sphere.
  Points path(31, 3);
  for (int f = 0; f <= 30; ++f) path.row(f) << 0.0, -0.06 * f, 0.0;
  StrandOptions options;
  options.colliders = {post};
  StrandBatch batch({chain}, options);
  ASSERT_TRUE(internal::SetStrandEngine(&batch, "scalar"));
  for (int f = 1; f <= 30; ++f) StepStrands(&batch, path.row(f));

  // The chain's run one sub-step at a time: the contact sweep, which the scalar strand engine
  // takes link by link (a run's pipeline takes these 8 links on the wavefront, whose exp rounds
  // otherwise).
  RunOptions run;
  run.method = Method::kTractrix;
  run.colliders = {post};
  FrameRecorder frames;
  const RunResult result = internal::RunSubstepBySubstep(MakeChain(chain), path, run, &frames);
  EXPECT_GT(result.contacts.contact_link_steps, 0) << frames.frames.back().points;
  const Points last = frames.frames.back().points;
  EXPECT_TRUE(batch.strand(0) == last) << batch.strand(0) << "\n\n" << last;
}

// The SIMD engines take the contact step against a lone sphere (a scalp) in their lanes, in
// closed form; the scalar engine takes it link by link (the single chain's contact sweep). From
// the same start, one frame of contacts agrees to rounding (1e-15 here). Over 30 frames the
// rounding grows where the step is ill-conditioned (an old direction nearly through the sphere's
// centre, whose exit direction on the cone is nearly undetermined): to 1.1e-8 here, bounded
// below by 1e-6; the same contact steps are taken.
TEST(StrandCollidersTest, TheLanesContactStepIsTheScalarOne) {
  const std::vector<Points> strands = LyingStrands(48, 3, 16, 5);
  StrandOptions options;
  options.body_colliders = {Sphere(Vector3d::Zero(), 1.0)};
  for (int frames : {1, 30}) {
    StrandBatch scalar(strands, options);
    ASSERT_TRUE(internal::SetStrandEngine(&scalar, "scalar"));
    for (int f = 1; f <= frames; ++f) StepStrands(&scalar, TurningPose(f, 3));
    ASSERT_GT(scalar.contacts().contact_link_steps, frames == 1 ? 10 : 1000);
    for (const char* engine : {"avx2", "avx512"}) {
      StrandBatch lanes(strands, options);
      if (!internal::SetStrandEngine(&lanes, engine)) continue;
      for (int f = 1; f <= frames; ++f) StepStrands(&lanes, TurningPose(f, 3));
      double worst = 0.0;
      for (int s = 0; s < lanes.size(); ++s) {
        worst = std::max(worst, (lanes.strand(s) - scalar.strand(s)).cwiseAbs().maxCoeff());
      }
      EXPECT_LT(worst, frames == 1 ? 1e-13 : 1e-6) << engine << ", " << frames << " frames";
      EXPECT_EQ(lanes.contacts().contact_link_steps, scalar.contacts().contact_link_steps)
          << engine;
      EXPECT_GE(lanes.contacts().least_clearance, -1e-13) << engine;
    }
  }
}

// The SIMD engines' check of a sphere after the sweep (StrandSphereCheckFn), which takes the exact
// clearance only of links that can change its answers, against the check it replaced: every
// link's clearance from the same engine's StrandBoundsFn, then CheckLanes' loop (near: within a
// link's length; entering: below -kContactSlack of it; the least clearance over the length).
// Blocks of links lying on the sphere, a rounding inside and outside it, within and beyond the
// slack, deep inside, near and far; a sphere of 1e-4 among links of 0.1 (the squared distance's
// cancellation); carried-over answers of other colliders. The same bits for every lane; and the
// same bits from the sphere sweep's own check, made link by link as the sweep leaves each.
TEST(StrandCollidersTest, TheLanesSphereCheckIsEveryLinksMeasure) {
  constexpr int L = internal::kStrandLanes;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal;
  int checked = 0, entered = 0, near_lanes = 0, swept_contacts = 0;
  for (const char* engine : {"avx2", "avx512"}) {
    internal::StrandEngineEntries entries;
    if (!internal::StrandEngineOf(engine, &entries)) continue;
    const internal::StrandSphereCheckFn check = entries.check_sphere;
    const internal::StrandBoundsFn measure = entries.bounds;
    for (int dim : {2, 3}) {
      for (int trial = 0; trial < 200; ++trial) {
        const int n = 4 + trial % 13, head = trial % 3 == 0 ? 1 : 0;
        internal::ColliderBound bound;
        bound.exact = true;
        bound.radius = trial % 5 == 4 ? 1e-4 : 0.5 + unit(rng);
        for (int k = 0; k < dim; ++k) bound.center[k] = normal(rng);
        // The engine's arrays are 64-byte aligned.
        std::vector<double> store((n + 1) * dim * L + 2 * n * L + dim * L + 24);
        double* base = store.data();
        while (reinterpret_cast<uintptr_t>(base) % 64 != 0) ++base;
        double* points = base;
        double* lengths = points + (n + 1) * dim * L;
        double* inv = lengths + n * L;
        double* heads = inv + n * L;
        for (int lane = 0; lane < L; ++lane) {
          Eigen::Vector3d p = Eigen::Vector3d::Zero(), c = Eigen::Vector3d::Zero();
          for (int k = 0; k < dim; ++k) c[k] = bound.center[k];
          for (int i = 0; i <= n; ++i) {
            Eigen::Vector3d d = Eigen::Vector3d::Zero();
            for (int k = 0; k < dim; ++k) d[k] = normal(rng);
            d.normalize();
            if (i == 0) {
              p = c + (bound.radius + 0.3 * unit(rng)) * d;
            } else {
              p += (0.05 + 0.15 * unit(rng)) * d;
            }
            // Onto the surface, a rounding or the slack inside or outside it, or deep inside.
            const double pick = unit(rng);
            const double scale = pick < 0.2    ? 1.0
                                 : pick < 0.3  ? 1.0 - 1e-15
                                 : pick < 0.4  ? 1.0 + 1e-14
                                 : pick < 0.5  ? 1.0 - 2e-13
                                 : pick < 0.55 ? 0.5
                                               : 0.0;
            if (scale > 0.0) p = c + scale * bound.radius * (p - c).normalized();
            for (int k = 0; k < dim; ++k) points[(i * dim + k) * L + lane] = p[k];
          }
          for (int i = 1; i <= n; ++i) {
            double l2 = 0.0;
            for (int k = 0; k < dim; ++k) {
              const double e =
                  points[(i * dim + k) * L + lane] - points[((i - 1) * dim + k) * L + lane];
              l2 += e * e;
            }
            lengths[(i - 1) * L + lane] = std::sqrt(l2);
            inv[(i - 1) * L + lane] = 1.0 / std::sqrt(l2);
          }
        }
        // What other colliders left: nothing, or a clearance and an entering link.
        std::vector<double> least(L), want_least(L);
        std::vector<int> first(L), want_first(L);
        for (int lane = 0; lane < L; ++lane) {
          least[lane] = lane % 4 == 1 ? 0.2 * unit(rng) : std::numeric_limits<double>::infinity();
          first[lane] = lane % 5 == 2 ? 1 + static_cast<int>(unit(rng) * n) : n + 1;
        }
        want_least = least;
        want_first = first;
        std::vector<double> clear((n - head) * L);
        measure(dim, n, head, points, &bound, 1, clear.data());
        std::vector<uint8_t> want_near(L, 0), near(L, 7);
        for (int i = head + 1; i <= n; ++i) {
          for (int lane = 0; lane < L; ++lane) {
            const double c = clear[(i - head - 1) * L + lane];
            const double len = lengths[(i - 1) * L + lane];
            if (!(c < len)) continue;
            want_near[lane] = 1;
            if (c < -internal::kContactSlack * len)
              want_first[lane] = std::min(want_first[lane], i);
            want_least[lane] = std::min(want_least[lane], c * inv[(i - 1) * L + lane]);
          }
        }
        check(dim, n, head, points, lengths, inv, bound, internal::kContactSlack, least.data(),
              first.data(), near.data());
        for (int lane = 0; lane < L; ++lane) {
          ASSERT_EQ(near[lane], want_near[lane]) << engine << " " << dim << "D, trial " << trial;
          ASSERT_EQ(first[lane], want_first[lane]) << engine << " " << dim << "D, trial " << trial;
          // Bit for bit (infinity where no link came near).
          ASSERT_EQ(std::memcmp(&least[lane], &want_least[lane], sizeof(double)), 0)
              << engine << " " << dim << "D, trial " << trial << ", lane " << lane << ": "
              << least[lane] << " against " << want_least[lane];
          near_lanes += want_near[lane];
          entered += want_first[lane] <= n;
          ++checked;
        }
        // The sphere sweep's own check, made as it leaves each link: the check's answers on
        // the swept points, bit for bit (the leading ends moved a tenth of a link, so that
        // links follow, some onto the sphere by the contact step).
        const internal::StrandSphereSweepFn sweep = entries.sphere_sweep;
        for (int lane = 0; lane < L; ++lane) {
          for (int k = 0; k < dim; ++k) {
            heads[k * L + lane] = points[(head * dim + k) * L + lane] + 0.01 * normal(rng);
          }
        }
        internal::StrandSphere sphere;
        for (int k = 0; k < 3; ++k) sphere.center[k] = bound.center[k];
        sphere.radius = bound.radius;
        sphere.slack = internal::kContactSlack;
        std::vector<uint8_t> contact((n + 1) * L, 0);
        std::vector<int> fallback(L, n + 1);
        std::vector<double> saved((n + 1) * dim * L);
        internal::StrandSphereFound found;
        sweep(Method::kTractrix, dim, n, head, heads, lengths, inv, points, sphere, contact.data(),
              fallback.data(), saved.data(), &found);
        std::vector<double> after(L, std::numeric_limits<double>::infinity());
        std::vector<int> after_first(L, n + 1);
        std::vector<uint8_t> after_near(L, 0);
        check(dim, n, head, points, lengths, inv, bound, internal::kContactSlack, after.data(),
              after_first.data(), after_near.data());
        for (int lane = 0; lane < L; ++lane) {
          ASSERT_EQ(found.near[lane], after_near[lane]) << engine << " trial " << trial;
          ASSERT_EQ(found.first_enter[lane], after_first[lane]) << engine << " trial " << trial;
          ASSERT_EQ(std::memcmp(&found.least[lane], &after[lane], sizeof(double)), 0)
              << engine << " trial " << trial << ", lane " << lane;
          // Its count of contact steps is the lane's flags'.
          int flagged = 0;
          for (int i = head + 1; i <= n; ++i) flagged += contact[i * L + lane];
          ASSERT_EQ(found.contacts[lane], flagged) << engine << " trial " << trial;
          swept_contacts += contact[(n * L) + lane] + contact[((head + 1) * L) + lane];
        }
      }
    }
  }
  if (checked == 0) GTEST_SKIP() << "no SIMD engine here";
  // The blocks exercise every answer.
  EXPECT_GT(near_lanes, checked / 2);
  EXPECT_GT(entered, checked / 10);
  EXPECT_LT(entered, checked);
  EXPECT_GT(swept_contacts, 0);
}

// A strand's motion is its own, whichever strands share its block (docs/strands.md, "Layout":
// blocks are made of strands rooted near each other, so a batch of other strands makes other
// blocks): every third strand of a batch, stepped as a batch of its own, moves as in the whole
// batch, with contacts against the scalp and a neck capsule, on 1 and 2 threads: bit for bit on
// the scalar engine; on the SIMD engines within their documented rounding (a register takes the
// exp's reduction and the rule's pushing branch for all its lanes when one needs it, so a lane's
// last bits depend on its mates), here 1e-12 after 25 frames.
TEST(StrandCollidersTest, AStrandMovesAsInAnyOtherBlock) {
  const std::vector<Points> strands = LyingStrands(75, 3, 10, 5);
  std::vector<Points> thirds;
  for (size_t s = 0; s < strands.size(); s += 3) thirds.push_back(strands[s]);
  StrandOptions options;
  options.body_colliders = {Sphere(Vector3d::Zero(), 1.0),
                            CapsuleBetween(Vector3d(0, 0, -0.8), Vector3d(0, 0, -2.0), 0.35)};
  for (const char* engine : {"scalar", "avx2", "avx512"}) {
    for (int threads : {1, 2}) {
      options.threads = threads;
      StrandBatch all(strands, options), some(thirds, options);
      if (!internal::SetStrandEngine(&all, engine)) continue;
      ASSERT_TRUE(internal::SetStrandEngine(&some, engine));
      for (int f = 1; f <= 25; ++f) {
        StepStrands(&all, TurningPose(f, 3));
        StepStrands(&some, TurningPose(f, 3));
      }
      EXPECT_GT(some.contacts().contact_link_steps, 100) << engine;
      double worst = 0.0;
      for (int s = 0; s < some.size(); ++s) {
        if (std::string(engine) == "scalar") {
          ASSERT_TRUE(some.strand(s) == all.strand(3 * s))
              << engine << ", " << threads << " threads, strand " << 3 * s;
        }
        worst = std::max(worst, (some.strand(s) - all.strand(3 * s)).cwiseAbs().maxCoeff());
      }
      EXPECT_LT(worst, 1e-12) << engine << ", " << threads << " threads";
      std::printf("%s, %d threads: largest difference %.1e\n", engine, threads, worst);
    }
  }
}

// The same frames whatever the number of threads, with contacts.
TEST(StrandCollidersTest, ThreadsChangeNoBit) {
  const std::vector<Points> strands = LyingStrands(70, 3, 10, 11);
  StrandOptions options;
  options.body_colliders = {Sphere(Vector3d::Zero(), 1.0)};
  options.threads = 1;
  StrandBatch one(strands, options);
  options.threads = 3;
  StrandBatch three(strands, options);
  for (int f = 1; f <= 20; ++f) {
    StepStrands(&one, TurningPose(f, 3));
    StepStrands(&three, TurningPose(f, 3));
  }
  EXPECT_GT(one.contacts().contact_link_steps, 0);
  EXPECT_EQ(one.contacts().contact_link_steps, three.contacts().contact_link_steps);
  for (int s = 0; s < one.size(); ++s) ASSERT_TRUE(one.strand(s) == three.strand(s));
}

TEST(StrandCollidersTest, AStartInsideIsRefusedWithPointColliderAndDepth) {
  std::vector<Points> strands = LyingStrands(5, 3, 6, 1);
  strands[3](4, 0) *= 0.5, strands[3](4, 1) *= 0.5, strands[3](4, 2) *= 0.5;  // into the scalp
  StrandOptions options;
  options.colliders = {Sphere(Vector3d(5, 0, 0), 0.1)};
  options.body_colliders = {Sphere(Vector3d::Zero(), 1.0)};
  try {
    StrandBatch batch(strands, options);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem().field, "strands[3]");
    const std::string text = e.what();
    EXPECT_NE(text.find("point 4 lies inside body_colliders[0] (a sphere) by 0.4"),
              std::string::npos)
        << text;
  }
}

TEST(StrandCollidersTest, BadCollidersAndRootStepsAreRefused) {
  const std::vector<Points> strands = LyingStrands(2, 3, 4, 1);
  StrandOptions options;
  options.body_colliders = {Sphere(Vector3d::Zero(), 0.0)};
  try {
    StrandBatch batch(strands, options);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem().field, "body_colliders[0].radius") << e.what();
  }
  options.body_colliders = {Sphere(Vector3d::Zero(), 1.0)};
  StrandBatch batch(strands, options);
  Points roots(2, 3);
  roots << 0, 0, 1, 1, 0, 0;
  try {
    StepStrands(&batch, roots);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem().field, "roots");
  }
}

// A keyframed world collider (Collider::motion, times in seconds as given to StepStrands): a
// ball swept through hanging strands at every sub-step's time pushes them aside; no free link is
// ever inside it where its motion has it at the frame's time, lengths are kept; a body collider
// refuses a motion; a start inside where the motion starts it is refused.
TEST(StrandCollidersTest, AKeyframedWorldColliderSweepsThroughHangingStrands) {
  std::vector<Points> strands;
  for (int i = 0; i < 12; ++i) {
    Points p(11, 3);
    for (int j = 0; j <= 10; ++j) p.row(j) << 0.05 * i, 0.0, -0.1 * j;
    strands.push_back(p);
  }
  Collider ball = Sphere(Vector3d(0.3, 0.0, -0.6), 0.2);
  auto motion = std::make_shared<ColliderMotion>();
  motion->keyframes.resize(2);
  motion->keyframes[0].time = 0.0;
  motion->keyframes[0].pose.translation = Vector3d(0.0, -0.8, 0.0);
  motion->keyframes[1].time = 1.0;
  motion->keyframes[1].pose.translation = Vector3d(0.0, 0.8, 0.0);
  motion->interpolation = KeyframeInterpolation::kLinear;
  ball.motion = motion;
  for (int substeps : {1, 3}) {
    StrandOptions options;
    options.substeps = substeps;
    options.colliders = {ball};
    StrandBatch batch(strands, options);
    double least = 1e300, moved = 0.0, worst_length = 0.0;
    for (int f = 1; f <= 60; ++f) {
      const double time = f / 60.0;
      StepStrands(&batch, BodyPose(), time);
      const Collider at = ColliderAt(ball, time);
      for (int i = 0; i < batch.size(); ++i) {
        const Points p = batch.strand(i);
        for (Eigen::Index j = 1; j < p.rows(); ++j) {
          least = std::min(least, collider_test::SampledDistance(at, collider_test::At(p, j - 1),
                                                                 collider_test::At(p, j), 200));
          worst_length = std::max(worst_length, std::abs((p.row(j) - p.row(j - 1)).norm() - 0.1));
        }
        moved = std::max(moved, (p - strands[i]).rowwise().norm().maxCoeff());
      }
    }
    SCOPED_TRACE("substeps " + std::to_string(substeps));
    EXPECT_GE(least, -1e-12 * 0.1);
    EXPECT_LT(worst_length, 1e-13);
    EXPECT_GT(moved, 0.15);  // pushed aside (the ball crosses where the strands hang)
    EXPECT_GT(batch.contacts().contact_link_steps, 0);
  }
  // The same ball without its motion (where its own pose puts it, through the strands) is
  // refused at the start; with the motion it starts 0.8 away.
  StrandOptions still;
  still.colliders = {ball};
  still.colliders[0].motion = nullptr;
  EXPECT_THROW(StrandBatch(strands, still), InputError);
  // Where the motion starts it inside (time 0.5: on the strands), the start is refused.
  StrandOptions moving;
  moving.colliders = {ball};
  EXPECT_THROW(StrandBatch(strands, moving, BodyPose(), 0.5), InputError);
  // A body collider moves with the body: a motion is refused by name.
  StrandOptions body;
  body.body_colliders = {ball};
  try {
    StrandBatch batch(strands, body);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem().field, "body_colliders[0].motion") << e.what();
  }
}

}  // namespace
}  // namespace flexkin

namespace flexkin {
namespace {

// A small head groom: the scalp (a collider by default) and a neck capsule, turning.
std::string HeadGroom(const std::string& colliders, const std::string& extra = "") {
  return R"({
    "groom": {"scalp": {"shape": "sphere", "radius": 0.1}, "roots": 300,
              "region": {"axis": [0, 0, 1], "max_angle_deg": 110}, "links": 12,
              "link_length": 0.008, "direction": {"droop": 0.6}, "seed": 3},
    "motion": {"fps": 30, "keyframes": [
      {"time": 0, "rotation": {"axis": [0, 0, 1], "angle_deg": 0}},
      {"time": 0.5, "rotation": {"axis": [0, 0, 1], "angle_deg": 70}},
      {"time": 1.0, "rotation": {"axis": [1, 0, 0], "angle_deg": 25}}]},
    "colliders": )" +
         colliders + extra + "}";
}

TEST(GroomCollidersTest, TheScalpAndANeckKeepTheHairOut) {
  const GroomScenario s =
      ParseGroomText(HeadGroom(R"([{"shape": "capsule", "from": [0, 0, -0.09], "to": [0, 0, -0.3],
                     "radius": 0.05}])"));
  ASSERT_EQ(s.options.body_colliders.size(), 2u);
  EXPECT_EQ(s.options.body_colliders[0].shape, ColliderShape::kCapsule);
  EXPECT_EQ(s.options.body_colliders[1].shape, ColliderShape::kSphere);  // the scalp, last
  const StrandRunReport report = RunGroom(s, nullptr);
  EXPECT_GT(report.contact_link_steps, 0);
  EXPECT_GE(report.least_clearance, -1e-13);
  EXPECT_LT(report.max_length_error, 1e-13);
  // Without the scalp collider, nothing is in contact with it.
  const GroomScenario bare = ParseGroomText(HeadGroom("[]", R"(, "scalp_collider": false)"));
  EXPECT_TRUE(bare.options.body_colliders.empty());
}

TEST(GroomCollidersTest, AStartInsideNamesTheColliderTheRootAndThePoint) {
  try {
    ParseGroomText(HeadGroom(R"([{"shape": "sphere", "center": [0, 0, 0], "radius": 0.13}])"));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem().field, "/colliders/0") << e.what();
    const std::string text = e.what();
    EXPECT_NE(text.find("the strand of root "), std::string::npos) << text;
    EXPECT_NE(text.find("lies inside it by"), std::string::npos) << text;
  }
  try {
    ParseGroomText(HeadGroom("[]", R"(, "scalp_collider": 1)"));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem().field, "/scalp_collider") << e.what();
  }
  try {
    ParseGroomText(HeadGroom(R"([{"shape": "capsule", "from": [0, 0, 1], "to": [0, 0, 2],
                                  "radius": 0}])"));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem().field, "/colliders/0/radius") << e.what();
  }
}

// A groom's world collider may be keyframed (times in seconds, the body motion's clock); one that
// moves with the body may not.
TEST(GroomCollidersTest, AKeyframedWorldColliderIsReadAndRunAndABodyOneRefused) {
  const GroomScenario s = ParseGroomText(HeadGroom("[]", R"(, "world_colliders": [
      {"shape": "sphere", "center": [0.22, -0.6, 0.05], "radius": 0.06,
       "motion": {"interpolation": "linear", "keyframes": [
         {"time": 0, "translation": [0, 0, 0]}, {"time": 1, "translation": [0, 0.9, 0]}]}}])"));
  ASSERT_EQ(s.options.colliders.size(), 1u);
  ASSERT_NE(s.options.colliders[0].motion, nullptr);
  const StrandRunReport report = RunGroom(s, nullptr);
  EXPECT_GT(report.contact_link_steps, 0);
  EXPECT_GE(report.least_clearance, -1e-12);
  EXPECT_LT(report.max_length_error, 1e-13);
  try {
    ParseGroomText(HeadGroom(R"([{"shape": "sphere", "center": [0, 0, -0.5], "radius": 0.05,
        "motion": {"keyframes": [{"time": 0}]}}])"));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem().field, "/colliders/0/motion") << e.what();
  }
  try {
    ParseGroomText(HeadGroom("[]", R"(, "world_colliders": [{"shape": "sphere",
        "center": [0, 0, -0.5], "radius": 0.05,
        "motion": {"keyframes": [{"time": 1}, {"time": 0.5}]}}])"));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem().field, "/world_colliders/0/motion/keyframes/1/time") << e.what();
  }
}

}  // namespace
}  // namespace flexkin
