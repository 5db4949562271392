// Dense frames (flexkin/frames.h): one (F, n+1, dim) array in C order, the form of the .npz file
// and of Python's Result.frames, with a view per frame.
#include "flexkin/frames.h"

#include <gtest/gtest.h>

#include <cstring>
#include <stdexcept>

#include "flexkin/result_io.h"
#include "flexkin/run.h"
#include "test_util.h"

namespace flexkin {
namespace {

Points Config(int64_t f, int rows, int dim) {
  Points p(rows, dim);
  for (int i = 0; i < rows; ++i) {
    for (int k = 0; k < dim; ++k) p(i, k) = 100.0 * f + 10.0 * i + k;
  }
  return p;
}

TEST(FramesTest, LayoutIsTheArrayOfTheResultFile) {
  for (const int dim : {2, 3}) {
    Frames frames;
    const int rows = 5;
    for (int64_t f = 0; f < 4; ++f) {
      frames.Add(2 * f, Config(f, rows, dim), Eigen::VectorXd::Constant(rows - 1, 0.5 * f));
    }
    ASSERT_EQ(frames.size(), 4u);
    EXPECT_EQ(frames.num_points(), rows);
    EXPECT_EQ(frames.dim(), dim);
    ASSERT_TRUE(frames.has_link_angles());
    // Element [f][i][k] of the (F, n+1, dim) C-order array is at (f * (n+1) + i) * dim + k.
    const FrameArray<double>& data = frames.points_data();
    ASSERT_EQ(data.size(), static_cast<size_t>(4 * rows * dim));
    for (int64_t f = 0; f < 4; ++f) {
      for (int i = 0; i < rows; ++i) {
        for (int k = 0; k < dim; ++k) {
          EXPECT_EQ(data[static_cast<size_t>((f * rows + i) * dim + k)], 100.0 * f + 10.0 * i + k);
        }
      }
      const Frame frame = frames[static_cast<size_t>(f)];
      EXPECT_EQ(frame.step, 2 * f);
      EXPECT_EQ(Points(frame.points), Config(f, rows, dim));
      EXPECT_EQ(frame.link_angles.size(), rows - 1);
      EXPECT_EQ(frame.link_angles[rows - 2], 0.5 * f);
      // The views point into the dense arrays: no copy per frame.
      EXPECT_EQ(frame.points.data(), data.data() + f * rows * dim);
      EXPECT_EQ(frame.link_angles.data(), frames.link_angles_data().data() + f * (rows - 1));
    }
    EXPECT_EQ(frames.all_points().rows(), 4 * rows);
    EXPECT_EQ(frames.all_points()(rows + 2, 1), 100.0 + 20.0 + 1);
    int64_t visited = 0;
    for (const Frame& frame : frames) EXPECT_EQ(frame.step, 2 * visited++);
    EXPECT_EQ(visited, 4);
  }
}

TEST(FramesTest, EveryFrameHasTheShapeOfTheFirst) {
  Frames frames;
  frames.Add(0, Config(0, 4, 2), Eigen::VectorXd::Zero(3));
  EXPECT_THROW(frames.Add(1, Config(1, 5, 2), Eigen::VectorXd::Zero(4)), std::invalid_argument);
  EXPECT_THROW(frames.Add(1, Config(1, 4, 3), Eigen::VectorXd::Zero(3)), std::invalid_argument);
  EXPECT_THROW(frames.Add(1, Config(1, 4, 2)), std::invalid_argument);  // angles in frame 0
  EXPECT_THROW(frames.Add(1, Config(1, 4, 2), Eigen::VectorXd::Zero(2)), std::invalid_argument);
  EXPECT_EQ(frames.size(), 1u);
  Frames bare;
  bare.Add(0, Config(0, 4, 2));
  EXPECT_FALSE(bare.has_link_angles());
  EXPECT_THROW(bare.Add(1, Config(1, 4, 2), Eigen::VectorXd::Zero(3)), std::invalid_argument);
  EXPECT_EQ(bare[0].link_angles.size(), 0);
}

TEST(FramesTest, TruncateDropAndClear) {
  Frames frames;
  for (int64_t f = 0; f < 5; ++f) frames.Add(f, Config(f, 3, 3), Eigen::VectorXd::Ones(2));
  frames.Truncate(2);
  EXPECT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames.points_data().size(), 2u * 3 * 3);
  EXPECT_EQ(Points(frames.back().points), Config(1, 3, 3));
  frames.DropLinkAngles();
  EXPECT_FALSE(frames.has_link_angles());
  EXPECT_EQ(frames.back().link_angles.size(), 0);
  frames.Add(2, Config(2, 3, 3));  // without angles now
  EXPECT_EQ(frames.size(), 3u);
  frames.Clear();
  EXPECT_TRUE(frames.empty());
  frames.Add(0, Config(0, 6, 2));  // a new shape after Clear
  EXPECT_EQ(frames.num_points(), 6);
}

// A block of a wider matrix (outer stride above dim) is packed on the way in.
TEST(FramesTest, AddsAStridedView) {
  const Points wide = Config(7, 4, 3);
  Frames frames;
  frames.Add(0, wide.leftCols(2));
  EXPECT_EQ(Points(frames[0].points), Points(wide.leftCols(2)));
}

// A run's frames are the same numbers whether kept by Run or streamed to a sink, and the .npz
// file read back holds the same dense arrays, byte for byte.
class FramesFileTest : public test_util::TempDirTest {};

TEST_F(FramesFileTest, RunAndResultFileHoldTheSameArrays) {
  const Chain chain = MakeChain((Points(4, 2) << 0, 0, -1, 0, -2, 0.5, -3, 0.2).finished());
  Points steps(6, 2);
  for (int s = 0; s < 6; ++s) steps.row(s) << 0.3 * (s + 1), 0.1 * s * s;
  RunOptions options;
  options.substeps = 3;
  options.record_every = 2;
  const RunResult run = flexkin::Run(chain, steps, options);
  ASSERT_EQ(run.frames.size(), static_cast<size_t>(CountRecordedFrames(6, 2)));
  EXPECT_EQ(run.frames.points_data().capacity(), run.frames.points_data().size());  // one block
  FrameRecorder streamed;
  flexkin::Run(chain, steps, options, &streamed);
  EXPECT_EQ(streamed.frames.points_data(), run.frames.points_data());
  EXPECT_EQ(streamed.frames.steps(), run.frames.steps());
  EXPECT_EQ(streamed.frames.link_angles_data(), run.frames.link_angles_data());
  WriteResultFile(run, Path("r.npz"), ResultFileFormat::kNpz);
  const ResultFile back = ReadResultFile(Path("r.npz"));
  ASSERT_EQ(back.result.frames.points_data().size(), run.frames.points_data().size());
  EXPECT_EQ(std::memcmp(back.result.frames.points_data().data(), run.frames.points_data().data(),
                        sizeof(double) * run.frames.points_data().size()),
            0);
  EXPECT_EQ(back.result.frames.steps(), run.frames.steps());
  EXPECT_EQ(back.result.frames.link_angles_data(), run.frames.link_angles_data());
}

}  // namespace
}  // namespace flexkin
