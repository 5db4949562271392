// SIGINT and SIGTERM during the command line's long commands: each is started on work that takes
// many seconds, over an output path that already holds an earlier file, and signalled once it is
// writing. It must stop within 2 s, exit 128 + the signal (130, 143) saying so, leave the earlier
// file byte-identical and no temporary file, and leave no ffmpeg running.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_process.h"
#include "test_util.h"

namespace flexkin {
namespace {

using test_util::CliProcess;
using test_util::kCli;
using test_util::kExamples;
using test_util::ReadFile;

// `text` with the first `from` replaced by `to` (which must be there).
std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// The long inputs, written into the test's directory: a chain scenario of 25000 leader steps, a
// robot following 2 million targets, a groom of 90000 frames, and a chain result of 6250 frames
// (for the animations).
void WriteLongInputs(const std::string& dir) {
  std::ofstream(dir + "/chain.json") << Replace(ReadFile(kExamples + "fig10_planar_curve.json"),
                                                "\"max_step\": 0.075", "\"max_step\": 0.00075");
  std::ofstream(dir + "/robot.json") << Replace(ReadFile(kExamples + "robot_planar_8link.json"),
                                                "\"steps\": 200", "\"steps\": 2000000");
  std::string groom = ReadFile(kExamples + "groom_grass_2d.json");
  groom = Replace(groom, "{\"time\": 3, ", "{\"time\": 3000, ");
  groom = Replace(groom, "\"substeps\": 2", "\"substeps\": 200");
  groom = Replace(groom, "\"every\": 1", "\"every\": 1000");
  std::ofstream(dir + "/groom.json") << groom;
  std::ofstream(dir + "/frames.json") << Replace(ReadFile(kExamples + "fig10_planar_curve.json"),
                                                 "\"max_step\": 0.075", "\"max_step\": 0.003");
}

// One interruption: the command, the output that holds an earlier file, the signal.
struct Case {
  const char* name;
  std::vector<std::string> args;
  std::string output;  // relative to the test's directory
  int signal;
};

std::ostream& operator<<(std::ostream& os, const Case& c) { return os << c.name; }

const Case kCases[] = {
    {"run_sigint",
     {"run", "chain.json", "-o", "out.json", "--substeps", "2000", "--record-every", "1000"},
     "out.json",
     SIGINT},
    {"run_sigterm",
     {"run", "chain.json", "-o", "out.npz", "--csv", "out.csv", "--substeps", "2000",
      "--record-every", "1000"},
     "out.npz",
     SIGTERM},
    {"robot_sigint",
     {"robot", "robot.json", "-o", "t.json", "--csv", "t.csv", "--max-output-size", "0", "-q"},
     "t.json",
     SIGINT},
    {"robot_sigterm",
     {"robot", "robot.json", "-o", "t.json", "--max-output-size", "0", "-q"},
     "t.json",
     SIGTERM},
    {"groom_sigint", {"run", "groom.json", "-o", "hair.npz", "-q"}, "hair.npz", SIGINT},
    {"groom_sigterm", {"run", "groom.json", "-o", "hair.npz", "-q"}, "hair.npz", SIGTERM},
    {"render_mp4_sigint",
     {"render", "frames.npz", "--formats", "mp4", "--every", "1", "--width", "320", "-q"},
     "frames.mp4",
     SIGINT},
    {"render_gif_sigterm",
     {"render", "frames.npz", "--formats", "gif", "--every", "1", "--width", "320", "-q"},
     "frames.gif",
     SIGTERM},
};

class InterruptTest : public test_util::TempDirTest, public testing::WithParamInterface<Case> {};

TEST_P(InterruptTest, StopsAtOnceAndKeepsTheEarlierFile) {
  ASSERT_FALSE(kCli.empty()) << "FLEXKIN_CLI is empty: configure with FLEXKIN_BUILD_APPS=ON";
  const Case& c = GetParam();
  WriteLongInputs(dir_);
  if (c.args[0] == "render") {
    CliProcess run(kCli, dir_, {"run", "frames.json", "-o", "frames.npz", "-q"});
    ASSERT_TRUE(run.Wait(60) && run.exit_code() == 0) << run.err();
  }
  const std::string earlier = "earlier " + c.output + "\n";
  std::ofstream(Path(c.output)) << earlier;

  // An animation's output directory given whole, so that ffmpeg's command line names it.
  std::vector<std::string> args = c.args;
  if (args[0] == "render") args.insert(args.end(), {"-o", dir_});
  CliProcess cli(kCli, dir_, args);
  // Writing: its temporary file is there (for an animation, ffmpeg is running).
  const std::string temp = "." + c.output + ".tmp-";
  bool writing = false;
  while (!writing && cli.seconds_since_start() < 30 && !cli.Wait(0.01)) {
    for (const std::string& name : Files()) writing |= name.rfind(temp, 0) == 0;
  }
  ASSERT_TRUE(writing) << "no temporary file " << temp << "*; " << cli.err();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ASSERT_FALSE(cli.Wait(0)) << "done before the signal: make the work longer; " << cli.err();
  const bool video = c.args[0] == "render";
  if (video) {
    EXPECT_FALSE(test_util::ProcessesMentioning(dir_).empty()) << "no ffmpeg running";
  }

  const auto signalled = std::chrono::steady_clock::now();
  cli.Signal(c.signal);
  ASSERT_TRUE(cli.Wait(2.0)) << "still running 2 s after the signal";
  const double latency =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - signalled).count();
  std::printf("%s: stopped %.3f s after the signal\n", c.name, latency);
  RecordProperty("stop_latency_ms", static_cast<int>(latency * 1000));

  ASSERT_TRUE(WIFEXITED(cli.status())) << "ended by signal " << WTERMSIG(cli.status());
  EXPECT_EQ(cli.exit_code(), 128 + c.signal) << cli.err();
  const std::string name = c.signal == SIGINT ? "SIGINT" : "SIGTERM";
  EXPECT_NE(cli.err().find("flexkin: interrupted by " + name + "; nothing was written to "),
            std::string::npos)
      << cli.err();
  EXPECT_NE(cli.err().find(c.output), std::string::npos) << cli.err();
  EXPECT_EQ(ReadFile(Path(c.output)), earlier);
  EXPECT_EQ(test_util::TemporaryFilesIn(dir_), std::vector<std::string>{});
  if (video) EXPECT_EQ(test_util::ProcessesMentioning(dir_), std::vector<pid_t>{});
  // The other outputs of the command were not written either.
  for (const std::string& other : {"out.csv", "t.csv"})
    EXPECT_FALSE(std::filesystem::exists(Path(other)));
}

INSTANTIATE_TEST_SUITE_P(LongCommands, InterruptTest, testing::ValuesIn(kCases),
                         [](const testing::TestParamInfo<Case>& info) { return info.param.name; });

}  // namespace
}  // namespace flexkin
