// Tests of strand files (include/flexkin/strand_file.h): frames written by the streaming writer
// read back exactly (float64 bit for bit, float32 as the float32 rounding of the values), numpy
// reads the archive with nothing but numpy, a failed or abandoned write leaves nothing behind
// and an earlier file untouched, and a damaged file is an InputError, never a crash.
#include "flexkin/strand_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "flexkin/strands.h"
#include "test_util.h"

namespace flexkin {
namespace {

namespace fs = std::filesystem;
using test_util::ExpectInputError;
using test_util::ReadFile;

using StrandFileTest = test_util::TempDirTest;

// Three strands of 2, 4 and 1 links in 3D (or 2D).
StrandFileHeader SmallHeader(int dim, bool float32, int64_t frames) {
  StrandFileHeader h;
  h.name = "small";
  h.description = "three strands";
  h.dim = dim;
  h.offsets = {0, 3, 8, 10};
  h.link_lengths = Eigen::VectorXd::LinSpaced(7, 0.5, 2.0);
  h.num_frames = frames;
  h.float32 = float32;
  h.fps = 24.0;
  h.method = "ftl";
  h.substeps = 3;
  h.pinned = 2;
  h.record_every = 2;
  h.scalp.shape = "ellipsoid";
  h.scalp.center = {0.5, -1.0, 2.0};
  h.scalp.radii = {1.0, 2.0, 3.0};
  return h;
}

// Frame k: values that use every bit of a double (not representable in float32).
StrandFrame MakeFrame(const StrandFileHeader& h, int64_t k) {
  StrandFrame f;
  f.frame = 2 * k;
  f.time = f.frame / h.fps;
  f.pose = BodyPose::FromQuaternion(1.0, 0.1 * k, -0.2, 0.05 * k, Eigen::Vector3d(k, 0.25, -k));
  f.points.resize(h.num_points(), h.dim);
  for (Eigen::Index i = 0; i < f.points.size(); ++i) {
    f.points.data()[i] = std::sin(1.0 + 0.731 * static_cast<double>(i) + 0.1 * k) / 3.0;
  }
  return f;
}

void WriteSmall(const std::string& path, const StrandFileHeader& h) {
  StrandFileWriter writer(path, h);
  for (int64_t k = 0; k < h.num_frames; ++k) writer.Add(MakeFrame(h, k));
  StrandRunReport report;
  report.max_length_error = 3e-16;
  report.seconds = 0.125;
  report.engine = "scalar";
  report.threads = 2;
  writer.Commit(report);
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST_F(StrandFileTest, Float64ReadsBackBitForBit) {
  for (int dim : {2, 3}) {
    const StrandFileHeader h = SmallHeader(dim, false, 5);
    WriteSmall(Path("s.npz"), h);
    EXPECT_TRUE(IsStrandFile(Path("s.npz")));
    StrandFileReader reader(Path("s.npz"));
    const StrandFileHeader& r = reader.header();
    EXPECT_EQ(r.name, h.name);
    EXPECT_EQ(r.description, h.description);
    EXPECT_EQ(r.dim, dim);
    EXPECT_EQ(r.offsets, h.offsets);
    EXPECT_EQ(r.link_lengths, h.link_lengths);
    EXPECT_EQ(r.num_frames, 5);
    EXPECT_FALSE(r.float32);
    EXPECT_EQ(r.fps, 24.0);
    EXPECT_EQ(r.method, "ftl");
    EXPECT_EQ(r.substeps, 3);
    EXPECT_EQ(r.pinned, 2);
    EXPECT_EQ(r.record_every, 2);
    EXPECT_EQ(r.scalp.shape, "ellipsoid");
    EXPECT_EQ(r.scalp.center, h.scalp.center);
    EXPECT_EQ(r.scalp.radii, h.scalp.radii);
    EXPECT_EQ(reader.report().max_length_error, 3e-16);
    EXPECT_EQ(reader.report().engine, "scalar");
    EXPECT_EQ(reader.report().threads, 2);
    ASSERT_EQ(reader.frame_info().size(), 5u);
    StrandFrame f;
    for (int64_t k = 0; k < 5; ++k) {
      ASSERT_TRUE(reader.Next(&f));
      const StrandFrame expected = MakeFrame(h, k);
      EXPECT_EQ(f.frame, expected.frame);
      EXPECT_EQ(reader.frame_info()[k].frame, expected.frame);
      EXPECT_TRUE(SameBits(f.time, expected.time));
      EXPECT_EQ(f.pose.rotation, expected.pose.rotation);
      EXPECT_EQ(f.pose.translation, expected.pose.translation);
      ASSERT_EQ(f.points.rows(), 10);
      ASSERT_EQ(f.points.cols(), dim);
      for (Eigen::Index i = 0; i < f.points.size(); ++i) {
        ASSERT_TRUE(SameBits(f.points.data()[i], expected.points.data()[i])) << i;
      }
    }
    EXPECT_FALSE(reader.Next(&f));
  }
}

TEST_F(StrandFileTest, Float32HoldsTheFloat32Rounding) {
  const StrandFileHeader h = SmallHeader(3, true, 3);
  WriteSmall(Path("s.npz"), h);
  StrandFileReader reader(Path("s.npz"));
  EXPECT_TRUE(reader.header().float32);
  StrandFrame f;
  for (int64_t k = 0; k < 3; ++k) {
    ASSERT_TRUE(reader.Next(&f));
    const StrandFrame expected = MakeFrame(h, k);
    for (Eigen::Index i = 0; i < f.points.size(); ++i) {
      const float rounded = static_cast<float>(expected.points.data()[i]);
      ASSERT_EQ(f.points.data()[i], static_cast<double>(rounded)) << i;
    }
    // The pose is kept in double.
    EXPECT_EQ(f.pose.translation, expected.pose.translation);
  }
  // Half the bytes of the float64 file's points, give or take the fixed members.
  WriteSmall(Path("d.npz"), SmallHeader(3, false, 3));
  EXPECT_LT(fs::file_size(Path("s.npz")), fs::file_size(Path("d.npz")));
}

TEST_F(StrandFileTest, WritesFromABatch) {
  // Two strands of 3 and 2 links stepped by a pose; the file's frame equals the batch's strands.
  std::vector<Points> strands(2);
  strands[0].resize(4, 3);
  strands[0] << 0, 0, 1, 0, 0, 1.5, 0.1, 0, 2, 0.2, 0.1, 2.4;
  strands[1].resize(3, 3);
  strands[1] << 1, 0, 0, 1.5, 0, 0, 2, 0.2, 0;
  StrandBatch batch(strands);
  StrandFileHeader h;
  h.dim = 3;
  h.offsets = {0, 4, 7};
  h.link_lengths.resize(5);
  h.link_lengths << 0.5, (strands[0].row(2) - strands[0].row(1)).norm(),
      (strands[0].row(3) - strands[0].row(2)).norm(), 0.5,
      (strands[1].row(2) - strands[1].row(1)).norm();
  h.num_frames = 2;
  h.float32 = false;
  StrandFileWriter writer(Path("b.npz"), h);
  writer.Add(0, 0.0, BodyPose(), batch);
  const BodyPose pose = BodyPose::FromQuaternion(0.9, 0.1, 0.3, 0.0, Eigen::Vector3d(0.2, 0, 0));
  StepStrands(&batch, pose);
  writer.Add(1, 1.0 / 30, pose, batch);
  writer.Commit({});
  StrandFileReader reader(Path("b.npz"));
  StrandFrame f;
  ASSERT_TRUE(reader.Next(&f));
  EXPECT_EQ(Points(f.points.topRows(4)), strands[0]);
  ASSERT_TRUE(reader.Next(&f));
  EXPECT_EQ(Points(f.points.topRows(4)), batch.strand(0));
  EXPECT_EQ(Points(f.points.bottomRows(3)), batch.strand(1));
}

TEST_F(StrandFileTest, NumpyReadsIt) {
  if (std::system("/usr/bin/python3 -c 'import numpy' > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "/usr/bin/python3 has no numpy (Debian package python3-numpy, installed by "
                    "scripts/install-deps.sh)";
  }
  for (bool float32 : {true, false}) {
    const StrandFileHeader h = SmallHeader(3, float32, 4);
    WriteSmall(Path("s.npz"), h);
    // numpy prints what it read with 17 digits; the test compares with what was written.
    const std::string script = Path("read.py");
    std::ofstream(script) << R"(import json, sys
import numpy as np
r = np.load(sys.argv[1])
p = r["points"]
info = json.loads(r["groom.json"])
print(p.dtype, p.shape, r["offsets"].tolist(), r["frames"].tolist(), r["body_rotation"].shape,
      r["body_translation"].shape, r["link_lengths"].shape, info["num_strands"], info["precision"])
for v in p.reshape(-1).tolist():
    print(repr(float(v)))
for v in r["body_rotation"].reshape(-1).tolist() + r["times"].tolist():
    print(repr(float(v)))
)";
    const std::string out = Path("numpy.txt");
    ASSERT_EQ(
        std::system(
            ("/usr/bin/python3 '" + script + "' '" + Path("s.npz") + "' > '" + out + "'").c_str()),
        0);
    std::ifstream in(out);
    std::string first;
    std::getline(in, first);
    EXPECT_EQ(first, std::string(float32 ? "float32" : "float64") +
                         " (4, 10, 3) [0, 3, 8, 10] [0, 2, 4, 6] (4, 3, 3) (4, 3) (7,) 3 " +
                         (float32 ? "float32" : "float64"));
    for (int64_t k = 0; k < 4; ++k) {
      const StrandFrame f = MakeFrame(h, k);
      for (Eigen::Index i = 0; i < f.points.size(); ++i) {
        double v = 0;
        in >> v;
        const double expected =
            float32 ? static_cast<float>(f.points.data()[i]) : f.points.data()[i];
        ASSERT_TRUE(SameBits(v, expected)) << k << " " << i << " " << v;
      }
    }
    for (int64_t k = 0; k < 4; ++k) {
      const StrandFrame f = MakeFrame(h, k);
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) {
          double v = 0;
          in >> v;
          ASSERT_TRUE(SameBits(v, f.pose.rotation(a, b))) << "rotation of frame " << k;
        }
      }
    }
    for (int64_t k = 0; k < 4; ++k) {
      double v = 0;
      in >> v;
      EXPECT_TRUE(SameBits(v, MakeFrame(h, k).time));
    }
  }
}

TEST_F(StrandFileTest, FailedWritesLeaveNothingAndKeepAnEarlierFile) {
  const StrandFileHeader h = SmallHeader(3, true, 3);
  WriteSmall(Path("s.npz"), h);
  const std::string before = ReadFile(Path("s.npz"));
  // A NaN in frame 1.
  {
    StrandFileWriter writer(Path("s.npz"), h);
    writer.Add(MakeFrame(h, 0));
    StrandFrame bad = MakeFrame(h, 1);
    bad.points(7, 2) = std::nan("");
    ExpectInputError([&] { writer.Add(bad); }, "frames[1].points[7][2]", "not a finite number");
  }
  // Too few frames at Commit; too many; a frame number not increasing; a wrong shape.
  {
    StrandFileWriter writer(Path("s.npz"), h);
    writer.Add(MakeFrame(h, 0));
    ExpectInputError([&] { writer.Commit({}); }, "frames", "1 frames were added");
    ExpectInputError([&] { writer.Add(MakeFrame(h, 0)); }, "frames[1].frame", "above");
    StrandFrame wrong = MakeFrame(h, 1);
    wrong.points.resize(9, 3);
    ExpectInputError([&] { writer.Add(wrong); }, "frames[1].points", "expected 10 x 3");
  }
  {
    StrandFileWriter writer(Path("s.npz"), h);
    for (int64_t k = 0; k < 3; ++k) writer.Add(MakeFrame(h, k));
    ExpectInputError([&] { writer.Add(MakeFrame(h, 3)); }, "frames", "more than");
  }
  EXPECT_EQ(ReadFile(Path("s.npz")), before);
  EXPECT_EQ(Files(), std::vector<std::string>{"s.npz"});
  // A bad header is refused before anything is created.
  StrandFileHeader bad = h;
  bad.offsets = {0, 3, 4};
  ExpectInputError([&] { StrandFileWriter w(Path("t.npz"), bad); }, "header.offsets[2]",
                   "at least one link");
  bad = h;
  bad.link_lengths[3] = -1.0;
  ExpectInputError([&] { StrandFileWriter w(Path("t.npz"), bad); }, "header.link_lengths[3]");
  bad = h;
  bad.dim = 4;
  ExpectInputError([&] { StrandFileWriter w(Path("t.npz"), bad); }, "header.dim", "2 or 3");
  EXPECT_EQ(Files(), std::vector<std::string>{"s.npz"});
  // A directory that does not exist: system_error naming the path.
  try {
    StrandFileWriter w(Path("missing/t.npz"), h);
    ADD_FAILURE() << "no error";
  } catch (const std::system_error& e) {
    EXPECT_NE(std::string(e.what()).find("missing/t.npz"), std::string::npos) << e.what();
  }
}

TEST_F(StrandFileTest, DamagedFilesAreInputErrors) {
  const StrandFileHeader h = SmallHeader(3, false, 3);
  WriteSmall(Path("s.npz"), h);
  const std::string good = ReadFile(Path("s.npz"));
  // Everything a reader gives, as text: "" if it refused the file with an InputError.
  auto read = [&](const std::string& bytes) -> std::string {
    std::ofstream(Path("bad.npz"), std::ios::binary) << bytes;
    try {
      StrandFileReader reader(Path("bad.npz"));
      const StrandFileHeader& r = reader.header();
      std::string all = r.name + r.description + r.method + r.scalp.shape +
                        std::to_string(r.num_frames) + std::to_string(r.dim);
      auto add = [&](const double* p, Eigen::Index n) {
        all.append(reinterpret_cast<const char*>(p), sizeof(double) * n);
      };
      add(r.link_lengths.data(), r.link_lengths.size());
      add(r.scalp.radii.data(), 3);
      for (int64_t o : r.offsets) all += std::to_string(o) + ",";
      StrandFrame f;
      while (reader.Next(&f)) {
        add(f.points.data(), f.points.size());
        add(f.pose.rotation.data(), 9);
        add(f.pose.translation.data(), 3);
        add(&f.time, 1);
        all += std::to_string(f.frame);
      }
      return all;
    } catch (const InputError&) {
      return "";
    }
  };
  const std::string expected = read(good);
  ASSERT_FALSE(expected.empty());
  // Every truncation is refused.
  for (size_t cut = 0; cut < good.size(); cut += 7) {
    ASSERT_EQ(read(good.substr(0, cut)), "") << "cut at " << cut;
  }
  // A flipped byte is refused, or (in a byte no reader needs: a ZIP timestamp, the version that
  // made the archive) reads the same data: never different data.
  int refused = 0, flips = 0;
  for (size_t at = 0; at < good.size(); at += 5, ++flips) {
    std::string bytes = good;
    bytes[at] = static_cast<char>(bytes[at] ^ 0x5a);
    const std::string got = read(bytes);
    if (got.empty()) {
      ++refused;
    } else {
      ASSERT_EQ(got, expected) << "a flipped byte at " << at << " gave other data";
    }
  }
  EXPECT_GT(refused, flips * 8 / 10);
  EXPECT_FALSE(IsStrandFile(Path("missing.npz")));
  std::ofstream(Path("text.npz")) << "not a zip";
  EXPECT_FALSE(IsStrandFile(Path("text.npz")));
}

}  // namespace
}  // namespace flexkin
