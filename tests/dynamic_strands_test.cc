// Dynamic strands (flexkin/strands.h `dynamics`, docs/dynamics.md "Strands"): each strand of the
// batch against SimulateChain of its own chain, on every engine and thread count; nothing inside
// a collider; refusals by name.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "flexkin/dynamics.h"
#include "flexkin/groom.h"
#include "flexkin/strand_file.h"
#include "flexkin/strands.h"
#include "strands/strand_engine.h"
#include "world/contact.h"

namespace flexkin {
namespace {

// A strand of n links of about `length` each, leaving `root` along `direction` and curling.
Points MakeStrand(int n, int dim, double length, const Eigen::Vector3d& root, double angle,
                  double curl, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> u(0.8, 1.2);
  Points p(n + 1, dim);
  Eigen::Vector3d at = root;
  for (int k = 0; k < dim; ++k) p(0, k) = at[k];
  for (int i = 1; i <= n; ++i) {
    const double a = angle + curl * i;
    const double l = length * u(*rng);
    Eigen::Vector3d d(std::cos(a), std::sin(a), dim == 3 ? 0.3 * std::sin(2.0 * a) : 0.0);
    d.normalize();
    at += l * d;
    for (int k = 0; k < dim; ++k) p(i, k) = at[k];
  }
  return p;
}

DynamicOptions Dynamics(int dim, Projection projection) {
  DynamicOptions o;
  o.projection = projection;
  o.gravity = Eigen::VectorXd::Zero(dim);
  o.gravity[1] = -9.81;
  o.damping = 0.5;
  o.wind = Eigen::VectorXd::Zero(dim);
  o.wind[0] = 0.7;
  o.frame_rate = 60.0;
  return o;
}

struct Case {
  std::vector<Points> strands;
  std::vector<Points> root_paths;  // per strand: one row per frame
};

Case MakeCase(int dim, int count, int frames) {
  std::mt19937_64 rng(7);
  Case c;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int s = 0; s < count; ++s) {
    const int n = 3 + s % 5 * 3;  // link counts 3 .. 15: several blocks, padding lanes
    const Eigen::Vector3d root(0.1 * s, 0.05 * u(rng), dim == 3 ? 0.05 * u(rng) : 0.0);
    c.strands.push_back(MakeStrand(n, dim, 0.05, root, -0.3 + 0.2 * u(rng), 0.1 * u(rng), &rng));
    Points path(frames, dim);
    for (int f = 0; f < frames; ++f) {
      const double t = (f + 1) / 60.0;
      for (int k = 0; k < dim; ++k) path(f, k) = root[k];
      path(f, 0) += 0.2 * std::sin(3.0 * t) + 0.05 * (s % 3) * t;
      path(f, 1) += 0.1 * std::sin(5.0 * t + s);
    }
    c.root_paths.push_back(path);
  }
  return c;
}

double MaxRelativeDifference(const Points& a, const Points& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

// Runs the batch with roots given as points; returns every strand's frames.
std::vector<std::vector<Points>> RunBatch(const Case& c, const StrandOptions& options,
                                          const char* engine, std::vector<double>* energy) {
  StrandBatch batch(c.strands, options);
  if (!internal::SetStrandEngine(&batch, engine)) return {};
  const int count = static_cast<int>(c.strands.size());
  const int dim = static_cast<int>(c.strands[0].cols());
  std::vector<std::vector<Points>> frames(count);
  for (int s = 0; s < count; ++s) frames[s].push_back(batch.strand(s));
  Points roots(count, dim);
  for (Eigen::Index f = 0; f < c.root_paths[0].rows(); ++f) {
    for (int s = 0; s < count; ++s) roots.row(s) = c.root_paths[s].row(f);
    StepStrands(&batch, roots);
    for (int s = 0; s < count; ++s) frames[s].push_back(batch.strand(s));
    if (energy != nullptr) energy->push_back(batch.dynamics().energy);
  }
  return frames;
}

class EveryProjection : public ::testing::TestWithParam<std::tuple<Projection, int, int>> {};

// Each strand of the batch is SimulateChain of its chain: bit for bit on the scalar engine, to
// 1e-12 on the SIMD ones (the vector exp's rounding); the energy is the strands' sum.
TEST_P(EveryProjection, EachStrandIsSimulateChainOfItsChain) {
  const auto [projection, dim, substeps] = GetParam();
  const Case c = MakeCase(dim, 21, 90);
  StrandOptions options;
  options.substeps = substeps;
  options.dynamics = Dynamics(dim, projection);
  options.dynamics->substeps = substeps;
  std::vector<std::vector<Points>> expected;
  std::vector<double> expected_energy(c.root_paths[0].rows(), 0.0);
  for (size_t s = 0; s < c.strands.size(); ++s) {
    const DynamicResult r =
        SimulateChain(MakeChain(c.strands[s]), c.root_paths[s], *options.dynamics);
    expected.push_back(r.frames);
    for (Eigen::Index f = 0; f + 1 < r.energy.size(); ++f) expected_energy[f] += r.energy[f + 1];
    EXPECT_LT(r.max_relative_length_error, 1e-13);
  }
  for (const char* engine : {"scalar", "avx2", "avx512"}) {
    std::vector<double> energy;
    const auto frames = RunBatch(c, options, engine, &energy);
    if (frames.empty()) continue;  // no such engine on this CPU
    // The SIMD engines' rounding (the vector exp's) differs from the scalar one's by an ulp or
    // so; the motion (a swinging chain) then amplifies that difference from frame to frame, so
    // they are held to 1e-12 over the first 10 frames and reported over the run.
    double worst = 0.0, worst_early = 0.0;
    for (size_t s = 0; s < frames.size(); ++s) {
      ASSERT_EQ(frames[s].size(), expected[s].size());
      for (size_t f = 0; f < frames[s].size(); ++f) {
        const double d = MaxRelativeDifference(frames[s][f], expected[s][f]);
        worst = std::max(worst, d);
        if (f <= 10) worst_early = std::max(worst_early, d);
      }
    }
    SCOPED_TRACE(engine);
    double energy_worst = 0.0;
    for (size_t f = 0; f < energy.size(); ++f) {
      energy_worst = std::max(energy_worst, std::fabs(energy[f] - expected_energy[f]));
    }
    if (std::string(engine) == "scalar") {
      EXPECT_EQ(worst, 0.0);
      EXPECT_LT(energy_worst, 1e-12 * (1.0 + std::fabs(expected_energy.back())));
    } else {
      EXPECT_LT(worst_early, 1e-12);
      std::printf("%s %s %dD %d sub-steps: largest difference %.2e over 10 frames, %.2e over %d\n",
                  engine, ProjectionName(projection), dim, substeps, worst_early, worst,
                  static_cast<int>(frames[0].size()) - 1);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Dynamics, EveryProjection,
    ::testing::Combine(::testing::Values(Projection::kOverall, Projection::kShake,
                                         Projection::kTractrix, Projection::kDftl),
                       ::testing::Values(2, 3), ::testing::Values(1, 3)));

// Given masses: each strand with its own masses (or the batch's one profile) is SimulateChain of
// its chain with those masses, bit for bit on the scalar engine and to 1e-12 over 10 frames on the
// SIMD ones; the overall projection weighs its motion by them, so they change the result.
TEST(DynamicStrands, GivenMassesAreEachStrandsSimulateChainMasses) {
  const Case c = MakeCase(3, 21, 40);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.2, 3.0);
  StrandOptions options;
  options.dynamics = Dynamics(3, Projection::kOverall);
  options.masses.resize(c.strands.size());
  for (size_t s = 0; s < c.strands.size(); ++s) {
    if (s % 4 == 3) continue;  // this one by length, as the others say
    options.masses[s] = Eigen::VectorXd(c.strands[s].rows() - 1);
    for (Eigen::Index j = 0; j < options.masses[s].size(); ++j) options.masses[s][j] = u(rng);
  }
  std::vector<double> expected_energy(c.root_paths[0].rows(), 0.0);
  std::vector<std::vector<Points>> expected, by_length;
  for (size_t s = 0; s < c.strands.size(); ++s) {
    DynamicOptions own = *options.dynamics;
    own.masses = options.masses[s];
    const DynamicResult r = SimulateChain(MakeChain(c.strands[s]), c.root_paths[s], own);
    expected.push_back(r.frames);
    for (Eigen::Index f = 0; f + 1 < r.energy.size(); ++f) expected_energy[f] += r.energy[f + 1];
    by_length.push_back(
        SimulateChain(MakeChain(c.strands[s]), c.root_paths[s], *options.dynamics).frames);
  }
  for (const char* engine : {"scalar", "avx2", "avx512"}) {
    std::vector<double> energy;
    const auto frames = RunBatch(c, options, engine, &energy);
    if (frames.empty()) continue;  // no such engine on this CPU
    SCOPED_TRACE(engine);
    const bool scalar = std::string(engine) == "scalar";
    double worst = 0.0, moved = 0.0;
    for (size_t s = 0; s < frames.size(); ++s) {
      for (size_t f = 0; f < frames[s].size() && f <= 10; ++f) {
        worst = std::max(worst, MaxRelativeDifference(frames[s][f], expected[s][f]));
        if (options.masses[s].size() == 0) {
          EXPECT_EQ(MaxRelativeDifference(expected[s][f], by_length[s][f]), 0.0);
        } else {
          moved = std::max(moved, MaxRelativeDifference(frames[s][f], by_length[s][f]));
        }
      }
    }
    if (scalar) {
      EXPECT_EQ(worst, 0.0);
    } else {
      EXPECT_LT(worst, 1e-12);
    }
    EXPECT_GT(moved, 1e-4);  // the masses matter
    for (size_t f = 0; f < energy.size(); ++f) {
      EXPECT_NEAR(energy[f], expected_energy[f], 1e-12 * (1.0 + std::fabs(expected_energy[f])));
    }
  }
  // One profile for every strand of a batch of one link count (dynamics.masses); only the
  // ratios matter: the profile times 7 gives the same motion to rounding.
  Case same;
  for (size_t s = 0; s < c.strands.size(); ++s) {
    if (c.strands[s].rows() != 7) continue;
    same.strands.push_back(c.strands[s]);
    same.root_paths.push_back(c.root_paths[s]);
  }
  ASSERT_GE(same.strands.size(), 3u);
  StrandOptions profile;
  profile.dynamics = Dynamics(3, Projection::kOverall);
  profile.dynamics->masses = Eigen::VectorXd::LinSpaced(6, 3.0, 0.5);  // heavy at the root
  StrandOptions times7 = profile;
  times7.dynamics->masses *= 7.0;
  const auto a = RunBatch(same, profile, "scalar", nullptr);
  const auto b = RunBatch(same, times7, "scalar", nullptr);
  for (size_t s = 0; s < same.strands.size(); ++s) {
    const DynamicResult r =
        SimulateChain(MakeChain(same.strands[s]), same.root_paths[s], *profile.dynamics);
    for (size_t f = 0; f < a[s].size(); ++f) {
      EXPECT_EQ(a[s][f], r.frames[f]);
      EXPECT_LT(MaxRelativeDifference(b[s][f], a[s][f]), 1e-12);
    }
  }
}

// Threads change the speed only: the points and the energy bit for bit.
TEST(DynamicStrands, ThreadsChangeNothing) {
  const Case c = MakeCase(3, 40, 30);
  for (Projection projection : {Projection::kOverall, Projection::kTractrix}) {
    StrandOptions one;
    one.dynamics = Dynamics(3, projection);
    StrandOptions two = one;
    two.threads = 2;
    std::vector<double> e1, e2;
    const auto a = RunBatch(c, one, "scalar", &e1);
    const auto b = RunBatch(c, two, "scalar", &e2);
    for (size_t s = 0; s < a.size(); ++s) {
      for (size_t f = 0; f < a[s].size(); ++f) EXPECT_EQ(a[s][f], b[s][f]);
    }
    EXPECT_EQ(e1, e2);
  }
}

// A batch whose body turns: the pinned points (two per strand) stay on the body at every frame,
// and the free points keep their lengths to rounding.
TEST(DynamicStrands, PinnedPointsFollowTheBody) {
  std::mt19937_64 rng(3);
  std::vector<Points> strands;
  for (int s = 0; s < 20; ++s) {
    strands.push_back(
        MakeStrand(12, 3, 0.04, Eigen::Vector3d(0.0, 0.0, 0.1 * s), 0.2 * s, 0.05, &rng));
  }
  StrandOptions options;
  options.pinned = 2;
  options.substeps = 2;
  options.dynamics = Dynamics(3, Projection::kOverall);
  options.dynamics->substeps = 2;
  StrandBatch batch(strands, options);
  for (int f = 1; f <= 60; ++f) {
    const double angle = 0.03 * f;
    const BodyPose pose = BodyPose::FromQuaternion(std::cos(angle / 2), 0.0, 0.0,
                                                   std::sin(angle / 2), Eigen::Vector3d(0, 0, 0));
    StepStrands(&batch, pose, f / 60.0);
    for (int s = 0; s < 20; ++s) {
      const Points p = batch.strand(s);
      for (int j = 0; j < 2; ++j) {
        const Eigen::Vector3d expected = pose.rotation * strands[s].row(j).transpose();
        EXPECT_LT((p.row(j).transpose() - expected).norm(), 1e-14);
      }
      const Eigen::VectorXd rest = MakeChain(strands[s]).lengths;
      for (int i = 1; i < p.rows(); ++i) {
        EXPECT_NEAR((p.row(i) - p.row(i - 1)).norm(), rest[i - 1], 1e-14 * rest[i - 1]);
      }
    }
  }
  EXPECT_EQ(batch.dynamics().failures, 0);
}

// `count` strands of `links` links of 0.06 grown straight out of the upper half of a unit sphere.
std::vector<Points> GrownStraightOut(int count, int links, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Points> strands;
  for (int s = 0; s < count; ++s) {
    Eigen::Vector3d normal(u(rng), u(rng), 0.2 + std::fabs(u(rng)));
    normal.normalize();
    Points p(links + 1, 3);
    for (int i = 0; i <= links; ++i) p.row(i) = ((1.0 + 0.06 * i) * normal).transpose();
    strands.push_back(p);
  }
  return strands;
}

// The scalp under those strands, a hair inside their roots.
Collider Scalp() {
  Collider scalp;
  scalp.shape = ColliderShape::kSphere;
  scalp.radius = 1.0 - 1e-9;
  return scalp;
}

// Hair that falls onto a head: nothing inside the scalp (points and links, sampled) in any frame
// beyond 1e-12 of a link, for every projection; the contacts are counted.
TEST(DynamicStrands, NothingInsideTheScalp) {
  const std::vector<Points> strands = GrownStraightOut(64, 16, 11);
  const Collider scalp = Scalp();
  for (Projection projection :
       {Projection::kOverall, Projection::kShake, Projection::kTractrix, Projection::kDftl}) {
    SCOPED_TRACE(ProjectionName(projection));
    StrandOptions options;
    options.body_colliders = {scalp};
    options.dynamics = Dynamics(3, projection);
    options.dynamics->gravity = Eigen::Vector3d(0.0, 0.0, -9.81);
    options.dynamics->damping = 1.0;
    StrandBatch batch(strands, options);
    double least = std::numeric_limits<double>::infinity();
    for (int f = 1; f <= 120; ++f) {
      const double angle = 0.5 * std::sin(f / 20.0);
      const BodyPose pose = BodyPose::FromQuaternion(std::cos(angle / 2), std::sin(angle / 2), 0.0,
                                                     0.0, Eigen::Vector3d(0.0, 0.0, 0.0));
      StepStrands(&batch, pose, f / 60.0);
      for (int s = 0; s < batch.size(); ++s) {
        const Points p = batch.strand(s);
        for (int i = 1; i < p.rows(); ++i) {
          const Eigen::Vector3d a = p.row(i - 1).transpose(), b = p.row(i).transpose();
          const double length = (b - a).norm();
          EXPECT_NEAR(length, 0.06, 1e-14);
          for (int t = 0; t <= 16; ++t) {
            const double d = (a + (b - a) * (t / 16.0)).norm() - scalp.radius;
            least = std::min(least, d / length);
          }
        }
      }
    }
    EXPECT_GT(least, -1e-12);
    EXPECT_GT(batch.contacts().contact_link_steps, 0);
    if (projection == Projection::kOverall || projection == Projection::kShake) {
      EXPECT_GT(batch.dynamics().contact_substeps, 0);
    }
    // The hair fell: its tips are lower on average than where they were grown.
    double tips_start = 0.0, tips_end = 0.0;
    for (int s = 0; s < batch.size(); ++s) {
      tips_start += strands[s](16, 2);
      tips_end += batch.strand(s)(16, 2);
    }
    EXPECT_LT(tips_end, tips_start - 0.5 * batch.size());
    EXPECT_TRUE(std::isfinite(batch.dynamics().energy));
    std::printf("%s: least clearance %.2e of a link, %lld contact link steps\n",
                ProjectionName(projection), least,
                static_cast<long long>(batch.contacts().contact_link_steps));
  }
}

// A strand's motion is its own, whichever strands share its block (docs/strands.md, "Layout"):
// hair falling onto a scalp, every third strand stepped as a batch of its own moves as in the
// whole batch, with every projection (the overall one and SHAKE solve a block's lanes together,
// each lane to its own end): bit for bit on the scalar engine; on the SIMD engines a register's
// branches are taken for all its lanes, and their rounding-level differences grow through 40
// frames of falling onto the scalp to about 2e-9 (measured), held here below 1e-7.
TEST(DynamicStrands, AStrandMovesAsInAnyOtherBlock) {
  const std::vector<Points> strands = GrownStraightOut(72, 12, 5);
  std::vector<Points> thirds;
  for (size_t s = 0; s < strands.size(); s += 3) thirds.push_back(strands[s]);
  const Collider scalp = Scalp();
  for (Projection projection :
       {Projection::kOverall, Projection::kShake, Projection::kTractrix, Projection::kDftl}) {
    for (const char* engine : {"scalar", "avx2", "avx512"}) {
      SCOPED_TRACE(std::string(ProjectionName(projection)) + ", " + engine);
      StrandOptions options;
      options.body_colliders = {scalp};
      options.dynamics = Dynamics(3, projection);
      options.dynamics->gravity = Eigen::Vector3d(0.0, 0.0, -9.81);
      options.dynamics->damping = 1.0;
      options.threads = 2;
      StrandBatch all(strands, options), some(thirds, options);
      if (!internal::SetStrandEngine(&all, engine)) continue;
      ASSERT_TRUE(internal::SetStrandEngine(&some, engine));
      for (int f = 1; f <= 40; ++f) {
        const double angle = 0.5 * std::sin(f / 20.0);
        const BodyPose pose = BodyPose::FromQuaternion(std::cos(angle / 2), std::sin(angle / 2),
                                                       0.0, 0.0, Eigen::Vector3d(0.0, 0.0, 0.0));
        StepStrands(&all, pose, f / 60.0);
        StepStrands(&some, pose, f / 60.0);
      }
      EXPECT_GT(some.contacts().contact_link_steps, 0);
      double worst = 0.0;
      for (int s = 0; s < some.size(); ++s) {
        if (std::string(engine) == "scalar") {
          ASSERT_TRUE(some.strand(s) == all.strand(3 * s)) << "strand " << 3 * s;
        }
        worst = std::max(worst, (some.strand(s) - all.strand(3 * s)).cwiseAbs().maxCoeff());
      }
      EXPECT_LT(worst, 1e-7);
      std::printf("%s, %s: largest difference %.1e\n", ProjectionName(projection), engine, worst);
    }
  }
}

TEST(DynamicStrands, RefusesByName) {
  const std::vector<Points> strands = {MakeCase(3, 1, 1).strands[0]};
  const auto field_of = [&](const StrandOptions& options) {
    try {
      StrandBatch batch(strands, options);
    } catch (const InputError& e) {
      return e.field();
    }
    return std::string("none");
  };
  StrandOptions options;
  options.dynamics = Dynamics(3, Projection::kShake);
  EXPECT_EQ(field_of(options), "none");
  options.dynamics = Dynamics(3, Projection::kOverall);
  options.dynamics->masses = Eigen::VectorXd::Ones(4);  // the strand has 3 links
  EXPECT_EQ(field_of(options), "dynamics.masses");
  options.dynamics = Dynamics(3, Projection::kOverall);
  options.masses = {Eigen::VectorXd::Ones(2)};
  EXPECT_EQ(field_of(options), "masses[0]");
  options.masses = {Eigen::Vector3d(1.0, -1.0, 1.0)};
  EXPECT_EQ(field_of(options), "masses[0][1]");
  options.masses = {Eigen::Vector3d(1.0, 1.0, std::nan(""))};
  EXPECT_EQ(field_of(options), "masses[0][2]");
  options.masses = {Eigen::Vector3d(1.0, 2.0, 3.0), Eigen::Vector3d(1.0, 2.0, 3.0)};
  EXPECT_EQ(field_of(options), "masses");  // two entries for one strand
  options.masses = {Eigen::Vector3d(1.0, 2.0, 3.0)};
  EXPECT_EQ(field_of(options), "none");
  options.dynamics.reset();
  EXPECT_EQ(field_of(options), "masses");  // masses without dynamics
  options.masses.clear();
  options.dynamics = Dynamics(3, Projection::kOverall);
  options.dynamics->gravity = Eigen::VectorXd::Zero(2);
  EXPECT_EQ(field_of(options), "dynamics.gravity");
  options.dynamics = Dynamics(3, Projection::kOverall);
  options.dynamics->substeps = 4;
  EXPECT_EQ(field_of(options), "dynamics.substeps");
  options.dynamics = Dynamics(3, Projection::kOverall);
  options.dynamics->damping = -1.0;
  EXPECT_EQ(field_of(options), "dynamics.damping");
  options.dynamics = Dynamics(3, Projection::kOverall);
  EXPECT_EQ(field_of(options), "none");
}

}  // namespace
}  // namespace flexkin

namespace flexkin {
namespace {

// A small dynamic groom: strands given point by point, a body that turns.
std::string GroomText(const std::string& dynamics, const std::string& extra = "") {
  return R"({"strands": [{"points": [[0, 0, 1], [0, 0.05, 1.05], [0, 0.1, 1.1], [0, 0.15, 1.15]]},
                         {"points": [[1, 0, 0], [1.05, 0, 0.05], [1.1, 0, 0.1]]}],
             "motion": {"fps": 30, "keyframes": [{"time": 0}, {"time": 1, "rotation":
                        {"axis": [0, 0, 1], "angle_deg": 40}}]},
             "colliders": [{"shape": "sphere", "center": [0, 0, 0], "radius": 0.9}],
             "substeps": 2, "dynamics": )" +
         dynamics + extra + "}";
}

std::vector<std::string> Fields(const Problems& problems) {
  std::vector<std::string> fields;
  for (const Problem& p : problems) fields.push_back(p.field);
  return fields;
}

TEST(DynamicGroom, ReadsTheDynamicsAndTakesFpsAndSubsteps) {
  const GroomScenario s = ParseGroomText(GroomText(
      R"({"projection": "dftl", "gravity": [0, 0, -9.81], "damping": 0.5, "wind": [1, 0, 0],
          "mass": "uniform", "dftl_damping": 0.8})"));
  ASSERT_TRUE(s.options.dynamics.has_value());
  const DynamicOptions& d = *s.options.dynamics;
  EXPECT_EQ(d.projection, Projection::kDftl);
  EXPECT_EQ(d.gravity, Eigen::Vector3d(0, 0, -9.81));
  EXPECT_EQ(d.damping, 0.5);
  EXPECT_EQ(d.wind, Eigen::Vector3d(1, 0, 0));
  EXPECT_FALSE(d.mass_by_length);
  EXPECT_EQ(d.dftl_damping, 0.8);
  EXPECT_EQ(d.frame_rate, 30.0);  // the motion's fps
  EXPECT_EQ(d.substeps, 2);       // the groom's substeps
  EXPECT_NE(GroomSummary(s).find("dynamic, projection dftl"), std::string::npos);
}

TEST(DynamicGroom, NamesEveryProblemByPointer) {
  const auto fields = [](const std::string& dynamics, const std::string& extra = "") {
    return Fields(ValidateGroomText(GroomText(dynamics, extra)));
  };
  using V = std::vector<std::string>;
  EXPECT_EQ(fields(R"({"projection": "overall"})"), V{"/dynamics/gravity"});
  EXPECT_EQ(fields(R"({"gravity": [0, -9.81]})"), V{"/dynamics/gravity"});
  EXPECT_EQ(fields(R"({"gravity": [0, 0, -9.81], "projection": "shake"})"), V{});
  EXPECT_EQ(fields(R"({"gravity": [0, 0, -9.81], "projection": "overal"})"),
            V{"/dynamics/projection"});
  EXPECT_EQ(fields(R"({"gravity": [0, 0, -9.81], "frame_rate": 60})"), V{"/dynamics/frame_rate"});
  EXPECT_EQ(fields(R"({"gravity": [0, 0, -9.81], "substeps": 4})"), V{"/dynamics/substeps"});
  // The given strands have 3 and 2 links: one profile of 3 masses does not fit the second.
  EXPECT_EQ(fields(R"({"gravity": [0, 0, -9.81], "mass": [1, 2, 3]})"), V{"/dynamics/mass"});
  EXPECT_EQ(fields(R"({"gravity": [0, 0, -9.81], "mass": [1, 2, -3]})"), V{"/dynamics/mass/2"});
  EXPECT_EQ(fields(R"({"gravity": [0, 0, -9.81], "mass": "heavy"})"), V{"/dynamics/mass"});
  EXPECT_EQ(fields(R"({"gravity": [0, 0, -9.81], "damping": -1})"), V{"/dynamics/damping"});
  EXPECT_EQ(fields(R"({"gravity": [0, 0, -9.81], "dftl_damping": 2})"),
            V{"/dynamics/dftl_damping"});
  EXPECT_EQ(fields(R"({"gravity": [0, 0, -9.81], "wind_keys": [{"time": 1, "velocity": [1, 0, 0]},
                                                               {"time": 0.5, "velocity": [0, 0, 0]}]})"),
            V{"/dynamics/wind_keys/1/time"});
  EXPECT_EQ(fields(R"({"gravity": [0, 0, -9.81], "gust": 1})"), V{"/dynamics/gust"});
  EXPECT_EQ(fields(R"({"gravity": [0, 0, -9.81]})", R"(, "method": "ftl")"), V{"/method"});
  EXPECT_EQ(fields(R"([0, 0, -9.81])"), V{"/dynamics"});
}

// Given masses in a groom file: a strand's own ("/strands/i/masses") and the one profile
// ("/dynamics/mass") for the strands without their own; each problem by pointer.
TEST(DynamicGroom, ReadsGivenMasses) {
  const auto text = [](const std::string& masses0, const std::string& masses1,
                       const std::string& mass) {
    return R"({"strands": [{"points": [[0, 0, 1], [0, 0.05, 1.05], [0, 0.1, 1.1]])" + masses0 +
           R"(}, {"points": [[1, 0, 0], [1.05, 0, 0.05], [1.1, 0, 0.1]])" + masses1 + R"(}],
             "motion": {"fps": 30, "keyframes": [{"time": 0}, {"time": 1}]},
             "dynamics": {"gravity": [0, 0, -9.81])" +
           mass + "}}";
  };
  const GroomScenario s = ParseGroomText(text(R"(, "masses": [1, 2])", "", R"(, "mass": [3, 1])"));
  ASSERT_EQ(s.options.masses.size(), 2u);
  EXPECT_EQ(s.options.masses[0], Eigen::Vector2d(1, 2));
  EXPECT_EQ(s.options.masses[1].size(), 0);  // the profile's
  EXPECT_EQ(s.options.dynamics->masses, Eigen::Vector2d(3, 1));
  StrandBatch batch(s.strands, s.options);  // the batch takes them
  // The strand file says so: the profile, and that strands have their own.
  const std::string path = ::testing::TempDir() + "groom_masses.npz";
  RunGroomToFile(s, path);
  {
    StrandFileReader file(path);
    ASSERT_TRUE(file.header().dynamics.has_value());
    EXPECT_EQ(file.header().dynamics->masses, Eigen::Vector2d(3, 1));
    EXPECT_TRUE(file.header().own_masses);
  }
  std::remove(path.c_str());
  using V = std::vector<std::string>;
  EXPECT_EQ(Fields(ValidateGroomText(text(R"(, "masses": [1, 2, 3])", "", ""))),
            V{"/strands/0/masses"});
  EXPECT_EQ(Fields(ValidateGroomText(text(R"(, "masses": [1, 0])", "", ""))),
            V{"/strands/0/masses/1"});
  EXPECT_EQ(Fields(ValidateGroomText(text("", "", R"(, "mass": [1, 2, 3])"))), V{"/dynamics/mass"});
  const std::string no_dynamics = R"({"strands": [{"points": [[0, 0, 1], [0, 0.05, 1.05]],
      "masses": [1]}], "motion": {"fps": 30, "keyframes": [{"time": 0}]}})";
  EXPECT_EQ(Fields(ValidateGroomText(no_dynamics)), V{"/strands/0/masses"});
  // A grown groom: the profile has one mass per grown link.
  const std::string grown = R"({"groom": {"scalp": {"shape": "sphere", "radius": 1}, "roots": 4,
      "links": 3, "link_length": 0.05}, "motion": {"fps": 30, "keyframes": [{"time": 0}]},
      "dynamics": {"gravity": [0, 0, -9.81], "mass": )";
  EXPECT_TRUE(ValidateGroomText(grown + "[1, 1, 2]}}").empty());
  EXPECT_EQ(Fields(ValidateGroomText(grown + "[1, 2]}}")), V{"/dynamics/mass"});
}

// The groom run: frame by frame the batch stepped directly, the energy in the report and back
// from the file.
TEST(DynamicGroom, RunIsTheBatchSteppedFrameByFrame) {
  const GroomScenario s = ParseGroomText(GroomText(R"({"projection": "overall",
      "gravity": [0, 0, -9.81], "damping": 0.5, "wind_keys": [{"time": 0, "velocity": [0, 0, 0]},
      {"time": 0.5, "velocity": [2, 0, 0]}]})"));
  const std::string path = ::testing::TempDir() + "dynamic_groom.npz";
  const StrandRunReport report = RunGroomToFile(s, path);
  StrandFileReader file(path);
  ASSERT_TRUE(file.header().dynamics.has_value());
  EXPECT_EQ(file.header().dynamics->projection, Projection::kOverall);
  EXPECT_EQ(file.report().energy.size(), report.energy.size());
  EXPECT_EQ(static_cast<int64_t>(report.energy.size()), file.header().num_frames);
  EXPECT_TRUE(std::isnan(file.report().energy[0]));
  for (size_t f = 1; f < report.energy.size(); ++f) {
    EXPECT_EQ(file.report().energy[f], report.energy[f]);
  }
  // The same strands stepped by hand: the batch at the first pose, one StepStrands a frame.
  StrandBatch batch(s.strands, s.options, s.motion.PoseAt(0), s.motion.TimeOf(0));
  for (int64_t f = 1; f < s.motion.num_frames(); ++f) {
    StepStrands(&batch, s.motion.PoseAt(f), s.motion.TimeOf(f));
  }
  StrandFrame frame, last;
  while (file.Next(&frame)) last = frame;
  for (int i = 0; i < batch.size(); ++i) {
    const Points p = batch.strand(i);
    for (Eigen::Index j = 0; j < p.rows(); ++j) {
      const Eigen::Index row = file.header().offsets[i] + j;
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(last.points(row, k), p(j, k), 1e-6);  // float32
    }
  }
  EXPECT_EQ(report.energy.back(), batch.dynamics().energy);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace flexkin

namespace flexkin {
namespace {

double CapsuleDistance(const Eigen::Vector3d& x, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                       double radius) {
  const double t = std::clamp((x - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
  return (x - (a + t * (b - a))).norm() - radius;
}

// Hair falling onto a head with a neck (the crevice where the scalp meets the neck collects it):
// every projection keeps every point and link outside both, measured here by sampling (the
// overall one through its contact fallback, which once stopped "wedged" on links lying along the
// neck: tests/contact_test.cc, ALinkAlongACapsuleIsNoClearerThanItsEnds).
TEST(DynamicStrands, HairFallsIntoTheCreviceOfScalpAndNeckAndStaysOutside) {
  GrowSpec spec;
  spec.scalp.shape = "sphere";
  spec.scalp.radii = Eigen::Vector3d::Constant(0.1);
  spec.roots = 200;
  spec.region_axis = Eigen::Vector3d::UnitZ();
  spec.max_angle_deg = 110.0;
  spec.links = 24;
  spec.link_length = 0.006;
  spec.droop = 0.2;
  const std::vector<Points> strands = GrowStrands(spec);
  Collider scalp, neck;
  scalp.shape = ColliderShape::kSphere;
  scalp.radius = 0.1;
  neck.shape = ColliderShape::kCapsule;
  neck.pose.translation() = Eigen::Vector3d(0.0, 0.0, -0.195);
  neck.half_length = 0.105;
  neck.radius = 0.05;
  const Eigen::Vector3d neck_a(0, 0, -0.09), neck_b(0, 0, -0.3);
  for (Projection projection : {Projection::kDftl, Projection::kTractrix, Projection::kOverall}) {
    SCOPED_TRACE(ProjectionName(projection));
    StrandOptions options;
    options.pinned = 2;
    options.substeps = 2;
    options.body_colliders = {scalp, neck};
    options.dynamics = Dynamics(3, projection);
    options.dynamics->gravity = Eigen::Vector3d(0.0, 0.0, -9.81);
    options.dynamics->wind.resize(0);
    options.dynamics->damping = 2.0;
    options.dynamics->substeps = 2;
    options.dynamics->frame_rate = 30.0;
    StrandBatch batch(strands, options);
    double least = std::numeric_limits<double>::infinity();
    for (int f = 1; f <= 60; ++f) {
      const double yaw = 0.8 * std::sin(f / 10.0);
      const BodyPose pose = BodyPose::FromQuaternion(std::cos(yaw / 2), 0.0, 0.0, std::sin(yaw / 2),
                                                     Eigen::Vector3d::Zero());
      StepStrands(&batch, pose, f / 30.0);
      if (f % 5 != 0) continue;
      for (int s = 0; s < batch.size(); ++s) {
        const Points p = batch.strand(s);
        for (int i = 2; i < p.rows(); ++i) {
          const Eigen::Vector3d a = p.row(i - 1).transpose(), b = p.row(i).transpose();
          for (int t = 0; t <= 8; ++t) {
            // In body coordinates (the colliders move with the head).
            const Eigen::Vector3d x = pose.rotation.transpose() * (a + (b - a) * (t / 8.0));
            const double d = std::min(x.norm() - 0.1, CapsuleDistance(x, neck_a, neck_b, 0.05));
            least = std::min(least, d / (b - a).norm());
          }
        }
      }
    }
    EXPECT_GT(least, -1e-12);
    EXPECT_GT(batch.contacts().contact_link_steps, 0);
  }
}

}  // namespace
}  // namespace flexkin
