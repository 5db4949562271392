// The library is safe to call from several threads at once on different chains and arms (the
// thread-safety statement of include/flexkin/flexkin.h): every example scenario of the paper and
// every robot scenario (planar, spherical, URDF arms with axes, pointing and velocity limits) is
// read and run by several threads at the same time, each in another order, and every thread's
// result must equal, bit for bit, the result of the same scenario run alone. Under
// ThreadSanitizer (make test-thread) any data race between the runs fails the test.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "flexkin/flexkin.h"
#include "flexkin/urdf.h"

namespace flexkin {
namespace {

namespace fs = std::filesystem;

const fs::path kExamples = fs::path(FLEXKIN_SOURCE_DIR) / "examples";

// The bytes of every number that a result holds: equal fingerprints are equal results.
template <typename Matrix>
void Append(std::string* out, const Matrix& m) {
  const auto* begin = reinterpret_cast<const char*>(m.data());
  out->append(begin, begin + sizeof(double) * m.size());
}

void AppendNumber(std::string* out, double x) {
  char bytes[sizeof x];
  std::memcpy(bytes, &x, sizeof x);
  out->append(bytes, sizeof x);
}

// A chain scenario (fig*.json): read, run, fingerprint of its frames and metrics; the result is
// also written to `out_path` and read back.
std::string RunChainScenario(const fs::path& scenario_path, const fs::path& out_path) {
  const Scenario scenario = LoadScenarioFile(scenario_path.string());
  RunOptions options = scenario.options;
  const RunResult result = Run(scenario.chain, scenario.leader_steps, options);
  std::string print;
  for (const Frame& frame : result.frames) {
    Append(&print, frame.points);
    Append(&print, frame.link_angles);
  }
  AppendNumber(&print, result.metrics.max_relative_length_error);
  WriteResultFile(result, out_path.string(), ResultFileFormat::kJson, scenario.name);
  const ResultFile back = ReadResultFile(out_path.string());
  for (const Frame& frame : back.result.frames) Append(&print, frame.points);
  return print;
}

// A robot scenario (robot_*.json; URDF arms through urdfdom): read, track, fingerprint of every
// step's angles and points.
std::string RunRobotScenario(const fs::path& scenario_path) {
  const RobotScenario scenario =
      LoadRobotScenarioFile(scenario_path.string(), UrdfRobotScenarioOptions());
  const ArmTrajectory trajectory = TrackPath(scenario.model, scenario.path, scenario.options);
  std::string print;
  for (const ArmStepReport& step : trajectory.steps) {
    Append(&print, step.state.points);
    Append(&print, step.state.angles.angle);
    AppendNumber(&print, step.ee_error);
  }
  AppendNumber(&print, trajectory.max_pointing_error);
  return print;
}

struct Job {
  std::string name;
  std::function<std::string(int thread)> run;  // the fingerprint; `thread` names its own files
};

std::vector<Job> Jobs(const fs::path& dir) {
  std::vector<Job> jobs;
  for (const fs::directory_entry& entry : fs::directory_iterator(kExamples)) {
    const fs::path path = entry.path();
    const std::string name = path.filename().string();
    if (path.extension() != ".json") continue;
    if (name.rfind("fig", 0) == 0) {
      jobs.push_back({name, [path, dir, name](int thread) {
                        return RunChainScenario(path, dir / (std::to_string(thread) + "_" + name));
                      }});
    } else if (name.rfind("robot_", 0) == 0) {
      jobs.push_back({name, [path](int) { return RunRobotScenario(path); }});
    }
  }
  std::sort(jobs.begin(), jobs.end(), [](const Job& a, const Job& b) { return a.name < b.name; });
  return jobs;
}

TEST(ThreadSafety, ScenariosRunTogetherGiveTheirResultsAlone) {
  const fs::path dir = fs::path(::testing::TempDir()) / "flexkin_thread_safety";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::vector<Job> jobs = Jobs(dir);
  ASSERT_GE(jobs.size(), 10u);  // the paper's figures and the robot examples
  std::vector<std::string> alone;
  for (const Job& job : jobs) alone.push_back(job.run(0));

  constexpr int kThreads = 4;
  std::vector<std::vector<std::string>> together(kThreads, std::vector<std::string>(jobs.size()));
  std::vector<std::string> errors(kThreads);
  std::atomic<int> ready{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      ++ready;
      while (ready.load() < kThreads) std::this_thread::yield();  // start together
      try {
        // Each thread takes the jobs in another order (rotated by t, odd threads reversed), so
        // that different scenarios and the same one overlap.
        for (size_t i = 0; i < jobs.size(); ++i) {
          size_t k = (i + static_cast<size_t>(t) * jobs.size() / kThreads) % jobs.size();
          if (t % 2 == 1) k = jobs.size() - 1 - k;
          together[t][k] = jobs[k].run(t + 1);
        }
      } catch (const std::exception& e) {
        errors[t] = e.what();
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  for (int t = 0; t < kThreads; ++t) {
    EXPECT_EQ(errors[t], "") << "thread " << t;
    for (size_t k = 0; k < jobs.size(); ++k) {
      EXPECT_FALSE(alone[k].empty()) << jobs[k].name;
      EXPECT_TRUE(together[t][k] == alone[k])
          << jobs[k].name << " in thread " << t << " differs from its run alone";
    }
  }
  fs::remove_all(dir);
}

// Arms built from URDF text in several threads at once (urdfdom's error handler is process-wide;
// flexkin serialises its use), with refusals among them: each thread gets its own model or its
// own message.
TEST(ThreadSafety, UrdfArmsReadInSeveralThreads) {
  std::ifstream in(kExamples / "robot_universal_snake.urdf");
  std::stringstream text;
  text << in.rdbuf();
  const std::string good = text.str();
  const std::string bad =
      "<robot name=\"r\"><link name=\"a\"/><joint name=\"j\" type=\"floating\">"
      "<parent link=\"a\"/><child link=\"b\"/></joint><link name=\"b\"/></robot>";
  const ArmModel expected = ArmFromUrdf(good);
  std::string refusal;
  try {
    ArmFromUrdf(bad);
  } catch (const InputError& e) {
    refusal = e.what();
  }
  ASSERT_FALSE(refusal.empty());
  constexpr int kThreads = 4, kRounds = 20;
  std::vector<int> same(kThreads, 0), refused(kThreads, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (int r = 0; r < kRounds; ++r) {
        if ((r + t) % 2 == 0) {
          const ArmModel model = ArmFromUrdf(good);
          same[t] += model.link_lengths == expected.link_lengths &&
                     model.joint_axes == expected.joint_axes &&
                     model.joint_names == expected.joint_names;
        } else {
          try {
            ArmFromUrdf(bad);
          } catch (const InputError& e) {
            refused[t] += e.what() == refusal;
          }
        }
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  for (int t = 0; t < kThreads; ++t) {
    EXPECT_EQ(same[t], kRounds / 2) << "thread " << t;
    EXPECT_EQ(refused[t], kRounds / 2) << "thread " << t;
  }
}

}  // namespace
}  // namespace flexkin
