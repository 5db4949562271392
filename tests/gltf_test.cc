// glTF export (include/flexkin/gltf.h): positions read back from .gltf and .glb files, the rig and
// the tube, the Khronos glTF validator on written files, and bad input.
#include "flexkin/gltf.h"

#include <dirent.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <system_error>
#include <tuple>
#include <vector>

#include "flexkin/result_io.h"
#include "flexkin/run.h"
#include "flexkin/scenario.h"
#include "flexkin/tree.h"
#include "gltf/reader.h"
#include "gltf/rig.h"
#include "gltf/tube.h"
#include "io/json_file.h"  // ReadJsonFile, WriteFileAtomically
#include "scenes/scenes.h"
#include "test_util.h"
#include "tree_test_util.h"

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

// The rest pose of a written file's tube, seen through the file alone: its vertices, and the
// joints where the skin's inverse bind matrices put them (the origin of each joint's bind space,
// in the scene's coordinates).
struct RestTube {
  std::vector<Eigen::Vector3d> vertices, normals, joints;
  double size = 0.0;  // the largest coordinate: float32 rounds relative to it
};
RestTube ReadRestTube(const std::string& path) {
  const gltf::SkinnedMeshRestPose pose = gltf::ReadSkinnedMeshRestPose(path);
  RestTube tube;
  tube.vertices = pose.positions;
  tube.normals = pose.normals;
  for (const Eigen::Matrix4d& m : pose.inverse_bind_matrices) {
    tube.joints.push_back(m.inverse().topRightCorner<3, 1>());
  }
  for (const Eigen::Vector3d& v : tube.vertices)
    tube.size = std::max(tube.size, v.cwiseAbs().maxCoeff());
  return tube;
}

// Distance from `v` to the segment from a to b.
double SegmentDistance(const Eigen::Vector3d& v, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double t = std::clamp((v - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (v - (a + t * ab)).norm();
}

// Expects the tube of `path` to be the chain of capsules of radii `radii` (times `scale`): every
// vertex on the surface of its link's capsule, each link's cylinder with a full ring of `sides`
// vertices of its radius at both its joints, and hemispheres of the end links' radii beyond the
// end joints, reaching one radius past them, their normals pointing away from the end joint.
void ExpectCapsules(const std::string& path, const Eigen::VectorXd& radii, double scale,
                    int sides) {
  const RestTube tube = ReadRestTube(path);
  const Eigen::Index n = radii.size();
  ASSERT_EQ(static_cast<Eigen::Index>(tube.joints.size()), n + 1) << path;
  ASSERT_EQ(tube.normals.size(), tube.vertices.size()) << path;
  const double tolerance = 1e-6 * tube.size;
  const std::vector<Eigen::Vector3d>& p = tube.joints;
  const auto radius = [&](Eigen::Index k) { return scale * radii[k]; };
  // On a capsule's surface: at its radius from some link's segment.
  double worst = 0.0;
  for (const Eigen::Vector3d& v : tube.vertices) {
    double best = HUGE_VAL;
    for (Eigen::Index k = 0; k < n; ++k) {
      best = std::min(best, std::abs(SegmentDistance(v, p[k], p[k + 1]) - radius(k)));
    }
    worst = std::max(worst, best);
  }
  EXPECT_LE(worst, tolerance) << path << ": a vertex off every capsule";
  // Each link's cylinder: a ring of its radius at each of its joints, in the joint's plane.
  for (Eigen::Index k = 0; k < n; ++k) {
    const Eigen::Vector3d u = (p[k + 1] - p[k]).normalized();
    for (const Eigen::Index j : {k, k + 1}) {
      int ring = 0;
      for (const Eigen::Vector3d& v : tube.vertices) {
        ring += std::abs((v - p[j]).dot(u)) <= tolerance &&
                std::abs((v - p[j]).norm() - radius(k)) <= tolerance;
      }
      EXPECT_GE(ring, sides) << path << ": link " << k << " at joint " << j;
    }
  }
  // The caps: beyond each end joint, every vertex at the end link's radius from it with the
  // sphere's normal there, and the farthest one radius out along the end link.
  for (const auto& [end, next, k] :
       {std::tuple<Eigen::Index, Eigen::Index, Eigen::Index>{0, 1, 0}, {n, n - 1, n - 1}}) {
    const Eigen::Vector3d out = (p[end] - p[next]).normalized();
    double reach = 0.0;
    int beyond = 0;
    for (size_t i = 0; i < tube.vertices.size(); ++i) {
      const Eigen::Vector3d d = tube.vertices[i] - p[end];
      reach = std::max(reach, d.dot(out));
      if (d.dot(out) <= tolerance) continue;
      beyond += 1;
      EXPECT_NEAR(d.norm(), radius(k), tolerance) << path << " vertex " << i;
      EXPECT_LT((tube.normals[i] - d.normalized()).norm(), 1e-5) << path << " vertex " << i;
    }
    EXPECT_NEAR(reach, radius(k), tolerance) << path << ": the cap at joint " << end;
    EXPECT_GT(beyond, 2 * sides) << path << ": the cap at joint " << end;
  }
}

// Links of a radius (a result's "link_radii") are exported as their capsules, unless the tube's
// radius is given; in 2D and 3D, both formats, either up axis and a scale. Radii that change from
// link to link and some that do not; a link of radius 0 takes the default tube's radius where that
// is thinner than every capsule (below, the least capsule's).
TEST(GltfCapsules, LinksOfARadiusAreTheirCapsules) {
  TempDir dir;
  std::vector<std::string> files;
  for (const int dim : {2, 3}) {
    ResultFile file = MakeResult(dim, 7, 20);
    file.link_radii.resize(7);
    file.link_radii << 0.05, 0.05, 0.09, 0.03, 0.03, 0.06, 0.04;
    GltfOptions options;
    options.tube_sides = dim == 2 ? 12 : 7;
    if (dim == 3) options.scale = 0.01;
    const std::string stem = "capsules" + std::to_string(dim);
    ExpectRoundTrip(file, options, dir, stem);
    for (const std::string ext : {".gltf", ".glb"}) {
      ExpectCapsules(dir / (stem + ext), file.link_radii, options.scale, options.tube_sides);
      files.push_back(dir / (stem + ext));
    }
    // A link of radius 0: the thinner of the default tube and the least capsule.
    const double total = file.result.lengths.sum();
    const double thin = std::min(0.25 * total / 7, 0.02 * total);
    file.link_radii[2] = 0.0;
    WriteGltf(file, options, dir / "zero.glb");
    Eigen::VectorXd expected = file.link_radii;
    expected[2] = std::min(thin, 0.03);
    ExpectCapsules(dir / "zero.glb", expected, options.scale, options.tube_sides);
    file.link_radii.setConstant(10.0 * thin);  // one radius: no steps between links
    WriteGltf(file, options, dir / (stem + "_even.glb"));
    ExpectCapsules(dir / (stem + "_even.glb"), file.link_radii, options.scale, options.tube_sides);
    files.push_back(dir / (stem + "_even.glb"));
  }
  ExpectValidGltf(files);
}

// The capsules' mesh itself: closed (every edge, between vertices told apart by position, in two
// triangles, once each way: vertices with other normals at the same place, as at an annulus, are
// one point of the surface), every triangle of area > 0 and facing outwards (its normal along its
// vertices' normals), the weights summing to 1.
TEST(GltfCapsules, TheCapsuleMeshIsClosedAndFacesOutwards) {
  Eigen::VectorXd arc(5), radii(4);
  arc << 0.0, 1.0, 1.5, 2.7, 3.0;
  radii << 0.2, 0.1, 0.1, 0.3;
  for (const int sides : {3, 8, 13}) {
    const gltf::TubeMesh tube =
        gltf::MakeCapsuleTube(arc, radii, sides, 2, 0.5 * Eigen::Matrix3d::Identity());
    // Rings: 2 x 2 on the caps, 5 joints' and 3 more at each of the two steps (the annulus's two
    // and the thicker link's side); 2 poles.
    ASSERT_EQ(tube.num_vertices(), (4 + 5 + 2 * 3) * sides + 2) << sides;
    std::map<std::array<float, 3>, uint32_t> places;
    std::vector<uint32_t> place(tube.num_vertices());
    for (int v = 0; v < tube.num_vertices(); ++v) {
      const std::array<float, 3> p = {tube.positions[3 * v], tube.positions[3 * v + 1],
                                      tube.positions[3 * v + 2]};
      place[v] = places.emplace(p, static_cast<uint32_t>(places.size())).first->second;
    }
    EXPECT_EQ(places.size(), (4 + 5 + 2) * sides + 2u) << sides;
    std::map<std::pair<uint32_t, uint32_t>, int> edges;
    for (size_t t = 0; t < tube.indices.size(); t += 3) {
      const Eigen::Vector3f a(&tube.positions[3 * tube.indices[t]]);
      const Eigen::Vector3f b(&tube.positions[3 * tube.indices[t + 1]]);
      const Eigen::Vector3f c(&tube.positions[3 * tube.indices[t + 2]]);
      Eigen::Vector3f normals = Eigen::Vector3f::Zero();
      for (int k = 0; k < 3; ++k) {
        normals += Eigen::Vector3f(&tube.normals[3 * tube.indices[t + k]]);
        edges[{place[tube.indices[t + k]], place[tube.indices[t + (k + 1) % 3]]}] += 1;
      }
      const Eigen::Vector3f face = (b - a).cross(c - a);
      EXPECT_GT(face.norm(), 1e-6f) << sides << " triangle " << t / 3;
      EXPECT_GT(face.dot(normals), 0.0f) << sides << " triangle " << t / 3;
    }
    for (const auto& [edge, count] : edges) {
      EXPECT_EQ(count, 1) << edge.first << "-" << edge.second;
      EXPECT_EQ(edges.count({edge.second, edge.first}), 1u) << edge.first << "-" << edge.second;
    }
    for (int v = 0; v < tube.num_vertices(); ++v) {
      EXPECT_NEAR(tube.weights[4 * v] + tube.weights[4 * v + 1], 1.0, 1e-7);
    }
  }
}

// Without link radii (or with radii all 0), and wherever the tube's radius is given, the export is
// the one of a result without radii, byte for byte: the straight tube of that radius with flat
// end caps.
TEST(GltfCapsules, WithoutRadiiOrWithAGivenTubeRadiusTheTubeIsAsBefore) {
  TempDir dir;
  for (const int dim : {2, 3}) {
    ResultFile file = MakeResult(dim, 6, 12);
    GltfOptions options;
    WriteGltf(file, options, dir / "plain.glb");
    const std::string plain = ReadAll(dir / "plain.glb");
    // The default tube: every ring at min(0.25 x mean link, 0.02 x total) from the straight axis.
    const RestTube tube = ReadRestTube(dir / "plain.glb");
    ASSERT_EQ(tube.vertices.size(), 7u * 12 + 2 * 13);
    const double total = file.result.lengths.sum();
    const double radius = std::min(0.25 * total / 6, 0.02 * total);
    for (size_t i = 0; i < 7 * 12; ++i) {
      EXPECT_NEAR(SegmentDistance(tube.vertices[i], tube.joints.front(), tube.joints.back()),
                  radius, 1e-6 * tube.size)
          << i;
    }
    file.link_radii = Eigen::VectorXd::Zero(6);
    WriteGltf(file, options, dir / "zeros.glb");
    EXPECT_EQ(ReadAll(dir / "zeros.glb"), plain) << dim << "D, radii all 0";
    file.link_radii << 0.1, 0.2, 0.1, 0.05, 0.05, 0.1;
    WriteGltf(file, options, dir / "capsules.glb");
    EXPECT_NE(ReadAll(dir / "capsules.glb"), plain);
    options.include_mesh = false;
    WriteGltf(file, options, dir / "skeleton.gltf");
    const std::string skeleton = ReadAll(dir / "skeleton.gltf");
    options.tube_radius = 0.03;
    options.include_mesh = true;
    WriteGltf(file, options, dir / "given.gltf");
    const std::string given = ReadAll(dir / "given.gltf");
    file.link_radii.resize(0);
    WriteGltf(file, options, dir / "given_plain.gltf");
    EXPECT_EQ(given, ReadAll(dir / "given_plain.gltf")) << dim << "D, tube radius given";
    options.include_mesh = false;
    WriteGltf(file, options, dir / "skeleton_plain.gltf");
    EXPECT_EQ(skeleton, ReadAll(dir / "skeleton_plain.gltf")) << dim << "D, no mesh";
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

namespace flexkin {
namespace {

// A tree result: a random tree (root 0) driven at a leaf round a circle, `frames` frames.
TreeResultFile MakeTreeResult(int dim, int count, int frames, unsigned seed) {
  const Tree tree = scenes::RandomTree(count, dim, seed);
  const int leaf = test_util::Leaves(tree, static_cast<size_t>(count)).back();
  const TreeStepper stepper = MakeTreeStepper(Method::kTractrix, tree, leaf);
  TreeResultFile file;
  file.name = "random tree";
  file.dim = dim;
  file.parents = tree.parents;
  file.targets = {leaf};
  Points p = tree.points;
  file.frames.push_back(p);
  for (int f = 1; f < frames; ++f) {
    Eigen::VectorXd target = tree.points.row(leaf).transpose();
    const double a = 2.0 * M_PI * f / frames;
    target[0] += 2.0 * (std::cos(a) - 1.0);
    target[1] += 2.0 * std::sin(a);
    MoveTreePoint(stepper, target, 8, &p);
    file.frames.push_back(p);
    file.reached.push_back(1);
  }
  return file;
}

// Every joint read back where the tree's point it sits on is, in every frame, to 1e-6 of the
// scene's size; the joints are the root, a bone per link, a tip per leaf.
void ExpectTreeRoundTrip(const TreeResultFile& tree, const GltfOptions& options,
                         const std::string& path) {
  WriteTreeGltf(tree, options, path);
  const GltfJointMotion motion = ReadGltfJointPositions(path);
  EXPECT_EQ(motion.dim, tree.dim);
  const size_t leaves =
      test_util::Leaves(Tree{tree.frames[0], tree.parents}, tree.parents.size()).size();
  ASSERT_EQ(motion.joint_points.size(), tree.parents.size() + leaves);
  ASSERT_EQ(motion.positions.size(), tree.frames.size());
  double worst = 0.0, size = 0.0;
  for (size_t f = 0; f < tree.frames.size(); ++f) {
    EXPECT_EQ(motion.times[f], static_cast<float>(f / options.steps_per_second));
    for (size_t j = 0; j < motion.joint_points.size(); ++j) {
      worst = std::max(
          worst, (motion.positions[f].row(j) - tree.frames[f].row(motion.joint_points[j])).norm());
    }
    size = std::max(size, tree.frames[f].cwiseAbs().maxCoeff());
  }
  EXPECT_LE(worst, 1e-6 * size) << path;
  std::printf("  %s: %zu frames x %zu joints, max error %.3g (scene size %.3g)\n", path.c_str(),
              tree.frames.size(), motion.joint_points.size(), worst, size);
}

TEST(GltfTree, JointsFollowThePointsInBothFormsAndAxes) {
  TempDir dir;
  std::vector<std::string> files;
  for (const int dim : {2, 3}) {
    const TreeResultFile tree = MakeTreeResult(dim, 40, 30, 7 + dim);
    for (const char* ext : {".gltf", ".glb"}) {
      files.push_back(dir / ("tree" + std::to_string(dim) + ext));
      ExpectTreeRoundTrip(tree, GltfOptions{}, files.back());
    }
    GltfOptions options;
    options.scale = 0.01;
    options.up_axis = dim == 2 ? GltfUpAxis::kZ : GltfUpAxis::kY;
    options.steps_per_second = 24.0;
    files.push_back(dir / ("tree_scaled" + std::to_string(dim) + ".glb"));
    ExpectTreeRoundTrip(tree, options, files.back());
  }
  // The plant: a binary tree of depth 10 (2,047 points, 3,071 joints).
  const Tree binary = scenes::TreeShape(scenes::TreeKind::kBinary10);
  TreeResultFile plant;
  plant.dim = 3;
  plant.parents = binary.parents;
  const TreeStepper trunk = MakeTreeStepper(Method::kTractrix, binary, 0);
  Points p = binary.points;
  plant.frames = {p};
  for (int f = 1; f <= 3; ++f) {
    MoveTreePoint(trunk, Eigen::Vector3d(0.8 * f, 0.3 * f * f, 0.0), 4, &p);
    plant.frames.push_back(p);
    plant.reached.push_back(1);
  }
  GltfOptions plant_options;
  plant_options.tube_sides = 6;
  files.push_back(dir / "binary.glb");
  ExpectTreeRoundTrip(plant, plant_options, files.back());
  ExpectValidGltf(files);
}

// The mesh: a capsule per link in the first frame's pose (every vertex at the capsule's radius
// from its link, in the scene's coordinates), and the inverse bind matrices put each joint on its
// point of the first frame.
TEST(GltfTree, CapsulesLieOnTheLinksAndTheBindPoseIsTheFirstFrame) {
  TempDir dir;
  const TreeResultFile tree = MakeTreeResult(3, 25, 5, 3);
  GltfOptions options;
  options.up_axis = GltfUpAxis::kY;  // the scene's coordinates are flexkin's
  options.tube_radius = 0.05;
  const std::string path = dir / "tree.glb";
  WriteTreeGltf(tree, options, path);
  const gltf::SkinnedMeshRestPose rest = gltf::ReadSkinnedMeshRestPose(path);
  const Points& first = tree.frames.front();
  for (size_t v = 0; v < rest.positions.size(); ++v) {
    double nearest = HUGE_VAL;
    for (size_t c = 0; c < tree.parents.size(); ++c) {
      if (tree.parents[c] < 0) continue;
      const Eigen::Vector3d a = first.row(tree.parents[c]).transpose();
      const Eigen::Vector3d b = first.row(c).transpose();
      const double t =
          std::clamp((rest.positions[v] - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
      nearest = std::min(nearest, (rest.positions[v] - (a + t * (b - a))).norm());
    }
    // On some capsule's surface (or inside another where links meet), never off the tree.
    EXPECT_LE(nearest, 0.05 * (1 + 1e-5)) << v;
  }
  const GltfJointMotion motion = ReadGltfJointPositions(path);
  ASSERT_EQ(rest.inverse_bind_matrices.size(), motion.joint_points.size());
  for (size_t j = 0; j < motion.joint_points.size(); ++j) {
    const Eigen::Vector3d origin = rest.inverse_bind_matrices[j].inverse().topRightCorner<3, 1>();
    EXPECT_LT((origin - first.row(motion.joint_points[j]).transpose()).norm(), 1e-5) << j;
  }
}

// A tree whose links slide (a robot tree's prismatic joints): point 2's link, closed in the first
// frame, opens along a turning direction and has a child; the leaf 4's telescopes from 0.3 to 0.7.
TreeResultFile SlidingTree3d() {
  TreeResultFile tree;
  tree.name = "telescopes";
  tree.dim = 3;
  tree.parents = {-1, 0, 1, 2, 1};
  tree.fixed = {0};
  for (int f = 0; f <= 8; ++f) {
    const double a = 0.15 * f, slide = 0.05 * f;
    Points p(5, 3);
    p.row(0) << 0, 0, 0;
    p.row(1) << 0, 0, 1;
    p.row(2) = p.row(1) + slide * Eigen::RowVector3d(std::cos(a), std::sin(a), 0.2);
    p.row(3) = p.row(2) + 0.4 * Eigen::RowVector3d(std::cos(2 * a), 0.0, std::sin(2 * a));
    p.row(4) = p.row(1) + (0.3 + 0.05 * f) * Eigen::RowVector3d(0.0, -std::cos(a), std::sin(a));
    tree.frames.push_back(p);
    if (f > 0) tree.reached.push_back(1);
  }
  tree.sliding = {2, 4};
  return tree;
}

// Sliding links are exported: every joint on its point in every frame (a joint "slide_2" on the
// sliding point that is not a leaf, as a tip on the leaf 4), and each sliding link's capsule as
// long as its longest, its far end's joint bound there (its inverse bind matrix), so that the
// capsule stretches with the link; the rigid links' capsules and joints in the first frame's
// pose, as without sliding links.
TEST(GltfTree, SlidingLinksStretchTheirCapsules) {
  TempDir dir;
  const TreeResultFile tree = SlidingTree3d();
  ASSERT_TRUE(ValidateTreeResult(tree).empty()) << ValidateTreeResult(tree).front().Text();
  GltfOptions options;
  options.up_axis = GltfUpAxis::kY;  // the scene's coordinates are flexkin's
  options.tube_radius = 0.04;
  const std::string path = dir / "telescopes.glb";
  WriteTreeGltf(tree, options, path);
  ExpectValidGltf({path});
  const GltfJointMotion motion = ReadGltfJointPositions(path);
  // point_0, link_1, link_2, link_4, link_3 (breadth first), tip_4, tip_3, slide_2.
  ASSERT_EQ(motion.joint_points, (std::vector<int>{0, 0, 1, 1, 2, 4, 3, 2}));
  ASSERT_EQ(motion.positions.size(), tree.frames.size());
  double worst = 0.0;
  for (size_t f = 0; f < tree.frames.size(); ++f) {
    for (size_t j = 0; j < motion.joint_points.size(); ++j) {
      worst = std::max(
          worst, (motion.positions[f].row(j) - tree.frames[f].row(motion.joint_points[j])).norm());
    }
  }
  EXPECT_LE(worst, 1e-6);
  // The bind pose: the joints of the rigid links and the root on the first frame's points; the
  // end joints of the sliding links (slide_2, tip_4) at the far end of a capsule as long as the
  // link's longest, along the link's first direction (point 2's: the direction it opens in).
  const gltf::SkinnedMeshRestPose rest = gltf::ReadSkinnedMeshRestPose(path);
  ASSERT_EQ(rest.inverse_bind_matrices.size(), motion.joint_points.size());
  const Points& first = tree.frames.front();
  const auto direction = [&](int c, size_t f) -> Eigen::Vector3d {
    return (tree.frames[f].row(c) - tree.frames[f].row(tree.parents[c])).transpose().normalized();
  };
  const auto longest = [&](int c) {
    double most = 0.0;
    for (const Points& p : tree.frames)
      most = std::max(most, (p.row(c) - p.row(tree.parents[c])).norm());
    return most;
  };
  const Eigen::Vector3d far2 = first.row(1).transpose() + longest(2) * direction(2, 1);
  const Eigen::Vector3d far4 = first.row(1).transpose() + longest(4) * direction(4, 0);
  for (size_t j = 0; j < motion.joint_points.size(); ++j) {
    const Eigen::Vector3d origin = rest.inverse_bind_matrices[j].inverse().topRightCorner<3, 1>();
    const Eigen::Vector3d expected =
        j == 7   ? far2
        : j == 5 ? far4
                 : Eigen::Vector3d(first.row(motion.joint_points[j]).transpose());
    EXPECT_LT((origin - expected).norm(), 1e-5) << j;
  }
  // Every vertex on its capsule, of radius 0.04: the rigid links' in the first frame, the sliding
  // links' from their first point to the far ends above. The capsules come in the links' joints'
  // order (link_1, link_2, link_4, link_3), each with as many vertices.
  const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> axes = {
      {first.row(0).transpose(), first.row(1).transpose()},
      {first.row(1).transpose(), far2},
      {first.row(1).transpose(), far4},
      {first.row(2).transpose(), first.row(3).transpose()}};
  ASSERT_EQ(rest.positions.size() % axes.size(), 0u);
  const size_t each = rest.positions.size() / axes.size();
  for (size_t v = 0; v < rest.positions.size(); ++v) {
    const auto& [a, b] = axes[v / each];
    const double t =
        std::clamp((rest.positions[v] - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    EXPECT_NEAR((rest.positions[v] - (a + t * (b - a))).norm(), 0.04, 1e-6) << v;
  }
}

TEST(GltfTree, RefusedWithoutWriting) {
  TempDir dir;
  TreeResultFile tree = MakeTreeResult(2, 6, 3, 1);
  const std::string path = dir / "tree.glb";
  EXPECT_THROW(WriteTreeGltf(tree, GltfOptions{}, dir / "tree.obj"), InputError);
  tree.frames[2].row(4) = tree.frames[2].row(tree.parents[4]);
  try {
    WriteTreeGltf(tree, GltfOptions{}, path);
    ADD_FAILURE() << "a link of length 0 was written";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "frames[2].points[4]");
    EXPECT_NE(std::string(e.what()).find("coincides with its parent"), std::string::npos);
  }
  GltfOptions bad;
  bad.tube_sides = 2;
  EXPECT_THROW(WriteTreeGltf(MakeTreeResult(2, 6, 3, 1), bad, path), InputError);
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace flexkin
