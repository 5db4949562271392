// glTF export (include/flexkin/gltf.h): positions read back from .gltf and .glb files, the rig and
// the tube, the Khronos glTF validator on written files, and bad input.
#include "flexkin/gltf.h"

#include <dirent.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "flexkin/result_io.h"
#include "flexkin/run.h"
#include "flexkin/scenario.h"
#include "gltf/rig.h"
#include "gltf/tube.h"
#include "io/json_file.h"  // ReadJsonFile, WriteFileAtomically
#include "scenes/scenes.h"
#include "test_util.h"

namespace flexkin {
namespace {

using test_util::ExpectInputError;

// A fresh directory, removed with its files at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::string name = (std::filesystem::temp_directory_path() / "flexkin_gltf_XXXXXX").string();
    path_ = ::mkdtemp(name.data());
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string operator/(const std::string& name) const { return path_ + "/" + name; }
  // Names of the files in the directory (to see that no temporary file is left).
  std::vector<std::string> Files() const {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(path_)) {
      names.push_back(entry.path().filename().string());
    }
    return names;
  }

 private:
  std::string path_;
};

std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A result of `Run` on a curved chain of `n` links whose leading end follows a wavy path of
// `steps` leader steps (3D: a helix-like path), recorded every `record_every` steps.
ResultFile MakeResult(int dim, int n, int steps, int record_every = 1) {
  const Chain chain = scenes::CurvedChain(dim, n, 1.0, 0.35);
  Points leader(steps, dim);
  for (int s = 0; s < steps; ++s) {
    const double u = (s + 1) * 0.05;
    leader(s, 0) = chain.points(0, 0) + 1.5 * u;
    leader(s, 1) = chain.points(0, 1) + 0.6 * std::sin(3.0 * u);
    if (dim == 3) leader(s, 2) = chain.points(0, 2) + 0.4 * std::cos(2.0 * u) - 0.4;
  }
  RunOptions options;
  options.record_every = record_every;
  ResultFile file;
  file.result = Run(chain, leader, options);
  file.dim = dim;
  file.scenario_name = "test";
  return file;
}

// Largest distance between the input's points and those read back, and the largest absolute
// coordinate of the input (float32 rounds relative to it); checks the shapes and times.
struct Comparison {
  double max_error = 0.0;
  double scene_size = 0.0;
};
Comparison Compare(const ResultFile& file, const GltfJointMotion& motion, double steps_per_second) {
  Comparison c;
  const auto& frames = file.result.frames;
  EXPECT_EQ(motion.dim, file.dim);
  EXPECT_EQ(motion.times.size(), frames.size());
  EXPECT_EQ(motion.positions.size(), frames.size());
  if (motion.positions.size() != frames.size() || motion.times.size() != frames.size()) return c;
  for (size_t f = 0; f < frames.size(); ++f) {
    EXPECT_EQ(motion.times[f], static_cast<float>(frames[f].step / steps_per_second)) << f;
    const Points& p = frames[f].points;
    EXPECT_EQ(motion.positions[f].rows(), p.rows());
    EXPECT_EQ(motion.positions[f].cols(), p.cols());
    if (motion.positions[f].rows() != p.rows() || motion.positions[f].cols() != p.cols()) return c;
    c.max_error = std::max(c.max_error, (motion.positions[f] - p).rowwise().norm().maxCoeff());
    c.scene_size = std::max(c.scene_size, p.cwiseAbs().maxCoeff());
  }
  return c;
}

// Writes `file` to .gltf and .glb with `options` and expects every point of every frame back to
// 1e-6 of the scene size.
void ExpectRoundTrip(const ResultFile& file, const GltfOptions& options, const TempDir& dir,
                     const std::string& stem = "motion") {
  for (const std::string name : {stem + ".gltf", stem + ".glb"}) {
    WriteGltf(file, options, dir / name);
    const Comparison c =
        Compare(file, ReadGltfJointPositions(dir / name), options.steps_per_second);
    EXPECT_GT(c.scene_size, 0.0);
    EXPECT_LE(c.max_error, 1e-6 * c.scene_size) << name << ": scene size " << c.scene_size;
    std::printf("  %s, %dD, %zu frames x %d points: max error %.3g (scene size %.3g), %zu bytes\n",
                name.c_str(), file.dim, file.result.frames.size(),
                static_cast<int>(file.result.lengths.size()) + 1, c.max_error, c.scene_size,
                static_cast<size_t>(std::filesystem::file_size(dir / name)));
  }
}

// Runs the Khronos glTF validator (tests/gltf/validate.mjs with Node.js) on `files` and expects
// no errors and no warnings in any of them.
void ExpectValidGltf(const std::vector<std::string>& files) {
  const std::string modules = FLEXKIN_NODE_MODULES;
  if (std::system("node --version > /dev/null 2>&1") != 0) {
    FAIL() << "node (Node.js) is not on the PATH; run scripts/install-deps.sh";
  }
  if (!std::filesystem::exists(modules + "/gltf-validator/package.json")) {
    FAIL() << "gltf-validator is not installed in " << modules << "; run scripts/install-deps.sh";
  }
  std::string command =
      "node '" + std::string(FLEXKIN_SOURCE_DIR) + "/tests/gltf/validate.mjs' '" + modules + "'";
  for (const std::string& f : files) command += " '" + f + "'";
  command += " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buffer[4096];
  while (const size_t got = std::fread(buffer, 1, sizeof buffer, pipe)) output.append(buffer, got);
  const int status = ::pclose(pipe);
  std::printf("%s", output.c_str());
  EXPECT_EQ(status, 0) << output;
  for (const std::string& f : files) {
    EXPECT_NE(output.find(f + ": 0 errors, 0 warnings,"), std::string::npos) << f << "\n" << output;
  }
}

TEST(GltfRoundTrip, Planar) {
  TempDir dir;
  ExpectRoundTrip(MakeResult(2, 12, 60), GltfOptions{}, dir);
}

TEST(GltfRoundTrip, SpatialWithScaleAndEitherUpAxis) {
  TempDir dir;
  const ResultFile file = MakeResult(3, 15, 60, 3);
  GltfOptions options;
  options.scale = 0.01;
  options.steps_per_second = 24.0;
  ExpectRoundTrip(file, options, dir);
  options.up_axis = GltfUpAxis::kY;
  options.include_mesh = false;
  ExpectRoundTrip(file, options, dir);
}

// Links folded back onto each other (half turns between bones, and of a bone between frames),
// in 2D and along the z axis in 3D (where the usual half-turn axis, z, is the bone itself).
TEST(GltfRoundTrip, FoldedChains) {
  TempDir dir;
  std::vector<std::string> files;
  for (const int dim : {2, 3}) {
    const int axis = dim == 2 ? 0 : 2;
    ResultFile file;
    file.dim = dim;
    file.result.lengths = Eigen::VectorXd::Ones(3);
    for (const double sign : {1.0, -1.0, 1.0}) {
      Points points = Points::Zero(4, dim);
      points(1, axis) = points(3, axis) = sign;
      file.result.frames.Add(static_cast<int64_t>(file.result.frames.size()), points);
    }
    const std::string stem = "folded" + std::to_string(dim);
    ExpectRoundTrip(file, GltfOptions{}, dir, stem);
    files.push_back(dir / (stem + ".gltf"));
    files.push_back(dir / (stem + ".glb"));
  }
  ExpectValidGltf(files);
}

// The scene's axes and units, seen without the file's flexkin extras (as another glTF reader
// sees them): 3D z-up data as glTF (x, z, -y), 2D data in the x-y plane, both times `scale`.
TEST(GltfRoundTrip, SceneAxesAndScale) {
  TempDir dir;
  for (const int dim : {2, 3}) {
    const ResultFile file = MakeResult(dim, 6, 10);
    GltfOptions options;
    options.scale = 0.01;
    WriteGltf(file, options, dir / "axes.gltf");
    nlohmann::json json = ReadJsonFile(dir / "axes.gltf");
    ASSERT_TRUE(json["asset"]["extras"].contains("flexkin"));
    json["asset"].erase("extras");
    WriteFileAtomically(dir / "plain.gltf", [&](std::ostream& out) { out << json; });
    const GltfJointMotion motion = ReadGltfJointPositions(dir / "plain.gltf");
    ASSERT_EQ(motion.dim, 3);
    ASSERT_EQ(motion.positions.size(), file.result.frames.size());
    for (size_t f = 0; f < motion.positions.size(); ++f) {
      const Points& p = file.result.frames[f].points;
      Points expected = Points::Zero(p.rows(), 3);
      if (dim == 2) {
        expected.leftCols(2) = 0.01 * p;
      } else {
        expected.col(0) = 0.01 * p.col(0);
        expected.col(1) = 0.01 * p.col(2);
        expected.col(2) = -0.01 * p.col(1);
      }
      EXPECT_LT((motion.positions[f] - expected).cwiseAbs().maxCoeff(),
                1e-6 * 0.01 * p.cwiseAbs().maxCoeff())
          << dim << "D frame " << f;
    }
  }
}

// The paper's Figs. 10 (2D, 80 links, 250 steps) and 12 (3D, 20 links, 2650 steps); the files
// pass the validator too.
TEST(GltfRoundTrip, PaperScenarios) {
  TempDir dir;
  std::vector<std::string> files;
  for (const char* name : {"fig10_planar_curve", "fig12_spatial_curve"}) {
    const Scenario scenario =
        LoadScenarioFile(std::string(FLEXKIN_SOURCE_DIR) + "/examples/" + name + ".json");
    ResultFile file;
    file.result = flexkin::Run(scenario.chain, scenario.leader_steps, scenario.options);
    file.dim = scenario.chain.dim();
    file.scenario_name = scenario.name;
    ExpectRoundTrip(file, GltfOptions{}, dir, name);
    files.push_back(dir / (std::string(name) + ".gltf"));
    files.push_back(dir / (std::string(name) + ".glb"));
  }
  ExpectValidGltf(files);
}

// Every glTF file written here passes the Khronos glTF validator without errors or warnings.
TEST(GltfValidator, WrittenFilesAreValid) {
  TempDir dir;
  std::vector<std::string> files;
  GltfOptions options;
  const ResultFile planar = MakeResult(2, 8, 30);
  const ResultFile spatial = MakeResult(3, 10, 30, 2);
  for (const char* ext : {".gltf", ".glb"}) {
    files.push_back(dir / (std::string("planar") + ext));
    WriteGltf(planar, options, files.back());
    files.push_back(dir / (std::string("spatial") + ext));
    WriteGltf(spatial, options, files.back());
  }
  options.include_mesh = false;
  files.push_back(dir / "skeleton_only.glb");
  WriteGltf(spatial, options, files.back());
  ResultFile single = planar;  // one frame: an animation of one keyframe
  single.result.frames.Truncate(1);
  files.push_back(dir / "single_frame.gltf");
  WriteGltf(single, GltfOptions{}, files.back());
  ExpectValidGltf(files);
}

// The rig: bones along the links, translations the link vectors, unit quaternions that keep
// their sign from frame to frame, and no twist in a planar motion.
TEST(GltfRig, BonesFollowTheLinks) {
  for (const int dim : {2, 3}) {
    const ResultFile file = MakeResult(dim, 9, 40);
    std::vector<Points> frames;
    for (const Frame& frame : file.result.frames) {
      Points p = Points::Zero(frame.points.rows(), 3);
      p.leftCols(dim) = frame.points;
      frames.push_back(p);
    }
    const gltf::RigAnimation rig = gltf::PoseChain(frames);
    const int joints = rig.num_joints;
    ASSERT_EQ(joints, 10);
    ASSERT_EQ(rig.num_frames, static_cast<int>(frames.size()));
    for (int f = 0; f < rig.num_frames; ++f) {
      Eigen::Matrix3d world = Eigen::Matrix3d::Identity();
      for (int j = 0; j < joints; ++j) {
        const float* q = &rig.rotation[j][4 * f];
        const float* t = &rig.translation[j][3 * f];
        EXPECT_NEAR(std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]), 1.0, 1e-6);
        if (dim == 2) {  // turns about z only
          EXPECT_EQ(q[0], 0.0f);
          EXPECT_EQ(q[1], 0.0f);
        }
        if (f > 0) {
          const float* r = &rig.rotation[j][4 * (f - 1)];
          EXPECT_GE(q[0] * r[0] + q[1] * r[1] + q[2] * r[2] + q[3] * r[3], 0.0f) << f << " " << j;
        }
        if (j > 0) {  // the link vector in the parent's frame: along +Y, its length
          const double length = file.result.lengths[j - 1];
          EXPECT_NEAR(t[0], 0.0, 1e-6 * length);
          EXPECT_NEAR(t[1], (frames[f].row(j) - frames[f].row(j - 1)).norm(), 1e-6 * length);
          EXPECT_NEAR(t[2], 0.0, 1e-6 * length);
        }
        world = world * gltf::QuaternionMatrix(q[0], q[1], q[2], q[3]);
        if (j + 1 < joints) {  // the bone points to the next point
          const Eigen::Vector3d link = (frames[f].row(j + 1) - frames[f].row(j)).normalized();
          EXPECT_LT((world.col(1) - link).norm(), 1e-6) << "frame " << f << " joint " << j;
        }
      }
    }
  }
}

// The tube, skinned to the posed joints as glTF does (linear blend skinning), stays around the
// chain: each ring's centre is on its point, each vertex within the radius of it.
TEST(GltfTube, SkinnedTubeFollowsTheChain) {
  const ResultFile file = MakeResult(3, 6, 20);
  const int n = 6, sides = 8;
  const double radius = 0.05;
  Eigen::VectorXd arc = Eigen::VectorXd::Zero(n + 1);
  for (int i = 0; i < n; ++i) arc[i + 1] = arc[i] + file.result.lengths[i];
  const gltf::TubeMesh tube = gltf::MakeTube(arc, radius, sides, Eigen::Matrix3d::Identity());
  ASSERT_EQ(tube.num_vertices(), (n + 1) * sides + 2 * (sides + 1));
  ASSERT_EQ(tube.indices.size(), 3u * (2 * n * sides + 2 * sides));
  for (int v = 0; v < tube.num_vertices(); ++v) {
    EXPECT_NEAR(tube.weights[4 * v] + tube.weights[4 * v + 1], 1.0, 1e-7);
    EXPECT_NEAR(Eigen::Vector3f(&tube.normals[3 * v]).norm(), 1.0, 1e-6);
  }
  // Outward winding: each side triangle's normal points away from the axis (y).
  for (size_t t = 0; t < 3u * 2 * n * sides; t += 3) {
    const Eigen::Vector3f a(&tube.positions[3 * tube.indices[t]]);
    const Eigen::Vector3f b(&tube.positions[3 * tube.indices[t + 1]]);
    const Eigen::Vector3f c(&tube.positions[3 * tube.indices[t + 2]]);
    Eigen::Vector3f radial = (a + b + c) / 3.0f;
    radial.y() = 0.0f;
    EXPECT_GT((b - a).cross(c - a).dot(radial), 0.0f) << "triangle " << t / 3;
  }

  std::vector<Points> frames;
  for (const Frame& frame : file.result.frames) frames.push_back(frame.points);
  const gltf::RigAnimation rig = gltf::PoseChain(frames);
  for (int f = 0; f < rig.num_frames; f += 5) {
    std::vector<Eigen::Affine3d> skin(n + 1);  // joint world transform times inverse bind
    Eigen::Affine3d world = Eigen::Affine3d::Identity();
    for (int j = 0; j <= n; ++j) {
      const float* q = &rig.rotation[j][4 * f];
      const float* t = &rig.translation[j][3 * f];
      world = world * Eigen::Translation3d(t[0], t[1], t[2]) *
              Eigen::Affine3d(gltf::QuaternionMatrix(q[0], q[1], q[2], q[3]));
      skin[j] = world * Eigen::Translation3d(0.0, -arc[j], 0.0);
    }
    for (int j = 0; j <= n; ++j) {
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      for (int k = 0; k < sides; ++k) {
        const int v = j * sides + k;
        Eigen::Vector3d skinned = Eigen::Vector3d::Zero();
        for (int s = 0; s < 2; ++s) {
          const Eigen::Vector3d rest = Eigen::Vector3f(&tube.positions[3 * v]).cast<double>();
          skinned += tube.weights[4 * v + s] * (skin[tube.joints[4 * v + s]] * rest);
        }
        const double distance = (skinned - frames[f].row(j).transpose()).norm();
        EXPECT_LE(distance, radius * (1 + 1e-6));
        EXPECT_GE(distance, 0.5 * radius);  // a bend of at most 120 degrees between links
        centre += skinned / sides;
      }
      EXPECT_LT((centre - frames[f].row(j).transpose()).norm(), 1e-6) << f << " " << j;
    }
  }
}

// Bad input: a clear InputError naming the field, no file, an existing file untouched.
TEST(GltfBadInput, RefusedWithoutWriting) {
  TempDir dir;
  const std::string path = dir / "out.glb";
  { std::ofstream(path) << "keep"; }
  const ResultFile good = MakeResult(2, 5, 6);
  const GltfOptions options;
  GltfOptions bad;

  ResultFile nan = good;
  nan.result.frames.mutable_points(2)(3, 1) = std::nan("");
  ExpectInputError([&] { WriteGltf(nan, options, path); }, "frames[2].points[3][1]", "nan");
  ResultFile inf = good;
  inf.result.frames.mutable_points(0)(0, 0) = HUGE_VAL;
  ExpectInputError([&] { WriteGltf(inf, options, path); }, "frames[0].points[0][0]", "inf");
  ResultFile empty = good;
  empty.result.frames.Clear();
  ExpectInputError([&] { WriteGltf(empty, options, path); }, "frames", "no frames");
  ResultFile same = good;
  same.result.frames.mutable_points(1).row(2) = same.result.frames[1].points.row(1);
  ExpectInputError([&] { WriteGltf(same, options, path); }, "frames[1].points[2]", "coincides");
  ResultFile steps = good;
  steps.result.frames.set_step(3, steps.result.frames[2].step);
  ExpectInputError([&] { WriteGltf(steps, options, path); }, "frames[3].step", "increase");
  ExpectInputError([&] { WriteGltf(good, options, dir / "out.obj"); }, "path", ".glb");
  bad.steps_per_second = 1e-300;  // step 1 at 1e300 s
  ExpectInputError([&] { WriteGltf(good, bad, path); }, "steps_per_second", "overflows");
  bad = GltfOptions{};
  bad.steps_per_second = 0.0;
  ExpectInputError([&] { WriteGltf(good, bad, path); }, "steps_per_second", "> 0");
  bad = GltfOptions{};
  bad.tube_sides = 2;
  ExpectInputError([&] { WriteGltf(good, bad, path); }, "tube_sides", "3 to 64");
  bad = GltfOptions{};
  bad.scale = -1.0;
  ExpectInputError([&] { WriteGltf(good, bad, path); }, "scale", "-1");
  bad = GltfOptions{};
  bad.tube_radius = std::nan("");
  ExpectInputError([&] { WriteGltf(good, bad, path); }, "tube_radius", "nan");
  ExpectInputError([] { ParseGltfUpAxis("x"); }, "up_axis", "\"x\"");
  EXPECT_EQ(ParseGltfUpAxis("z"), GltfUpAxis::kZ);

  EXPECT_EQ(ReadAll(path), "keep");
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"out.glb"});  // no temporary file left
  // A directory that does not exist: a system error, nothing written.
  EXPECT_THROW(WriteGltf(good, options, dir / "missing/out.gltf"), std::system_error);
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"out.glb"});
  // Replacing works and the result reads back.
  WriteGltf(good, options, path);
  EXPECT_EQ(ReadGltfJointPositions(path).positions.size(), good.result.frames.size());
}

// The reader: missing, truncated and foreign files.
TEST(GltfBadInput, ReaderErrors) {
  TempDir dir;
  EXPECT_THROW(ReadGltfJointPositions(dir / "missing.gltf"), std::system_error);
  WriteGltf(MakeResult(3, 4, 5), GltfOptions{}, dir / "good.glb");
  const std::string bytes = ReadAll(dir / "good.glb");
  for (const size_t keep : {size_t{0}, size_t{10}, bytes.size() / 2, bytes.size() - 4}) {
    { std::ofstream(dir / "cut.glb", std::ios::binary) << bytes.substr(0, keep); }
    EXPECT_THROW(ReadGltfJointPositions(dir / "cut.glb"), InputError) << keep << " bytes";
  }
  WriteGltf(MakeResult(2, 4, 5), GltfOptions{}, dir / "good.gltf");
  const std::string text = ReadAll(dir / "good.gltf");
  for (const size_t keep : {size_t{1}, text.size() / 3, text.size() - 10}) {
    { std::ofstream(dir / "cut.gltf") << text.substr(0, keep); }
    EXPECT_THROW(ReadGltfJointPositions(dir / "cut.gltf"), InputError) << keep << " bytes";
  }
  { std::ofstream(dir / "no_skin.gltf") << R"({"asset": {"version": "2.0"}})"; }
  ExpectInputError([&] { ReadGltfJointPositions(dir / "no_skin.gltf"); }, "skins", "no skin");
}

}  // namespace
}  // namespace flexkin
