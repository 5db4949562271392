// The golden test: every example scenario (examples/*.json) run through the command line, and its
// whole result (every frame, every metric, every per-step report) compared with the result pinned
// in tests/golden/scenarios/. It is the safety net of refactors: a change of structure changes no
// number.
//
// Each scenario runs twice. With FLEXKIN_SIMD=scalar (the portable engine) the result must be the
// pinned one bit for bit: the FNV-1a hash of its canonical JSON text (every double written so
// that it reads back as the same bits) equals the pinned hash. The pinned file also holds a
// sample of the result (arrays longer than 48 elements thinned to every k-th element and the
// last), which locates a difference when the hash differs. With the SIMD engines the machine has
// (FLEXKIN_SIMD unset), every number must be within 1e-14 of the scalar run's (relative to its
// magnitude, absolute below 1), and every integer, flag and string the same; the frames' points
// to 1e-14 of the frame's magnitude, their link angles and the per-step L2 sums within the bounds
// that gives them (CompareFrames). The fixed-base arms'
// SIMD path (src/arm/lanes.cc, AVX2 and FMA) solves each step to the solver's tolerance by another
// sequence of iterates, so its result is not the scalar one to 1e-14 (joint angles differ by up to
// 1e-11, iteration counts by one): for robot scenarios that path is pinned by a hash of its own,
// bit for bit, on any CPU with AVX2 and FMA.
//
// The pinned files were written by the scalar engine with
//   FLEXKIN_GOLDEN_UPDATE=1 build/tests/golden_test
// which is to be run only when a result is meant to change, and the change explained in the
// commit that updates the files.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "test_util.h"

namespace flexkin {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::string kCli = FLEXKIN_CLI;
const fs::path kSource = FLEXKIN_SOURCE_DIR;

// Keys whose values are wall-clock times: they differ from run to run and are not compared.
const std::set<std::string> kTimingKeys = {"seconds",      "solve_seconds", "wall_seconds",
                                           "microseconds", "time_us",       "timing"};

bool Updating() {
  const char* update = std::getenv("FLEXKIN_GOLDEN_UPDATE");
  return update != nullptr && std::string(update) == "1";
}

// The example scenarios: examples/fig*.json are run with "flexkin run", examples/robot_*.json
// with "flexkin robot".
std::vector<std::string> Examples() {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(kSource / "examples")) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() != ".json") continue;
    if (name.rfind("fig", 0) == 0 || name.rfind("robot_", 0) == 0) {
      names.push_back(entry.path().stem().string());
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

json WithoutTimings(const json& j) {
  if (j.is_object()) {
    json out = json::object();
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (kTimingKeys.count(it.key()) == 0) out[it.key()] = WithoutTimings(it.value());
    }
    return out;
  }
  if (j.is_array()) {
    json out = json::array();
    for (const json& v : j) out.push_back(WithoutTimings(v));
    return out;
  }
  return j;
}

// FNV-1a, 64 bits.
uint64_t Hash(const std::string& text) {
  uint64_t h = 14695981039346656037ull;
  for (const unsigned char c : text) h = (h ^ c) * 1099511628211ull;
  return h;
}

std::string Hex(uint64_t h) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

constexpr size_t kSampleMax = 48;

// `j` with every array longer than kSampleMax replaced by {"sampled_length": N, "every": k,
// "items": [elements 0, k, 2k, ..., and N-1]}.
json Sample(const json& j) {
  if (j.is_object()) {
    json out = json::object();
    for (auto it = j.begin(); it != j.end(); ++it) out[it.key()] = Sample(it.value());
    return out;
  }
  if (!j.is_array()) return j;
  if (j.size() <= kSampleMax) {
    json out = json::array();
    for (const json& v : j) out.push_back(Sample(v));
    return out;
  }
  const size_t every = (j.size() + kSampleMax - 1) / kSampleMax;
  json items = json::array();
  for (size_t i = 0; i < j.size(); i += every) items.push_back(Sample(j[i]));
  if ((j.size() - 1) % every != 0) items.push_back(Sample(j.back()));
  return {{"sampled_length", j.size()}, {"every", every}, {"items", items}};
}

// Compares `actual` with `golden`, recording the first few differences in `diffs`.
void Compare(const json& actual, const json& golden, const std::string& where, bool exact,
             std::vector<std::string>* diffs, double* worst) {
  if (diffs->size() >= 10) return;
  const bool a_float = actual.is_number_float(), g_float = golden.is_number_float();
  if ((a_float || g_float) && actual.is_number() && golden.is_number()) {
    const double a = actual.get<double>(), g = golden.get<double>();
    if (exact) {
      if (!(a == g) && !(std::isnan(a) && std::isnan(g))) {
        diffs->push_back(where + ": " + json(a).dump() + " != pinned " + json(g).dump());
      }
      return;
    }
    const double err = std::abs(a - g) / std::max(1.0, std::abs(g));
    *worst = std::max(*worst, err);
    if (!(err <= 1e-14)) {
      diffs->push_back(where + ": " + json(a).dump() + " differs from pinned " + json(g).dump() +
                       " by " + test_util::Str(err) + " (relative) > 1e-14");
    }
    return;
  }
  if (actual.is_array() && golden.is_object() && golden.contains("sampled_length")) {
    const size_t length = golden["sampled_length"].get<size_t>();
    const size_t every = golden["every"].get<size_t>();
    if (actual.size() != length) {
      diffs->push_back(where + ": " + std::to_string(actual.size()) + " elements, pinned " +
                       std::to_string(length));
      return;
    }
    const json& items = golden["items"];
    for (size_t k = 0; k < items.size(); ++k) {
      const size_t i = std::min(k * every, length - 1);
      Compare(Sample(actual[i]), items[k], where + "/" + std::to_string(i), exact, diffs, worst);
    }
    return;
  }
  if (actual.type() != golden.type()) {
    diffs->push_back(where + ": " + actual.dump().substr(0, 80) + " has another type than pinned " +
                     golden.dump().substr(0, 80));
    return;
  }
  if (actual.is_object()) {
    for (auto it = golden.begin(); it != golden.end(); ++it) {
      if (!actual.contains(it.key())) {
        diffs->push_back(where + "/" + it.key() + ": missing");
      } else {
        Compare(actual[it.key()], it.value(), where + "/" + it.key(), exact, diffs, worst);
      }
    }
    for (auto it = actual.begin(); it != actual.end(); ++it) {
      if (!golden.contains(it.key())) diffs->push_back(where + "/" + it.key() + ": not pinned");
    }
    return;
  }
  if (actual.is_array()) {
    if (actual.size() != golden.size()) {
      diffs->push_back(where + ": " + std::to_string(actual.size()) + " elements, pinned " +
                       std::to_string(golden.size()));
      return;
    }
    for (size_t i = 0; i < actual.size(); ++i) {
      Compare(actual[i], golden[i], where + "/" + std::to_string(i), exact, diffs, worst);
    }
    return;
  }
  if (actual != golden) {
    diffs->push_back(where + ": " + actual.dump() + " != pinned " + golden.dump());
  }
}

bool IsRobot(const std::string& name) { return name.rfind("robot_", 0) == 0; }

bool HasAvx2Fma() {
#if defined(__x86_64__)
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
  return false;
#endif
}

// Runs the example `name` through the command line, with FLEXKIN_SIMD=scalar if `scalar`, and
// returns its result without the timings.
json RunExample(const std::string& name, bool scalar) {
  const bool robot = IsRobot(name);
  const fs::path dir =
      fs::temp_directory_path() / ("flexkin_golden_" + name + "_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path out = dir / "result.json";
  // The engine is chosen once per process from the environment (src/sequential/propagate.cc).
  const std::string cli =
      std::string(scalar ? "FLEXKIN_SIMD=scalar " : "env -u FLEXKIN_SIMD ") + "'" + kCli + "'";
  const std::string args = std::string(robot ? "robot '" : "run '") +
                           (kSource / "examples" / (name + ".json")).string() + "' -o '" +
                           out.string() + "' --quiet";
  const std::string command =
      "cd '" + dir.string() + "' && " + cli + " " + args + " > stdout.txt 2> stderr.txt";
  const int status = std::system(command.c_str());
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
  const std::string err = test_util::ReadFile((dir / "stderr.txt").string());
  const std::string text = test_util::ReadFile(out.string());
  fs::remove_all(dir);
  // Exit 3: a robot scenario with targets out of reach, reported and written (docs/robots.md).
  EXPECT_TRUE(code == 0 || (robot && code == 3)) << name << ": exit " << code << ": " << err;
  if (text.empty()) return json();
  return WithoutTimings(json::parse(text));
}

class GoldenTest : public testing::TestWithParam<std::string> {};

TEST_P(GoldenTest, ScalarEngineGivesThePinnedResultBitForBit) {
  ASSERT_FALSE(kCli.empty()) << "the flexkin command line was not built";
  const std::string name = GetParam();
  const json actual = RunExample(name, true);
  ASSERT_FALSE(actual.is_null()) << name << ": no result";
  const std::string hash = Hex(Hash(actual.dump()));
  const fs::path pinned = kSource / "tests" / "golden" / "scenarios" / (name + ".json");
  if (Updating()) {
    json file = {{"fnv1a64", hash}, {"sample", Sample(actual)}};
    if (IsRobot(name)) {
      ASSERT_TRUE(HasAvx2Fma()) << "pin robot scenarios on a CPU with AVX2 and FMA";
      file["fnv1a64_avx2"] = Hex(Hash(RunExample(name, false).dump()));
    }
    std::ofstream(pinned) << file.dump(1) << "\n";
    GTEST_SKIP() << "pinned " << pinned;
  }
  const std::string text = test_util::ReadFile(pinned.string());
  ASSERT_FALSE(text.empty()) << "no pinned result " << pinned;
  const json golden = json::parse(text);
  std::vector<std::string> diffs;
  double worst = 0.0;
  Compare(actual, golden["sample"], "", true, &diffs, &worst);
  std::string all;
  for (const std::string& d : diffs) all += "\n  " + d;
  EXPECT_TRUE(diffs.empty()) << name << " (sampled values, bit for bit):" << all;
  EXPECT_EQ(hash, golden["fnv1a64"].get<std::string>())
      << name << ": the result differs from the pinned one"
      << (diffs.empty() ? " outside the sample" : "");
}

// The frames: every coordinate of a frame is computed with the others, so its rounding is that of
// the frame's magnitude X (its largest coordinate, at least 1), not its own: a coordinate near 0
// in a chain far from the origin differs by ulps of X. Points are checked to 1e-14 X. Link angles
// are computed from the points: a difference of d in a point turns its link by up to d / L, so
// they are checked to 2e-14 X / L (both ends of the link may move). Both are then removed so that
// Compare sees the rest (metrics, reports) with its own tolerance.
void CompareFrames(json* simd, json* scalar, std::vector<std::string>* diffs, double* worst) {
  if (!scalar->contains("frames") || !simd->contains("frames")) return;
  const json& lengths = (*scalar)["link_lengths"];
  json& a_frames = (*simd)["frames"];
  json& g_frames = (*scalar)["frames"];
  if (a_frames.size() != g_frames.size()) return;  // Compare reports it
  auto check = [&](double a, double g, double bound, const std::string& where) {
    const double err = std::abs(a - g);
    *worst = std::max(*worst, err / bound * 1e-14);
    if (!(err <= bound) && diffs->size() < 10) {
      diffs->push_back(where + ": " + json(a).dump() + " differs from " + json(g).dump() + " by " +
                       test_util::Str(err) + " > " + test_util::Str(bound));
    }
  };
  double run_magnitude = 1.0;
  for (const json& frame : g_frames) {
    for (const json& point : frame["points"]) {
      for (const json& x : point)
        run_magnitude = std::max(run_magnitude, std::abs(x.get<double>()));
    }
  }
  for (size_t f = 0; f < g_frames.size(); ++f) {
    json& a = a_frames[f];
    json& g = g_frames[f];
    const std::string where = "/frames/" + std::to_string(f);
    double magnitude = 1.0;
    for (const json& point : g["points"]) {
      for (const json& x : point) magnitude = std::max(magnitude, std::abs(x.get<double>()));
    }
    if (a["points"].size() != g["points"].size()) continue;
    for (size_t i = 0; i < g["points"].size(); ++i) {
      if (a["points"][i].size() != g["points"][i].size()) continue;
      for (size_t k = 0; k < g["points"][i].size(); ++k) {
        check(a["points"][i][k].get<double>(), g["points"][i][k].get<double>(), 1e-14 * magnitude,
              where + "/points/" + std::to_string(i) + "/" + std::to_string(k));
      }
    }
    a.erase("points");
    g.erase("points");
    if (!a.contains("link_angles") || !g.contains("link_angles")) continue;
    const json& a_angles = a["link_angles"];
    const json& g_angles = g["link_angles"];
    if (a_angles.size() != g_angles.size()) continue;
    for (size_t i = 0; i < g_angles.size(); ++i) {
      check(a_angles[i].get<double>(), g_angles[i].get<double>(),
            2e-14 * magnitude / lengths[i].get<double>(),
            where + "/link_angles/" + std::to_string(i));
    }
    a.erase("link_angles");
    g.erase("link_angles");
  }
  // The distances of a leader step are differences of points known to 1e-14 X (X the largest
  // magnitude of any frame): each of the n+1 distances to 2e-14 X, so each step's L2 sum to
  // 2 (n+1) 1e-14 X, and its weighted sum (weights summing to the chain's length) to twice the
  // chain's length times 1e-14 X.
  double total_length = 0.0;
  for (const json& length : lengths) total_length += length.get<double>();
  const std::pair<const char*, double> per_step[] = {
      {"l2_per_step", 2e-14 * static_cast<double>(lengths.size() + 1) * run_magnitude},
      {"l2_weighted_per_step", 2e-14 * total_length * run_magnitude}};
  for (const auto& [key, bound] : per_step) {
    json& a = (*simd)["metrics"][key];
    json& g = (*scalar)["metrics"][key];
    if (!a.is_array() || !g.is_array() || a.size() != g.size()) continue;
    for (size_t s = 0; s < g.size(); ++s) {
      check(a[s].get<double>(), g[s].get<double>(),
            std::max(bound, 1e-14 * std::abs(g[s].get<double>())),
            "/metrics/" + std::string(key) + "/" + std::to_string(s));
    }
    (*simd)["metrics"].erase(key);
    (*scalar)["metrics"].erase(key);
  }
}

TEST_P(GoldenTest, SimdEnginesAgreeWithTheScalarEngineTo1e14) {
  ASSERT_FALSE(kCli.empty()) << "the flexkin command line was not built";
  const std::string name = GetParam();
  if (IsRobot(name)) {
    if (!HasAvx2Fma()) GTEST_SKIP() << "no AVX2 and FMA: the arms run the scalar path only";
#if defined(__SANITIZE_ADDRESS__)
    // The sanitizer build compiles the AVX2 lanes to other instruction sequences, so their
    // iterates differ in the last bits; the hash pins the plain build's path.
    GTEST_SKIP() << "the AVX2 arm path's hash is pinned for the plain (unsanitized) build";
#endif
    const json simd = RunExample(name, false);
    ASSERT_FALSE(simd.is_null()) << name << ": no result";
    const json golden = json::parse(test_util::ReadFile(
        (kSource / "tests" / "golden" / "scenarios" / (name + ".json")).string()));
    EXPECT_EQ(Hex(Hash(simd.dump())), golden["fnv1a64_avx2"].get<std::string>())
        << name << ": the AVX2 arm path's result differs from the pinned one";
    return;
  }
  json scalar = RunExample(name, true);
  json simd = RunExample(name, false);
  ASSERT_FALSE(scalar.is_null() || simd.is_null()) << name << ": no result";
  std::vector<std::string> diffs;
  double worst = 0.0;
  CompareFrames(&simd, &scalar, &diffs, &worst);
  Compare(simd, scalar, "", false, &diffs, &worst);
  std::string all;
  for (const std::string& d : diffs) all += "\n  " + d;
  EXPECT_TRUE(diffs.empty()) << name << " (SIMD against scalar):" << all;
  RecordProperty("worst_relative_difference", test_util::Str(worst));
}

INSTANTIATE_TEST_SUITE_P(Examples, GoldenTest, testing::ValuesIn(Examples()),
                         [](const testing::TestParamInfo<std::string>& info) {
                           return info.param;
                         });

// The test above would pass vacuously if no example were found.
TEST(GoldenExamples, EveryKindOfScenarioIsPinned) {
  const std::vector<std::string> names = Examples();
  EXPECT_GE(names.size(), 17u);
  for (const std::string& name : names) {
    EXPECT_TRUE(fs::exists(kSource / "tests" / "golden" / "scenarios" / (name + ".json"))) << name;
  }
}

}  // namespace
}  // namespace flexkin
