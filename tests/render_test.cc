// Tests of flexkin_render: golden PNG images of two small scenes, every frame and every point
// drawn (checked in the SVG's paths), the plots' markers, the animations (ffprobe), and bad
// input leaving no file behind.
//
// Regenerate the goldens (tests/golden/*.png) after an intended change of the look with
//   FLEXKIN_UPDATE_GOLDEN=1 build/tests/render_test --gtest_filter='*Golden*'
// and look at them before committing.
#include <cairo.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/render.h"
#include "render/snapshot.h"
#include "render_test_util.h"
#include "test_util.h"

namespace flexkin {
namespace {

using render_test::Exists;
using render_test::ReadFile;
using render_test::SmallScene;
using render_test::SvgPath;
using render_test::SvgPaths;
using render_test::TempDir;

// ---------------------------------------------------------------------------------------------
// Golden images.

struct Image {
  int width = 0, height = 0;
  std::vector<uint32_t> pixels;  // 0xXXRRGGBB
};

Image ReadPng(const std::string& path) {
  Image image;
  cairo_surface_t* s = cairo_image_surface_create_from_png(path.c_str());
  if (cairo_surface_status(s) == CAIRO_STATUS_SUCCESS) {
    cairo_surface_flush(s);
    image.width = cairo_image_surface_get_width(s);
    image.height = cairo_image_surface_get_height(s);
    const unsigned char* data = cairo_image_surface_get_data(s);
    const int stride = cairo_image_surface_get_stride(s);
    for (int y = 0; y < image.height; ++y) {
      const auto* row = reinterpret_cast<const uint32_t*>(data + static_cast<size_t>(y) * stride);
      image.pixels.insert(image.pixels.end(), row, row + image.width);
    }
  }
  cairo_surface_destroy(s);
  return image;
}

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
}

// ---------------------------------------------------------------------------------------------
// Every frame and every point is drawn: the SVG's paths are searched for each configuration.

constexpr double kTolerance = 0.02;  // pixels; cairo keeps 1/256 px and writes 6 decimals

bool Near(const std::pair<double, double>& v, const Eigen::Vector2d& p) {
  return std::abs(v.first - p.x()) < kTolerance && std::abs(v.second - p.y()) < kTolerance;
}

// Distance from `p` to the segment a-b.
double SegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = b - a;
  const double t = d.squaredNorm() > 0 ? std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
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
  moved.result.frames[2].points(3, 1) += 0.02;  // about 1 pixel in a 480 x 360 picture
  EXPECT_EQ(FramesFoundInSvg(file, moved, options, dir.Path("all.svg")),
            (std::vector<int>{0, 1, 3, 4, 5, 6}));
}

INSTANTIATE_TEST_SUITE_P(Dims, EveryPointTest, testing::Values(2, 3),
                         [](const testing::TestParamInfo<int>& i) { return std::to_string(i.param) + "D"; });

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
  for (const char* name : {"f.svg", "f.PNG", "f.pdf"}) WriteSnapshotFigure(file, options, dir.Path(name));
  EXPECT_EQ(ReadFile(dir.Path("f.svg")).rfind("<?xml", 0), 0u);
  EXPECT_EQ(ReadFile(dir.Path("f.PNG")).substr(1, 3), "PNG");
  EXPECT_EQ(ReadFile(dir.Path("f.pdf")).rfind("%PDF-", 0), 0u);
  const Image png = ReadPng(dir.Path("f.PNG"));
  EXPECT_EQ(png.width, 960);
  EXPECT_GE(png.height, 384);
  EXPECT_LE(png.height, 1152);
}

}  // namespace
}  // namespace flexkin
