// The follow_path method (docs/colliders.md "Follow the path"): every point on the head's path,
// link lengths exact, a straight pull a rigid translation, a circle kept; the path report and
// PathDeviation checked against brute-force measures written here; the refusals and errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "flexkin/any_scenario.h"
#include "flexkin/chain.h"
#include "flexkin/colliders.h"
#include "flexkin/propagate.h"
#include "flexkin/run.h"
#include "flexkin/strands.h"

namespace flexkin {
namespace {

// The head's path written out again: the initial points reversed, then the targets.
Points PathOf(const Chain& chain, const Points& targets, int64_t step) {
  const Eigen::Index n1 = chain.points.rows();
  Points path(n1 + step, chain.dim());
  for (Eigen::Index i = 0; i < n1; ++i) path.row(i) = chain.points.row(n1 - 1 - i);
  for (int64_t s = 0; s < step; ++s) path.row(n1 + s) = targets.row(s);
  return path;
}

// Distance from x to the polyline, every segment tried.
double BruteDistance(const Points& path, const Eigen::RowVectorXd& x) {
  double best = (x - path.row(0)).norm();
  for (Eigen::Index k = 1; k < path.rows(); ++k) {
    const Eigen::RowVectorXd a = path.row(k - 1), d = path.row(k) - path.row(k - 1);
    const double dd = d.squaredNorm();
    const double t = dd > 0.0 ? std::clamp((x - a).dot(d) / dd, 0.0, 1.0) : 0.0;
    best = std::min(best, (x - (a + t * d)).norm());
  }
  return best;
}

// The point of the polyline at arc length s from its start (clamped to its ends).
Eigen::RowVectorXd BrutePointAt(const Points& path, double s) {
  if (s <= 0.0) return path.row(0);
  for (Eigen::Index k = 1; k < path.rows(); ++k) {
    const double length = (path.row(k) - path.row(k - 1)).norm();
    if (s <= length && length > 0.0) {
      return path.row(k - 1) + (s / length) * (path.row(k) - path.row(k - 1));
    }
    s -= length;
  }
  return path.row(path.rows() - 1);
}

double ArcLength(const Points& path) {
  double s = 0.0;
  for (Eigen::Index k = 1; k < path.rows(); ++k) s += (path.row(k) - path.row(k - 1)).norm();
  return s;
}

// A straight chain of n links of length `link` lying along -x from the head at the origin.
Chain StraightChain(int n, double link) {
  Points p(n + 1, 2);
  for (int i = 0; i <= n; ++i) p.row(i) << -link * i, 0.0;
  return MakeChain(p);
}

RunOptions FollowPath() {
  RunOptions o;
  o.method = Method::kFollowPath;
  return o;
}

TEST(FollowPathTest, PointsOnThePathAndLengthsExactOver10000Steps) {
  const Chain chain = StraightChain(12, 0.1);
  const int m = 10000;
  Points targets(m, 2);
  for (int s = 0; s < m; ++s) {
    const double t = 6.0 * (s + 1) / m;
    targets.row(s) << t, 0.3 * std::sin(3.0 * t) * std::min(1.0, t);
  }
  RunOptions options = FollowPath();
  options.record_every = 250;
  const RunResult r = flexkin::Run(chain, targets, options);
  EXPECT_LE(r.metrics.max_relative_length_error, 1e-13);  // every leader step
  ASSERT_TRUE(r.path.enabled);
  ASSERT_EQ(r.path.deviation.size(), m);
  EXPECT_LE(r.path.max_deviation, 1e-12);
  for (const Frame frame : r.frames) {
    const Points path = PathOf(chain, targets, frame.step);
    for (Eigen::Index i = 0; i < frame.points.rows(); ++i) {
      EXPECT_LE(BruteDistance(path, frame.points.row(i)), 1e-12)
          << "step " << frame.step << " point " << i;
      if (i > 0) {
        EXPECT_NEAR((frame.points.row(i) - frame.points.row(i - 1)).norm(), 0.1, 1e-14);
      }
    }
    // The tip error, measured independently.
    if (frame.step > 0) {
      const double expected = (frame.points.row(frame.points.rows() - 1) -
                               BrutePointAt(path, ArcLength(path) - chain.lengths.sum()))
                                  .norm();
      EXPECT_NEAR(r.path.tip_error[frame.step - 1], expected, 1e-12);
    }
  }
  // The path turns: the chords are shorter than the arcs, so the tip falls behind.
  EXPECT_GT(r.path.max_tip_error, 1e-4);
  // The report's deviation is PathDeviation's, frame by frame.
  const PathComparison c = PathDeviation(chain, targets, r.frames);
  for (size_t f = 1; f < r.frames.size(); ++f) {
    EXPECT_EQ(c.deviation.row(static_cast<Eigen::Index>(f)).maxCoeff(),
              r.path.deviation[r.frames[f].step - 1]);
    EXPECT_EQ(c.tip_error[static_cast<Eigen::Index>(f)], r.path.tip_error[r.frames[f].step - 1]);
  }
}

TEST(FollowPathTest, StraightPullIsARigidTranslation) {
  const Chain chain = StraightChain(10, 0.25);
  Points targets(40, 2);
  for (int s = 0; s < 40; ++s) targets.row(s) << 0.037 * (s + 1), 0.0;
  RunOptions options = FollowPath();
  options.substeps = 3;
  const RunResult r = flexkin::Run(chain, targets, options);
  for (const Frame frame : r.frames) {
    const Eigen::RowVectorXd shift = frame.points.row(0) - chain.points.row(0);
    for (Eigen::Index i = 0; i < frame.points.rows(); ++i) {
      EXPECT_LE((frame.points.row(i) - chain.points.row(i) - shift).norm(), 1e-12)
          << "step " << frame.step << " point " << i;
    }
  }
  EXPECT_LE(r.path.max_tip_error, 1e-12);
  EXPECT_LE(r.path.max_deviation, 1e-12);
  EXPECT_TRUE(std::isinf(r.path.least_clearance));
  // Sub-steps refine the metrics, not the configuration: each point moves 40 x 0.037.
  EXPECT_NEAR(r.metrics.path_length[10], 40 * 0.037, 1e-12);
}

// A chain inscribed in a circle, its head going on round the same inscribed polygon (5 head
// steps per link): every joint lands on a vertex, so on the circle, lap after lap.
TEST(FollowPathTest, CirclePathKeepsEveryJointOnTheCircle) {
  const double radius = 2.0, step = 2.0 * M_PI / 500;  // 500 head steps per lap
  const int n = 16, per_link = 5, m = 1200;
  Points p(n + 1, 2);
  for (int i = 0; i <= n; ++i) {
    const double a = -step * per_link * i;
    p.row(i) << radius * std::cos(a), radius * std::sin(a);
  }
  const Chain chain = MakeChain(p);
  Points targets(m, 2);
  for (int s = 0; s < m; ++s) {
    targets.row(s) << radius * std::cos(step * (s + 1)), radius * std::sin(step * (s + 1));
  }
  const RunResult r = flexkin::Run(chain, targets, FollowPath());
  // Once the body has left its initial links (chords of 5 polygon sides each, n * per_link head
  // steps), every joint lies on a vertex of the polygon; before, within a link's sagitta.
  const double sagitta = radius * (1.0 - std::cos(step * per_link / 2));
  for (const Frame frame : r.frames) {
    for (Eigen::Index i = 0; i < frame.points.rows(); ++i) {
      if (frame.step >= n * per_link) {
        EXPECT_NEAR(frame.points.row(i).norm(), radius, 1e-12) << "step " << frame.step;
      } else {
        EXPECT_NEAR(frame.points.row(i).norm(), radius - sagitta / 2, sagitta / 2 + 1e-12);
      }
    }
  }
  EXPECT_LE(r.metrics.max_relative_length_error, 1e-13);
  // The tip is n links of per_link polygon sides behind the head along the path; the report
  // measures it against the arc n L behind.
  const double side = 2.0 * radius * std::sin(step / 2), link = chain.lengths[0];
  const double behind = n * link, actual = n * per_link * side;
  const Points path = PathOf(chain, targets, m);
  const double total = ArcLength(path);
  EXPECT_NEAR(r.path.tip_error[m - 1],
              (BrutePointAt(path, total - behind) - BrutePointAt(path, total - actual)).norm(),
              1e-10);
  EXPECT_GT(r.path.tip_error[m - 1], 1e-4);

  // A tractrix run of the same chain cuts inside the circle: PathDeviation says how far.
  RunOptions tractrix;
  tractrix.substeps = 4;
  const RunResult t = flexkin::Run(chain, targets, tractrix);
  const PathComparison c = PathDeviation(chain, targets, t.frames);
  ASSERT_EQ(c.deviation.rows(), static_cast<Eigen::Index>(t.frames.size()));
  ASSERT_EQ(c.deviation.cols(), n + 1);
  EXPECT_GT(c.deviation.maxCoeff(), 1e-2);
  EXPECT_LE(c.deviation.col(0).maxCoeff(), 1e-15);  // the head is on its path
  EXPECT_LE(c.deviation.row(0).maxCoeff(), 1e-15);  // the start is the path's beginning
  // Brute force agrees on a few frames.
  for (size_t f : {size_t{1}, size_t{300}, t.frames.size() - 1}) {
    const Frame frame = t.frames[f];
    const Points tpath = PathOf(chain, targets, frame.step);
    for (Eigen::Index i = 0; i <= n; ++i) {
      EXPECT_NEAR(c.deviation(static_cast<Eigen::Index>(f), i),
                  BruteDistance(tpath, frame.points.row(i)), 1e-14);
    }
  }
}

TEST(FollowPathTest, SpatialHelixStaysOnThePath) {
  Points p(9, 3);
  for (int i = 0; i <= 8; ++i) p.row(i) << -0.2 * i, 0.0, 0.0;
  const Chain chain = MakeChain(p);
  Points targets(2000, 3);
  for (int s = 0; s < 2000; ++s) {
    const double t = 0.005 * (s + 1);
    targets.row(s) << 0.5 * std::sin(t), 0.5 - 0.5 * std::cos(t), 0.1 * t;
  }
  RunOptions options = FollowPath();
  options.record_every = 100;
  const RunResult r = flexkin::Run(chain, targets, options);
  EXPECT_LE(r.path.max_deviation, 1e-12);
  EXPECT_LE(r.metrics.max_relative_length_error, 1e-13);
}

TEST(FollowPathTest, APathTooShortForTheBodyIsAnInputErrorNamingTheStep) {
  // The second link folds back along the first: behind the head, the path runs out.
  Points p(3, 2);
  p << 0, 0, -1, 0, -0.1, 0.1;
  const Chain chain = MakeChain(p);
  Points targets(2, 2);
  targets << 0.25, 0, 0.5, 0;
  try {
    flexkin::Run(chain, targets, FollowPath());
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "leader_steps[0]");
    EXPECT_NE(std::string(e.what()).find("leader step 1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("too short"), std::string::npos) << e.what();
  }
}

TEST(FollowPathTest, RefusedWhereItMakesNoSense) {
  const Chain chain = StraightChain(4, 0.5);
  // Accuracy control.
  RunOptions options = FollowPath();
  options.tolerance = 1e-6;
  const Problems problems = options.Validate();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].field, "tolerance");
  // The single-step APIs: not a link rule.
  EXPECT_THROW(MakeStepper(Method::kFollowPath, chain), InputError);
  Chain moved = chain;
  try {
    MoveLeader(Method::kFollowPath, Eigen::Vector2d(0.1, 0.0), 1, &moved);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "method");
    EXPECT_NE(std::string(e.what()).find("\"tractrix\""), std::string::npos) << e.what();
  }
  // The strand engine.
  StrandOptions strands;
  strands.method = Method::kFollowPath;
  const Problems refused = strands.Validate();
  ASSERT_FALSE(refused.empty());
  EXPECT_EQ(refused[0].field, "method");
  EXPECT_NE(refused[0].message.find("\"tractrix\" or \"ftl\""), std::string::npos);
}

TEST(FollowPathTest, CollidersAreMeasuredNotAvoided) {
  const Chain chain = StraightChain(8, 0.25);
  Points targets(100, 2);
  for (int s = 0; s < 100; ++s) targets.row(s) << 0.03 * (s + 1), 0.0;
  Collider off;  // beside the path
  off.pose.translation() = Eigen::Vector3d(1.0, 0.5, 0.0);
  off.radius = 0.2;
  Collider on = off;  // on it
  on.pose.translation() = Eigen::Vector3d(1.5, 0.05, 0.0);
  RunOptions options = FollowPath();
  options.colliders = {off};
  const RunResult clear = flexkin::Run(chain, targets, options);
  EXPECT_NEAR(clear.path.least_clearance, 0.3, 1e-12);
  EXPECT_GT(clear.path.least_clearance_step, 0);
  EXPECT_NEAR(clear.contacts.least_clearance, 0.3 / 0.25, 1e-12);
  for (Eigen::Index s = 0; s < 100; ++s) EXPECT_GE(clear.path.clearance[s], 0.3 - 1e-12);
  // The path enters the second collider: the run goes through it, and says so.
  options.colliders = {off, on};
  const RunResult through = flexkin::Run(chain, targets, options);
  EXPECT_NEAR(through.path.least_clearance, -0.15, 1e-12);
  EXPECT_EQ(through.frames.back().points, clear.frames.back().points);
  EXPECT_NE(through.BriefReport().find("PASSES THROUGH"), std::string::npos)
      << through.BriefReport();
}

TEST(FollowPathTest, OtherMethodsHaveNoPathReport) {
  const Chain chain = StraightChain(4, 0.5);
  Points targets(3, 2);
  targets << 0.1, 0.1, 0.2, 0.3, 0.4, 0.3;
  const RunResult r = flexkin::Run(chain, targets, RunOptions());
  EXPECT_FALSE(r.path.enabled);
  EXPECT_EQ(r.path.deviation.size(), 0);
  EXPECT_EQ(r.BriefReport().find("head's path"), std::string::npos);
}

TEST(FollowPathTest, ScenarioFilesNameTheMethod) {
  const AnyScenario s = ReadScenarioText(R"({
    "curve": {"shape": "line", "start": [0, 0], "direction": [-1, 0], "links": 5,
              "link_length": 0.2},
    "leader": {"path": [[1, 0], [1, 1]], "max_step": 0.05},
    "method": "follow_path",
    "colliders": [{"shape": "sphere", "center": [0.5, 0.5], "radius": 0.2}]
  })");
  ASSERT_TRUE(s.valid()) << s.problems[0].message;
  EXPECT_EQ(s.chain->options.method, Method::kFollowPath);
  const RunResult r = flexkin::Run(s.chain->chain, s.chain->leader_steps, s.chain->options);
  EXPECT_TRUE(r.path.enabled);
  EXPECT_LE(r.path.max_deviation, 1e-12);
  EXPECT_NE(r.BriefReport().find("follow_path: 5 links"), std::string::npos) << r.BriefReport();

  const AnyScenario refused = ReadScenarioText(R"({
    "curve": {"points": [[0, 0], [-1, 0]]}, "leader": {"pull": [1, 0], "steps": 2},
    "method": "follow_path", "accuracy": {"tolerance": 1e-6}
  })");
  ASSERT_FALSE(refused.valid());
  EXPECT_NE(refused.problems[0].field.find("tolerance"), std::string::npos)
      << refused.problems[0].field;
}

}  // namespace
}  // namespace flexkin
