// Tests of the viewer for many strands (WriteStrandsViewerHtml, include/flexkin/strands_viewer.h):
// the page is self-contained, its embedded frames decode (here, independently of the page's script)
// to the file's points within the quantization step, bad options and pages over the limits are
// refused without touching the output file, the page is the one both viewers share (the shared
// page, style sheet and script of src/viewer/viewer_common.*, each once, and none of the chain
// viewer's own), and the page works in headless Chromium (tests/viewer/strands_browser_check.mjs),
// playing 10,000 strands of 32 links at >= 30 frames per second with software rendering.
#include "flexkin/strands_viewer.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/run.h"
#include "flexkin/strand_file.h"
#include "flexkin/viewer.h"
#include "scenes/scenes.h"
#include "test_util.h"

namespace flexkin {
namespace {

namespace fs = std::filesystem;
using test_util::ExpectInputError;
using test_util::ReadFile;

// `strands` strands of `links` links each growing from the upper half of a unit sphere (3D) or
// circle (2D), swaying over `frames` frames while the body turns and moves a little. Every link
// is a unit direction times its length, so the lengths are exact.
void MakeStrandFile(const std::string& path, int dim, int strands, int links, int frames,
                    bool float32 = true, const std::string& name = "swaying strands",
                    const std::vector<Collider>& body_colliders = {}) {
  StrandFileHeader h;
  h.name = name;
  h.description = "synthetic strands for the viewer test";
  h.dim = dim;
  h.float32 = float32;
  h.num_frames = frames;
  h.fps = 30.0;
  h.scalp.shape = dim == 3 ? "sphere" : "";
  h.scalp.radii = Eigen::Vector3d::Constant(1.0);
  h.body_colliders = body_colliders;
  for (int s = 0; s <= strands; ++s) h.offsets.push_back(static_cast<int64_t>(s) * (links + 1));
  h.link_lengths =
      Eigen::VectorXd::Constant(static_cast<Eigen::Index>(strands) * links, 1.2 / links);
  StrandFileWriter writer(path, h);
  StrandFrame f;
  f.points.resize(h.num_points(), dim);
  for (int k = 0; k < frames; ++k) {
    const double t = k / h.fps;
    f.frame = k;
    f.time = t;
    f.pose = dim == 3 ? BodyPose::FromQuaternion(1.0, 0.0, 0.0, 0.1 * std::sin(t),
                                                 Eigen::Vector3d(0.1 * t, 0.0, 0.0))
                      : BodyPose::Planar(0.1 * std::sin(t), 0.1 * t, 0.0);
    for (int s = 0; s < strands; ++s) {
      // Roots spread evenly (a Fibonacci spiral on the sphere), in the body's frame.
      const double z = dim == 3 ? 1.0 - (s + 0.5) / strands : 0.0;
      const double phi = dim == 3 ? 2.399963 * s : M_PI * (s + 0.5) / strands;
      const double r = std::sqrt(1.0 - z * z);
      Eigen::Vector3d root(r * std::cos(phi), r * std::sin(phi), z);
      const Eigen::Vector3d normal = root;
      root = f.pose.rotation * root + f.pose.translation;
      Eigen::Vector3d p = root;
      for (int j = 0; j <= links; ++j) {
        f.points.row(h.offsets[s] + j) = p.head(dim).transpose();
        const double a = static_cast<double>(j) / links;
        Eigen::Vector3d d = normal + a * Eigen::Vector3d(0.6 * std::sin(2.0 * t + 0.01 * s),
                                                         dim == 3 ? 0.3 * std::cos(1.3 * t) : -1.0,
                                                         dim == 3 ? -1.5 : 0.0);
        if (dim == 2) d.z() = 0.0;
        p += h.link_lengths[0] * d.normalized();
      }
    }
    writer.Add(f);
  }
  StrandRunReport report;
  report.max_length_error = 2.5e-7;
  report.seconds = 0.125;
  report.engine = "scalar";
  writer.Commit(report);
}

class StrandsViewerTest : public testing::Test {
 protected:
  void SetUp() override {
    std::string name = (fs::temp_directory_path() / "flexkin_strands_viewer_XXXXXX").string();
    ASSERT_NE(::mkdtemp(name.data()), nullptr);
    dir_ = name;
  }
  void TearDown() override {
    if (std::getenv("FLEXKIN_VIEWER_TEST_KEEP") != nullptr) {
      std::printf("strands viewer test output kept in %s\n", dir_.c_str());
    } else if (!dir_.empty()) {
      fs::remove_all(dir_);
    }
  }
  std::string Path(const std::string& name) const { return dir_ + "/" + name; }
  std::string dir_;
};

// The text of every element `<script ... class="flexkin-frame">` and of the facts' element.
struct PageData {
  nlohmann::json meta;
  std::vector<std::string> frames;
};
PageData ParsePage(const std::string& page) {
  PageData data;
  const std::string frame_open =
      "<script type=\"application/octet-stream\" class=\"flexkin-frame\">";
  for (size_t at = page.find(frame_open); at != std::string::npos;
       at = page.find(frame_open, at + 1)) {
    const size_t begin = at + frame_open.size();
    data.frames.push_back(page.substr(begin, page.find("</script>", begin) - begin));
  }
  const std::string meta_open = "<script type=\"application/json\" id=\"flexkin-strands\">";
  const size_t begin = page.find(meta_open) + meta_open.size();
  data.meta = nlohmann::json::parse(page.substr(begin, page.find("</script>", begin) - begin));
  return data;
}

std::vector<unsigned char> Base64Decode(const std::string& text) {
  std::vector<unsigned char> out;
  uint32_t bits = 0;
  int count = 0;
  for (char ch : text) {
    int v;
    if (ch >= 'A' && ch <= 'Z')
      v = ch - 'A';
    else if (ch >= 'a' && ch <= 'z')
      v = ch - 'a' + 26;
    else if (ch >= '0' && ch <= '9')
      v = ch - '0' + 52;
    else if (ch == '+')
      v = 62;
    else if (ch == '/')
      v = 63;
    else
      continue;  // '=' padding
    bits = (bits << 6) | v;
    count += 6;
    if (count >= 8) {
      count -= 8;
      out.push_back(static_cast<unsigned char>((bits >> count) & 0xff));
    }
  }
  return out;
}

// Every embedded frame's points, decoded as docs/viewer.md describes the encoding: points x dim,
// point-major, one vector per frame.
std::vector<std::vector<double>> DecodeFrames(const PageData& data) {
  const int dim = data.meta["dim"];
  const size_t points = data.meta["num_points"];
  const size_t values = points * dim;
  std::vector<std::vector<double>> frames;
  std::vector<uint16_t> codes(values, 0);
  for (size_t k = 0; k < data.frames.size(); ++k) {
    const std::vector<unsigned char> packed = Base64Decode(data.frames[k]);
    std::vector<unsigned char> raw(2 * values);
    uLongf size = raw.size();
    EXPECT_EQ(uncompress(raw.data(), &size, packed.data(), packed.size()), Z_OK);
    EXPECT_EQ(size, raw.size());
    const nlohmann::json& f = data.meta["frames"][k];
    std::vector<double> xyz(values);
    for (int c = 0; c < dim; ++c) {
      uint16_t before = 0;
      for (size_t i = 0; i < points; ++i) {
        const size_t j = c * points + i;
        const uint16_t delta = raw[j] | (raw[j + values] << 8);
        codes[j] = static_cast<uint16_t>((k == 0 ? before : codes[j]) + delta);
        before = codes[j];
        xyz[i * dim + c] =
            f["lo"][c].get<double>() + codes[j] / 65535.0 * f["ext"][c].get<double>();
      }
    }
    frames.push_back(std::move(xyz));
  }
  return frames;
}

TEST_F(StrandsViewerTest, EmbeddedFramesDecodeToTheFilesPointsWithinTheStep) {
  for (int dim : {3, 2}) {
    SCOPED_TRACE(dim);
    MakeStrandFile(Path("s.npz"), dim, 50, 8, 23, /*float32=*/false, "strands </script><b>&");
    StrandsViewerOptions options;
    options.max_frames = 6;
    options.max_strands = 20;
    {
      StrandFileReader reader(Path("s.npz"));
      WriteStrandsViewerHtml(&reader, options, Path("s.html"));
    }
    const std::string page = ReadFile(Path("s.html"));
    EXPECT_EQ(page.rfind("<!DOCTYPE html>", 0), 0u);
    for (const char* outside : {"http:", "https:", "//cdn", "<link", "src=", "@import", "url("}) {
      EXPECT_EQ(page.find(outside), std::string::npos) << outside;
    }
    const PageData data = ParsePage(page);
    const nlohmann::json& meta = data.meta;
    EXPECT_EQ(meta["title"], "strands </script><b>&");
    EXPECT_EQ(meta["dim"], dim);
    EXPECT_EQ(meta["file_strands"], 50);
    EXPECT_EQ(meta["file_frames"], 23);
    EXPECT_EQ(meta["report"]["max_length_error"], 2.5e-7);
    EXPECT_EQ(meta["report"]["engine"], "scalar");
    // 23 s/30 of motion: played in real time by default.
    EXPECT_NEAR(meta["options"]["playback_seconds"].get<double>(), 22.0 / 30.0, 1e-12);
    ASSERT_EQ(meta["offsets"].size(), 21u);
    EXPECT_EQ(meta["num_points"], 20 * 9);
    ASSERT_EQ(data.frames.size(), 6u);
    ASSERT_EQ(meta["frames"].size(), 6u);
    EXPECT_EQ(meta["frames"][0]["index"], 0);
    EXPECT_EQ(meta["frames"][5]["index"], 22);

    // Every embedded point against the file's, within half a step of its frame's box.
    const std::vector<std::vector<double>> decoded = DecodeFrames(data);
    StrandFileReader reader(Path("s.npz"));
    StrandFrame frame;
    size_t embedded = 0;
    for (int64_t index = 0; reader.Next(&frame); ++index) {
      if (embedded == data.frames.size() || meta["frames"][embedded]["index"] != index) continue;
      const nlohmann::json& f = meta["frames"][embedded];
      EXPECT_EQ(f["time"].get<double>(), frame.time);
      EXPECT_EQ(f["translation"][0].get<double>(), frame.pose.translation.x());
      for (int s = 0; s < 20; ++s) {
        const int file_strand = s * 50 / 20;  // the even subset
        const int64_t first = meta["offsets"][s];
        for (int j = 0; j <= 8; ++j) {
          for (int c = 0; c < dim; ++c) {
            const double step = f["ext"][c].get<double>() / 65535.0;
            EXPECT_NEAR(decoded[embedded][(first + j) * dim + c],
                        frame.points(file_strand * 9 + j, c), 0.5 * step + 1e-12)
                << "frame " << index << " strand " << s << " point " << j;
          }
        }
      }
      ++embedded;
    }
    EXPECT_EQ(embedded, data.frames.size());
    EXPECT_GT(meta["precision"].get<double>(), 0.0);
    EXPECT_LT(meta["precision"].get<double>(), 5e-5);
  }
}

TEST_F(StrandsViewerTest, OptionsAreValidatedNamingTheField) {
  EXPECT_TRUE(StrandsViewerOptions().Validate().empty());
  MakeStrandFile(Path("s.npz"), 3, 10, 4, 5);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto expect = [&](auto change, const std::string& field) {
    StrandsViewerOptions options;
    change(options);
    StrandFileReader reader(Path("s.npz"));
    ExpectInputError([&] { WriteStrandsViewerHtml(&reader, options, Path("v.html")); }, field);
    EXPECT_FALSE(fs::exists(Path("v.html"))) << field;
  };
  expect([](StrandsViewerOptions& o) { o.playback_seconds = -1; }, "options.playback_seconds");
  expect([&](StrandsViewerOptions& o) { o.playback_seconds = nan; }, "options.playback_seconds");
  expect([&](StrandsViewerOptions& o) { o.azimuth = nan; }, "options.azimuth");
  expect([](StrandsViewerOptions& o) { o.elevation = -91; }, "options.elevation");
  expect([](StrandsViewerOptions& o) { o.max_frames = 0; }, "options.max_frames");
  expect([](StrandsViewerOptions& o) { o.max_strands = -1; }, "options.max_strands");
  expect([](StrandsViewerOptions& o) { o.max_megabytes = 0; }, "options.max_megabytes");
  expect([&](StrandsViewerOptions& o) { o.max_memory_megabytes = nan; },
         "options.max_memory_megabytes");
  // One frame: the first only; the title falls back to the file's name.
  StrandsViewerOptions one;
  one.max_frames = 1;
  StrandFileReader reader(Path("s.npz"));
  WriteStrandsViewerHtml(&reader, one, Path("v.html"));
  const PageData data = ParsePage(ReadFile(Path("v.html")));
  EXPECT_EQ(data.frames.size(), 1u);
  EXPECT_EQ(data.meta["title"], "swaying strands");
}

TEST_F(StrandsViewerTest, PageOverTheLimitsIsRefusedAndAnEarlierFileLeftUntouched) {
  MakeStrandFile(Path("s.npz"), 3, 400, 16, 30);
  { std::ofstream(Path("existing.html")) << "the old page"; }
  const auto expect = [&](auto change, const std::string& text) {
    StrandsViewerOptions options;
    change(options);
    for (const char* name : {"new.html", "existing.html"}) {
      StrandFileReader reader(Path("s.npz"));
      ExpectInputError([&] { WriteStrandsViewerHtml(&reader, options, Path(name)); },
                       "options.max_frames", text);
    }
    EXPECT_FALSE(fs::exists(Path("new.html"))) << text;
    EXPECT_EQ(ReadFile(Path("existing.html")), "the old page") << text;
  };
  // 30 frames of 6,800 points: a page of several 100 kB, 1.6 MB of browser memory.
  expect([](StrandsViewerOptions& o) { o.max_megabytes = 0.2; },
         "MB, more than options.max_megabytes");
  expect([](StrandsViewerOptions& o) { o.max_memory_megabytes = 1; },
         "MB of the browser's memory, more than options.max_memory_megabytes");
  // Nothing else was left in the directory (no temporary files).
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 2);
  // Within the limits, with fewer strands.
  StrandsViewerOptions fewer;
  fewer.max_megabytes = 0.2;
  fewer.max_strands = 20;
  StrandFileReader reader(Path("s.npz"));
  WriteStrandsViewerHtml(&reader, fewer, Path("existing.html"));
  EXPECT_EQ(ParsePage(ReadFile(Path("existing.html"))).meta["num_points"], 20 * 17);
}

// How many times `part` occurs in `text` (overlapping occurrences included).
size_t Count(const std::string& text, const std::string& part) {
  size_t count = 0;
  for (size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++count;
  return count;
}

// The two viewers' pages are one page: the shared page (viewer_common.html) with each viewer's
// parts in its slots, one style element holding the shared style sheet and then the viewer's own,
// one script element holding the shared script and then the viewer's own; nothing of the other
// viewer's styles or script, and the shared assets once each, not copied into either viewer's.
TEST_F(StrandsViewerTest, BothViewersWriteTheSharedPageStyleSheetAndScriptOnce) {
  MakeStrandFile(Path("s.npz"), 3, 12, 5, 4);
  {
    StrandFileReader reader(Path("s.npz"));
    WriteStrandsViewerHtml(&reader, StrandsViewerOptions(), Path("strands.html"));
  }
  const Chain chain = scenes::CurvedChain(3, 6, 1.0, 0.4);
  Points targets(5, 3);
  for (int s = 0; s < 5; ++s) {
    targets.row(s) = chain.points.row(0);
    targets(s, 0) -= 0.05 * (s + 1);
  }
  ResultFile result;
  result.result = flexkin::Run(chain, targets, RunOptions());
  result.dim = 3;
  WriteViewerHtml(result, ViewerOptions(), Path("chain.html"));

  const std::string source = std::string(FLEXKIN_SOURCE_DIR) + "/src/viewer/";
  const auto asset = [&](const std::string& name) {
    const std::string text = ReadFile(source + name);
    EXPECT_GT(text.size(), 100u) << name;
    return text;
  };
  const std::string shell = asset("viewer_common.html"), common_css = asset("viewer_common.css"),
                    common_js = asset("viewer_common.js");
  struct Viewer {
    std::string page, css, js;
  };
  const Viewer chain_viewer{ReadFile(Path("chain.html")), asset("viewer.css"), asset("viewer.js")};
  const Viewer strands_viewer{ReadFile(Path("strands.html")), asset("strands_viewer.css"),
                              asset("strands_viewer.js")};
  // Each viewer's own assets hold nothing of the shared ones (no copied rule or function).
  for (const std::string& own :
       {chain_viewer.css, chain_viewer.js, strands_viewer.css, strands_viewer.js}) {
    EXPECT_EQ(own.find("html, body {"), std::string::npos);
    EXPECT_EQ(own.find("#controls,"), std::string::npos);
    EXPECT_EQ(own.find("addEventListener('keydown'"), std::string::npos);
    EXPECT_EQ(own.find("addEventListener('pointerdown'"), std::string::npos);
  }
  for (const auto& [viewer, other] :
       {std::pair(&chain_viewer, &strands_viewer), std::pair(&strands_viewer, &chain_viewer)}) {
    const std::string& page = viewer->page;
    SCOPED_TRACE(viewer == &chain_viewer ? "chain viewer" : "strands viewer");
    EXPECT_EQ(Count(page, common_css), 1u);
    EXPECT_EQ(Count(page, common_js), 1u);
    EXPECT_EQ(Count(page, "<style>\n" + common_css + viewer->css + "</style>"), 1u);
    EXPECT_EQ(Count(page, "<script>\n" + common_js + viewer->js + "</script>"), 1u);
    EXPECT_EQ(Count(page, "<style>"), 1u);
    EXPECT_EQ(Count(page, "<script>"), 1u);
    EXPECT_EQ(page.find(other->css), std::string::npos);
    EXPECT_EQ(page.find(other->js), std::string::npos);
    // The shared page's text between its slots, in order, and every slot filled.
    size_t at = 0, from = 0;
    for (size_t slot = shell.find("<!--slot "); from < shell.size();
         slot = shell.find("<!--slot ", from)) {
      const std::string piece = shell.substr(from, slot == std::string::npos ? slot : slot - from);
      const size_t found = page.find(piece, at);
      ASSERT_NE(found, std::string::npos) << piece;
      at = found + piece.size();
      from = slot == std::string::npos ? shell.size() : shell.find("-->", slot) + 3;
    }
    EXPECT_EQ(page.find("<!--slot"), std::string::npos);
    EXPECT_EQ(page.find("<!--part"), std::string::npos);
    // The controls the scripts and the browser checks look for, once each.
    for (const char* id : {"title", "subtitle", "view", "hint", "message", "play", "prev", "next",
                           "timeline", "counter", "speed", "reset", "facts", "now"}) {
      EXPECT_EQ(Count(page, std::string("id=\"") + id + "\""), 1u) << id;
    }
  }
  // Each viewer's own controls on its page only.
  for (const char* id : {"leader", "trails", "trail-points", "perspective", "profile", "l2plot"}) {
    EXPECT_EQ(Count(chain_viewer.page, std::string("id=\"") + id + "\""), 1u) << id;
    EXPECT_EQ(Count(strands_viewer.page, std::string("id=\"") + id + "\""), 0u) << id;
  }
  for (const char* id : {"soft-view", "blend", "scalp", "perf"}) {
    EXPECT_EQ(Count(strands_viewer.page, std::string("id=\"") + id + "\""), 1u) << id;
    EXPECT_EQ(Count(chain_viewer.page, std::string("id=\"") + id + "\""), 0u) << id;
  }
}

// Runs `command`, returns its exit status and appends its stdout and stderr to `output`.
int RunCommand(const std::string& command, std::string* output) {
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return -1;
  char buffer[4096];
  size_t got;
  while ((got = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) output->append(buffer, got);
  const int status = ::pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

TEST_F(StrandsViewerTest, PlaysTenThousandStrandsInHeadlessChromium) {
  const std::string source = FLEXKIN_SOURCE_DIR;
  const std::string tools = source + "/tools/node";
  const std::string chromium =
      std::getenv("FLEXKIN_CHROMIUM") ? std::getenv("FLEXKIN_CHROMIUM") : "/usr/bin/chromium";
  std::string ignored;
  if (RunCommand("node --version", &ignored) != 0) {
    GTEST_SKIP() << "node is missing: run scripts/install-deps.sh";
  }
  if (!fs::exists(tools + "/node_modules/playwright-core/package.json")) {
    GTEST_SKIP() << "playwright-core is missing from tools/node: run scripts/install-deps.sh";
  }
  if (!fs::exists(chromium)) GTEST_SKIP() << chromium << " is missing: run scripts/install-deps.sh";

  StrandsViewerOptions options;
  MakeStrandFile(Path("small_2d.npz"), 2, 60, 12, 40);
  {
    StrandFileReader reader(Path("small_2d.npz"));
    WriteStrandsViewerHtml(&reader, options, Path("small_2d.html"));
  }
  // A neck under the head (a capsule moving with the body), drawn by both renderers.
  Collider neck;
  neck.shape = ColliderShape::kCapsule;
  neck.radius = 0.4;
  neck.half_length = 0.5;
  neck.pose.translation() = Eigen::Vector3d(0.0, 0.0, -1.4);
  MakeStrandFile(Path("neck_3d.npz"), 3, 300, 12, 30, true, "strands over a neck", {neck});
  {
    StrandFileReader reader(Path("neck_3d.npz"));
    WriteStrandsViewerHtml(&reader, options, Path("neck_3d.html"));
  }
  // The size that must play smoothly: 10,000 strands of 32 links.
  MakeStrandFile(Path("hair.npz"), 3, 10000, 32, 40);
  {
    StrandFileReader reader(Path("hair.npz"));
    WriteStrandsViewerHtml(&reader, options, Path("hair_10000x32.html"));
  }
  const auto size = fs::file_size(Path("hair_10000x32.html"));
  std::printf("page of 10,000 x 32 links, 40 frames: %ju bytes (%.0f per frame)\n",
              static_cast<uintmax_t>(size), size / 40.0);

  // Points of the files, for the browser check to compare with the page's decoding.
  for (const char* name : {"small_2d", "hair_10000x32"}) {
    StrandFileReader reader(Path(std::string(name) == "small_2d" ? "small_2d.npz" : "hair.npz"));
    nlohmann::json points = nlohmann::json::array();
    StrandFrame frame;
    for (int k = 0; reader.Next(&frame); ++k) {
      if (k % 7 != 0) continue;
      for (Eigen::Index i = 0; i < frame.points.rows(); i += frame.points.rows() / 5 + 1) {
        std::vector<double> xyz(frame.points.cols());
        for (int c = 0; c < frame.points.cols(); ++c) xyz[c] = frame.points(i, c);
        points.push_back({{"frame", k}, {"point", i}, {"xyz", xyz}});
      }
    }
    std::ofstream(Path(std::string(name) + ".points.json")) << points.dump();
  }

  // Under the sanitizers the instrumented writers above run; the browser's run of their pages
  // (the page's script is the browser's, not instrumented) is the plain build's.
  if (test_util::kSanitized) {
    GTEST_SKIP() << "the browser check runs in the plain build; here only the page writers";
  }
  std::string output;
  const int status = RunCommand("node '" + source + "/tests/viewer/strands_browser_check.mjs' '" +
                                    tools + "' '" + dir_ + "' '" + Path("small_2d.html") + "' '" +
                                    Path("neck_3d.html") + "' '" + Path("hair_10000x32.html") + "'",
                                &output);
  std::printf("%s", output.c_str());
  EXPECT_EQ(status, 0) << output;
  EXPECT_NE(output.find("all strands viewer checks passed"), std::string::npos);
  EXPECT_TRUE(fs::exists(Path("hair_10000x32-playing.png")));
}

}  // namespace
}  // namespace flexkin
