// Tests of groom runs (RunGroom, include/flexkin/groom.h) and `flexkin run GROOM.json`: the
// frames recorded are the ones asked for, the strands start rigidly placed on the body, the
// pinned roots stay rigid with it, every link keeps its length, threads change no bit, a straight
// pull makes the motion die out toward the tips and aligns the strands with it, and bad grooms,
// options and outputs are refused with messages that name them, leaving no file behind.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "flexkin/groom.h"
#include "flexkin/strand_file.h"
#include "flexkin/strands.h"
#include "test_util.h"

namespace flexkin {
namespace {

namespace fs = std::filesystem;
using test_util::ExpectInputError;
using test_util::ReadFile;
using test_util::RunCli;

using GroomRunTest = test_util::TempDirTest;

// Straight strands of 2 to 9 links sticking out of a unit sphere along its normals.
GroomScenario Hedgehog(int strands) {
  GroomScenario s;
  s.name = "hedgehog";
  s.dim = 3;
  for (int i = 0; i < strands; ++i) {
    const double z = -0.9 + 1.8 * (i + 0.5) / strands, a = 2.399963 * i;
    const Eigen::RowVector3d n(std::sqrt(1 - z * z) * std::cos(a),
                               std::sqrt(1 - z * z) * std::sin(a), z);
    const int links = 2 + i % 8;
    Points p(links + 1, 3);
    for (int j = 0; j <= links; ++j) p.row(j) = n * (1.0 + 0.1 * j * (1.0 + 0.01 * (i % 5)));
    s.strands.push_back(p);
  }
  s.scalp.shape = "sphere";
  s.scalp.radii = Eigen::Vector3d::Ones();
  s.float32 = false;
  return s;
}

BodyKeyframe Key(double time, double angle, const Eigen::Vector3d& axis,
                 const Eigen::Vector3d& translation) {
  BodyKeyframe k;
  k.time = time;
  const Eigen::Vector3d u = axis.normalized();
  k.pose = BodyPose::FromQuaternion(std::cos(angle / 2), u.x() * std::sin(angle / 2),
                                    u.y() * std::sin(angle / 2), u.z() * std::sin(angle / 2),
                                    translation);
  return k;
}

// A turn, a nod and a shift over 2 s at 30 fps, starting away from the identity.
BodyMotion TurnAndNod() {
  BodyMotion m;
  m.fps = 30;
  m.keyframes = {Key(0.0, 0.3, {0, 0, 1}, {0.1, 0, 0}), Key(0.7, 1.2, {0, 0, 1}, {0.1, 0.2, 0}),
                 Key(1.4, 0.5, {0, 1, 0}, {0, 0.2, 0.1}), Key(2.0, 0.0, {1, 0, 0}, {0, 0, 0})};
  return m;
}

// Every frame of a strand file.
std::vector<StrandFrame> ReadAll(const std::string& path, StrandFileHeader* header = nullptr) {
  StrandFileReader reader(path);
  if (header != nullptr) *header = reader.header();
  std::vector<StrandFrame> frames;
  StrandFrame f;
  while (reader.Next(&f)) frames.push_back(f);
  return frames;
}

StrandRunReport RunTo(const GroomScenario& s, const std::string& path) {
  StrandFileWriter writer(path, MakeStrandFileHeader(s));
  const StrandRunReport report = RunGroom(s, &writer);
  writer.Commit(report);
  return report;
}

TEST_F(GroomRunTest, RecordsTheFramesAskedFor) {
  GroomScenario s = Hedgehog(20);
  s.motion = TurnAndNod();  // 61 frames
  ASSERT_EQ(s.motion.num_frames(), 61);
  for (int every : {1, 2, 7, 60, 100}) {
    s.record_every = every;
    RunTo(s, Path("h.npz"));
    StrandFileHeader h;
    const std::vector<StrandFrame> frames = ReadAll(Path("h.npz"), &h);
    std::vector<int64_t> expected;
    for (int64_t f = 0; f < 61; f += every) expected.push_back(f);
    if (expected.back() != 60) expected.push_back(60);
    ASSERT_EQ(frames.size(), expected.size()) << every;
    for (size_t k = 0; k < frames.size(); ++k) {
      EXPECT_EQ(frames[k].frame, expected[k]);
      EXPECT_EQ(frames[k].time, s.motion.TimeOf(expected[k]));
      const BodyPose pose = s.motion.PoseAt(expected[k]);
      EXPECT_EQ(frames[k].pose.rotation, pose.rotation);
      EXPECT_EQ(frames[k].pose.translation, pose.translation);
    }
    EXPECT_EQ(h.record_every, every);
    EXPECT_EQ(h.num_strands(), 20);
  }
}

// Frame 0 is the groom placed rigidly at the first pose; the roots stay rigid with the body; the
// lengths are kept to rounding, and the report's largest error is the file's.
TEST_F(GroomRunTest, PlacedRigidRootsAndExactLengths) {
  for (int pinned : {1, 2}) {
    GroomScenario s = Hedgehog(50);
    s.motion = TurnAndNod();
    s.options.pinned = pinned;
    const StrandRunReport report = RunTo(s, Path("h.npz"));
    StrandFileHeader h;
    const std::vector<StrandFrame> frames = ReadAll(Path("h.npz"), &h);
    double largest = 0.0;
    for (const StrandFrame& f : frames) {
      const Eigen::Matrix3d& r = f.pose.rotation;
      const Eigen::Vector3d& t = f.pose.translation;
      Eigen::Index link = 0;
      for (int i = 0; i < h.num_strands(); ++i) {
        const Points body = s.strands[i];
        for (int64_t j = h.offsets[i]; j < h.offsets[i + 1]; ++j) {
          const int64_t local = j - h.offsets[i];
          const Eigen::Vector3d placed = r * body.row(local).transpose() + t;
          const Eigen::Vector3d got = f.points.row(j).transpose();
          if (f.frame == 0 || local < pinned) {
            EXPECT_LE((got - placed).norm(), 4e-16 * 3) << "strand " << i << " point " << local;
          }
          if (local > 0) {
            const double rest = (body.row(local) - body.row(local - 1)).norm();
            const double e =
                std::abs((got - Eigen::Vector3d(f.points.row(j - 1).transpose())).norm() -
                         h.link_lengths[link]) /
                h.link_lengths[link];
            // Placing the strand rounds its points (|p| up to 2, links of 0.1).
            EXPECT_NEAR(h.link_lengths[link], rest, 2e-14 * rest);
            largest = std::max(largest, e);
            ++link;
          }
        }
      }
    }
    EXPECT_LE(largest, 8e-15);
    EXPECT_EQ(report.max_length_error, largest);
  }
}

TEST_F(GroomRunTest, ThreadsChangeNoBit) {
  GroomScenario s = Hedgehog(300);
  s.motion = TurnAndNod();
  s.options.substeps = 2;
  std::vector<std::vector<StrandFrame>> runs;
  for (int threads : {1, 2, 3}) {
    s.options.threads = threads;
    const StrandRunReport report = RunTo(s, Path("h.npz"));
    EXPECT_EQ(report.threads, threads);
    runs.push_back(ReadAll(Path("h.npz")));
  }
  for (size_t r = 1; r < runs.size(); ++r) {
    ASSERT_EQ(runs[r].size(), runs[0].size());
    for (size_t k = 0; k < runs[0].size(); ++k) {
      ASSERT_TRUE(runs[r][k].points == runs[0][k].points) << "threads run " << r << " frame " << k;
    }
  }
}

// A long straight pull: every strand's points travel less the farther they are from the root
// (the motion dies out toward the tip), and at the end every strand trails behind its root,
// aligned with the pull.
TEST_F(GroomRunTest, StraightPullDiesOutAndAligns) {
  GroomScenario s = Hedgehog(40);
  s.motion.fps = 60;
  s.motion.interpolation = KeyframeInterpolation::kLinear;
  const Eigen::Vector3d pull(0.6, -0.8, 0.0);  // unit
  s.motion.keyframes = {Key(0, 0, {0, 0, 1}, Eigen::Vector3d::Zero()),
                        Key(4, 0, {0, 0, 1}, 20.0 * pull)};
  s.options.substeps = 4;
  RunTo(s, Path("h.npz"));
  StrandFileHeader h;
  const std::vector<StrandFrame> frames = ReadAll(Path("h.npz"), &h);
  for (int i = 0; i < h.num_strands(); ++i) {
    const int64_t a = h.offsets[i], b = h.offsets[i + 1];
    std::vector<double> travel(b - a, 0.0);
    for (size_t k = 1; k < frames.size(); ++k) {
      for (int64_t j = a; j < b; ++j) {
        travel[j - a] += (frames[k].points.row(j) - frames[k - 1].points.row(j)).norm();
      }
    }
    for (size_t j = 2; j < travel.size(); ++j) {
      EXPECT_LE(travel[j], travel[j - 1] * (1 + 1e-12)) << "strand " << i << " point " << j;
    }
    const Points& last = frames.back().points;
    const Eigen::Vector3d along = (last.row(b - 1) - last.row(a + 1)).transpose().normalized();
    EXPECT_LT(along.dot(pull), -0.99) << "strand " << i << " does not trail the pull";
  }
}

TEST_F(GroomRunTest, StillBodyMovesNothing) {
  GroomScenario s = Hedgehog(30);
  s.motion.keyframes = {Key(0, 0.4, {1, 1, 0}, {1, 2, 3}), Key(1, 0.4, {1, 1, 0}, {1, 2, 3})};
  RunTo(s, Path("h.npz"));
  const std::vector<StrandFrame> frames = ReadAll(Path("h.npz"));
  for (const StrandFrame& f : frames) EXPECT_TRUE(f.points == frames[0].points) << f.frame;
}

TEST_F(GroomRunTest, TwoDimensionalStrands) {
  GroomScenario s;
  s.dim = 2;
  for (int i = 0; i < 12; ++i) {
    Points p(2 + i % 4, 2);
    for (int j = 0; j < p.rows(); ++j) p.row(j) << 0.3 * i, 0.2 * j;
    s.strands.push_back(p);
  }
  BodyKeyframe a, b;
  b.time = 1;
  b.pose = BodyPose::Planar(0.5, 1.0, -0.5);
  s.motion.keyframes = {a, b};
  s.float32 = false;
  RunTo(s, Path("g.npz"));
  StrandFileHeader h;
  const std::vector<StrandFrame> frames = ReadAll(Path("g.npz"), &h);
  EXPECT_EQ(h.dim, 2);
  ASSERT_EQ(frames.back().points.cols(), 2);
  // The roots at the last frame: rotated by 0.5 rad and moved by (1, -0.5).
  for (int i = 0; i < 12; ++i) {
    const Eigen::Vector2d q(0.3 * i, 0.0);
    const Eigen::Vector2d expected =
        Eigen::Rotation2D<double>(0.5).toRotationMatrix() * q + Eigen::Vector2d(1.0, -0.5);
    EXPECT_LE((frames.back().points.row(h.offsets[i]).transpose() - expected).norm(), 1e-15);
  }
}

TEST_F(GroomRunTest, StoppedRunWritesNothing) {
  GroomScenario s = Hedgehog(10);
  s.motion = TurnAndNod();
  std::ofstream(Path("h.npz")) << "earlier";
  {
    StrandFileWriter writer(Path("h.npz"), MakeStrandFileHeader(s));
    int calls = 0;
    ExpectInputError([&] { RunGroom(s, &writer, [&](int64_t, int64_t) { return ++calls < 5; }); },
                     "interrupted", "stopped at frame 6 of 61");
  }
  EXPECT_EQ(ReadFile(Path("h.npz")), "earlier");
  EXPECT_EQ(Files(), std::vector<std::string>{"h.npz"});
}

// The command line, with the example groom made small.
TEST_F(GroomRunTest, CommandLine) {
  const std::string cli = FLEXKIN_CLI;
  if (cli.empty()) GTEST_SKIP() << "the command line is not built (FLEXKIN_BUILD_APPS=OFF)";
  std::ofstream(Path("g.json")) << R"({
  "name": "small head",
  "groom": {"scalp": {"shape": "sphere", "center": [0, 0, 0], "radius": 0.1}, "roots": 200,
            "links": 8, "link_length": 0.01, "direction": {"droop": 0.5}, "seed": 3},
  "motion": {"fps": 30, "keyframes": [
    {"time": 0},
    {"time": 1, "rotation": {"axis": [0, 0, 1], "angle_deg": 60}}]},
  "record": {"every": 3}
})";
  test_util::CliResult r = RunCli(cli, dir_, "run g.json -o hair.npz");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("hair.npz: 200 strands, 1800 points, 31 frames (11 recorded, float32)"),
            std::string::npos)
      << r.out;
  StrandFileHeader h;
  const std::vector<StrandFrame> frames = ReadAll(Path("hair.npz"), &h);
  EXPECT_EQ(frames.size(), 11u);
  EXPECT_TRUE(h.float32);
  EXPECT_EQ(h.scalp.shape, "sphere");
  EXPECT_EQ(h.name, "small head");
  const std::string good = ReadFile(Path("hair.npz"));

  r = RunCli(cli, dir_, "validate g.json");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("ok: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("11 frames recorded of 31"), std::string::npos) << r.out;

  // Overrides.
  r = RunCli(cli, dir_,
             "run g.json -o d.npz --precision float64 --threads 2 --method ftl "
             "--record-every 30 --substeps 2 -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "");
  const std::vector<StrandFrame> d = ReadAll(Path("d.npz"), &h);
  EXPECT_EQ(d.size(), 2u);
  EXPECT_FALSE(h.float32);
  EXPECT_EQ(h.method, "ftl");
  EXPECT_EQ(h.substeps, 2);

  // Refusals: each names what is wrong, exits 1 and leaves hair.npz as it was.
  struct Bad {
    std::string args, text;
  };
  const std::vector<Bad> bad = {
      {"run g.json -o hair.json", "-o"},
      {"run g.json -o hair.npz --csv f.csv", "--csv"},
      {"run g.json -o hair.npz --tolerance 1e-3", "--tolerance"},
      {"run g.json -o hair.npz --method overall", "\"tractrix\" or \"ftl\""},
      {"run g.json -o hair.npz --precision half", "--precision"},
      {"run g.json -o hair.npz --substeps 0", "substeps"},
      {"run g.json -o hair.npz --threads -1", "threads"},
      {"run g.json -o hair.npz --record-every 0", "--record-every"},
      {"run g.json -o hair.npz --max-output-size 100K", "--record-every"},
      {"run g.json -o hair.npz --max-output-size 20K", "--max-output-size 1M"},
  };
  for (const Bad& b : bad) {
    r = RunCli(cli, dir_, b.args);
    EXPECT_EQ(r.exit_code, 1) << b.args << "\n" << r.err;
    EXPECT_NE(r.err.find(b.text), std::string::npos) << b.args << "\n" << r.err;
    EXPECT_EQ(ReadFile(Path("hair.npz")), good) << b.args;
  }
  // A bad groom file: the file and the field named.
  std::ofstream(Path("bad.json")) << R"({"groom": {"scalp": {"shape": "sphere", "radius": -1},
    "roots": 10, "links": 4, "link_length": 0.01}, "motion": {"keyframes": [{"time": 0}]}})";
  r = RunCli(cli, dir_, "run bad.json -o hair.npz");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("bad.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/groom/scalp/radius"), std::string::npos) << r.err;
  EXPECT_EQ(ReadFile(Path("hair.npz")), good);
  // A directory that does not exist: exit 4.
  r = RunCli(cli, dir_, "run g.json -o missing/hair.npz");
  EXPECT_EQ(r.exit_code, 4) << r.err;
  // Groom options on a chain scenario are refused.
  r = RunCli(cli, dir_,
             "run '" + std::string(FLEXKIN_SOURCE_DIR) +
                 "/examples/fig07_straight_link.json' -o c.json --threads 2");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--threads"), std::string::npos) << r.err;
  EXPECT_EQ(Files(), (std::vector<std::string>{"bad.json", "d.npz", "g.json", "hair.npz"}));
}

}  // namespace
}  // namespace flexkin
