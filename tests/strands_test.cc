// The strand engine (flexkin/strands.h, docs/strands.md): every strand equal to its single-chain
// run, the same result whatever the threads, the SIMD engines within 1e-14 of the scalar one,
// lengths kept, pinned points rigid with the body, mixed and degenerate batches, input errors.
#include "flexkin/strands.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "chain/substep.h"
#include "sequential/sweep.h"
#include "strands/strand_engine.h"

namespace flexkin {
namespace {

// Hair-like strands: a root on the unit sphere (circle in 2D), links of random lengths growing
// outward with random bends. Link counts cycle through `links`.
std::vector<Points> MakeStrands(int count, int dim, const std::vector<int>& links, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(0.02, 0.08);
  std::vector<Points> strands;
  for (int s = 0; s < count; ++s) {
    const int n = links[s % links.size()];
    Points p(n + 1, dim);
    Eigen::VectorXd dir(dim);
    for (int k = 0; k < dim; ++k) dir[k] = normal(rng);
    dir.normalize();
    p.row(0) = dir.transpose();
    for (int i = 1; i <= n; ++i) {
      Eigen::VectorXd bend(dim);
      for (int k = 0; k < dim; ++k) bend[k] = 0.3 * normal(rng);
      dir = (dir + bend).normalized();
      p.row(i) = p.row(i - 1) + uniform(rng) * dir.transpose();
    }
    strands.push_back(p);
  }
  return strands;
}

// A wobbling body: rotation about a tilted axis and a bounded translation, smooth in `frame`.
BodyPose PoseAt(int frame, int dim) {
  const double t = 0.05 * frame;
  if (dim == 2)
    return BodyPose::Planar(0.7 * std::sin(t), 0.3 * std::sin(1.3 * t), 0.2 * std::cos(t));
  const double angle = 0.8 * std::sin(t);
  Eigen::Vector3d axis(std::cos(0.3 * t), 0.5, std::sin(0.7 * t));
  axis.normalize();
  return BodyPose::FromQuaternion(
      std::cos(angle / 2), std::sin(angle / 2) * axis[0], std::sin(angle / 2) * axis[1],
      std::sin(angle / 2) * axis[2],
      Eigen::Vector3d(0.4 * std::sin(t), 0.3 * std::sin(0.9 * t), -0.2 * std::cos(0.6 * t)));
}

// The pinned points as the engine computes them: p = R q + t, summed in this order.
Eigen::VectorXd Apply(const BodyPose& pose, const Eigen::VectorXd& q) {
  const int dim = static_cast<int>(q.size());
  Eigen::VectorXd p(dim);
  for (int r = 0; r < dim; ++r) {
    double s = pose.rotation(r, 0) * q[0];
    for (int c = 1; c < dim; ++c) s += pose.rotation(r, c) * q[c];
    p[r] = s + pose.translation[r];
  }
  return p;
}

void ExpectBitEqual(const Points& a, const Points& b, const std::string& what) {
  ASSERT_EQ(a.rows(), b.rows()) << what;
  ASSERT_EQ(a.cols(), b.cols()) << what;
  for (Eigen::Index i = 0; i < a.rows(); ++i) {
    for (Eigen::Index k = 0; k < a.cols(); ++k) {
      ASSERT_EQ(a(i, k), b(i, k)) << what << " point " << i << " coordinate " << k;
    }
  }
}

double MaxRelativeDifference(const Points& a, const Points& b) {
  return ((a - b).cwiseAbs().array() / (1.0 + a.cwiseAbs().array())).maxCoeff();
}

std::vector<std::string> Engines() {
  std::vector<std::string> names = {"scalar"};
  for (const auto& e : internal::AvailableWavefronts()) names.push_back(e.name);
  return names;
}

// The single-chain path for one strand and one frame: the first k points from the body, the
// chain from point k-1 on moved by MoveLeader to the new point k-1.
void SingleChainFrame(Method method, int substeps, int pinned, const BodyPose& pose,
                      const Points& body, Points* p) {
  const int n = static_cast<int>(p->rows()) - 1;
  const int k = std::min(pinned, n + 1);
  for (int j = 0; j + 1 < k; ++j) p->row(j) = Apply(pose, body.row(j).transpose()).transpose();
  const Eigen::VectorXd target = Apply(pose, body.row(k - 1).transpose());
  if (k == n + 1) {
    p->row(n) = target.transpose();
    return;
  }
  Chain tail = MakeChain(p->bottomRows(n + 2 - k));
  // The lengths of the whole strand, as the batch measured them at the start.
  tail.lengths = MakeChain(body).lengths.tail(n + 1 - k);
  Stepper stepper = MakeStepper(method, tail);
  MoveLeader(stepper, target, substeps, &tail.points);
  p->bottomRows(n + 2 - k) = tail.points;
}

struct Case {
  Method method;
  int dim;
  int substeps;
  int pinned;
};

class StrandsSingleChain : public ::testing::TestWithParam<Case> {};

// Each strand equals its own single-chain run: bit for bit on the scalar engine, to 1e-14 on the
// SIMD ones. Strands of many link counts (1 to 33) in one batch.
TEST_P(StrandsSingleChain, EachStrandEqualsItsChain) {
  const Case c = GetParam();
  const std::vector<Points> strands = MakeStrands(70, c.dim, {1, 2, 5, 8, 9, 17, 33}, 7);
  for (const std::string& engine : Engines()) {
    StrandOptions options;
    options.method = c.method;
    options.substeps = c.substeps;
    options.pinned = c.pinned;
    options.threads = 2;
    StrandBatch batch(strands, options);
    ASSERT_TRUE(internal::SetStrandEngine(&batch, engine.c_str()));
    // The rest pose is the identity: the body coordinates are the points themselves (scaled by
    // 1 and shifted by 0, exactly).
    std::vector<Points> single = strands;
    for (int frame = 1; frame <= 20; ++frame) {
      const BodyPose pose = PoseAt(frame, c.dim);
      StepStrands(&batch, pose);
      for (size_t s = 0; s < strands.size(); ++s) {
        // Lengths of the original strand, as the batch keeps them.
        SingleChainFrame(c.method, c.substeps, c.pinned, pose, strands[s], &single[s]);
      }
    }
    for (size_t s = 0; s < strands.size(); ++s) {
      const Points got = batch.strand(static_cast<int>(s));
      if (engine == "scalar") {
        ExpectBitEqual(got, single[s], engine + " strand " + std::to_string(s));
      } else {
        EXPECT_LE(MaxRelativeDifference(got, single[s]), 1e-14) << engine << " strand " << s;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, StrandsSingleChain,
    ::testing::Values(Case{Method::kTractrix, 3, 1, 1}, Case{Method::kTractrix, 3, 3, 1},
                      Case{Method::kTractrix, 2, 1, 1}, Case{Method::kFollowTheLeader, 3, 1, 1},
                      Case{Method::kFollowTheLeader, 2, 3, 1}, Case{Method::kTractrix, 3, 2, 3},
                      Case{Method::kFollowTheLeader, 3, 1, 2}, Case{Method::kTractrix, 2, 1, 4}));

// Roots given as points: with k = 1 exactly MoveLeader(method, root, substeps) on each strand.
TEST(Strands, RootPointsEqualMoveLeader) {
  const std::vector<Points> strands = MakeStrands(40, 3, {4, 12, 32}, 11);
  for (Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
    StrandOptions options;
    options.method = method;
    options.substeps = 2;
    StrandBatch batch(strands, options);
    ASSERT_TRUE(internal::SetStrandEngine(&batch, "scalar"));
    std::vector<Chain> chains;
    for (const Points& p : strands) chains.push_back(MakeChain(p));
    Points roots(strands.size(), 3);
    for (int frame = 1; frame <= 30; ++frame) {
      for (size_t s = 0; s < strands.size(); ++s) {
        roots.row(s) = strands[s].row(0) +
                       Eigen::RowVector3d(0.1 * std::sin(0.2 * frame + s), 0.05 * frame, 0.0);
        MoveLeader(method, roots.row(s).transpose(), 2, &chains[s]);
      }
      StepStrands(&batch, roots);
    }
    for (size_t s = 0; s < strands.size(); ++s) {
      ExpectBitEqual(batch.strand(static_cast<int>(s)), chains[s].points,
                     std::string(MethodName(method)) + " strand " + std::to_string(s));
    }
  }
}

// With k > 1 and root points, the other pinned points translate with the root.
TEST(Strands, RootPointsTranslatePinnedPoints) {
  const std::vector<Points> strands = MakeStrands(5, 3, {6}, 3);
  StrandOptions options;
  options.pinned = 3;
  StrandBatch batch(strands, options);
  Points roots(5, 3);
  for (int s = 0; s < 5; ++s) roots.row(s) = strands[s].row(0) + Eigen::RowVector3d(0.5, 0, 0);
  StepStrands(&batch, roots);
  for (int s = 0; s < 5; ++s) {
    const Points p = batch.strand(s);
    EXPECT_EQ(p.row(0), roots.row(s));
    for (int j = 1; j < 3; ++j) {
      EXPECT_NEAR((p.row(j) - strands[s].row(j) - Eigen::RowVector3d(0.5, 0, 0)).norm(), 0.0,
                  1e-15);
    }
  }
}

// The strands after 30 frames of the wobbling body (3D).
std::vector<Points> ThirtyFrames(StrandBatch* batch) {
  for (int frame = 1; frame <= 30; ++frame) StepStrands(batch, PoseAt(frame, 3));
  std::vector<Points> out;
  for (int s = 0; s < batch->size(); ++s) out.push_back(batch->strand(s));
  return out;
}

// Bit for bit the same whatever the number of threads.
TEST(Strands, DeterministicAcrossThreads) {
  const std::vector<Points> strands = MakeStrands(300, 3, {3, 16, 31, 32}, 5);
  std::vector<std::vector<Points>> results;
  for (int threads : {1, 2, 3, 7}) {
    StrandOptions options;
    options.threads = threads;
    options.pinned = 2;
    StrandBatch batch(strands, options);
    results.push_back(ThirtyFrames(&batch));
  }
  for (size_t r = 1; r < results.size(); ++r) {
    for (size_t s = 0; s < strands.size(); ++s) {
      ExpectBitEqual(results[r][s], results[0][s], "threads run " + std::to_string(r));
    }
  }
}

// The SIMD widths agree with each other and with the scalar engine to 1e-14.
TEST(Strands, SimdWidthsAgree) {
  const std::vector<Points> strands = MakeStrands(100, 3, {8, 32}, 9);
  std::vector<std::vector<Points>> results;
  for (const std::string& engine : Engines()) {
    StrandBatch batch(strands);
    ASSERT_TRUE(internal::SetStrandEngine(&batch, engine.c_str()));
    EXPECT_EQ(std::string(batch.engine()), engine);
    results.push_back(ThirtyFrames(&batch));
  }
  for (size_t r = 1; r < results.size(); ++r) {
    for (size_t s = 0; s < strands.size(); ++s) {
      EXPECT_LE(MaxRelativeDifference(results[r][s], results[0][s]), 1e-14) << Engines()[r];
    }
  }
}

// Lengths kept to rounding over 10,000 frames, and the pinned points exactly rigid with the body.
TEST(Strands, LengthsKeptAndPinnedRigidOver10000Frames) {
  const std::vector<Points> strands = MakeStrands(40, 3, {2, 10, 24}, 13);
  for (Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
    StrandOptions options;
    options.method = method;
    options.pinned = 2;
    options.threads = 2;
    StrandBatch batch(strands, options);
    BodyPose pose;
    for (int frame = 1; frame <= 10000; ++frame) {
      pose = PoseAt(frame, 3);
      StepStrands(&batch, pose);
    }
    double worst_length = 0.0, worst_rigid = 0.0;
    for (int s = 0; s < batch.size(); ++s) {
      const Points p = batch.strand(s);
      const Eigen::VectorXd lengths = MakeChain(strands[s]).lengths;
      for (int i = 1; i < p.rows(); ++i) {
        // Absolute error in units of the rounding of the coordinates (about 2 here).
        const double scale =
            std::numeric_limits<double>::epsilon() * std::max(1.0, p.row(i).cwiseAbs().maxCoeff());
        worst_length = std::max(
            worst_length, std::abs((p.row(i) - p.row(i - 1)).norm() - lengths[i - 1]) / scale);
      }
      for (int j = 0; j < 2; ++j) {
        const Eigen::Vector3d body =
            pose.rotation.transpose() * (p.row(j).transpose() - pose.translation);
        worst_rigid = std::max(worst_rigid, (body - strands[s].row(j).transpose()).norm());
      }
    }
    EXPECT_LE(worst_length, 8.0) << MethodName(method);  // a few ulps, not growing
    EXPECT_LE(worst_rigid, 1e-14) << MethodName(method);
  }
}

TEST(Strands, EmptyBatch) {
  StrandBatch batch(std::vector<Points>{});
  EXPECT_EQ(batch.size(), 0);
  StepStrands(&batch, BodyPose());
  StepStrands(&batch, Points(0, 3));
  EXPECT_THROW(StepStrands(&batch, Points(1, 3)), InputError);
}

TEST(Strands, OneLinkStrandsAndCoincidentRoots) {
  // Every strand rooted at the same point, one link each, in every direction.
  std::vector<Points> strands;
  for (int s = 0; s < 20; ++s) {
    Points p(2, 3);
    p << 0, 0, 0, std::cos(s), std::sin(s), 0.1 * s;
    strands.push_back(p);
  }
  StrandBatch batch(strands);
  Points roots(20, 3);
  for (int frame = 1; frame <= 50; ++frame) {
    roots.rowwise() = Eigen::RowVector3d(0.1 * frame, std::sin(0.1 * frame), 0.0);
    StepStrands(&batch, roots);
  }
  for (int s = 0; s < 20; ++s) {
    Chain chain = MakeChain(strands[s]);
    for (int frame = 1; frame <= 50; ++frame) {
      MoveLeader(Method::kTractrix, Eigen::Vector3d(0.1 * frame, std::sin(0.1 * frame), 0.0), 1,
                 &chain);
    }
    EXPECT_LE(MaxRelativeDifference(batch.strand(s), chain.points), 1e-14);
    EXPECT_NEAR((batch.strand(s).row(1) - batch.strand(s).row(0)).norm(), chain.lengths[0], 1e-14);
  }
}

// A body that does not move leaves every strand exactly where it is.
TEST(Strands, StillBodyMovesNothing) {
  const std::vector<Points> strands = MakeStrands(50, 3, {1, 7, 20}, 17);
  for (int pinned : {1, 3}) {
    StrandOptions options;
    options.pinned = pinned;
    StrandBatch batch(strands, options);
    for (int frame = 0; frame < 10; ++frame) StepStrands(&batch, BodyPose());
    for (int s = 0; s < batch.size(); ++s) ExpectBitEqual(batch.strand(s), strands[s], "still");
  }
}

std::string FieldOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.field();
  }
  return "(no error)";
}

TEST(Strands, InputErrorsNameTheField) {
  std::vector<Points> strands = MakeStrands(3, 3, {4}, 1);
  StrandOptions options;
  options.substeps = 0;
  EXPECT_EQ(FieldOf([&] { StrandBatch b(strands, options); }), "substeps");
  options = {};
  options.pinned = 0;
  EXPECT_EQ(FieldOf([&] { StrandBatch b(strands, options); }), "pinned");
  options = {};
  options.method = Method::kOverall;
  EXPECT_EQ(FieldOf([&] { StrandBatch b(strands, options); }), "method");
  options = {};
  options.threads = -1;
  EXPECT_EQ(FieldOf([&] { StrandBatch b(strands, options); }), "threads");
  std::vector<Points> bad = strands;
  bad[1].row(2) = bad[1].row(1);
  EXPECT_EQ(FieldOf([&] { StrandBatch b(bad); }), "strands[1]");
  bad = strands;
  bad[2] = Points::Zero(3, 2);
  bad[2](1, 0) = 1;
  bad[2](2, 0) = 2;
  EXPECT_EQ(FieldOf([&] { StrandBatch b(bad); }), "strands[2]");
  StrandBatch batch(strands);
  EXPECT_EQ(FieldOf([&] { StepStrands(&batch, Points(2, 3)); }), "roots");
  Points roots = Points::Zero(3, 3);
  roots(1, 1) = std::nan("");
  EXPECT_EQ(FieldOf([&] { StepStrands(&batch, roots); }), "roots");
  BodyPose pose;
  pose.rotation(0, 0) = 2.0;
  EXPECT_EQ(FieldOf([&] { StepStrands(&batch, pose); }), "pose.rotation");
  pose = BodyPose();
  pose.translation[2] = INFINITY;
  EXPECT_EQ(FieldOf([&] { StepStrands(&batch, pose); }), "pose.translation");
  EXPECT_EQ(FieldOf([&] { batch.strand(3); }), "strand");
}

}  // namespace
}  // namespace flexkin
