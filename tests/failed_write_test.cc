// Every output of the command line against a write that fails half way: the command runs under a
// file size limit too small for its output (RLIMIT_FSIZE, SIGXFSZ ignored: write(2) fails with
// EFBIG, as on a full disk), over a path that already holds an earlier file. Each must exit 4,
// name the path and the reason, leave the earlier file byte-identical and no temporary file.
// One row per writer: the table below is the list of the command line's outputs.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli_process.h"
#include "test_util.h"

namespace flexkin {
namespace {

using test_util::CliProcess;
using test_util::kCli;
using test_util::kExamples;
using test_util::ReadFile;

// One output: the command that writes it (run in a fresh directory holding the inputs run.json,
// a chain result, and hair.npz, a strand file), the outputs that already exist before it, the
// one whose failure the message must name, and the file size limit.
struct Writer {
  const char* name;
  std::vector<std::string> args;
  std::vector<std::string> earlier;  // outputs present before the command, all kept
  std::string failing;               // the one that cannot be written
  uint64_t limit;
};

std::ostream& operator<<(std::ostream& os, const Writer& w) { return os << w.name; }

std::vector<Writer> Writers() {
  const std::string chain = kExamples + "fig10_planar_curve.json";
  const std::string robot = kExamples + "robot_planar_8link.json";
  const std::string groom = kExamples + "groom_grass_2d.json";
  std::vector<Writer> rows = {
      {"result_json", {"run", chain, "-o", "out.json", "-q"}, {"out.json"}, "out.json", 4096},
      {"result_npz", {"run", chain, "-o", "out.npz", "-q"}, {"out.npz"}, "out.npz", 4096},
      // The result fits under the limit, the frames (text) do not.
      {"frames_csv",
       {"run", chain, "-o", "out.npz", "--csv", "frames.csv", "--no-link-angles", "-q"},
       {"out.npz", "frames.csv"},
       "frames.csv",
       400000},
      {"robot_trajectory", {"robot", robot, "-o", "t.json", "-q"}, {"t.json"}, "t.json", 4096},
      {"robot_joints_csv",
       {"robot", robot, "-o", "t.json", "--csv", "joints.csv", "-q"},
       {"t.json", "joints.csv"},
       "",  // whichever fails first
       4096},
      {"strand_file", {"run", groom, "-o", "new.npz", "-q"}, {"new.npz"}, "new.npz", 4096},
  };
  // flexkin render, chain results and strand files: one row per format.
  const struct {
    const char* format;
    const char* file;
    uint64_t limit;
  } chain_formats[] = {
      {"svg", "run.svg", 4096},   {"png", "run.png", 4096},
      {"pdf", "run.pdf", 4096},   {"plots", "run_path_length.svg", 4096},
      {"mp4", "run.mp4", 2048},   {"gif", "run.gif", 2048},
      {"html", "run.html", 4096}, {"gltf", "run.gltf", 1024},
      {"glb", "run.glb", 1024},
  };
  for (const auto& f : chain_formats) {
    rows.push_back({f.format,
                    {"render", "run.json", "-o", "out", "--formats", f.format, "-q"},
                    {std::string("out/") + f.file},
                    std::string("out/") + f.file,
                    f.limit});
  }
  for (const char* format : {"svg", "png", "pdf", "mp4", "gif", "html"}) {
    const std::string file = std::string("out/hair.") + format;
    rows.push_back({format,
                    {"render", "hair.npz", "-o", "out", "--formats", format, "-q"},
                    {file},
                    file,
                    2048});
  }
  return rows;
}

class FailedWriteTest : public testing::TestWithParam<Writer> {
 protected:
  // The inputs, made once: a chain result and a strand file.
  static void SetUpTestSuite() {
    inputs_ = new std::string(MakeDirectory());
    CliProcess chain(kCli, *inputs_,
                     {"run", kExamples + "fig10_planar_curve.json", "-o", "run.json", "-q"});
    CliProcess groom(kCli, *inputs_,
                     {"run", kExamples + "groom_grass_2d.json", "-o", "hair.npz", "-q"});
    ASSERT_TRUE(chain.Wait(60) && chain.exit_code() == 0) << chain.err();
    ASSERT_TRUE(groom.Wait(60) && groom.exit_code() == 0) << groom.err();
  }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*inputs_);
    delete inputs_;
  }
  void SetUp() override {
    ASSERT_FALSE(kCli.empty()) << "FLEXKIN_CLI is empty: configure with FLEXKIN_BUILD_APPS=ON";
    dir_ = MakeDirectory();
    std::filesystem::copy_file(*inputs_ + "/run.json", dir_ + "/run.json");
    std::filesystem::copy_file(*inputs_ + "/hair.npz", dir_ + "/hair.npz");
    std::filesystem::create_directory(dir_ + "/out");
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  static std::string MakeDirectory() {
    std::string name = (std::filesystem::temp_directory_path() / "flexkin_test_XXXXXX").string();
    if (::mkdtemp(name.data()) == nullptr) return "";
    return name;
  }

  static std::string* inputs_;
  std::string dir_;
};

std::string* FailedWriteTest::inputs_ = nullptr;

TEST_P(FailedWriteTest, ExitsFourNamingThePathAndKeepsTheEarlierFile) {
  const Writer& w = GetParam();
  for (const std::string& path : w.earlier) {
    std::ofstream(dir_ + "/" + path) << "earlier " << path << "\n";
  }
  CliProcess cli(kCli, dir_, w.args, w.limit);
  ASSERT_TRUE(cli.Wait(120)) << "still running after 120 s";
  EXPECT_EQ(cli.exit_code(), 4) << cli.err();
  if (!w.failing.empty()) EXPECT_NE(cli.err().find("'" + w.failing + "'"), std::string::npos);
  bool named = false;
  for (const std::string& path : w.earlier) named |= cli.err().find(path) != std::string::npos;
  EXPECT_TRUE(named) << "no output named in: " << cli.err();
  EXPECT_NE(cli.err().find("File too large"), std::string::npos) << cli.err();
  EXPECT_EQ(cli.err().find("\n"), cli.err().size() - 1) << "one line: " << cli.err();
  for (const std::string& path : w.earlier) {
    EXPECT_EQ(ReadFile(dir_ + "/" + path), "earlier " + path + "\n") << path;
  }
  EXPECT_EQ(test_util::TemporaryFilesIn(dir_), std::vector<std::string>{});
}

INSTANTIATE_TEST_SUITE_P(EveryOutput, FailedWriteTest, testing::ValuesIn(Writers()),
                         [](const testing::TestParamInfo<Writer>& info) {
                           const Writer& w = info.param;
                           const bool strands = w.args.size() > 1 && w.args[1] == "hair.npz";
                           return std::string(strands ? "strands_" : "") + w.name;
                         });

}  // namespace
}  // namespace flexkin
