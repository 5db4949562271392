// The one call that draws a file of any kind (flexkin/draw.h): its table of formats per kind, the
// shared settings applied to every component, and files named after what is drawn.
#include "flexkin/draw.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <limits>

#include "flexkin/run.h"
#include "test_util.h"

namespace flexkin {
namespace {

std::vector<std::string> Names(const std::vector<OutputFormat>& formats) {
  std::vector<std::string> names;
  for (OutputFormat f : formats) names.push_back(NameOf(f));
  return names;
}

TEST(DrawTest, EachKindHasItsFormatsAndDefaults) {
  EXPECT_EQ(Names(FormatsOf(DrawnKind::kChainResult)),
            (std::vector<std::string>{"svg", "png", "pdf", "plots", "mp4", "gif", "html", "gltf",
                                      "glb"}));
  const std::vector<std::string> pictures = {"svg", "png", "pdf", "mp4", "gif", "html"};
  EXPECT_EQ(Names(FormatsOf(DrawnKind::kRobotTrajectory)), pictures);
  EXPECT_EQ(Names(FormatsOf(DrawnKind::kStrandFile)), pictures);
  EXPECT_EQ(Names(DefaultFormats(DrawnKind::kChainResult)),
            (std::vector<std::string>{"svg", "png", "plots"}));
  EXPECT_EQ(Names(DefaultFormats(DrawnKind::kStrandFile)),
            (std::vector<std::string>{"svg", "png"}));
  DrawOptions options;
  options.formats = {OutputFormat::kPng, OutputFormat::kGlb};
  EXPECT_TRUE(ValidateDrawOptions(DrawnKind::kChainResult, options).empty());
  const Problems problems = ValidateDrawOptions(DrawnKind::kStrandFile, options);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].field, "formats");
  EXPECT_NE(problems[0].message.find("\"glb\" is not available for strand files"),
            std::string::npos);
}

TEST(DrawTest, FormatListsAreParsedInTheVocabularysOrderOnce) {
  EXPECT_EQ(Names(ParseOutputFormats("glb,svg,glb", "--formats")),
            (std::vector<std::string>{"svg", "glb"}));
  test_util::ExpectInputError([] { ParseOutputFormats("svg,jpeg", "--formats"); }, "--formats",
                              "\"jpeg\"");
  test_util::ExpectInputError([] { ParseOutputFormats(std::vector<std::string>{}, "formats"); },
                              "formats", "empty");
}

TEST(DrawTest, ShorthandsReachEveryComponentThatHasThem) {
  DrawOptions o;
  DrawShorthands s;
  s.width = 321;
  s.height = 0;  // from the data: the plots keep their own height
  s.azimuth = 12.5;
  s.max_frames = 7;
  s.max_strands = 9;
  s.title = "T";
  s.ffmpeg = "my-ffmpeg";
  const int plot_height = o.plot.height;
  ApplyShorthands(s, &o);
  EXPECT_EQ(o.figure.width, 321);
  EXPECT_EQ(o.plot.width, 321);
  EXPECT_EQ(o.animation.width, 321);
  EXPECT_EQ(o.strands.width, 321);
  EXPECT_EQ(o.plot.height, plot_height);
  EXPECT_EQ(o.figure.height, 0);
  EXPECT_EQ(o.strands_viewer.azimuth, 12.5);
  EXPECT_EQ(o.animation.max_frames, 7);
  EXPECT_EQ(o.strands_viewer.max_frames, 7);
  EXPECT_EQ(o.strands.max_strands, 9);
  EXPECT_EQ(o.strands_viewer.title, "T");
  EXPECT_EQ(o.strands.ffmpeg, "my-ffmpeg");
  EXPECT_EQ(o.animation.ffmpeg, "my-ffmpeg");
  s = DrawShorthands();
  s.width = 3;
  ApplyShorthands(s, &o);
  const Problems problems = ValidateDrawOptions(DrawnKind::kChainResult, o);
  ASSERT_FALSE(problems.empty());
  EXPECT_EQ(problems.front().field, "figure.width");
}

class DrawFileTest : public test_util::TempDirTest {};

TEST_F(DrawFileTest, AResultFileIsDrawnUnderItsOwnName) {
  const Chain chain = MakeChain((Points(4, 2) << 0, 0, -1, 0, -2, 0.5, -3, 0.2).finished());
  const RunResult run =
      flexkin::Run(chain, (Points(2, 2) << 0.2, 0.1, 0.4, 0.3).finished(), RunOptions());
  WriteResultFile(run, Path("pull.npz"), ResultFileFormat::kNpz);
  DrawOptions options;
  options.formats = {OutputFormat::kSvg, OutputFormat::kHtml};
  options.base = OutputBaseOf(Path("pull.npz"), Path("out/deeper"));
  std::vector<std::string> announced;
  options.writing = [&](const std::string& path) { announced.push_back(path); };
  const std::vector<std::string> written = DrawFile(Path("pull.npz"), options);
  EXPECT_EQ(written,
            (std::vector<std::string>{Path("out/deeper/pull.svg"), Path("out/deeper/pull.html")}));
  EXPECT_EQ(announced, written);
  for (const std::string& path : written) EXPECT_TRUE(std::filesystem::exists(path)) << path;
  // The viewer's trails name points of the result: n = 3 at most.
  options.viewer.trail_points = {4};
  test_util::ExpectInputError([&] { DrawFile(Path("pull.npz"), options); },
                              "viewer.trail_points[0]", "<= 3");
}

// A result in memory is checked once, by Draw, before any output: a non-finite point is named
// and nothing is written, whichever formats were asked for (the writers Draw calls do not check
// again: flexkin/render.h, internal::CheckedDrawing). Written as a file, the same result draws.
TEST_F(DrawFileTest, AResultInMemoryIsCheckedOnceBeforeAnyOutput) {
  const Chain chain = MakeChain((Points(3, 2) << 0, 0, -1, 0, -2, 0.5).finished());
  const RunResult run =
      flexkin::Run(chain, (Points(3, 2) << 0.2, 0.1, 0.4, 0.3, 0.5, 0.6).finished(), RunOptions());
  ResultFile file;
  file.dim = 2;
  file.result = run;
  DrawOptions options;
  options.formats = {OutputFormat::kSvg, OutputFormat::kHtml, OutputFormat::kGlb};
  options.base = Path("drawn/pull");
  const std::vector<std::string> written = Draw(file, options);
  ASSERT_EQ(written.size(), 3u);
  for (const std::string& path : written) EXPECT_TRUE(std::filesystem::exists(path)) << path;

  file.result.frames.mutable_points(2)(1, 0) = std::numeric_limits<double>::quiet_NaN();
  options.base = Path("bad/pull");
  test_util::ExpectInputError([&] { Draw(file, options); }, "frames[2].points[1][0]");
  EXPECT_FALSE(std::filesystem::exists(Path("bad")));
}

}  // namespace
}  // namespace flexkin
