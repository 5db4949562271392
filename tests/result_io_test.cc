// Tests of result files: every double reads back bit for bit, the documented keys are there, the
// CSV has one row per point per frame, and a failed write never leaves a partial file or touches
// an existing destination.
#include "flexkin/result_io.h"

#include <dirent.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/error.h"
#include "flexkin/run.h"
#include "flexkin/scenario.h"
#include "io/atomic_file.h"  // WriteFileAtomically
#include "io/json_file.h"    // ParseJsonText
#include "io/result_json.h"  // ResultFromJson of a parsed document

namespace flexkin {
namespace {

// A fresh directory, removed with its files at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::string name =
        (std::filesystem::temp_directory_path() / "flexkin_result_io_XXXXXX").string();
    path_ = ::mkdtemp(name.data());
  }
  ~TempDir() {
    ::chmod(path_.c_str(), 0700);
    for (const std::string& f : Files()) ::unlink((path_ + "/" + f).c_str());
    for (const std::string& f : Files()) ::rmdir((path_ + "/" + f).c_str());
    ::rmdir(path_.c_str());
  }
  const std::string& path() const { return path_; }
  std::string operator/(const std::string& name) const { return path_ + "/" + name; }
  std::vector<std::string> Files() const {
    std::vector<std::string> names;
    if (DIR* dir = ::opendir(path_.c_str())) {
      while (const dirent* entry = ::readdir(dir)) {
        const std::string name = entry->d_name;
        if (name != "." && name != "..") names.push_back(name);
      }
      ::closedir(dir);
    }
    return names;
  }

 private:
  std::string path_;
};

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void ExpectSameBits(const Eigen::Ref<const Eigen::VectorXd>& a,
                    const Eigen::Ref<const Eigen::VectorXd>& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    EXPECT_TRUE(SameBits(a[i], b[i])) << what << "[" << i << "]: " << a[i] << " vs " << b[i];
  }
}

// A result whose numbers are awkward for text: a real run with its values replaced by random
// bit patterns (finite ones), negative zero, subnormals and the extremes.
RunResult AwkwardResult(int dim, uint64_t seed) {
  const Chain chain = MakeChain(Points::Random(6, dim));
  Points steps = Points::Random(4, dim);
  RunOptions options;
  options.tolerance = 1e-3;
  RunResult r = Run(chain, steps, options);
  std::mt19937_64 rng(seed);
  const double specials[] = {-0.0,
                             0.1,
                             1.0 / 3.0,
                             5e-324,
                             2.2250738585072014e-308,
                             std::numeric_limits<double>::max(),
                             -1e300,
                             123456789012345678.0};
  size_t next_special = 0;
  auto awkward = [&](double* x) {
    if (next_special < std::size(specials)) {
      *x = specials[next_special++];
      return;
    }
    double value;
    do {
      const uint64_t bits = rng();
      std::memcpy(&value, &bits, sizeof value);
    } while (!std::isfinite(value));
    *x = value;
  };
  for (size_t i = 0; i < r.frames.points_data().size(); ++i) {
    awkward(r.frames.mutable_points_data() + i);
  }
  for (size_t i = 0; i < r.frames.link_angles_data().size(); ++i) {
    awkward(r.frames.mutable_link_angles_data() + i);
  }
  for (Eigen::Index i = 0; i < r.metrics.path_length.size(); ++i) {
    awkward(r.metrics.path_length.data() + i);
  }
  awkward(&r.metrics.l2_total);
  awkward(&r.accuracy.estimated_error);
  awkward(&r.accuracy.tolerance);
  r.accuracy.max_substeps = 4096;
  return r;
}

TEST(ResultJsonTest, RoundTripIsBitExact) {
  TempDir dir;
  for (int dim : {2, 3}) {
    const RunResult r = AwkwardResult(dim, 7 + dim);
    const std::string path = dir / "result.json";
    WriteResultJson(r, path, "awkward \"name\"");
    const ResultFile back = ReadResultJson(path);
    EXPECT_EQ(back.dim, dim);
    EXPECT_EQ(back.scenario_name, "awkward \"name\"");
    EXPECT_EQ(back.result.method, r.method);
    EXPECT_EQ(back.result.num_steps, r.num_steps);
    ExpectSameBits(back.result.lengths, r.lengths, "lengths");
    ASSERT_EQ(back.result.frames.size(), r.frames.size());
    for (size_t f = 0; f < r.frames.size(); ++f) {
      EXPECT_EQ(back.result.frames[f].step, r.frames[f].step);
      const Points& a = back.result.frames[f].points;
      const Points& b = r.frames[f].points;
      ExpectSameBits(Eigen::Map<const Eigen::VectorXd>(a.data(), a.size()),
                     Eigen::Map<const Eigen::VectorXd>(b.data(), b.size()),
                     "frame " + std::to_string(f));
      ExpectSameBits(back.result.frames[f].link_angles, r.frames[f].link_angles, "angles");
    }
    const Metrics &m = back.result.metrics, &n = r.metrics;
    ExpectSameBits(m.l2_per_step, n.l2_per_step, "l2_per_step");
    ExpectSameBits(m.l2_weighted_per_step, n.l2_weighted_per_step, "l2_weighted_per_step");
    ExpectSameBits(m.path_length, n.path_length, "path_length");
    EXPECT_TRUE(SameBits(m.l2_total, n.l2_total));
    EXPECT_TRUE(SameBits(m.max_relative_length_error, n.max_relative_length_error));
    EXPECT_TRUE(SameBits(back.result.accuracy.estimated_error, r.accuracy.estimated_error));
    EXPECT_EQ(back.result.accuracy.enabled, r.accuracy.enabled);
    EXPECT_EQ(back.result.accuracy.substeps, r.accuracy.substeps);
    EXPECT_TRUE(SameBits(back.result.accuracy.tolerance, r.accuracy.tolerance));
    EXPECT_EQ(back.result.accuracy.max_substeps, r.accuracy.max_substeps);
    EXPECT_EQ(back.result.accuracy.met, r.accuracy.met);
  }
}

TEST(ResultJsonTest, HasTheDocumentedKeys) {
  const Scenario s = LoadScenarioFile(std::string(FLEXKIN_SOURCE_DIR) +
                                      "/examples/fig06_parabola_multi_step.json");
  const RunResult r = flexkin::Run(s.chain, s.leader_steps, s.options);
  std::ostringstream out;
  WriteResultJson(r, out, s.name);
  const nlohmann::json j = ParseJsonText(out.str());
  EXPECT_EQ(j["format"], "flexkin-result");
  EXPECT_EQ(j["version"], 1);
  EXPECT_EQ(j["scenario"], "fig06_parabola_multi_step");
  EXPECT_EQ(j["method"], "tractrix");
  EXPECT_EQ(j["dim"], 2);
  EXPECT_EQ(j["num_links"], 20);
  EXPECT_EQ(j["link_lengths"].size(), 20u);
  EXPECT_EQ(j["num_steps"], 5);
  EXPECT_EQ(j["substeps"], 1);
  for (const char* key : {"l2_per_step", "l2_weighted_per_step", "l2_total", "l2_weighted_total",
                          "max_relative_length_error", "path_length"}) {
    EXPECT_TRUE(j["metrics"].contains(key)) << key;
  }
  for (const char* key :
       {"enabled", "tolerance", "max_substeps", "substeps", "order", "estimated_error", "met"}) {
    EXPECT_TRUE(j["accuracy"].contains(key)) << key;
  }
  ASSERT_EQ(j["frames"].size(), 6u);
  EXPECT_EQ(j["frames"][0]["step"], 0);
  EXPECT_EQ(j["frames"][5]["step"], 5);
  EXPECT_EQ(j["frames"][5]["points"].size(), 21u);
  EXPECT_EQ(j["frames"][5]["link_angles"].size(), 20u);
  // Without a scenario name there is no "scenario" key.
  std::ostringstream unnamed;
  WriteResultJson(r, unnamed);
  EXPECT_FALSE(ParseJsonText(unnamed.str()).contains("scenario"));
}

TEST(ResultCsvTest, OneRowPerPointPerFrameReadingBackExactly) {
  const RunResult r = AwkwardResult(3, 99);
  std::ostringstream out;
  WriteFramesCsv(r, out);
  std::istringstream in(out.str());
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "step,point,x,y,z");
  for (const Frame& f : r.frames) {
    for (Eigen::Index i = 0; i < f.points.rows(); ++i) {
      ASSERT_TRUE(std::getline(in, line));
      std::istringstream row(line);
      std::string cell;
      std::getline(row, cell, ',');
      EXPECT_EQ(std::stoll(cell), f.step);
      std::getline(row, cell, ',');
      EXPECT_EQ(std::stoll(cell), i);
      for (int k = 0; k < 3; ++k) {
        std::getline(row, cell, ',');
        EXPECT_TRUE(SameBits(std::strtod(cell.c_str(), nullptr), f.points(i, k))) << line;
      }
    }
  }
  EXPECT_FALSE(std::getline(in, line)) << "extra row: " << line;
}

TEST(ResultCsvTest, PlanarHeader) {
  std::ostringstream out;
  WriteFramesCsv(AwkwardResult(2, 1), out);
  EXPECT_EQ(out.str().rfind("step,point,x,y\n", 0), 0u);
}

TEST(ResultAtomicWriteTest, NonFiniteValueWritesNothingAndKeepsTheOldFile) {
  TempDir dir;
  const std::string path = dir / "result.json";
  WriteText(path, "old contents");
  RunResult r = AwkwardResult(2, 3);
  r.frames.mutable_points(1)(2, 1) = std::numeric_limits<double>::quiet_NaN();
  try {
    WriteResultJson(r, path);
    FAIL() << "wrote a NaN";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "frames[1].points[2][1]");
  }
  EXPECT_THROW(WriteFramesCsv(r, path), InputError);
  EXPECT_EQ(ReadFile(path), "old contents");
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"result.json"});
}

TEST(ResultAtomicWriteTest, ExceptionInsideTheWriterRemovesTheTemporaryFile) {
  TempDir dir;
  const std::string path = dir / "out.txt";
  WriteText(path, "old");
  EXPECT_THROW(WriteFileAtomically(path,
                                   [](std::ostream& out) {
                                     out << std::string(1 << 20, 'x');  // already partly flushed
                                     throw std::runtime_error("stop");
                                   }),
               std::runtime_error);
  EXPECT_EQ(ReadFile(path), "old");
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"out.txt"});
}

TEST(ResultAtomicWriteTest, MissingDirectoryIsASystemError) {
  TempDir dir;
  const std::string path = dir / "no/such/dir/result.json";
  try {
    WriteResultJson(AwkwardResult(2, 4), path);
    FAIL() << "no error";
  } catch (const std::system_error& e) {
    EXPECT_EQ(e.code(), std::errc::no_such_file_or_directory);
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_TRUE(dir.Files().empty());
}

TEST(ResultAtomicWriteTest, DestinationThatIsADirectoryIsLeftAlone) {
  TempDir dir;
  ASSERT_EQ(::mkdir((dir / "taken").c_str(), 0755), 0);
  EXPECT_THROW(WriteResultJson(AwkwardResult(2, 5), dir / "taken"), std::system_error);
  struct stat st;
  ASSERT_EQ(::stat((dir / "taken").c_str(), &st), 0);
  EXPECT_TRUE(S_ISDIR(st.st_mode));
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"taken"});
}

// A write that fails half way (the file size limit, which holds for root too) leaves the old
// destination byte-identical and no temporary file.
TEST(ResultAtomicWriteTest, FailureInTheMiddleKeepsTheOldFile) {
  TempDir dir;
  const std::string path = dir / "result.json";
  const std::string old = "{\"old\": true}\n";
  WriteText(path, old);
  rlimit saved;
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &saved), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);  // get EFBIG instead of the signal
  rlimit small = saved;
  small.rlim_cur = 1024;  // the result is several KB
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  // A small result fails when the last buffer is flushed, a large one (megabytes) while the
  // frames are streamed; both report the system's reason.
  const Scenario big =
      LoadScenarioFile(std::string(FLEXKIN_SOURCE_DIR) + "/examples/fig10_planar_curve.json");
  const RunResult results[] = {AwkwardResult(3, 6),
                               flexkin::Run(big.chain, big.leader_steps, big.options)};
  int failures = 0;
  for (const RunResult& r : results) {
    for (bool csv : {false, true}) {
      try {
        csv ? WriteFramesCsv(r, path) : WriteResultJson(r, path);
      } catch (const std::system_error& e) {
        ++failures;
        EXPECT_EQ(e.code(), std::errc::file_too_large) << e.what();
      }
    }
  }
  ::setrlimit(RLIMIT_FSIZE, &saved);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_EQ(failures, 4);
  EXPECT_EQ(ReadFile(path), old);
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"result.json"});
}

TEST(ResultAtomicWriteTest, ReadOnlyDirectoryKeepsTheOldFile) {
  TempDir dir;
  const std::string path = dir / "result.json";
  WriteText(path, "old");
  ASSERT_EQ(::chmod(dir.path().c_str(), 0555), 0);
  if (::geteuid() != 0) {
    EXPECT_THROW(WriteResultJson(AwkwardResult(2, 8), path), std::system_error);
  } else {
    // Root writes into read-only directories, so the write is tried by a child process that
    // has given up root for the unprivileged user "nobody" (uid and gid 65534).
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      int code = 2;  // could not drop privileges
      if (::setgid(65534) == 0 && ::setuid(65534) == 0) {
        try {
          WriteResultJson(AwkwardResult(2, 8), path);
          code = 1;  // wrote into a read-only directory
        } catch (const std::system_error&) {
          code = 0;  // refused, as it must be
        } catch (...) {
          code = 3;
        }
      }
      ::_exit(code);
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0) << "1: the write succeeded, 2: could not drop root, 3: "
                                         "another exception than std::system_error";
  }
  ::chmod(dir.path().c_str(), 0700);
  EXPECT_EQ(ReadFile(path), "old");
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"result.json"});
}

TEST(ResultAtomicWriteTest, ReplacingKeepsTheFileMode) {
  TempDir dir;
  const std::string path = dir / "result.json";
  WriteText(path, "old");
  ASSERT_EQ(::chmod(path.c_str(), 0640), 0);
  WriteResultJson(AwkwardResult(2, 9), path);
  struct stat st;
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0640u);
  EXPECT_EQ(ReadResultJson(path).dim, 2);
}

TEST(ResultReadTest, RefusesOtherFormatsAndVersions) {
  TempDir dir;
  std::ostringstream out;
  WriteResultJson(AwkwardResult(2, 10), out);
  nlohmann::json j = ParseJsonText(out.str());
  j["version"] = 2;
  try {
    ResultFromJson(j);
    FAIL() << "accepted version 2";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "/version");
    EXPECT_NE(std::string(e.what()).find("expected 1"), std::string::npos) << e.what();
  }
  j["version"] = 1;
  j["format"] = "something-else";
  EXPECT_THROW(ResultFromJson(j), InputError);
  j["format"] = "flexkin-result";
  j["frames"][1]["points"][0] = {1.0};
  try {
    ResultFromJson(j);
    FAIL() << "accepted a 1D point";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "/frames/1/points/0");
  }
  EXPECT_THROW(ReadResultJson(dir / "missing.json"), std::system_error);
}

// The reader of text gives what the reader of the file gives; text that is not JSON is refused
// with its line and column.
TEST(ResultReadTest, FromTextAsFromTheFile) {
  TempDir dir;
  WriteResultJson(AwkwardResult(3, 20), dir / "r.json", "named");
  const ResultFile from_file = ReadResultJson(dir / "r.json");
  const ResultFile from_text = ResultFromText(ReadFile(dir / "r.json"));
  EXPECT_EQ(from_text.scenario_name, "named");
  EXPECT_EQ(from_text.dim, from_file.dim);
  ExpectSameBits(from_text.result.lengths, from_file.result.lengths, "lengths");
  ASSERT_EQ(from_text.result.frames.size(), from_file.result.frames.size());
  for (size_t f = 0; f < from_text.result.frames.size(); ++f) {
    EXPECT_EQ(from_text.result.frames[f].step, from_file.result.frames[f].step);
    EXPECT_EQ(from_text.result.frames[f].points, from_file.result.frames[f].points);
  }
  try {
    ResultFromText("{\"format\": ");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "");
    EXPECT_EQ(std::string(e.what()).rfind("line 1, column ", 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace flexkin
