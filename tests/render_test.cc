// Tests of flexkin_render: golden PNG images of two small scenes, every frame and every point
// drawn (checked in the SVG's paths), the plots' markers, the animations (ffprobe), and bad
// input leaving no file behind.
//
// Regenerate the goldens (tests/golden/*.png) after an intended change of the look with
//   FLEXKIN_UPDATE_GOLDEN=1 build/tests/render_test --gtest_filter='*Golden*'
// and look at them before committing.
#include "flexkin/render.h"

#include <cairo.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "flexkin/error.h"
#include "png_test_util.h"
#include "render/snapshot.h"
#include "render_test_util.h"
#include "test_util.h"

namespace flexkin {
namespace {

using render_test::Discs;
using render_test::Exists;
using render_test::ReadFile;
using render_test::SmallScene;
using render_test::SvgPath;
using render_test::SvgPaths;
using render_test::TempDir;

// ---------------------------------------------------------------------------------------------
// Golden images.

using render_test::Image;
using render_test::ReadPng;

// Pixels whose red, green or blue differ by more than `tolerance` (of 255).
int DifferingPixels(const Image& a, const Image& b, int tolerance) {
  int count = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    for (int shift : {0, 8, 16}) {
      const int ca = (a.pixels[i] >> shift) & 0xff, cb = (b.pixels[i] >> shift) & 0xff;
      if (std::abs(ca - cb) > tolerance) {
        ++count;
        break;
      }
    }
  }
  return count;
}

void ExpectMatchesGolden(const ResultFile& file, const FigureOptions& options,
                         const std::string& name) {
  const std::string golden = std::string(FLEXKIN_SOURCE_DIR) + "/tests/golden/" + name;
  const char* update = std::getenv("FLEXKIN_UPDATE_GOLDEN");
  if (update != nullptr && std::string(update) == "1") {
    WriteSnapshotFigure(file, options, golden);
    std::printf("updated %s: look at it before committing\n", golden.c_str());
    return;
  }
  TempDir dir;
  const std::string actual = dir.Path(name);
  WriteSnapshotFigure(file, options, actual);
  const Image want = ReadPng(golden), got = ReadPng(actual);
  ASSERT_GT(want.width, 0) << "cannot read " << golden
                           << "; regenerate with FLEXKIN_UPDATE_GOLDEN=1";
  ASSERT_EQ(got.width, want.width);
  ASSERT_EQ(got.height, want.height);
  // Small differences of anti-aliasing (another cairo or pixman build) pass; a moved line or
  // label does not: it changes hundreds of pixels.
  const int differing = DifferingPixels(want, got, 24);
  const int allowed = want.width * want.height / 1000;
  if (differing > allowed) {
    const std::string keep = (std::filesystem::temp_directory_path() / ("actual_" + name)).string();
    std::filesystem::copy_file(actual, keep, std::filesystem::copy_options::overwrite_existing);
    ADD_FAILURE() << differing << " pixels differ from " << golden << " (at most " << allowed
                  << " may); the new picture is " << keep;
  }
}

FigureOptions GoldenOptions() {
  FigureOptions options;
  options.width = 480;
  options.height = 360;
  return options;
}

TEST(RenderGoldenTest, PlanarSnapshotPng) {
  ExpectMatchesGolden(SmallScene(2), GoldenOptions(), "small_planar.png");
}

TEST(RenderGoldenTest, SpatialSnapshotPng) {
  FigureOptions options = GoldenOptions();
  options.azimuth = -50.0;
  options.elevation = 25.0;
  ExpectMatchesGolden(SmallScene(3), options, "small_spatial.png");
}

TEST(RenderGoldenTest, RenderingIsDeterministic) {
  // The same input gives the same pixels, byte for byte, within a process.
  TempDir dir;
  const ResultFile file = SmallScene(3);
  WriteSnapshotFigure(file, GoldenOptions(), dir.Path("a.png"));
  WriteSnapshotFigure(file, GoldenOptions(), dir.Path("b.png"));
  EXPECT_EQ(ReadFile(dir.Path("a.png")), ReadFile(dir.Path("b.png")));
  // SVG: the same paths with the same styles (the ids of surfaces and glyphs count up within a
  // process, so the bytes differ).
  WriteSnapshotFigure(file, GoldenOptions(), dir.Path("a.svg"));
  WriteSnapshotFigure(file, GoldenOptions(), dir.Path("b.svg"));
  const std::vector<SvgPath> a = SvgPaths(ReadFile(dir.Path("a.svg")));
  const std::vector<SvgPath> b = SvgPaths(ReadFile(dir.Path("b.svg")));
  ASSERT_EQ(a.size(), b.size());
  EXPECT_GT(a.size(), 100u);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].style, b[i].style) << i;
    EXPECT_EQ(a[i].vertices, b[i].vertices) << i;
  }
}

// ---------------------------------------------------------------------------------------------
// Every frame and every point is drawn: the SVG's paths are searched for each configuration.

constexpr double kTolerance = 0.02;  // pixels; cairo keeps 1/256 px and writes 6 decimals

bool Near(const std::pair<double, double>& v, const Eigen::Vector2d& p) {
  return std::abs(v.first - p.x()) < kTolerance && std::abs(v.second - p.y()) < kTolerance;
}

// Distance from `p` to the segment a-b.
double SegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                       const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = b - a;
  const double t =
      d.squaredNorm() > 0 ? std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
  return (a + t * d - p).norm();
}

// Whether `path` is the polyline through `points` in order: it starts and ends at their ends,
// each of its vertices is one of them (in order) and each point lies on it. (cairo merges
// collinear segments, so a vertex may be missing where a point lies on a straight run.)
bool IsPolylineThrough(const SvgPath& path, const std::vector<Eigen::Vector2d>& points) {
  if (path.closed || path.vertices.size() < 2 || !Near(path.vertices.front(), points.front()) ||
      !Near(path.vertices.back(), points.back())) {
    return false;
  }
  size_t next = 0;
  for (const auto& v : path.vertices) {
    while (next < points.size() && !Near(v, points[next])) ++next;
    if (next == points.size()) return false;
  }
  for (const Eigen::Vector2d& p : points) {
    double best = INFINITY;
    for (size_t k = 0; k + 1 < path.vertices.size(); ++k) {
      const Eigen::Vector2d a(path.vertices[k].first, path.vertices[k].second);
      const Eigen::Vector2d b(path.vertices[k + 1].first, path.vertices[k + 1].second);
      best = std::min(best, SegmentDistance(p, a, b));
    }
    if (best > kTolerance) return false;
  }
  return true;
}

// The frames of `file` whose configuration was drawn, found in the SVG at `path` that was drawn
// from `drawn` (the same or, to test the test, `file` changed slightly): 2D, a path through all
// its points; 3D, a segment path for each of its links.
std::vector<int> FramesFoundInSvg(const ResultFile& drawn, const ResultFile& file,
                                  const FigureOptions& options, const std::string& path) {
  const std::vector<SvgPath> paths = SvgPaths(ReadFile(path));
  const render::ChainScene scene = render::LayoutSnapshot(drawn, options).scene;
  std::vector<int> found;
  for (size_t f = 0; f < file.result.frames.size(); ++f) {
    std::vector<Eigen::Vector2d> points;
    for (Eigen::Index i = 0; i < file.result.frames[f].points.rows(); ++i) {
      points.push_back(scene.Pixel(file, static_cast<int>(f), static_cast<int>(i)));
    }
    bool drawn = false;
    if (file.dim == 2) {
      for (const SvgPath& p : paths) drawn = drawn || IsPolylineThrough(p, points);
    } else {
      drawn = true;
      for (size_t i = 0; i + 1 < points.size() && drawn; ++i) {
        bool link = false;
        for (const SvgPath& p : paths) {
          link = link || (p.vertices.size() == 2 && Near(p.vertices[0], points[i]) &&
                          Near(p.vertices[1], points[i + 1]));
        }
        drawn = link;
      }
    }
    if (drawn) found.push_back(static_cast<int>(f));
  }
  return found;
}

class EveryPointTest : public testing::TestWithParam<int> {};

TEST_P(EveryPointTest, EveryFrameAndPointIsDrawnWithEveryK1) {
  const ResultFile file = SmallScene(GetParam());
  FigureOptions options = GoldenOptions();
  options.every_k = 1;
  TempDir dir;
  WriteSnapshotFigure(file, options, dir.Path("all.svg"));
  EXPECT_EQ(FramesFoundInSvg(file, file, options, dir.Path("all.svg")),
            (std::vector<int>{0, 1, 2, 3, 4, 5, 6}));
}

TEST_P(EveryPointTest, EveryKthFrameAndTheLastAreDrawnAndNoOther) {
  const ResultFile file = SmallScene(GetParam());
  FigureOptions options = GoldenOptions();
  options.every_k = 4;
  TempDir dir;
  WriteSnapshotFigure(file, options, dir.Path("k4.svg"));
  EXPECT_EQ(FramesFoundInSvg(file, file, options, dir.Path("k4.svg")), (std::vector<int>{0, 4, 6}));
}

TEST_P(EveryPointTest, AMovedPointIsNotFound) {
  // The check itself: a frame whose point 3 is moved by 2 pixels' worth is not found.
  ResultFile file = SmallScene(GetParam());
  FigureOptions options = GoldenOptions();
  options.every_k = 1;
  TempDir dir;
  WriteSnapshotFigure(file, options, dir.Path("all.svg"));
  ResultFile moved = file;
  moved.result.frames.mutable_points(2)(3, 1) += 0.02;  // about 1 pixel in a 480 x 360 picture
  EXPECT_EQ(FramesFoundInSvg(file, moved, options, dir.Path("all.svg")),
            (std::vector<int>{0, 1, 3, 4, 5, 6}));
}

INSTANTIATE_TEST_SUITE_P(Dims, EveryPointTest, testing::Values(2, 3),
                         [](const testing::TestParamInfo<int>& i) {
                           return std::to_string(i.param) + "D";
                         });

TEST(SnapshotFramesTest, StrideAndLast) {
  EXPECT_EQ(SnapshotFrames(7, 1), (std::vector<int>{0, 1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(SnapshotFrames(7, 4), (std::vector<int>{0, 4, 6}));
  EXPECT_EQ(SnapshotFrames(1, 0), (std::vector<int>{0}));
  EXPECT_EQ(SnapshotFrames(16, 0).size(), 16u);
  for (int frames : {17, 100, 2651}) {
    const std::vector<int> drawn = SnapshotFrames(frames, 0);
    EXPECT_LE(drawn.size(), 16u) << frames;
    EXPECT_GE(drawn.size(), 9u) << frames;
    EXPECT_EQ(drawn.back(), frames - 1);
  }
}

TEST(SnapshotFigureTest, SvgPngPdfFromTheExtensionAndAutomaticHeight) {
  TempDir dir;
  FigureOptions options;  // height 0: automatic
  const ResultFile file = SmallScene(2);
  for (const char* name : {"f.svg", "f.PNG", "f.pdf"})
    WriteSnapshotFigure(file, options, dir.Path(name));
  EXPECT_EQ(ReadFile(dir.Path("f.svg")).rfind("<?xml", 0), 0u);
  EXPECT_EQ(ReadFile(dir.Path("f.PNG")).substr(1, 3), "PNG");
  EXPECT_EQ(ReadFile(dir.Path("f.pdf")).rfind("%PDF-", 0), 0u);
  const Image png = ReadPng(dir.Path("f.PNG"));
  EXPECT_EQ(png.width, 960);
  EXPECT_GE(png.height, 384);
  EXPECT_LE(png.height, 1152);
}

// Links with a radius (a run's link_radius, a robot's capsules) are drawn as their capsules: for
// every link of the last configuration, in 2D and 3D, one stroke between its ends' pixels with
// round caps and the width of its diameter at the scene's scale (orthographic: the capsule's
// exact outline); without radii, none.
TEST(SnapshotFigureTest, LinksWithARadiusAreDrawnAsTheirCapsules) {
  for (int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    TempDir dir;
    FigureOptions options;
    ResultFile file = SmallScene(dim);
    const Eigen::Index n = file.result.lengths.size();
    const Eigen::VectorXd radii = Eigen::VectorXd::LinSpaced(n, 0.03, 0.08);
    // The links of `f`'s last configuration drawn as a capsule of `radii`.
    const auto capsules = [&](const ResultFile& f, const std::string& name) {
      WriteSnapshotFigure(f, options, dir.Path(name));
      const std::vector<SvgPath> paths = SvgPaths(ReadFile(dir.Path(name)));
      const render::ChainScene scene = render::LayoutSnapshot(f, options).scene;
      const int last = static_cast<int>(f.result.frames.size()) - 1;
      int found = 0;
      for (Eigen::Index i = 0; i < n; ++i) {
        const Eigen::Vector2d a = scene.Pixel(f, last, static_cast<int>(i));
        const Eigen::Vector2d b = scene.Pixel(f, last, static_cast<int>(i + 1));
        const double scale = scene.scale();
        for (const SvgPath& p : paths) {
          if (p.vertices.size() != 2 || !Near(p.vertices[0], a) || !Near(p.vertices[1], b))
            continue;
          if (p.style.find("stroke-linecap:round") == std::string::npos) continue;
          const std::smatch m = [&] {
            std::smatch match;
            static const std::regex kWidth(R"(stroke-width:([0-9.]+))");
            std::regex_search(p.style, match, kWidth);
            return match;
          }();
          if (m.empty()) continue;
          const double width = std::stod(m[1].str());
          if (std::fabs(width - 2.0 * radii[i] * scale) < 1e-3 * width + 0.01) {
            ++found;
            break;
          }
        }
      }
      return found;
    };
    EXPECT_EQ(capsules(file, "plain.svg"), 0);
    file.link_radii = radii;
    EXPECT_EQ(capsules(file, "capsules.svg"), n);
  }
}

// ---------------------------------------------------------------------------------------------
// Plots.

// The discs (filled paths with curves) of an SVG: where each starts. cairo starts a full circle
// at angle 0, (x + r, y), so for discs of one radius these are their centres moved by (r, 0).

TEST(PlotTest, PathLengthHasOneMarkerPerPointAtItsValue) {
  const ResultFile file = SmallScene(2);
  TempDir dir;
  WritePlot(file, PlotKind::kPathLength, PlotOptions(), dir.Path("p.svg"));
  const std::vector<Eigen::Vector2d> marks = Discs(SvgPaths(ReadFile(dir.Path("p.svg"))));
  const Eigen::VectorXd& length = file.result.metrics.path_length;
  ASSERT_EQ(static_cast<Eigen::Index>(marks.size()), length.size());  // 6 points
  // Equally spaced in x, left to right; y linear in the path length (up = longer).
  const double dx = marks[1].x() - marks[0].x();
  EXPECT_GT(dx, 0.0);
  const double dy_per_unit =
      (marks.back().y() - marks[0].y()) / (length[length.size() - 1] - length[0]);
  EXPECT_LT(dy_per_unit, 0.0);
  for (size_t i = 0; i < marks.size(); ++i) {
    EXPECT_NEAR(marks[i].x() - marks[0].x(), dx * i, 0.02) << i;
    EXPECT_NEAR(marks[i].y() - marks[0].y(), dy_per_unit * (length[i] - length[0]), 0.05) << i;
  }
  // The motion dies out along the chain: the trailing end moved least.
  EXPECT_LT(length[length.size() - 1], length[0]);
}

TEST(PlotTest, LinkAnglesHasOneLinePerLinkThroughEveryFrame) {
  const ResultFile file = SmallScene(3);
  TempDir dir;
  WritePlot(file, PlotKind::kLinkAngles, PlotOptions(), dir.Path("a.svg"));
  // Lines with one vertex per frame (7) and distinct colours: one per link (5).
  std::vector<std::string> styles;
  for (const SvgPath& p : SvgPaths(ReadFile(dir.Path("a.svg")))) {
    if (!p.closed && !p.curved && p.vertices.size() == file.result.frames.size())
      styles.push_back(p.style);
  }
  EXPECT_EQ(styles.size(), 5u);
  std::sort(styles.begin(), styles.end());
  EXPECT_EQ(std::unique(styles.begin(), styles.end()) - styles.begin(), 5);
}

TEST(PlotTest, LengthErrorHasOneMarkerPerFrameOnALogScale) {
  ResultFile file = SmallScene(2);
  // Known errors: stretch link 2 of frame f by 10^-(f + 4), frame 0 exact.
  for (size_t f = 1; f < file.result.frames.size(); ++f) {
    Eigen::Map<Points> p = file.result.frames.mutable_points(f);
    const Eigen::RowVectorXd d = p.row(2) - p.row(1);
    p.row(2) = p.row(1) + d * (1.0 + std::pow(10.0, -static_cast<double>(f + 4)));
    // Keep the rest of the chain's links as they were.
    for (Eigen::Index i = 3; i < p.rows(); ++i)
      p.row(i) += d * std::pow(10.0, -static_cast<double>(f + 4));
  }
  const Eigen::VectorXd errors = FrameLengthErrors(file.result);
  for (size_t f = 1; f < file.result.frames.size(); ++f) {
    EXPECT_NEAR(std::log10(errors[f]), -static_cast<double>(f + 4), 0.01) << f;
  }
  TempDir dir;
  WritePlot(file, PlotKind::kLengthError, PlotOptions(), dir.Path("e.svg"));
  const std::vector<Eigen::Vector2d> marks = Discs(SvgPaths(ReadFile(dir.Path("e.svg"))));
  ASSERT_EQ(marks.size(), file.result.frames.size());
  // One decade is the same height everywhere (log scale).
  const double decade = marks[2].y() - marks[1].y();
  EXPECT_GT(decade, 5.0);
  for (size_t f = 2; f < marks.size(); ++f)
    EXPECT_NEAR(marks[f].y() - marks[f - 1].y(), decade, 0.3) << f;
}

TEST(PlotTest, NamesRoundTrip) {
  for (const auto& [kind, name, summary] : Vocabulary<PlotKind>::kEntries)
    EXPECT_EQ(ParsePlotKind(PlotKindName(kind)), kind);
  test_util::ExpectInputError([] { ParsePlotKind("speed", "--plot"); }, "--plot", "path_length");
}

// ---------------------------------------------------------------------------------------------
// Animations: what ffprobe says about them.

struct Probe {
  std::string codec;
  int width = 0, height = 0, frames = 0;
  std::string pix_fmt;
};

Probe FfProbe(const std::string& path) {
  const std::string command =
      "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
      "stream=codec_name,width,height,nb_read_frames,pix_fmt -of default=noprint_wrappers=1 '" +
      path + "'";
  Probe probe;
  FILE* out = ::popen(command.c_str(), "r");
  if (out == nullptr) return probe;
  char line[256];
  while (std::fgets(line, sizeof line, out) != nullptr) {
    std::string text(line);
    while (!text.empty() && text.back() == '\n') text.pop_back();
    const size_t eq = text.find('=');
    const std::string key = text.substr(0, eq), value = text.substr(eq + 1);
    if (key == "codec_name") probe.codec = value;
    if (key == "width") probe.width = std::stoi(value);
    if (key == "height") probe.height = std::stoi(value);
    if (key == "nb_read_frames") probe.frames = std::stoi(value);
    if (key == "pix_fmt") probe.pix_fmt = value;
  }
  ::pclose(out);
  return probe;
}

AnimationOptions SmallAnimation() {
  AnimationOptions options;
  options.width = 201;  // odd: rounded up to 202
  options.height = 150;
  options.fps = 10;
  options.min_seconds = 0.0;  // one video frame per picture
  options.end_pause = 0.0;
  return options;
}

TEST(AnimationTest, Mp4HasOneFramePerRecordedFrameInH264) {
  TempDir dir;
  WriteAnimation(SmallScene(3), SmallAnimation(), dir.Path("a.mp4"));
  const Probe probe = FfProbe(dir.Path("a.mp4"));
  EXPECT_EQ(probe.codec, "h264");
  EXPECT_EQ(probe.pix_fmt, "yuv420p");
  EXPECT_EQ(probe.width, 202);
  EXPECT_EQ(probe.height, 150);
  EXPECT_EQ(probe.frames, 7);
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"a.mp4"});  // no temporary file left
}

TEST(AnimationTest, GifSubsampledToMaxFrames) {
  TempDir dir;
  AnimationOptions options = SmallAnimation();
  options.max_frames = 4;  // 7 frames: 0, 2, 4, 6
  WriteAnimation(SmallScene(2), options, dir.Path("a.gif"));
  const Probe probe = FfProbe(dir.Path("a.gif"));
  EXPECT_EQ(probe.codec, "gif");
  EXPECT_EQ(probe.width, 202);
  EXPECT_EQ(probe.height, 150);
  EXPECT_EQ(probe.frames, 4);
}

TEST(AnimationTest, ShortRunsAreStretchedAndTheEndHeld) {
  TempDir dir;
  AnimationOptions options = SmallAnimation();
  options.min_seconds = 2.0;  // 7 pictures at 10 fps: each 3 times (2.1 s)
  options.end_pause = 0.5;    // and the last 5 more
  WriteAnimation(SmallScene(2), options, dir.Path("a.mp4"));
  EXPECT_EQ(FfProbe(dir.Path("a.mp4")).frames, 7 * 3 + 5);
}

TEST(AnimationTest, MissingFfmpegIsAClearErrorAndLeavesTheOldFile) {
  TempDir dir;
  render_test::WriteFile(dir.Path("a.mp4"), "precious");
  AnimationOptions options = SmallAnimation();
  options.ffmpeg = dir.Path("no-such-ffmpeg");
  try {
    WriteAnimation(SmallScene(2), options, dir.Path("a.mp4"));
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot run ffmpeg"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("No such file or directory"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(ReadFile(dir.Path("a.mp4")), "precious");
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"a.mp4"});
}

TEST(AnimationTest, FailingFfmpegIsAClearErrorAndLeavesTheOldFile) {
  TempDir dir;
  render_test::WriteFile(dir.Path("a.gif"), "precious");
  AnimationOptions options = SmallAnimation();
  options.ffmpeg = "false";  // exits 1 at once, without reading its input
  try {
    WriteAnimation(SmallScene(2), options, dir.Path("a.gif"));
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("exit status 1"), std::string::npos) << e.what();
  }
  EXPECT_EQ(ReadFile(dir.Path("a.gif")), "precious");
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"a.gif"});
}

// ---------------------------------------------------------------------------------------------
// Bad input: an InputError naming the field, and no file written or changed.

class BadInputTest : public testing::Test {
 protected:
  void SetUp() override {
    for (const char* name : {"f.svg", "f.png", "f.pdf", "p.png", "a.mp4"}) {
      render_test::WriteFile(dir_.Path(name), "precious");
    }
  }
  void TearDown() override {
    for (const char* name : {"f.svg", "f.png", "f.pdf", "p.png", "a.mp4"}) {
      EXPECT_EQ(ReadFile(dir_.Path(name)), "precious") << name;
    }
    EXPECT_EQ(dir_.Files().size(), 5u);
  }
  // Expects every writer to refuse `file` with an InputError for `field`.
  void ExpectAllRefuse(const ResultFile& file, const std::string& field) {
    for (const char* name : {"f.svg", "f.png", "f.pdf"}) {
      test_util::ExpectInputError(
          [&] { WriteSnapshotFigure(file, FigureOptions(), dir_.Path(name)); }, field, "");
    }
    test_util::ExpectInputError(
        [&] { WritePlot(file, PlotKind::kPathLength, PlotOptions(), dir_.Path("p.png")); }, field,
        "");
    test_util::ExpectInputError(
        [&] { WriteAnimation(file, AnimationOptions(), dir_.Path("a.mp4")); }, field, "");
  }
  TempDir dir_;
};

TEST_F(BadInputTest, NanInAPoint) {
  ResultFile file = SmallScene(3);
  file.result.frames.mutable_points(4)(2, 1) = std::nan("");
  ExpectAllRefuse(file, "frames[4].points[2][1]");
}

TEST_F(BadInputTest, InfiniteLinkAngle) {
  ResultFile file = SmallScene(2);
  file.result.frames.mutable_link_angles(1)[0] = INFINITY;
  ExpectAllRefuse(file, "frames[1].link_angles[0]");
}

TEST_F(BadInputTest, NoFrames) {
  ResultFile file = SmallScene(2);
  ResultFile none = file;
  none.result.frames.Clear();
  ExpectAllRefuse(none, "frames");
}

TEST_F(BadInputTest, InvalidOptionsNameTheField) {
  const ResultFile file = SmallScene(2);
  FigureOptions figure;
  figure.width = 0;
  test_util::ExpectInputError([&] { WriteSnapshotFigure(file, figure, dir_.Path("f.png")); },
                              "width", "64 to 8192");
  figure = FigureOptions();
  figure.elevation = 91;
  test_util::ExpectInputError([&] { WriteSnapshotFigure(file, figure, dir_.Path("f.svg")); },
                              "elevation", "-90 to 90");
  figure = FigureOptions();
  figure.every_k = -1;
  test_util::ExpectInputError([&] { WriteSnapshotFigure(file, figure, dir_.Path("f.svg")); },
                              "every_k", "-1");
  PlotOptions plot;
  plot.height = -5;
  test_util::ExpectInputError(
      [&] { WritePlot(file, PlotKind::kLinkAngles, plot, dir_.Path("p.png")); }, "height", "-5");
  AnimationOptions animation;
  animation.fps = 0;
  test_util::ExpectInputError([&] { WriteAnimation(file, animation, dir_.Path("a.mp4")); }, "fps",
                              "1 to 120");
  animation = AnimationOptions();
  animation.max_frames = 1;
  test_util::ExpectInputError([&] { WriteAnimation(file, animation, dir_.Path("a.mp4")); },
                              "max_frames", ">= 2");
  test_util::ExpectInputError(
      [&] { WriteSnapshotFigure(file, FigureOptions(), dir_.Path("f.jpg")); }, "path",
      ".svg, .png or .pdf");
  test_util::ExpectInputError([&] { WriteAnimation(file, AnimationOptions(), dir_.Path("a.avi")); },
                              "path", ".mp4 or .gif");
}

TEST(RenderFileErrorTest, MissingDirectoryIsASystemErrorAndWritesNothing) {
  TempDir dir;
  const ResultFile file = SmallScene(2);
  EXPECT_THROW(WriteSnapshotFigure(file, FigureOptions(), dir.Path("no/such/f.png")),
               std::system_error);
  EXPECT_THROW(WriteAnimation(file, SmallAnimation(), dir.Path("no/such/a.gif")),
               std::system_error);
  EXPECT_TRUE(dir.Files().empty());
}

}  // namespace
}  // namespace flexkin
