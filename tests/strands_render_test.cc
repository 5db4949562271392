// Tests of the strand file pictures (include/flexkin/strands_render.h) and of `flexkin render` of a
// strand file: valid images with the scalp and the strands in them, deterministic output,
// animations of the right size and length, options refused by name, files written whole or not
// at all, and chain results drawn as before.
#include "flexkin/strands_render.h"

#include <cairo.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "flexkin/strand_file.h"
#include "flexkin/strands.h"
#include "png_test_util.h"
#include "render/canvas.h"
#include "render/strands_scene.h"
#include "render/style.h"
#include "render_test_util.h"

namespace flexkin {
namespace {

using render_test::Exists;
using render_test::TempDir;
using test_util::ReadFile;

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "in: " << (text)

// A head of radius 0.1 (a circle in 2D) with `num_strands` straight strands of `links` links
// growing out of its upper part; over `frames` frames it turns 50 degrees about z, then nods 25
// degrees about y (2D: turns about z and back). Written with StrandFileWriter.
void WriteHairFile(const std::string& path, int num_strands, int links, int frames, int dim = 3,
                   bool scalp = true, double link_length = 0.012,
                   const std::vector<Collider>& body_colliders = {}) {
  constexpr double kRadius = 0.1;
  std::vector<Points> strands;
  StrandFileHeader header;
  header.name = "test groom";
  header.dim = dim;
  header.num_frames = frames;
  header.fps = 10.0;
  header.offsets.push_back(0);
  for (int i = 0; i < num_strands; ++i) {
    Eigen::Vector3d n;
    if (dim == 3) {  // a Fibonacci spiral over z > -0.3
      const double z = 1.0 - 1.3 * (i + 0.5) / num_strands;
      const double a = i * M_PI * (3.0 - std::sqrt(5.0));
      n = {std::sqrt(1.0 - z * z) * std::cos(a), std::sqrt(1.0 - z * z) * std::sin(a), z};
    } else {
      const double a = M_PI * (0.1 + 0.8 * (i + 0.5) / num_strands);
      n = {std::cos(a), std::sin(a), 0.0};
    }
    Points p(links + 1, dim);
    for (int k = 0; k <= links; ++k) {
      const Eigen::Vector3d q = (kRadius + k * link_length) * n;
      for (int c = 0; c < dim; ++c) p(k, c) = q[c];
    }
    strands.push_back(p);
    header.offsets.push_back(header.offsets.back() + links + 1);
  }
  header.link_lengths = Eigen::VectorXd::Constant(num_strands * links, link_length);
  if (scalp) {
    header.scalp.shape = "sphere";
    header.scalp.radii = Eigen::Vector3d::Constant(kRadius);
  }
  header.body_colliders = body_colliders;
  StrandBatch batch(strands);
  StrandFileWriter writer(path, header);
  for (int f = 0; f < frames; ++f) {
    const double s = frames > 1 ? static_cast<double>(f) / (frames - 1) : 0.0;
    BodyPose pose;
    if (dim == 3) {
      const double turn = 50.0 * std::min(1.0, 2.0 * s), nod = 25.0 * std::max(0.0, 2.0 * s - 1.0);
      pose.rotation = (Eigen::AngleAxisd(turn * M_PI / 180, Eigen::Vector3d::UnitZ()) *
                       Eigen::AngleAxisd(nod * M_PI / 180, Eigen::Vector3d::UnitY()))
                          .toRotationMatrix();
    } else {
      pose = BodyPose::Planar(0.8 * std::sin(M_PI * s), 0.0, 0.0);
    }
    if (f > 0) StepStrands(&batch, pose);
    writer.Add(f, f / header.fps, pose, batch);
  }
  writer.Commit(StrandRunReport{});
}

using render_test::Image;
using render_test::ReadPng;

// Pixels of the shaded scalp: a light, slightly warm grey (red a little above blue, green
// between), unlike the strands' purples and ambers and the white background.
int ScalpPixels(const Image& image) {
  int count = 0;
  for (const uint32_t p : image.pixels) {
    const double r = (p >> 16 & 255) / 255.0, g = (p >> 8 & 255) / 255.0, b = (p & 255) / 255.0;
    if (r > 0.55 && r < 0.985 && r - b > 0.02 && r - b < 0.10 && g <= r && g >= b) ++count;
  }
  return count;
}

// Pixels of the strands' colours: purple (blue above green) or warm (red well above blue),
// which neither the white background nor the scalp's grey nor its outline has.
int StrandPixels(const Image& image) {
  int count = 0;
  for (const uint32_t p : image.pixels) {
    const int r = p >> 16 & 255, g = p >> 8 & 255, b = p & 255;
    if (b > g + 15 || r - b > 50) ++count;
  }
  return count;
}

struct Probe {
  std::string codec;
  int width = 0, height = 0, frames = 0;
};

Probe FfProbe(const std::string& path) {
  const std::string command =
      "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
      "stream=codec_name,width,height,nb_read_frames -of default=noprint_wrappers=1 '" +
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
  }
  ::pclose(out);
  return probe;
}

class StrandsRenderTest : public testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(dir_.dir().empty());
    if (const char* keep = std::getenv("FLEXKIN_STRANDS_RENDER_KEEP")) keep_ = keep;
    hair_ = dir_.Path("hair.npz");
    WriteHairFile(hair_, 150, 8, 21);
  }
  void Snapshot(const std::string& name, const StrandsRenderOptions& options = {},
                const std::string& file = "") {
    StrandFileReader reader(file.empty() ? hair_ : file);
    RenderStrandsSnapshot(&reader, options, dir_.Path(name));
  }
  void Animation(const std::string& name, const StrandsRenderOptions& options,
                 const std::string& file = "") {
    StrandFileReader reader(file.empty() ? hair_ : file);
    RenderStrandsAnimation(&reader, options, dir_.Path(name));
  }
  // The field of the InputError that rendering with `options` throws ("" if none).
  std::string RefusedField(const StrandsRenderOptions& options) {
    try {
      Snapshot("refused.png", options);
    } catch (const InputError& e) {
      return e.field();
    }
    return "";
  }

  void TearDown() override {
    if (keep_.empty()) return;
    for (const std::string& name : dir_.Files()) {
      if (name.find(".npz") == std::string::npos)
        std::filesystem::copy_file(dir_.Path(name), keep_ + "/" + name,
                                   std::filesystem::copy_options::overwrite_existing);
    }
  }

  TempDir dir_;
  std::string hair_;
  std::string keep_;  // FLEXKIN_STRANDS_RENDER_KEEP: a directory to copy the pictures to
};

TEST_F(StrandsRenderTest, PngShowsTheScalpAndTheStrands) {
  StrandsRenderOptions options;
  options.width = 800;
  Snapshot("f.png", options);
  const Image image = ReadPng(dir_.Path("f.png"));
  ASSERT_EQ(image.width, 800);
  EXPECT_GT(image.height, 150);
  EXPECT_GT(ScalpPixels(image), 2000);
  EXPECT_GT(StrandPixels(image), 2000);
}

TEST_F(StrandsRenderTest, NoScalpWithoutOne) {
  WriteHairFile(dir_.Path("bare.npz"), 150, 8, 21, 3, /*scalp=*/false);
  Snapshot("bare.png", {}, dir_.Path("bare.npz"));
  Snapshot("f.png");
  const Image bare = ReadPng(dir_.Path("bare.png")), scalp = ReadPng(dir_.Path("f.png"));
  EXPECT_GT(ScalpPixels(scalp), 10 * ScalpPixels(bare));  // antialiased strands: a few
  EXPECT_GT(StrandPixels(bare), 2000);
}

// Pixels of the colliders' fill (render::kColliderFill, to antialiasing's rounding).
int ColliderPixels(const Image& image) {
  const render::Rgb want = render::kColliderFill;
  int count = 0;
  for (const uint32_t p : image.pixels) {
    const int r = p >> 16 & 255, g = p >> 8 & 255, b = p & 255;
    if (std::abs(r - std::lround(255 * want.r)) <= 2 &&
        std::abs(g - std::lround(255 * want.g)) <= 2 &&
        std::abs(b - std::lround(255 * want.b)) <= 2) {
      ++count;
    }
  }
  return count;
}

// A groom's colliders other than the scalp (a neck capsule under the head, moving with it) are
// drawn, in the colliders' grey; the scalp's own collider is not drawn twice.
TEST_F(StrandsRenderTest, TheNeckAndOtherCollidersAreDrawn) {
  Collider scalp;
  scalp.shape = ColliderShape::kSphere;
  scalp.radius = 0.1;
  Collider neck;
  neck.shape = ColliderShape::kCapsule;
  neck.radius = 0.045;
  neck.half_length = 0.06;
  neck.pose.translation() = Eigen::Vector3d(0.0, 0.0, -0.17);
  for (const int dim : {2, 3}) {
    // In 2D the neck lies in the plane: its axis along y (the 3D one is along z).
    neck.pose.linear() = dim == 2 ? Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()).matrix()
                                  : Eigen::Matrix3d::Identity();
    neck.pose.translation() =
        dim == 2 ? Eigen::Vector3d(0.0, -0.17, 0.0) : Eigen::Vector3d(0.0, 0.0, -0.17);
    WriteHairFile(dir_.Path("neck.npz"), 150, 8, 21, dim, true, 0.012, {scalp, neck});
    WriteHairFile(dir_.Path("bare.npz"), 150, 8, 21, dim, true, 0.012, {scalp});
    StrandsRenderOptions options;
    options.panels = 1;
    Snapshot("neck.png", options, dir_.Path("neck.npz"));
    Snapshot("bare.png", options, dir_.Path("bare.npz"));
    const Image with = ReadPng(dir_.Path("neck.png")), without = ReadPng(dir_.Path("bare.png"));
    SCOPED_TRACE(std::to_string(dim) + "D");
    EXPECT_LT(ColliderPixels(without), 50);  // the scalp is shaded, not filled grey
    EXPECT_GT(ColliderPixels(with), 1000);
    // The figure grows to hold the neck: its height in the picture is not clipped.
    EXPECT_GT(ScalpPixels(with), 500);
  }
}

// One strand of 6 links from the sphere's surface along `direction` (pointing at the viewer of
// the default view, or away from it), with a second one to the side so the view has extent.
void WriteOneStrandFile(const std::string& path, double sign) {
  const double az = -60.0 * M_PI / 180, el = 20.0 * M_PI / 180;
  const Eigen::Vector3d toward(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                               std::sin(el));
  StrandFileHeader header;
  header.num_frames = 2;
  header.offsets = {0, 7, 14};
  header.link_lengths = Eigen::VectorXd::Constant(12, 0.02);
  header.scalp.shape = "sphere";
  header.scalp.radii = Eigen::Vector3d::Constant(0.1);
  const Eigen::Vector3d side = toward.cross(Eigen::Vector3d::UnitZ()).normalized();
  // Tilted from the line of sight by 30 degrees: in front it is seen across the scalp.
  const Eigen::Vector3d along =
      (sign * toward * std::cos(M_PI / 6) + toward.cross(side).normalized() * std::sin(M_PI / 6));
  Points points(14, 3);
  for (int k = 0; k < 7; ++k) {
    points.row(k) = ((0.1 + 0.02 * k) * along).transpose();
    points.row(7 + k) = ((0.1 + 0.02 * k) * side).transpose();
  }
  StrandFileWriter writer(path, header);
  for (int f = 0; f < 2; ++f) {
    StrandFrame frame;
    frame.frame = f;
    frame.time = f / 30.0;
    frame.points = points;
    writer.Add(frame);
  }
  writer.Commit(StrandRunReport{});
}

TEST_F(StrandsRenderTest, TheScalpHidesTheStrandsBehindIt) {
  WriteOneStrandFile(dir_.Path("front.npz"), 1.0);
  WriteOneStrandFile(dir_.Path("back.npz"), -1.0);
  StrandsRenderOptions options;
  options.panels = 1;
  options.line_width = 6.0;
  Snapshot("front.png", options, dir_.Path("front.npz"));
  Snapshot("back.png", options, dir_.Path("back.npz"));
  // The side strand is seen in both; the one near the line of sight only in front, where it
  // lies across the scalp.
  const Image front = ReadPng(dir_.Path("front.png")), back = ReadPng(dir_.Path("back.png"));
  EXPECT_GT(StrandPixels(front), StrandPixels(back) + 200);
  EXPECT_LT(ScalpPixels(front), ScalpPixels(back) - 200);
}

// PNG only: cairo's SVG ids count the surfaces of the process (docs/rendering.md).
TEST_F(StrandsRenderTest, OutputIsDeterministic) {
  Snapshot("a.png");
  Snapshot("b.png");
  EXPECT_EQ(ReadFile(dir_.Path("a.png")), ReadFile(dir_.Path("b.png")));
}

TEST_F(StrandsRenderTest, SvgAndPdfAreDocuments) {
  Snapshot("f.svg");
  Snapshot("f.pdf");
  const std::string svg = ReadFile(dir_.Path("f.svg"));
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_CONTAINS(svg, "</svg>");
  EXPECT_EQ(ReadFile(dir_.Path("f.pdf")).rfind("%PDF", 0), 0u);
}

TEST_F(StrandsRenderTest, PanelsAndFewerStrandsChangeThePicture) {
  StrandsRenderOptions one;
  one.panels = 1;
  one.width = 400;
  Snapshot("one.png", one);
  EXPECT_EQ(ReadPng(dir_.Path("one.png")).width, 400);
  StrandsRenderOptions few;
  few.max_strands = 10;
  Snapshot("few.svg", few);
  Snapshot("all.svg");
  EXPECT_LT(ReadFile(dir_.Path("few.svg")).size(), ReadFile(dir_.Path("all.svg")).size() / 3);
}

TEST_F(StrandsRenderTest, PlanarFile) {
  WriteHairFile(dir_.Path("flat.npz"), 40, 10, 9, 2);
  Snapshot("flat.png", {}, dir_.Path("flat.npz"));
  const Image image = ReadPng(dir_.Path("flat.png"));
  EXPECT_GT(ScalpPixels(image), 1000);
  EXPECT_GT(StrandPixels(image), 1000);
  StrandsRenderOptions options;
  options.width = 160;
  Animation("flat.mp4", options, dir_.Path("flat.npz"));
  EXPECT_EQ(FfProbe(dir_.Path("flat.mp4")).width, 160);
}

TEST_F(StrandsRenderTest, Mp4HasOneFramePerDrawnFrameAndTheEndHeld) {
  StrandsRenderOptions options;
  options.width = 321;  // odd: rounded up to 322
  options.height = 241;
  options.end_pause = 0.5;  // at the file's 10 fps: 5 more
  Animation("a.mp4", options);
  const Probe probe = FfProbe(dir_.Path("a.mp4"));
  EXPECT_EQ(probe.codec, "h264");
  EXPECT_EQ(probe.width, 322);
  EXPECT_EQ(probe.height, 242);
  EXPECT_EQ(probe.frames, 21 + 5);
  EXPECT_EQ(dir_.Files(), (std::vector<std::string>{"a.mp4", "hair.npz"}));
}

TEST_F(StrandsRenderTest, GifSubsampledToMaxFrames) {
  StrandsRenderOptions options;
  options.width = 200;
  options.max_frames = 6;  // 21 frames: 0, 4, ..., 20
  options.end_pause = 0.0;
  Animation("a.gif", options);
  const Probe probe = FfProbe(dir_.Path("a.gif"));
  EXPECT_EQ(probe.codec, "gif");
  EXPECT_EQ(probe.frames, 6);
}

TEST_F(StrandsRenderTest, BadOptionsAreNamed) {
  const auto with = [](auto set) {
    StrandsRenderOptions o;
    set(o);
    return o;
  };
  EXPECT_EQ(RefusedField(with([](auto& o) { o.width = 10; })), "width");
  EXPECT_EQ(RefusedField(with([](auto& o) { o.height = 9000; })), "height");
  EXPECT_EQ(RefusedField(with([](auto& o) { o.panels = 9; })), "panels");
  EXPECT_EQ(RefusedField(with([](auto& o) { o.elevation = 91; })), "elevation");
  EXPECT_EQ(RefusedField(with([](auto& o) { o.azimuth = NAN; })), "azimuth");
  EXPECT_EQ(RefusedField(with([](auto& o) { o.max_strands = -1; })), "max_strands");
  EXPECT_EQ(RefusedField(with([](auto& o) { o.line_width = 50; })), "line_width");
  EXPECT_EQ(RefusedField(with([](auto& o) { o.fps = 500; })), "fps");
  EXPECT_EQ(RefusedField(with([](auto& o) { o.max_frames = 1; })), "max_frames");
  EXPECT_EQ(RefusedField(with([](auto& o) { o.crf = 52; })), "crf");
  EXPECT_EQ(RefusedField(with([](auto& o) { o.end_pause = -1; })), "end_pause");
  EXPECT_FALSE(Exists(dir_.Path("refused.png")));
  EXPECT_EQ(RefusedField({}), "");
  try {
    Snapshot("f.txt");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "path");
  }
}

TEST_F(StrandsRenderTest, FailedAnimationLeavesTheOldFile) {
  render_test::WriteFile(dir_.Path("a.mp4"), "precious");
  StrandsRenderOptions options;
  options.width = 128;
  options.ffmpeg = dir_.Path("no-such-ffmpeg");
  EXPECT_THROW(Animation("a.mp4", options), std::runtime_error);
  options.ffmpeg = "false";  // starts, then fails
  EXPECT_THROW(Animation("a.mp4", options), std::runtime_error);
  EXPECT_EQ(ReadFile(dir_.Path("a.mp4")), "precious");
  EXPECT_EQ(dir_.Files(), (std::vector<std::string>{"a.mp4", "hair.npz"}));
}

TEST_F(StrandsRenderTest, FailedFigureLeavesTheOldFile) {
  render_test::WriteFile(dir_.Path("f.png"), "precious");
  StrandsRenderOptions options;
  options.panels = 0;
  EXPECT_THROW(Snapshot("f.png", options), InputError);
  EXPECT_EQ(ReadFile(dir_.Path("f.png")), "precious");
}

// The figures of docs/rendering.md: milliseconds per drawn frame of a big groom. Run with
// --gtest_also_run_disabled_tests; FLEXKIN_STRANDS_TIMING="STRANDSxLINKSxFRAMES" sets the size
// (default 5000x24x31).
TEST_F(StrandsRenderTest, DISABLED_Timing) {
  int strands = 5000, links = 24, frames = 31;
  if (const char* size = std::getenv("FLEXKIN_STRANDS_TIMING"))
    std::sscanf(size, "%dx%dx%d", &strands, &links, &frames);
  WriteHairFile(dir_.Path("big.npz"), strands, links, frames, 3, true, 0.2 / links);
  using Clock = std::chrono::steady_clock;
  const auto ms = [](Clock::time_point since) {
    return std::chrono::duration<double, std::milli>(Clock::now() - since).count();
  };
  // The drawing alone: one 960 x 720 picture per frame.
  StrandFileReader reader(dir_.Path("big.npz"));
  render::StrandsView view(3, -60.0, 20.0);
  render::ViewBounds bounds;
  bounds.u0 = bounds.v0 = bounds.d0 = -0.35;
  bounds.u1 = bounds.v1 = bounds.d1 = 0.35;
  view.Fit(bounds, 0.0, {0, 0, 960, 720});
  std::vector<int> all(strands);
  for (int i = 0; i < strands; ++i) all[i] = i;
  render::StrandsStyle style;
  style.root_width = 0.9;
  render::StrandsWork work;
  render::Canvas canvas(ImageFormat::kPng, 960, 720);
  // CPU time of this thread: the figure holds on a busy machine.
  const auto cpu_ms = [] {
    timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return 1e3 * t.tv_sec + 1e-6 * t.tv_nsec;
  };
  StrandFrame frame;
  double drawing = 0.0;
  while (reader.Next(&frame)) {
    canvas.Clear();
    const double start = cpu_ms();
    render::DrawStrandsFrame(canvas.cr(), view, reader.header(), all, frame.points, frame.pose,
                             frame.time, style, &work);
    cairo_surface_flush(canvas.surface());
    drawing += cpu_ms() - start;
  }
  StrandsRenderOptions options;
  options.width = 960;
  options.end_pause = 0.0;
  auto start = Clock::now();
  Animation("big.mp4", options, dir_.Path("big.npz"));
  const double animation = ms(start);
  start = Clock::now();
  Snapshot("big.png", {}, dir_.Path("big.npz"));
  const double figure = ms(start);
  std::printf(
      "%d x %d, %d frames: drawing %.1f ms CPU per frame (960 x 720); the MP4 %.1f ms per "
      "frame (with reading and encoding); the figure of 4 panels %.0f ms\n",
      strands, links, frames, drawing / frames, animation / frames, figure);
}

// `flexkin render` of a strand file.
class StrandsRenderCliTest : public StrandsRenderTest {
 protected:
  test_util::CliResult Cli(const std::string& args) const {
    return test_util::RunCli(FLEXKIN_CLI, dir_.dir(), args);
  }
  std::vector<std::string> Outputs(const std::string& name) const {
    std::vector<std::string> files;
    if (!Exists(dir_.Path(name))) return files;
    for (const auto& e : std::filesystem::directory_iterator(dir_.Path(name))) {
      files.push_back(e.path().filename().string());
    }
    std::sort(files.begin(), files.end());
    return files;
  }
};

TEST_F(StrandsRenderCliTest, DefaultFormatsAreTheFigure) {
  const auto r = Cli("render hair.npz -o out --width 640");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(Outputs("out"), (std::vector<std::string>{"hair.png", "hair.svg"}));
  EXPECT_CONTAINS(r.out, "wrote out/hair.png");
  EXPECT_EQ(ReadPng(dir_.Path("out/hair.png")).width, 640);
}

TEST_F(StrandsRenderCliTest, FigureAndAnimation) {
  const auto r =
      Cli("render hair.npz -o out --formats svg,png,pdf,mp4,gif --width 320 --azimuth 30 "
          "--elevation 10 --fps 12 --max-frames 5 --max-strands 40 --title Hair -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(Outputs("out"),
            (std::vector<std::string>{"hair.gif", "hair.mp4", "hair.pdf", "hair.png", "hair.svg"}));
  const Probe probe = FfProbe(dir_.Path("out/hair.mp4"));
  EXPECT_EQ(probe.width, 320);
  EXPECT_EQ(probe.frames, 5 + 12);  // and the last held 1 s
  EXPECT_CONTAINS(ReadFile(dir_.Path("out/hair.svg")), "<svg");
}

TEST_F(StrandsRenderCliTest, FormatsOfChainsAreRefusedByName) {
  for (const char* format : {"plots", "glb", "gltf"}) {
    const auto r = Cli(std::string("render hair.npz -o out --formats png,") + format);
    EXPECT_EQ(r.exit_code, 1) << format;
    EXPECT_CONTAINS(r.err, "--formats");
    EXPECT_CONTAINS(r.err, std::string("\"") + format + "\"");
    EXPECT_CONTAINS(r.err, "strand files");
    EXPECT_CONTAINS(r.err, "svg, png, pdf, mp4, gif, html");
  }
  EXPECT_FALSE(Exists(dir_.Path("out")));
}

// html is the strand viewer (include/flexkin/strands_viewer.h, docs/viewer.md).
TEST_F(StrandsRenderCliTest, HtmlIsTheStrandViewer) {
  const auto r = Cli("render hair.npz -o out --formats png,html --max-frames 5 --title Hair");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(Outputs("out"), (std::vector<std::string>{"hair.html", "hair.png"}));
  const std::string page = ReadFile(dir_.Path("out/hair.html"));
  EXPECT_CONTAINS(page, "<html");
  EXPECT_CONTAINS(page, "Hair");
}

TEST_F(StrandsRenderCliTest, BadOptionsNameTheFlag) {
  auto r = Cli("render hair.npz -o out --width 10");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "--width");
  r = Cli("render hair.npz -o out --max-strands -2");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "--max-strands");
  r = Cli("render hair.npz -o out --formats mp4 --fps 1000");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_CONTAINS(r.err, "--fps");
  EXPECT_FALSE(Exists(dir_.Path("out")));
}

TEST_F(StrandsRenderCliTest, ChainResultsAreDrawnAsBefore) {
  WriteResultJson(render_test::SmallScene(3).result, dir_.Path("run.json"), "small");
  const auto r = Cli("render run.json -o out --formats svg,plots --max-strands 5");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(Outputs("out"),
            (std::vector<std::string>{"run.svg", "run_length_error.png", "run_length_error.svg",
                                      "run_link_angles.png", "run_link_angles.svg",
                                      "run_path_length.png", "run_path_length.svg"}));
}

}  // namespace
}  // namespace flexkin
