// Tests of the streaming result writers and the .npz result format: the npz reads back bit for
// bit (and numpy.load reads it as the JSON of the same run says), the streamed JSON parses to
// WriteResultJson's document, a failed or abandoned write leaves nothing behind and an existing
// file untouched, a corrupted npz is an InputError (never a crash), every member of an archive,
// known to the reader or not, is checked (its local header against the central directory, its
// bytes against the other members' and the central directory's, its CRC-32), and the size
// estimate is within a factor of the files written.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/error.h"
#include "flexkin/result_io.h"
#include "flexkin/run.h"
#include "flexkin/scenario.h"
#include "flexkin/strand_file.h"
#include "io/npz.h"
#include "test_util.h"

namespace flexkin {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using test_util::ReadFile;

class TempDir {
 public:
  // In memory where there is a tmpfs (the corruption test writes thousands of small files).
  explicit TempDir(bool memory = false) {
    const fs::path base = memory && fs::is_directory("/dev/shm") && ::access("/dev/shm", W_OK) == 0
                              ? fs::path("/dev/shm")
                              : fs::temp_directory_path();
    std::string name = (base / "flexkin_npz_XXXXXX").string();
    path_ = ::mkdtemp(name.data());
  }
  ~TempDir() { fs::remove_all(path_); }
  std::string operator/(const std::string& name) const { return path_ + "/" + name; }
  const std::string& path() const { return path_; }
  std::vector<std::string> Files() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(path_)) names.push_back(e.path().filename());
    std::sort(names.begin(), names.end());
    return names;
  }

 private:
  std::string path_;
};

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void ExpectSameBits(const Eigen::Ref<const Eigen::VectorXd>& a,
                    const Eigen::Ref<const Eigen::VectorXd>& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    ASSERT_TRUE(SameBits(a[i], b[i])) << what << "[" << i << "]: " << a[i] << " vs " << b[i];
  }
}

void ExpectSameFrames(const RunResult& a, const RunResult& b) {
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (size_t f = 0; f < a.frames.size(); ++f) {
    EXPECT_EQ(a.frames[f].step, b.frames[f].step);
    const Points &p = a.frames[f].points, &q = b.frames[f].points;
    ASSERT_EQ(p.rows(), q.rows());
    ASSERT_EQ(p.cols(), q.cols());
    ExpectSameBits(Eigen::Map<const Eigen::VectorXd>(p.data(), p.size()),
                   Eigen::Map<const Eigen::VectorXd>(q.data(), q.size()),
                   "frame " + std::to_string(f));
    ExpectSameBits(a.frames[f].link_angles, b.frames[f].link_angles, "angles");
  }
}

void ExpectSameResult(const ResultFile& back, const RunResult& r, int dim,
                      const std::string& name) {
  EXPECT_EQ(back.dim, dim);
  EXPECT_EQ(back.scenario_name, name);
  EXPECT_EQ(back.result.method, r.method);
  EXPECT_EQ(back.result.num_steps, r.num_steps);
  ExpectSameBits(back.result.lengths, r.lengths, "lengths");
  ExpectSameFrames(back.result, r);
  const Metrics &m = back.result.metrics, &n = r.metrics;
  ExpectSameBits(m.l2_per_step, n.l2_per_step, "l2_per_step");
  ExpectSameBits(m.l2_weighted_per_step, n.l2_weighted_per_step, "l2_weighted_per_step");
  ExpectSameBits(m.path_length, n.path_length, "path_length");
  EXPECT_TRUE(SameBits(m.l2_total, n.l2_total));
  EXPECT_TRUE(SameBits(m.l2_weighted_total, n.l2_weighted_total));
  EXPECT_TRUE(SameBits(m.max_relative_length_error, n.max_relative_length_error));
  EXPECT_TRUE(SameBits(back.result.accuracy.estimated_error, r.accuracy.estimated_error));
  EXPECT_TRUE(SameBits(back.result.accuracy.tolerance, r.accuracy.tolerance));
  EXPECT_EQ(back.result.accuracy.enabled, r.accuracy.enabled);
  EXPECT_EQ(back.result.accuracy.substeps, r.accuracy.substeps);
  EXPECT_EQ(back.result.accuracy.max_substeps, r.accuracy.max_substeps);
  EXPECT_EQ(back.result.accuracy.met, r.accuracy.met);
  EXPECT_EQ(back.result.overall.solves, r.overall.solves);
  EXPECT_EQ(back.result.overall.iterations, r.overall.iterations);
  EXPECT_TRUE(SameBits(back.result.overall.optimality, r.overall.optimality));
  for (const auto& [term, term_name, summary] : Vocabulary<ObjectiveTerm>::kEntries) {
    EXPECT_TRUE(SameBits(back.result.weights[term], r.weights[term])) << term_name;
  }
  EXPECT_TRUE(SameBits(back.result.seconds, r.seconds));
}

Scenario Example(const std::string& name) {
  return LoadScenarioFile(std::string(FLEXKIN_SOURCE_DIR) + "/examples/" + name);
}

// A run whose numbers are awkward: random finite bit patterns, negative zero, subnormals.
RunResult AwkwardResult(int dim, uint64_t seed) {
  const Chain chain = MakeChain(Points::Random(6, dim));
  RunOptions options;
  options.tolerance = 1e-3;
  RunResult r = flexkin::Run(chain, Points::Random(4, dim), options);
  std::mt19937_64 rng(seed);
  const double specials[] = {-0.0, 5e-324, std::numeric_limits<double>::max(), -1e300};
  size_t next = 0;
  auto awkward = [&](double* x) {
    if (next < std::size(specials)) {
      *x = specials[next++];
      return;
    }
    do {
      const uint64_t bits = rng();
      std::memcpy(x, &bits, sizeof *x);
    } while (!std::isfinite(*x));
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
  return r;
}

TEST(ResultNpzTest, RoundTripIsBitExact) {
  TempDir dir;
  for (int dim : {2, 3}) {
    const RunResult r = AwkwardResult(dim, 11 + dim);
    WriteResultFile(r, dir / "r.npz", ResultFileFormat::kNpz, "awkward \"name\"");
    ExpectSameResult(ReadResultFile(dir / "r.npz"), r, dim, "awkward \"name\"");
  }
  // The overall method (its report and weights) and frames without link angles.
  const Scenario s = Example("fig06_parabola_overall_multi_step.json");
  RunResult r = flexkin::Run(s.chain, s.leader_steps, s.options);
  ASSERT_EQ(r.method, Method::kOverall);
  WriteResultFile(r, dir / "overall.npz", ResultFileFormat::kNpz, s.name);
  ExpectSameResult(ReadResultFile(dir / "overall.npz"), r, 2, s.name);
  r.frames.DropLinkAngles();
  WriteResultFile(r, dir / "no_angles.npz", ResultFileFormat::kNpz);
  ExpectSameResult(ReadResultFile(dir / "no_angles.npz"), r, 2, "");
  // ReadResultFile reads JSON too, as ReadResultJson does.
  WriteResultJson(r, dir / "no_angles.json");
  ExpectSameResult(ReadResultFile(dir / "no_angles.json"), r, 2, "");
}

// Streams a plain run's frames and result through a ResultFileWriter.
void Stream(const RunResult& r, const std::string& path, ResultFileFormat format,
            const std::string& name) {
  ResultHeader header;
  header.method = r.method;
  header.dim = static_cast<int>(r.frames[0].points.cols());
  header.lengths = r.lengths;
  header.scenario_name = name;
  ResultFileWriter writer(path, format, header);
  for (const Frame& f : r.frames) writer.Add(f.step, f.points, f.link_angles);
  EXPECT_EQ(writer.frames(), static_cast<int64_t>(r.frames.size()));
  writer.Commit(r);
}

TEST(ResultStreamTest, StreamedJsonParsesAsWriteResultJson) {
  TempDir dir;
  for (const char* name : {"fig06_parabola_multi_step.json",
                           "fig06_parabola_overall_multi_step.json", "fig12_spatial_curve.json"}) {
    const Scenario s = Example(name);
    const RunResult r = flexkin::Run(s.chain, s.leader_steps, s.options);
    std::ostringstream whole;
    WriteResultJson(r, whole, s.name);
    Stream(r, dir / "streamed.json", ResultFileFormat::kJson, s.name);
    EXPECT_EQ(json::parse(ReadFile(dir / "streamed.json")), json::parse(whole.str())) << name;
    // Through Run's sink, as the command line does: the same but for the timing.
    {
      ResultFileWriter writer(dir / "run.json", ResultFileFormat::kJson,
                              MakeResultHeader(s.chain, s.options, s.name));
      const RunResult streamed = flexkin::Run(s.chain, s.leader_steps, s.options, &writer);
      EXPECT_TRUE(streamed.frames.empty());
      writer.Commit(streamed);
    }
    json a = json::parse(ReadFile(dir / "run.json")), b = json::parse(whole.str());
    a.erase("seconds");
    b.erase("seconds");
    EXPECT_EQ(a, b) << name;
    // And the npz of the same run reads back as the JSON does.
    Stream(r, dir / "streamed.npz", ResultFileFormat::kNpz, s.name);
    ExpectSameResult(ReadResultFile(dir / "streamed.npz"), r, s.chain.dim(), s.name);
  }
  EXPECT_EQ(dir.Files(), (std::vector<std::string>{"run.json", "streamed.json", "streamed.npz"}));
}

TEST(ResultStreamTest, CsvWriterWritesWhatWriteFramesCsvWrites) {
  TempDir dir;
  const Scenario s = Example("fig12_spatial_curve.json");
  const RunResult r = flexkin::Run(s.chain, s.leader_steps, s.options);
  FramesCsvWriter csv(dir / "run.csv", 3);
  const RunResult streamed = flexkin::Run(s.chain, s.leader_steps, s.options, &csv);
  csv.Commit();
  WriteFramesCsv(r, dir / "whole.csv");
  EXPECT_EQ(ReadFile(dir / "run.csv"), ReadFile(dir / "whole.csv"));
}

TEST(ResultStreamTest, NonFiniteFrameStopsTheRunAndWritesNothing) {
  TempDir dir;
  for (ResultFileFormat format : {ResultFileFormat::kJson, ResultFileFormat::kNpz}) {
    const std::string path = dir / (std::string("r.") + ResultFileFormatName(format));
    WriteText(path, "old");
    const Scenario s = Example("fig06_parabola_multi_step.json");
    const RunResult r = flexkin::Run(s.chain, s.leader_steps, s.options);
    ResultHeader header = MakeResultHeader(s.chain, s.options);
    test_util::ExpectInputError(
        [&] {
          ResultFileWriter writer(path, format, header);
          writer.Add(0, r.frames[0].points, r.frames[0].link_angles);
          Points bad = r.frames[1].points;
          bad(2, 1) = std::numeric_limits<double>::quiet_NaN();
          writer.Add(1, bad, r.frames[1].link_angles);
        },
        "frames[1].points[2][1]", "nothing was written");
    // A run that throws (here: a sink after the writer that fails at frame 3) leaves nothing.
    struct Failing : FrameSink {
      ResultFileWriter* writer;
      void Add(int64_t step, const PointsRef& p, const VectorRef& a) override {
        writer->Add(step, p, a);
        if (step == 3) throw std::runtime_error("stop");
      }
    };
    {
      ResultFileWriter writer(path, format, header);
      Failing sink;
      sink.writer = &writer;
      EXPECT_THROW(flexkin::Run(s.chain, s.leader_steps, s.options, &sink), std::runtime_error);
    }
    // Commit of a result that does not match the header.
    {
      ResultFileWriter writer(path, format, header);
      writer.Add(0, r.frames[0].points, r.frames[0].link_angles);
      RunResult other = r;
      other.method = Method::kFollowTheLeader;
      test_util::ExpectInputError([&] { writer.Commit(other); }, "method", "nothing was written");
    }
    EXPECT_EQ(ReadFile(path), "old");
    EXPECT_EQ(dir.Files().size(), format == ResultFileFormat::kJson ? 1u : 2u);
  }
}

// A write that fails half way (the file size limit, in a child process) leaves the old file
// byte-identical and no temporary file, for both formats and for small and large results.
TEST(ResultStreamTest, FailedWriteKeepsTheOldFile) {
  TempDir dir;
  const Scenario big = Example("fig10_planar_curve.json");
  const RunResult results[] = {AwkwardResult(3, 5),
                               flexkin::Run(big.chain, big.leader_steps, big.options)};
  for (ResultFileFormat format : {ResultFileFormat::kJson, ResultFileFormat::kNpz}) {
    for (const RunResult& r : results) {
      const std::string path = dir / "result";
      WriteText(path, "old");
      const pid_t child = ::fork();
      ASSERT_GE(child, 0);
      if (child == 0) {
        std::signal(SIGXFSZ, SIG_IGN);
        rlimit small;
        ::getrlimit(RLIMIT_FSIZE, &small);
        small.rlim_cur = 1024;
        ::setrlimit(RLIMIT_FSIZE, &small);
        try {
          WriteResultFile(r, path, format);
        } catch (const std::system_error& e) {
          std::_Exit(e.code() == std::errc::file_too_large ? 0 : 2);
        } catch (...) {
          std::_Exit(3);
        }
        std::_Exit(1);
      }
      int status = 0;
      ASSERT_EQ(::waitpid(child, &status, 0), child);
      ASSERT_TRUE(WIFEXITED(status));
      EXPECT_EQ(WEXITSTATUS(status), 0) << ResultFileFormatName(format);
      EXPECT_EQ(ReadFile(path), "old");
      EXPECT_EQ(dir.Files(), std::vector<std::string>{"result"});
    }
  }
}

// Cut at every offset, and every byte flipped: InputError or, where the flipped byte is one that
// readers ignore (a date, a version), the same frames; never a crash or another exception.
TEST(ResultNpzTest, CorruptedFilesAreInputErrors) {
  TempDir dir(true);
  const Scenario s = Example("fig06_parabola_multi_step.json");
  RunResult r = flexkin::Run(s.chain, s.leader_steps, s.options);
  r.frames.Truncate(3);
  WriteResultFile(r, dir / "good.npz", ResultFileFormat::kNpz, s.name);
  const std::string good = ReadFile(dir / "good.npz");
  const std::string path = dir / "bad.npz";
  int errors = 0, successes = 0;
  auto check = [&](const std::string& bytes, const std::string& what) {
    WriteText(path, bytes);
    try {
      const ResultFile back = ReadResultFile(path);
      ++successes;
      RunResult expected;
      expected.frames = r.frames;
      if (!back.result.frames.empty() && back.result.frames[0].link_angles.size() == 0) {
        expected.frames.DropLinkAngles();  // its member's name was hit
      }
      ExpectSameFrames(back.result, expected);
    } catch (const InputError& e) {
      ++errors;
      EXPECT_FALSE(std::string(e.what()).empty()) << what;
    }
  };
  for (size_t cut = 0; cut < good.size(); ++cut) check(good.substr(0, cut), "cut");
  EXPECT_EQ(successes, 0) << "a truncated file was read";
  for (size_t i = 0; i < good.size(); ++i) {
    std::string bytes = good;
    bytes[i] = static_cast<char>(bytes[i] ^ 0x5a);
    check(bytes, "byte " + std::to_string(i));
  }
  EXPECT_GT(errors, static_cast<int>(good.size() * 18 / 10)) << successes << " flips were read";
  // Hand-made corruptions: a shape far too large, a member compressed, a huge directory.
  auto replace = [&](const std::string& from, const std::string& to) {
    std::string bytes = good;
    const size_t at = bytes.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    bytes.replace(at, from.size(), to);
    return bytes;
  };
  test_util::ExpectInputError(
      [&] {  // the same length: the provisional header's spaces make room
        WriteText(path,
                  replace("'shape': (3, 21, 2), }          ", "'shape': (9999999999999, 21, 2)}"));
        ReadResultFile(path);
      },
      "frames.npy");
  test_util::ExpectInputError(
      [&] {
        WriteText(path, replace("'descr': '<f8', 'fortran_order': False, 'shape': (3, 21",
                                "'descr': '<f4', 'fortran_order': False, 'shape': (3, 21"));
        ReadResultFile(path);
      },
      "frames.npy");
}

TEST(ResultNpzTest, NumpyReadsWhatTheJsonOfTheSameRunSays) {
  if (std::system("/usr/bin/python3 -c 'import numpy' > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "/usr/bin/python3 has no numpy (Debian package python3-numpy, installed by "
                    "scripts/install-deps.sh)";
  }
  TempDir dir;
  for (const char* name : {"fig06_parabola_overall_multi_step.json", "fig12_spatial_curve.json"}) {
    const Scenario s = Example(name);
    const RunResult r = flexkin::Run(s.chain, s.leader_steps, s.options);
    WriteResultFile(r, dir / "r.npz", ResultFileFormat::kNpz, s.name);
    WriteResultFile(r, dir / "r.json", ResultFileFormat::kJson, s.name);
    const std::string script = dir / "check.py";
    WriteText(script, R"(
import json, sys
import numpy as np
r = np.load(sys.argv[1])
j = json.load(open(sys.argv[2]))
s = json.loads(r["result.json"])
frames = np.array([f["points"] for f in j["frames"]], dtype=np.float64)
assert r["frames"].dtype == np.float64 and r["frames"].shape == frames.shape, r["frames"].shape
assert (r["frames"] == frames).all()
assert r["steps"].dtype == np.int64 and list(r["steps"]) == [f["step"] for f in j["frames"]]
assert (r["link_angles"] == np.array([f["link_angles"] for f in j["frames"]])).all()
assert list(r["link_lengths"]) == j["link_lengths"]
for key in ("l2_per_step", "l2_weighted_per_step", "path_length"):
    assert list(r[key]) == j["metrics"][key], key
    del j["metrics"][key]
del j["frames"], j["link_lengths"]
assert s.pop("num_frames") == len(frames) and s.pop("link_angles") is True
assert s == j, (s, j)
print("ok", r["frames"].shape)
)");
    const std::string command = "/usr/bin/python3 '" + script + "' '" + (dir / "r.npz") + "' '" +
                                (dir / "r.json") + "' > '" + (dir / "out.txt") + "' 2>&1";
    EXPECT_EQ(std::system(command.c_str()), 0) << name << ": " << ReadFile(dir / "out.txt");
  }
}

TEST(ResultEstimateTest, FramesExactAndBytesWithinAFactorOfTheFiles) {
  TempDir dir;
  struct Case {
    const char* name;
    int record_every;
  };
  for (const Case& c :
       {Case{"fig06_parabola_multi_step.json", 1}, Case{"fig10_planar_curve.json", 1},
        Case{"fig10_planar_curve.json", 7}, Case{"fig12_spatial_curve.json", 50},
        Case{"fig06_parabola_overall_multi_step.json", 2}}) {
    Scenario s = Example(c.name);
    s.options.record_every = c.record_every;
    const RunResult r = flexkin::Run(s.chain, s.leader_steps, s.options);
    const ResultSizeEstimate e =
        EstimateResultSize(s.chain.num_links(), s.chain.dim(), s.leader_steps.rows(), s.options);
    EXPECT_EQ(e.frames, static_cast<int64_t>(r.frames.size())) << c.name;
    EXPECT_EQ(CountRecordedFrames(s.leader_steps.rows(), c.record_every), e.frames);
    for (ResultFileFormat format : {ResultFileFormat::kJson, ResultFileFormat::kNpz}) {
      const std::string path = dir / (std::string("r.") + ResultFileFormatName(format));
      WriteResultFile(r, path, format, s.name);
      const double actual = static_cast<double>(fs::file_size(path));
      const double estimate = static_cast<double>(e.bytes(format));
      EXPECT_EQ(EstimateResultBytes(s.chain.num_links(), s.chain.dim(), s.leader_steps.rows(),
                                    s.options, format),
                e.bytes(format));
      EXPECT_LT(estimate, 1.5 * actual) << c.name << " " << ResultFileFormatName(format);
      EXPECT_GT(estimate, actual / 1.5) << c.name << " " << ResultFileFormatName(format);
    }
    WriteFramesCsv(r, dir / "r.csv");
    const double csv = static_cast<double>(fs::file_size(dir / "r.csv"));
    EXPECT_LT(e.csv_bytes, 1.5 * csv) << c.name;
    EXPECT_GT(e.csv_bytes, csv / 1.5) << c.name;
  }
  EXPECT_EQ(CountRecordedFrames(0, 1), 1);
  EXPECT_EQ(CountRecordedFrames(10, 3), 5);  // 0, 3, 6, 9, 10
  EXPECT_EQ(CountRecordedFrames(9, 3), 4);   // 0, 3, 6, 9
}

TEST(ResultFormatTest, FormatFromTheExtension) {
  EXPECT_EQ(ResultFileFormatOfPath("a/b.json"), ResultFileFormat::kJson);
  EXPECT_EQ(ResultFileFormatOfPath("B.NPZ"), ResultFileFormat::kNpz);
  test_util::ExpectInputError([] { ResultFileFormatOfPath("r.csv", "-o"); }, "-o", ".npz");
  test_util::ExpectInputError([] { ResultFileFormatOfPath("dir.json/r", "-o"); }, "-o",
                              "no extension");
}

// A refused archive leaves no file descriptor open (the reader's constructor closes its file when
// it throws; each refused file used to keep one, until "Too many open files": result_fuzzer).
class ResultNpzFileTest : public test_util::TempDirTest {};

TEST_F(ResultNpzFileTest, RefusedArchiveClosesItsFile) {
  const std::string path = Path("bad.npz");
  std::ofstream(path, std::ios::binary) << std::string("PK\x03\x04", 4) << std::string(100, 'x');
  auto open_files = [] {
    return std::distance(fs::directory_iterator("/proc/self/fd"), fs::directory_iterator());
  };
  const auto before = open_files();
  for (int i = 0; i < 50; ++i) EXPECT_THROW(ReadResultFile(path), InputError);
  EXPECT_EQ(open_files(), before);
}

// A strand file (the other .npz flexkin writes, docs/strands.md) is not reported as a result
// whose result.json is missing: the message says what it is and what reads it.
TEST_F(ResultNpzFileTest, StrandFileIsNamedWithItsReader) {
  StrandFileHeader h;
  h.dim = 3;
  h.offsets = {0, 3};
  h.link_lengths = Eigen::VectorXd::Constant(2, 0.5);
  h.num_frames = 1;
  StrandFrame frame;
  frame.points = Points::Zero(3, 3);
  frame.points.col(2) << 0.0, -0.5, -1.0;
  const std::string path = Path("hair.npz");
  StrandFileWriter writer(path, h);
  writer.Add(frame);
  writer.Commit(StrandRunReport());
  ASSERT_TRUE(IsStrandFile(path));
  try {
    ReadResultFile(path);
    ADD_FAILURE() << "a strand file was read as a result";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "");
    const std::string what = e.what();
    EXPECT_NE(what.find("is a strand file"), std::string::npos) << what;
    EXPECT_NE(what.find("StrandFileReader"), std::string::npos) << what;
    EXPECT_NE(what.find("numpy.load"), std::string::npos) << what;
    EXPECT_EQ(what.find("result.json"), std::string::npos) << what;
  }
}

// ZIP archives built byte by byte, for the reader's checks of every member: stored members with
// plain (not ZIP64) headers, where a local header may differ from its central directory entry.
namespace zip {

void Put(std::string* out, uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

// CRC-32 (ISO 3309, as ZIP uses it), bit by bit: independent of the reader's zlib.
uint32_t Crc32(const std::string& data) {
  uint32_t crc = 0xffffffffu;
  for (const char c : data) {
    crc ^= static_cast<unsigned char>(c);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

std::string Hex(uint64_t v, int digits) {
  char text[32];
  std::snprintf(text, sizeof text, "0x%0*llx", digits, static_cast<unsigned long long>(v));
  return text;
}

// The fields that a local header and a central directory entry both hold.
struct Fields {
  std::string name;
  uint64_t flags = 0, method = 0, crc = 0, compressed = 0, size = 0;
};

std::string LocalHeader(const Fields& f) {
  std::string h;
  Put(&h, 0x04034b50, 4);
  Put(&h, 20, 2);  // version needed
  Put(&h, f.flags, 2);
  Put(&h, f.method, 2);
  Put(&h, 0, 2);     // time
  Put(&h, 0x21, 2);  // date: 1980-01-01
  Put(&h, f.crc, 4);
  Put(&h, f.compressed, 4);
  Put(&h, f.size, 4);
  Put(&h, f.name.size(), 2);
  Put(&h, 0, 2);  // extra field
  return h + f.name;
}

std::string CentralEntry(const Fields& f, uint64_t local_offset) {
  std::string h;
  Put(&h, 0x02014b50, 4);
  Put(&h, 20, 2);  // made by
  Put(&h, 20, 2);  // needed
  Put(&h, f.flags, 2);
  Put(&h, f.method, 2);
  Put(&h, 0, 2);
  Put(&h, 0x21, 2);
  Put(&h, f.crc, 4);
  Put(&h, f.compressed, 4);
  Put(&h, f.size, 4);
  Put(&h, f.name.size(), 2);
  Put(&h, 0, 2);  // extra field
  Put(&h, 0, 2);  // comment
  Put(&h, 0, 2);  // disk
  Put(&h, 0, 2);  // internal attributes
  Put(&h, 0, 4);  // external attributes
  Put(&h, local_offset, 4);
  return h + f.name;
}

std::string EndRecord(uint64_t entries, uint64_t cd_size, uint64_t cd_offset) {
  std::string h;
  Put(&h, 0x06054b50, 4);
  Put(&h, 0, 2);
  Put(&h, 0, 2);
  Put(&h, entries, 2);
  Put(&h, entries, 2);
  Put(&h, cd_size, 4);
  Put(&h, cd_offset, 4);
  Put(&h, 0, 2);
  return h;
}

struct Member {
  std::string name, data;
  // Edits the local header's fields (which start as the central directory entry's).
  std::function<void(Fields*)> local;
  uint64_t flags = 0;
  std::optional<uint32_t> crc;  // in both headers; the data's CRC-32 if not given
  std::string after;            // bytes after the data: a data descriptor
};

Fields FieldsOf(const Member& m) {
  Fields f;
  f.name = m.name;
  f.flags = m.flags;
  f.crc = m.crc ? *m.crc : Crc32(m.data);
  f.compressed = f.size = m.data.size();
  return f;
}

// The members one after another, then their central directory in the same order.
std::string Archive(const std::vector<Member>& members) {
  std::string bytes, cd;
  for (const Member& m : members) {
    const Fields f = FieldsOf(m);
    Fields local = f;
    if (m.local) m.local(&local);
    cd += CentralEntry(f, bytes.size());
    bytes += LocalHeader(local) + m.data + m.after;
  }
  const uint64_t cd_offset = bytes.size();
  return bytes + cd + EndRecord(members.size(), cd.size(), cd_offset);
}

}  // namespace zip

// The archives of these tests hold the members of a small result that flexkin wrote, rebuilt
// byte by byte, with an unknown member ("extra.bin") or a fault.
class ZipMemberChecksTest : public test_util::TempDirTest {
 protected:
  void SetUp() override {
    test_util::TempDirTest::SetUp();
    const Scenario s = Example("fig06_parabola_multi_step.json");
    RunResult r = flexkin::Run(s.chain, s.leader_steps, s.options);
    r.frames.Truncate(3);
    frames_ = r.frames;
    WriteResultFile(r, Path("good.npz"), ResultFileFormat::kNpz, s.name);
    ZipReader reader(Path("good.npz"));
    for (const char* name :
         {"link_lengths.npy", "frames.npy", "steps.npy", "link_angles.npy", "l2_per_step.npy",
          "l2_weighted_per_step.npy", "path_length.npy", "result.json"}) {
      members_.push_back({name, reader.ReadWhole(name, 1 << 20)});
    }
  }
  // The result's members with `extra` inserted before member `at` (at the end if past it).
  std::vector<zip::Member> With(const zip::Member& extra, size_t at = 100) const {
    std::vector<zip::Member> m = members_;
    m.insert(m.begin() + static_cast<std::ptrdiff_t>(std::min(at, m.size())), extra);
    return m;
  }
  zip::Member& Named(std::vector<zip::Member>* members, const std::string& name) const {
    for (zip::Member& m : *members) {
      if (m.name == name) return m;
    }
    throw std::logic_error("no member " + name);
  }
  // Reads `bytes` as a result file: the frames must be those written.
  void ExpectRead(const std::string& bytes, const std::string& what) {
    SCOPED_TRACE(what);
    WriteText(Path("r.npz"), bytes);
    try {
      RunResult expected;
      expected.frames = frames_;
      ExpectSameFrames(ReadResultFile(Path("r.npz")).result, expected);
    } catch (const InputError& e) {
      ADD_FAILURE() << "refused: " << e.what();
    }
  }
  // Reads `bytes` as a result file: refused with an InputError naming `field` whose message is
  // `message` followed by "; not a valid .npz result file".
  void ExpectRefused(const std::string& bytes, const std::string& field,
                     const std::string& message) {
    SCOPED_TRACE(message);
    WriteText(Path("r.npz"), bytes);
    try {
      ReadResultFile(Path("r.npz"));
      ADD_FAILURE() << "read; expected " << field << ": " << message;
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), field) << e.what();
      EXPECT_EQ(e.message(), message + "; not a valid .npz result file");
    }
  }

  std::vector<zip::Member> members_;
  Frames frames_;
};

TEST_F(ZipMemberChecksTest, ArchiveOfTheSameMembersIsRead) {
  ExpectRead(zip::Archive(members_), "rebuilt");
  // An unknown member anywhere: read and CRC-checked, its content ignored.
  const zip::Member extra{"extra.bin", std::string(1000, 'x') + "end"};
  for (size_t at : {0, 3, 100}) {
    ExpectRead(zip::Archive(With(extra, at)), "extra.bin at " + std::to_string(at));
  }
  ExpectRead(zip::Archive(With({"empty", ""}, 2)), "an empty unknown member");
  // Data descriptors (flag bit 3): the local header may hold 0 for the CRC-32 and the sizes,
  // which follow the data. Accepted as before, for unknown and known members.
  std::vector<zip::Member> described = With(extra, 1);
  for (zip::Member& m : described) {
    m.flags = 8;
    if (m.name == "extra.bin" || m.name == "frames.npy") {
      const zip::Fields real = zip::FieldsOf(m);
      m.local = [](zip::Fields* f) { f->crc = f->compressed = f->size = 0; };
      zip::Put(&m.after, 0x08074b50, 4);
      zip::Put(&m.after, real.crc, 4);
      zip::Put(&m.after, real.compressed, 4);
      zip::Put(&m.after, real.size, 4);
    }
  }
  ExpectRead(zip::Archive(described), "data descriptors");
}

TEST_F(ZipMemberChecksTest, UnknownMemberWithABadCrcIsRefused) {
  zip::Member extra{"extra.bin", std::string(3000, 'x')};
  const uint32_t crc = zip::Crc32(extra.data);
  extra.data[1234] = 'y';  // after the CRC-32 was taken: both headers hold the old one
  extra.crc = crc;
  const std::string message = "CRC-32 of its data is " + zip::Hex(zip::Crc32(extra.data), 8) +
                              "; expected " + zip::Hex(crc, 8) +
                              " as in the central directory (the member is corrupted)";
  for (size_t at : {0, 5, 100}) ExpectRefused(zip::Archive(With(extra, at)), "extra.bin", message);
  // A known member says the same when it is read.
  std::vector<zip::Member> members = members_;
  zip::Member& frames = Named(&members, "frames.npy");
  frames.crc = zip::Crc32(frames.data) ^ 1;
  ExpectRefused(zip::Archive(members), "frames.npy",
                "CRC-32 of its data is " + zip::Hex(zip::Crc32(frames.data), 8) + "; expected " +
                    zip::Hex(*frames.crc, 8) +
                    " as in the central directory (the member is corrupted)");
}

TEST_F(ZipMemberChecksTest, LocalHeaderThatDiffersFromTheCentralDirectoryIsRefused) {
  struct Case {
    const char* what;
    std::function<void(zip::Fields*)> edit;
    // The message, given the central directory entry's fields.
    std::function<std::string(const zip::Fields&)> message;
  };
  const std::string cd = " as in the central directory";
  const Case cases[] = {
      {"name", [](zip::Fields* f) { f->name.back() = 'Z'; },
       [&](const zip::Fields& f) {
         std::string other = f.name;
         other.back() = 'Z';
         return "local header names \"" + other + "\"; expected \"" + f.name + "\"" + cd;
       }},
      {"longer name", [](zip::Fields* f) { f->name += ".old"; },
       [&](const zip::Fields& f) {
         return "local header names \"" + f.name + ".old\"; expected \"" + f.name + "\"" + cd;
       }},
      {"method", [](zip::Fields* f) { f->method = 8; },
       [&](const zip::Fields&) { return "local header compression method 8; expected 0" + cd; }},
      {"crc", [](zip::Fields* f) { f->crc ^= 0x80; },
       [&](const zip::Fields& f) {
         return "local header CRC-32 " + zip::Hex(f.crc ^ 0x80, 8) + "; expected " +
                zip::Hex(f.crc, 8) + cd;
       }},
      {"uncompressed size", [](zip::Fields* f) { f->size -= 1; },
       [&](const zip::Fields& f) {
         return "local header uncompressed size " + std::to_string(f.size - 1) + "; expected " +
                std::to_string(f.size) + cd;
       }},
      {"compressed size", [](zip::Fields* f) { f->compressed += 1; },
       [&](const zip::Fields& f) {
         return "local header compressed size " + std::to_string(f.size + 1) + "; expected " +
                std::to_string(f.size) + cd;
       }},
      {"data descriptor flag", [](zip::Fields* f) { f->flags = 8; },
       [&](const zip::Fields&) {
         return "local header flags 0x0008 (bits 0, encrypted, and 3, data descriptor); expected "
                "0x0000 in those bits" +
                cd;
       }},
      {"encrypted flag", [](zip::Fields* f) { f->flags = 0x0801; },
       [&](const zip::Fields&) {
         return "local header flags 0x0801 (bits 0, encrypted, and 3, data descriptor); expected "
                "0x0000 in those bits" +
                cd;
       }},
  };
  for (const Case& c : cases) {
    for (const std::string& name : {"extra.bin", "frames.npy", "result.json"}) {
      SCOPED_TRACE(std::string(c.what) + " of " + name);
      std::vector<zip::Member> members = With({"extra.bin", "unknown to the reader"}, 4);
      zip::Member& m = Named(&members, name);
      m.local = c.edit;
      ExpectRefused(zip::Archive(members), name, c.message(zip::FieldsOf(m)));
    }
  }
  // Other flags than bits 0 and 3 (here bit 11, UTF-8 names) are not compared.
  std::vector<zip::Member> members = With({"extra.bin", "unknown"}, 4);
  Named(&members, "extra.bin").local = [](zip::Fields* f) { f->flags = 0x0800; };
  ExpectRead(zip::Archive(members), "bit 11 in a local header only");
  // The sizes in a ZIP64 extra field, as flexkin writes them: frames.npy's local header holds
  // 0xffffffff in its size fields and the sizes (uncompressed, compressed) in its extra field.
  const std::string good = ReadFile(Path("good.npz"));
  const std::string signature("PK\x03\x04", 4);
  size_t at = 0;
  while ((at = good.find(signature, at + 1)) != std::string::npos &&
         good.compare(at + 30, 10, "frames.npy") != 0) {
  }
  ASSERT_NE(at, std::string::npos);
  const size_t extra = at + 30 + 10;
  ASSERT_EQ(good.substr(extra, 4), std::string("\x01\x00\x10\x00", 4));  // ZIP64, 16 bytes
  uint64_t size = 0;
  for (int i = 7; i >= 0; --i) size = (size << 8) | static_cast<unsigned char>(good[extra + 4 + i]);
  ASSERT_EQ(size, Named(&members_, "frames.npy").data.size());
  for (const auto& [offset, what] : {std::pair{4, "uncompressed"}, {12, "compressed"}}) {
    std::string bytes = good, patched;
    zip::Put(&patched, size + 1, 8);
    bytes.replace(extra + offset, 8, patched);
    ExpectRefused(bytes, "frames.npy",
                  std::string("local header ") + what + " size " + std::to_string(size + 1) +
                      "; expected " + std::to_string(size) + " as in the central directory");
  }
}

TEST_F(ZipMemberChecksTest, OverlappingMembersAreRefused) {
  // "extra.bin" holds the whole of the next member, "steps.npy" (its local header and data),
  // or the first 10 bytes of its local header: each member's headers and CRC-32 are right.
  for (const size_t shared : {size_t{0}, size_t{10}}) {
    SCOPED_TRACE("shared " + std::to_string(shared));
    std::string bytes, cd;
    std::vector<std::pair<zip::Fields, uint64_t>> entries;  // central directory, offsets
    const zip::Member* steps = nullptr;
    for (const zip::Member& m : members_) {
      if (m.name == "steps.npy") steps = &m;
    }
    const zip::Fields steps_fields = zip::FieldsOf(*steps);
    const std::string steps_record = zip::LocalHeader(steps_fields) + steps->data;
    uint64_t extra_start = 0, steps_start = 0;
    for (const zip::Member& m : members_) {
      if (&m == steps) {
        // extra.bin: its own bytes, then all or part of steps.npy's record, counted as its data.
        zip::Member extra{"extra.bin", "extra bytes before steps.npy"};
        extra.data += shared == 0 ? steps_record : steps_record.substr(0, shared);
        extra_start = bytes.size();
        entries.push_back({zip::FieldsOf(extra), extra_start});
        bytes += zip::LocalHeader(zip::FieldsOf(extra)) + extra.data;
        steps_start = bytes.size() - (shared == 0 ? steps_record.size() : shared);
        entries.push_back({steps_fields, steps_start});
        if (shared != 0) bytes += steps_record.substr(shared);
        continue;
      }
      entries.push_back({zip::FieldsOf(m), bytes.size()});
      bytes += zip::LocalHeader(zip::FieldsOf(m)) + m.data;
    }
    for (const auto& [fields, offset] : entries) cd += zip::CentralEntry(fields, offset);
    const uint64_t cd_offset = bytes.size();
    bytes += cd + zip::EndRecord(entries.size(), cd.size(), cd_offset);
    const uint64_t extra_end = steps_start + (shared == 0 ? steps_record.size() : shared);
    const uint64_t steps_end = steps_start + steps_record.size();
    ExpectRefused(bytes, "steps.npy",
                  "local header and data (" + std::to_string(steps_record.size()) +
                      " bytes at offsets " + std::to_string(steps_start) + " to " +
                      std::to_string(steps_end) + ") overlap those of \"extra.bin\" (" +
                      std::to_string(extra_end - extra_start) + " bytes at offsets " +
                      std::to_string(extra_start) + " to " + std::to_string(extra_end) +
                      "); expected members apart");
  }
}

TEST_F(ZipMemberChecksTest, MemberOverlappingTheCentralDirectoryIsRefused) {
  // The last member's data runs 16 bytes into the central directory: into the start of the
  // first entry (not its own, so that its CRC-32 can be right).
  for (const std::string& name : {"extra.bin", "result.json"}) {
    SCOPED_TRACE(name);
    std::vector<zip::Member> members = members_;
    if (name == "extra.bin") members.push_back({"extra.bin", "the last member"});
    std::rotate(members.begin(), members.end() - 1, members.end());  // last, first in the file
    std::string bytes;
    std::vector<uint64_t> offsets;
    for (size_t k = 1; k < members.size(); ++k) {
      offsets.push_back(bytes.size());
      bytes += zip::LocalHeader(zip::FieldsOf(members[k])) + members[k].data;
    }
    // The central directory lists the members in the file's order, the last one last.
    std::string cd;
    for (size_t k = 1; k < members.size(); ++k) {
      cd += zip::CentralEntry(zip::FieldsOf(members[k]), offsets[k - 1]);
    }
    zip::Member last = members[0];
    const uint64_t last_start = bytes.size();
    const std::string own_data = last.data;
    bytes += zip::LocalHeader(zip::FieldsOf({last.name, own_data + cd.substr(0, 16)})) + own_data;
    last.data = own_data + cd.substr(0, 16);
    cd += zip::CentralEntry(zip::FieldsOf(last), last_start);
    const uint64_t cd_offset = bytes.size();
    bytes += cd + zip::EndRecord(members.size(), cd.size(), cd_offset);
    const uint64_t data_start = last_start + 30 + last.name.size();
    ExpectRefused(bytes, name,
                  "data (" + std::to_string(last.data.size()) + " bytes at offsets " +
                      std::to_string(data_start) + " to " +
                      std::to_string(data_start + last.data.size()) +
                      ") overlaps the central directory (" + std::to_string(cd.size()) +
                      " bytes at offsets " + std::to_string(cd_offset) + " to " +
                      std::to_string(cd_offset + cd.size()) + ")");
  }
}

}  // namespace
}  // namespace flexkin
