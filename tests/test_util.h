#pragma once
// Helpers shared by the test programs (their scenes are in scenes/scenes.h).

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/error.h"
#include "flexkin/tree_scenario.h"

namespace flexkin::test_util {

// True in the AddressSanitizer build (make test-sanitize). There, the longest simulations (tens of
// seconds of simulated time, minutes under the sanitizers) run a shorter span: the same code
// paths for the sanitizers, while the plain build checks where the runs end (a body at rest).
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif

// A number for a test message, 3 significant digits.
inline std::string Str(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

// Expects `make()` to throw InputError with the given field and a message containing `text`.
template <typename Make>
void ExpectInputError(Make make, const std::string& field, const std::string& text) {
  try {
    make();
    ADD_FAILURE() << "no InputError, expected one for " << field;
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), field) << e.what();
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
  }
}

// Expects `make()` to throw InputError whose field is `field` and whose message names it.
template <typename Make>
void ExpectInputError(Make make, const std::string& field) {
  ExpectInputError(make, field, field);
}

// The link lengths of a chain of points, (n+1) by dim -> n.
inline Eigen::VectorXd LengthsOf(const Points& p) {
  Eigen::VectorXd l(p.rows() - 1);
  for (Eigen::Index i = 1; i < p.rows(); ++i) l[i - 1] = (p.row(i) - p.row(i - 1)).norm();
  return l;
}

// The whole content of a file ("" if it cannot be read).
// The keys a JSON reader's unknown-key message lists ("unknown key "x"; valid keys here are "a",
// "b" or "c""): what the reader accepts there, for the tests that compare it with a schema.
inline std::set<std::string> KeysOfUnknownKeyMessage(const std::string& message) {
  std::set<std::string> keys;
  const std::string list = message.substr(message.find("valid keys here are"));
  for (size_t open = list.find('"'); open != std::string::npos;
       open = list.find('"', list.find('"', open + 1) + 1)) {
    const size_t close = list.find('"', open + 1);
    keys.insert(list.substr(open + 1, close - open - 1));
  }
  return keys;
}

inline std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// What a run of the command line gave.
struct CliResult {
  int exit_code = -1;
  std::string out, err;
};

// Runs `cli ARGS` in the directory `dir`, stdout and stderr captured through files there (so
// stderr is not a terminal and no progress is shown), which are removed afterwards.
inline CliResult RunCli(const std::string& cli, const std::string& dir, const std::string& args) {
  const std::string out = dir + "/stdout.txt", err = dir + "/stderr.txt";
  const std::string command =
      "cd '" + dir + "' && '" + cli + "' " + args + " > '" + out + "' 2> '" + err + "'";
  const int status = std::system(command.c_str());
  CliResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = ReadFile(out);
  r.err = ReadFile(err);
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return r;
}

// A test fixture with a fresh directory under the system's temporary one ("flexkin_test_..."),
// removed with everything in it after the test.
class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string name = (std::filesystem::temp_directory_path() / "flexkin_test_XXXXXX").string();
    ASSERT_NE(::mkdtemp(name.data()), nullptr) << name;
    dir_ = name;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string Path(const std::string& name) const { return dir_ + "/" + name; }
  // The names of the files in the directory, sorted.
  std::vector<std::string> Files() const {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(dir_)) {
      names.push_back(e.path().filename());
    }
    std::sort(names.begin(), names.end());
    return names;
  }
  std::string dir_;
};

// A tree result whose link into point 2 slides (a robot tree's prismatic joint), 2D, 6 frames:
// a base, a post of 1 on it, the sliding link turning 0.2 rad and growing 0.1 a frame from
// length 0, and a link of 0.5 along x at its end (point 3, the target).
inline TreeResultFile SlidingTreeResult() {
  TreeResultFile tree;
  tree.name = "lift";
  tree.dim = 2;
  tree.parents = {-1, 0, 1, 2};
  tree.targets = {3};
  tree.fixed = {0};
  for (int f = 0; f <= 5; ++f) {
    Points p(4, 2);
    const double a = 0.2 * f, slide = 0.1 * f;
    p << 0, 0, 0, 1, slide * std::cos(a), 1 + slide * std::sin(a), slide * std::cos(a) + 0.5,
        1 + slide * std::sin(a);
    tree.frames.push_back(p);
    if (f > 0) tree.reached.push_back(1);
  }
  tree.sliding = {2};
  return tree;
}

#ifdef FLEXKIN_SOURCE_DIR
// The text of a file of the source tree ("examples/robot_two_arms.urdf"); "" if it cannot be read.
inline std::string SourceFileText(const std::string& file) {
  std::ifstream in(std::string(FLEXKIN_SOURCE_DIR) + "/" + file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// examples/robot_two_arms.urdf with three of its joints made prismatic (sliding along their
// axes): the waist a lift along z (limits -0.1 to 0.3), the left upper arm's twist a telescope
// along the arm (y, -0.1 to 0.1), and the neck's tilt a rise along z from the pan joint's own
// point (origin moved to 0 0 0, limits 0 to 0.1). "" where a joint is not as expected.
inline std::string SlidingTwoArms() {
  std::string text = SourceFileText("examples/robot_two_arms.urdf");
  const auto edit = [&](const std::string& joint, const std::vector<std::string>& from,
                        const std::vector<std::string>& to) {
    const size_t begin = text.find("<joint name=\"" + joint + "\" type=\"revolute\">");
    const size_t end = text.find("</joint>", begin);
    if (begin == std::string::npos || end == std::string::npos) return false;
    std::string block = text.substr(begin, end - begin);
    block.replace(block.find("revolute"), 8, "prismatic");
    for (size_t i = 0; i < from.size(); ++i) {
      const size_t at = block.find(from[i]);
      if (at == std::string::npos) return false;
      block.replace(at, from[i].size(), to[i]);
    }
    text.replace(begin, end - begin, block);
    return true;
  };
  const bool ok =
      edit("waist", {"lower=\"-1.6\" upper=\"1.6\""}, {"lower=\"-0.1\" upper=\"0.3\""}) &&
      edit("l_upper_arm_twist", {"lower=\"-2.5\" upper=\"2.5\""},
           {"lower=\"-0.1\" upper=\"0.1\""}) &&
      edit("neck_tilt", {"xyz=\"0 0 0.08\"", "xyz=\"0 1 0\"", "lower=\"-0.8\" upper=\"0.8\""},
           {"xyz=\"0 0 0\"", "xyz=\"0 0 1\"", "lower=\"0\" upper=\"0.1\""});
  return ok ? text : std::string();
}
#endif

}  // namespace flexkin::test_util
