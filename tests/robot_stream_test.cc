// Tests of the streamed robot runs: TrackPath with an ArmStepSink (include/flexkin/arm.h) and the
// streaming trajectory writers (RobotTrajectoryWriter, RobotJointsCsvWriter in
// include/flexkin/robot_scenario.h): a failed or refused write leaves nothing and an existing file
// untouched; a streamed run keeps no per-step data. (That the streamed files equal the writers of
// a whole trajectory for every example is in robot_scenario_test.cc, which reads URDF arms.)
#include <gtest/gtest.h>
#include <malloc.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "flexkin/arm.h"
#include "flexkin/error.h"
#include "flexkin/robot_scenario.h"
#include "test_util.h"

namespace flexkin {
namespace {

using nlohmann::json;
using test_util::ReadFile;

// A fresh directory, removed with its files at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::string pattern =
        (std::filesystem::temp_directory_path() / "flexkin_robot_stream_XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string operator/(const std::string& name) const { return path_ + "/" + name; }
  std::vector<std::string> Files() const {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(path_)) {
      names.push_back(e.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  }

 private:
  std::string path_;
};

std::vector<std::string> RobotExamples() {
  std::vector<std::string> names;
  for (const auto& e :
       std::filesystem::directory_iterator(std::string(FLEXKIN_SOURCE_DIR) + "/examples")) {
    const std::string name = e.path().filename().string();
    if (name.rfind("robot_", 0) == 0 && e.path().extension() == ".json") {
      names.push_back(e.path().string());
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

// Streams the trajectory of `s` to `json_path` and `csv_path`; returns the summary.
ArmTrajectory Stream(const RobotScenario& s, const std::string& json_path,
                     const std::string& csv_path) {
  RobotTrajectoryWriter json_writer(s, json_path);
  RobotJointsCsvWriter csv_writer(s, csv_path);
  ArmStepFanOut sink({&json_writer, &csv_writer});
  const ArmTrajectory t = TrackPath(s.model, s.path, s.options, &sink);
  EXPECT_EQ(json_writer.steps(), s.path.rows());
  json_writer.Commit(t);
  csv_writer.Commit(t);
  return t;
}

RobotScenario SmallPlanar(int targets, double radius = 0.3) {
  RobotScenario s;
  s.name = "small planar arm on a circle";
  s.model = StraightArm(2, 3, 1.0);
  s.path.resize(targets, 2);
  for (int i = 0; i < targets; ++i) {
    const double a = 2 * M_PI * (i + 1) / 1000.0;  // a turn per 1000 targets
    s.path.row(i) << 2.0 + radius * std::cos(a), radius * std::sin(a);
  }
  return s;
}

// Refusals: a non-finite number in a step or in the summary, too many or too few steps; each
// names the field and leaves nothing, and an existing file untouched.
TEST(RobotStreamTest, NonFiniteValuesAreRefusedNamingTheFieldAndNothingIsWritten) {
  const RobotScenario s = SmallPlanar(3);
  ArmStepRecorder recorder;
  const ArmTrajectory t = TrackPath(s.model, s.path, s.options, &recorder);
  TempDir dir;
  const std::string path = dir / "t.json", csv = dir / "j.csv";
  std::ofstream(path) << "old";
  auto expect_refused = [&](const std::function<void()>& f, const std::string& field) {
    try {
      f();
      ADD_FAILURE() << "not refused: " << field;
    } catch (const InputError& e) {
      EXPECT_EQ(e.problem().field, field) << e.what();
      EXPECT_NE(std::string(e.what()).find("not a finite number"), std::string::npos) << e.what();
    }
    EXPECT_EQ(ReadFile(path), "old");
    EXPECT_EQ(dir.Files(), std::vector<std::string>{"t.json"});
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  {
    std::vector<ArmStepReport> steps = recorder.steps;
    steps[1].state.points(2, 1) = nan;
    expect_refused(
        [&] {
          RobotTrajectoryWriter w(s, path);
          for (const ArmStepReport& step : steps) w.Add(step);
        },
        "steps[1].points[2][1]");
  }
  {
    std::vector<ArmStepReport> steps = recorder.steps;
    steps[2].state.angles.angle[0] = std::numeric_limits<double>::infinity();
    for (const bool as_csv : {false, true}) {
      expect_refused(
          [&] {
            if (as_csv) {
              RobotJointsCsvWriter w(s, csv);
              for (const ArmStepReport& step : steps) w.Add(step);
            } else {
              RobotTrajectoryWriter w(s, path);
              for (const ArmStepReport& step : steps) w.Add(step);
            }
          },
          "steps[2].joint_angles[0]");
    }
    // The whole-trajectory writers refuse it too, before touching the file.
    ArmTrajectory bad = t;
    bad.steps = steps;
    expect_refused([&] { WriteRobotTrajectoryJson(s, bad, path); }, "steps[2].joint_angles[0]");
    expect_refused([&] { WriteRobotJointsCsv(s, bad, csv); }, "steps[2].joint_angles[0]");
  }
  {
    ArmTrajectory bad = t;
    bad.max_ee_error = nan;
    expect_refused(
        [&] {
          RobotTrajectoryWriter w(s, path);
          for (const ArmStepReport& step : recorder.steps) w.Add(step);
          w.Commit(bad);
        },
        "summary.max_ee_error");
  }
  // Too few steps at Commit, one too many at Add.
  try {
    RobotTrajectoryWriter w(s, path);
    w.Add(recorder.steps[0]);
    w.Commit(t);
    ADD_FAILURE() << "a trajectory with too few steps was committed";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem().field, "trajectory.steps") << e.what();
  }
  try {
    RobotJointsCsvWriter w(s, csv);
    for (int k = 0; k < 4; ++k) w.Add(recorder.steps[k % 3]);
    ADD_FAILURE() << "a step beyond the path was taken";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem().field, "trajectory.steps") << e.what();
  }
  EXPECT_EQ(ReadFile(path), "old");
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"t.json"});
  // Destroyed without Commit: nothing either.
  {
    RobotTrajectoryWriter w(s, path);
    w.Add(recorder.steps[0]);
  }
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"t.json"});
}

// A write that fails (the file size limit, in a child process) throws the system's reason while
// the steps are streamed or at Commit, removes the temporary file and leaves the old one.
TEST(RobotStreamTest, FailedWriteLeavesNothingAndKeepsTheOldFile) {
  TempDir dir;
  const std::string path = dir / "t.json", csv = dir / "j.csv";
  const std::string old = "{\"old\": true}\n";
  std::ofstream(path) << old;
  std::ofstream(csv) << old;
  // Limits of 8 KB (the write fails while the steps are streamed) and just under each file's
  // size (it fails when the last buffer is flushed, at Commit).
  const RobotScenario s = SmallPlanar(2000);
  TempDir sizes;
  Stream(s, sizes / "t.json", sizes / "j.csv");
  const rlim_t json_size = std::filesystem::file_size(sizes / "t.json");
  const rlim_t csv_size = std::filesystem::file_size(sizes / "j.csv");
  ASSERT_GT(csv_size, rlim_t{100000});
  for (const int which : {0, 1}) {
    for (const bool as_csv : {false, true}) {
      const rlim_t limit = which == 0 ? 8192 : (as_csv ? csv_size : json_size) - 100;
      const pid_t child = ::fork();
      ASSERT_GE(child, 0);
      if (child == 0) {
        std::signal(SIGXFSZ, SIG_IGN);  // EFBIG instead of the signal
        rlimit small;
        ::getrlimit(RLIMIT_FSIZE, &small);
        small.rlim_cur = limit;
        int code = 2;
        if (::setrlimit(RLIMIT_FSIZE, &small) == 0) {
          try {
            if (as_csv) {
              RobotJointsCsvWriter w(s, csv);
              w.Commit(TrackPath(s.model, s.path, s.options, &w));
            } else {
              RobotTrajectoryWriter w(s, path);
              w.Commit(TrackPath(s.model, s.path, s.options, &w));
            }
            code = 1;  // written past the limit
          } catch (const std::system_error& e) {
            code = e.code() == std::errc::file_too_large ? 0 : 3;
          } catch (...) {
            code = 4;
          }
        }
        ::_exit(code);
      }
      int status = 0;
      ASSERT_EQ(::waitpid(child, &status, 0), child);
      ASSERT_TRUE(WIFEXITED(status));
      EXPECT_EQ(WEXITSTATUS(status), 0) << "limit " << limit << (as_csv ? " csv" : " json");
      EXPECT_EQ(ReadFile(path), old);
      EXPECT_EQ(ReadFile(csv), old);
      EXPECT_EQ(dir.Files(), (std::vector<std::string>{"j.csv", "t.json"}));
    }
  }
}

// The heap in use (glibc: small blocks and mmapped ones), which holds Eigen's matrices too (they
// bypass operator new).
size_t HeapInUse() {
  const struct mallinfo2 m = ::mallinfo2();
  return m.uordblks + m.hblkhd;
}

// Samples the heap in use every 1,000 steps, passing the steps on to `next` (if any).
class HeapSampler : public ArmStepSink {
 public:
  explicit HeapSampler(ArmStepSink* next = nullptr) : next_(next) {}
  void Add(const ArmStepReport& step) override {
    if (next_ != nullptr) next_->Add(step);
    if (++steps % 1000 != 0) return;
    const size_t now = HeapInUse();
    if (first == 0) first = now;
    peak = std::max(peak, now);
  }
  size_t Growth() const { return peak - first; }
  long long steps = 0;
  size_t first = 0, peak = 0;

 private:
  ArmStepSink* next_;
};

// 200,000 targets of a 3-link planar arm through a counting sink: the heap does not grow with
// the steps, and the trajectory holds none; the plain form's recorder, for contrast, does grow.
TEST(RobotStreamTest, StreamedRunKeepsNoPerStepData) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer's allocator is not seen by mallinfo2, which measures the heap "
                  "here (the plain build runs this test)";
#endif
  const RobotScenario s = SmallPlanar(200000);
  HeapSampler sampler;
  const ArmTrajectory t = TrackPath(s.model, s.path, s.options, &sampler);
  EXPECT_EQ(sampler.steps, 200000);
  EXPECT_EQ(t.num_steps, 200000);
  EXPECT_TRUE(t.steps.empty());
  EXPECT_EQ(t.unreached, 0);
  EXPECT_LT(sampler.Growth(), size_t{1} << 20) << "the heap grew by " << sampler.Growth();

  ArmStepRecorder recorder;
  HeapSampler recording(&recorder);
  const RobotScenario fewer = SmallPlanar(20000);
  TrackPath(fewer.model, fewer.path, fewer.options, &recording);
  EXPECT_GT(recording.Growth(), size_t{4} << 20) << "the recorder's growth was not measured";
}

// The streaming writers keep one step and a buffer: 50,000 targets written to both files.
TEST(RobotStreamTest, StreamingWritersKeepNoPerStepData) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer's allocator is not seen by mallinfo2, which measures the heap "
                  "here (the plain build runs this test)";
#endif
  const RobotScenario s = SmallPlanar(50000);
  TempDir dir;
  RobotTrajectoryWriter json_writer(s, dir / "t.json");
  RobotJointsCsvWriter csv_writer(s, dir / "j.csv");
  ArmStepFanOut both({&json_writer, &csv_writer});
  HeapSampler sampler(&both);
  const ArmTrajectory t = TrackPath(s.model, s.path, s.options, &sampler);
  json_writer.Commit(t);
  csv_writer.Commit(t);
  EXPECT_LT(sampler.Growth(), size_t{1} << 20) << "the heap grew by " << sampler.Growth();
  EXPECT_GT(std::filesystem::file_size(dir / "t.json"), size_t{10} << 20);
  const json doc = json::parse(ReadFile(dir / "t.json"));
  EXPECT_EQ(doc["steps"].size(), 50000u);
  EXPECT_EQ(doc["summary"]["steps"], 50000);
}

TEST(RobotStreamTest, RecognisesRobotScenarios) {
  for (const std::string& path : RobotExamples()) EXPECT_TRUE(IsRobotScenarioFile(path)) << path;
  EXPECT_FALSE(
      IsRobotScenarioFile(std::string(FLEXKIN_SOURCE_DIR) + "/examples/fig12_spatial_curve.json"));
  EXPECT_TRUE(IsRobotScenarioText(R"({"arm": 1})"));
  EXPECT_TRUE(IsRobotScenarioText(R"({"urdf": "a.urdf", "path": []})"));
  EXPECT_TRUE(IsRobotScenarioText(R"({"format": "flexkin-robot"})"));
  EXPECT_FALSE(IsRobotScenarioText(R"({"format": "other", "arm": {}})"));
  EXPECT_FALSE(IsRobotScenarioText(R"({"curve": {}, "leader": {}})"));
  EXPECT_FALSE(IsRobotScenarioText(R"({"arm": {}, "curve": {}})"));
  EXPECT_FALSE(IsRobotScenarioText("[1, 2]"));
  EXPECT_FALSE(IsRobotScenarioText("{not json"));
}

}  // namespace
}  // namespace flexkin
