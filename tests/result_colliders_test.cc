// Colliders in everything that shows a chain run's result (docs/result-format.md, "colliders";
// docs/rendering.md): the result files (JSON and .npz) carry them in the scenario's form and read
// them back, checked like the rest; the figures draw them under the chain; glTF has a mesh node
// per collider; the viewer's page holds their data. examples/rope_round_post.json end to end.
#include <cairo.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "flexkin/colliders.h"
#include "flexkin/draw.h"
#include "flexkin/gltf.h"
#include "flexkin/render.h"
#include "flexkin/result_io.h"
#include "flexkin/robot_scenario.h"
#include "flexkin/scenario.h"
#include "flexkin/viewer.h"
#include "io/colliders_json.h"
#include "render/snapshot.h"
#include "render/style.h"
#include "render_test_util.h"

namespace flexkin {
namespace {

using render_test::SmallScene;
using render_test::TempDir;
using test_util::ReadFile;

// Every shape, in the scenario's form, away from the small scenes' chains.
const char* kColliders2d = R"([
  {"shape": "sphere", "center": [3, 0.5], "radius": 0.4},
  {"shape": "capsule", "from": [3, -1], "to": [4, -1.5], "radius": 0.2},
  {"shape": "cylinder", "from": [-3, 0], "to": [-3, 1], "radius": 0.3},
  {"shape": "box", "center": [0, 3], "half_extents": [0.5, 0.25], "angle": 0.3},
  {"shape": "ellipsoid", "center": [0, -3], "semi_axes": [0.6, 0.2], "angle": -0.7},
  {"shape": "half_space", "point": [0, -5], "normal": [0.2, 1]}])";
const char* kColliders3d = R"([
  {"shape": "sphere", "center": [3, 0.5, 1], "radius": 0.4},
  {"shape": "capsule", "from": [3, -1, 0], "to": [4, -1.5, 1], "radius": 0.2},
  {"shape": "cylinder", "from": [-3, 0, 0], "to": [-3, 1, 0.5], "radius": 0.3},
  {"shape": "box", "center": [0, 3, 0], "half_extents": [0.5, 0.25, 0.4],
   "rotation": [0.8, 0.2, 0.4, 0.4]},
  {"shape": "ellipsoid", "center": [0, -3, 1], "semi_axes": [0.6, 0.2, 0.3]},
  {"shape": "half_space", "point": [0, 0, -4], "normal": [0, 0, 1]}])";

std::vector<Collider> Colliders(const char* json, int dim) {
  Problems problems;
  std::vector<Collider> colliders =
      ReadCollidersJson(nlohmann::json::parse(json), "/colliders", dim, &problems);
  EXPECT_TRUE(problems.empty()) << problems.front().message;
  return colliders;
}

ResultFile SceneWithColliders(int dim) {
  ResultFile file = SmallScene(dim);
  file.colliders = Colliders(dim == 2 ? kColliders2d : kColliders3d, dim);
  return file;
}

// Two colliders are the same solid: the same signed distance (to 1e-12) at random points about
// them (in 2D, in the plane z = 0, where a 2D collider acts).
void ExpectSameColliders(const std::vector<Collider>& want, const std::vector<Collider>& got,
                         int dim) {
  ASSERT_EQ(want.size(), got.size());
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(-2.0, 2.0);
  for (size_t k = 0; k < want.size(); ++k) {
    EXPECT_EQ(want[k].shape, got[k].shape) << k;
    for (int s = 0; s < 200; ++s) {
      Eigen::Vector3d x = want[k].pose.translation();
      for (int a = 0; a < dim; ++a) x[a] += uniform(random);
      EXPECT_NEAR(QuerySurface(want[k], x).distance, QuerySurface(got[k], x).distance, 1e-12)
          << "collider " << k << " at " << x.transpose();
    }
  }
}

// The 8-bit RGB of pixel (x, y) of a PNG file.
struct Rgb8 {
  int r = -1, g = -1, b = -1;
};
Rgb8 PixelOf(const std::string& png, int x, int y) {
  Rgb8 rgb;
  cairo_surface_t* s = cairo_image_surface_create_from_png(png.c_str());
  if (cairo_surface_status(s) == CAIRO_STATUS_SUCCESS) {
    cairo_surface_flush(s);
    const unsigned char* data = cairo_image_surface_get_data(s);
    uint32_t word;
    std::memcpy(&word, data + y * cairo_image_surface_get_stride(s) + 4 * x, 4);
    rgb = {static_cast<int>((word >> 16) & 255), static_cast<int>((word >> 8) & 255),
           static_cast<int>(word & 255)};
  }
  cairo_surface_destroy(s);
  return rgb;
}

bool IsColliderColor(const Rgb8& c) {
  const render::Rgb want = render::kColliderFill;
  return std::abs(c.r - std::lround(255 * want.r)) <= 2 &&
         std::abs(c.g - std::lround(255 * want.g)) <= 2 &&
         std::abs(c.b - std::lround(255 * want.b)) <= 2;
}

// The pixels of a PNG in the colliders' colour.
int ColliderPixels(const std::string& png) {
  int count = 0;
  cairo_surface_t* s = cairo_image_surface_create_from_png(png.c_str());
  if (cairo_surface_status(s) == CAIRO_STATUS_SUCCESS) {
    cairo_surface_flush(s);
    const unsigned char* data = cairo_image_surface_get_data(s);
    for (int y = 0; y < cairo_image_surface_get_height(s); ++y) {
      for (int x = 0; x < cairo_image_surface_get_width(s); ++x) {
        uint32_t word;
        std::memcpy(&word, data + y * cairo_image_surface_get_stride(s) + 4 * x, 4);
        count +=
            IsColliderColor({static_cast<int>((word >> 16) & 255),
                             static_cast<int>((word >> 8) & 255), static_cast<int>(word & 255)});
      }
    }
  }
  cairo_surface_destroy(s);
  return count;
}

// The rope dragged round its post, run into a result file through the one call.
ResultFile RopeRoundPost(const std::string& path) {
  const Scenario s =
      LoadScenarioFile(std::string(FLEXKIN_SOURCE_DIR) + "/examples/rope_round_post.json");
  EXPECT_EQ(s.options.colliders.size(), 1u);
  RunToFiles(s.chain, s.leader_steps, s.options, s.name, {path, ""});
  return ReadResultFile(path);
}

TEST(ResultColliders, RoundTripBothFormatsEveryShape) {
  TempDir dir;
  for (const int dim : {2, 3}) {
    const ResultFile file = SceneWithColliders(dim);
    for (const char* name : {"r.json", "r.npz"}) {
      const std::string path = dir.Path(name);
      WriteResultFile(file, path, ResultFileFormatOfPath(path));
      const ResultFile back = ReadResultFile(path);
      EXPECT_EQ(back.dim, dim);
      ExpectSameColliders(file.colliders, back.colliders, dim);
      // Written again, the colliders' form is the same text (stable through a round trip).
      const std::string again = dir.Path(std::string("again_") + name);
      WriteResultFile(back, again, ResultFileFormatOfPath(again));
      const ResultFile third = ReadResultFile(again);
      ExpectSameColliders(file.colliders, third.colliders, dim);
    }
    // The JSON document holds them as a scenario's "colliders" array.
    std::ostringstream out;
    WriteResultJson(file, out);
    const nlohmann::json doc = nlohmann::json::parse(out.str());
    ASSERT_TRUE(doc.contains("colliders"));
    ASSERT_EQ(doc["colliders"].size(), 6u);
    EXPECT_EQ(doc["colliders"][0]["shape"], "sphere");
    EXPECT_EQ(doc["colliders"][0]["center"].size(), static_cast<size_t>(dim));
    EXPECT_EQ(doc["colliders"][0]["radius"], 0.4);
    EXPECT_EQ(doc["colliders"][5]["shape"], "half_space");
  }
}

TEST(ResultColliders, WithoutCollidersTheFileIsAsBefore) {
  TempDir dir;
  const ResultFile file = SmallScene(2);
  for (const char* name : {"a.json", "a.npz"}) {
    const std::string old_way = dir.Path(std::string("old_") + name);
    const std::string new_way = dir.Path(std::string("new_") + name);
    WriteResultFile(file.result, old_way, ResultFileFormatOfPath(old_way), file.scenario_name);
    WriteResultFile(file, new_way, ResultFileFormatOfPath(new_way));
    EXPECT_EQ(ReadFile(old_way), ReadFile(new_way)) << name;
    EXPECT_EQ(ReadFile(new_way).find("colliders"), std::string::npos) << name;
    EXPECT_TRUE(ReadResultFile(new_way).colliders.empty());
  }
}

// The field a result document's reader refuses, or "(no error)".
std::string FieldOfResultText(const nlohmann::json& doc) {
  try {
    ResultFromText(doc.dump());
  } catch (const InputError& e) {
    return e.field();
  }
  return std::string("(no error)");
}

TEST(ResultColliders, BadColliderNamedByPointer) {
  std::ostringstream out;
  WriteResultJson(SceneWithColliders(2), out);
  const nlohmann::json good = nlohmann::json::parse(out.str());
  nlohmann::json doc = good;
  doc["colliders"][0]["radius"] = -1;
  EXPECT_EQ(FieldOfResultText(doc), "/colliders/0/radius");
  doc = good;
  doc["colliders"][3]["half_extents"] = {0.5, 0.25, 1.0};  // 3 numbers in a 2D result
  EXPECT_EQ(FieldOfResultText(doc), "/colliders/3/half_extents");
  doc = good;
  doc["colliders"][1]["shape"] = "capsul";
  EXPECT_EQ(FieldOfResultText(doc), "/colliders/1/shape");
  doc = good;
  doc["colliders"][5].erase("normal");
  EXPECT_EQ(FieldOfResultText(doc), "/colliders/5/normal");
  doc = good;
  doc["colliders"][2]["radius"] = "wide";
  EXPECT_EQ(FieldOfResultText(doc), "/colliders/2/radius");
  doc = good;
  doc["colliders"] = 5;
  EXPECT_EQ(FieldOfResultText(doc), "/colliders");
}

TEST(ResultColliders, WritersRefuseACollider2dCannotSay) {
  TempDir dir;
  ResultFile file = SceneWithColliders(2);
  file.colliders[0].pose.translation().z() = 0.25;  // a sphere off the plane z = 0
  try {
    WriteResultFile(file, dir.Path("r.json"), ResultFileFormat::kJson);
    FAIL() << "a 2D result's collider off the plane was written";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "colliders[0]");
  }
  EXPECT_FALSE(render_test::Exists(dir.Path("r.json")));
  file = SceneWithColliders(3);
  file.colliders[1].radius = -0.5;
  EXPECT_FALSE(ValidateResult(file).empty());
  EXPECT_THROW(WriteSnapshotFigure(file, FigureOptions(), dir.Path("f.png")), InputError);
}

// The links' radii: written as "link_radii" when given (a run's link_radius, one per link),
// read back the same in both formats, absent otherwise; a bad list is refused by pointer when
// read and by field when written (nothing written).
TEST(ResultColliders, LinkRadiiRoundTripAndBadOnesNamed) {
  TempDir dir;
  ResultFile file = SceneWithColliders(2);
  const Eigen::Index n = file.result.lengths.size();
  file.link_radii = Eigen::VectorXd::LinSpaced(n, 0.01, 0.05);
  for (const char* name : {"r.json", "r.npz"}) {
    const std::string path = dir.Path(name);
    WriteResultFile(file, path, ResultFileFormatOfPath(path));
    EXPECT_EQ(ReadResultFile(path).link_radii, file.link_radii) << name;
  }
  std::ostringstream out;
  WriteResultJson(file, out);
  const nlohmann::json good = nlohmann::json::parse(out.str());
  ASSERT_EQ(good["link_radii"].size(), static_cast<size_t>(n));
  nlohmann::json doc = good;
  doc["link_radii"][1] = -0.5;
  EXPECT_EQ(FieldOfResultText(doc), "/link_radii/1");
  doc["link_radii"] = {0.1};
  EXPECT_EQ(FieldOfResultText(doc), "/link_radii");
  doc.erase("link_radii");
  EXPECT_EQ(FieldOfResultText(doc), "(no error)");
  file.link_radii[2] = std::nan("");
  try {
    WriteResultFile(file, dir.Path("bad.json"), ResultFileFormat::kJson);
    FAIL() << "a NaN link radius was written";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "link_radii[2]");
  }
  EXPECT_FALSE(render_test::Exists(dir.Path("bad.json")));
  // A run with a link radius writes it for every link.
  Scenario s = LoadScenarioFile(std::string(FLEXKIN_SOURCE_DIR) + "/examples/rope_round_post.json");
  s.options.link_radius = 0.02;
  RunToFiles(s.chain, s.leader_steps, s.options, s.name, {dir.Path("rope.json"), ""});
  EXPECT_EQ(ReadResultFile(dir.Path("rope.json")).link_radii,
            Eigen::VectorXd::Constant(s.chain.num_links(), 0.02));
}

TEST(ResultColliders, RopeRoundPostEndToEnd) {
  TempDir dir;
  for (const char* name : {"rope.npz", "rope.json"}) {
    const ResultFile rope = RopeRoundPost(dir.Path(name));
    ASSERT_EQ(rope.colliders.size(), 1u);
    const Collider& post = rope.colliders[0];
    EXPECT_EQ(post.shape, ColliderShape::kSphere);
    EXPECT_EQ(post.radius, 0.3);
    EXPECT_EQ(post.pose.translation(), Eigen::Vector3d(-0.35, 1.65, 0.0));
  }
  const nlohmann::json doc = nlohmann::json::parse(ReadFile(dir.Path("rope.json")));
  EXPECT_EQ(
      doc["colliders"],
      nlohmann::json::parse(R"([{"shape": "sphere", "center": [-0.35, 1.65], "radius": 0.3}])"));
}

// The post is drawn in the collider's colour where it is, under the rope; the same figure
// without it has none of that colour there.
TEST(ResultColliders, FigureDrawsThePost) {
  TempDir dir;
  ResultFile rope = RopeRoundPost(dir.Path("rope.npz"));
  FigureOptions options;
  options.width = 640;
  options.show_legend = false;
  WriteSnapshotFigure(rope, options, dir.Path("rope.png"));
  const render::SnapshotLayout layout = render::LayoutSnapshot(rope, options);
  const Collider& post = rope.colliders[0];
  int inside = 0, total = 0;
  for (int k = 0; k < 16; ++k) {
    const double a = 2.0 * M_PI * k / 16, r = 0.5 * post.radius * (k % 2 == 0 ? 1.0 : 0.3);
    const Eigen::Vector2d q =
        post.pose.translation().head<2>() + r * Eigen::Vector2d(std::cos(a), std::sin(a));
    const Eigen::Vector2d p = layout.scene.Pixel(q.data());
    inside += IsColliderColor(
        PixelOf(dir.Path("rope.png"), static_cast<int>(p.x()), static_cast<int>(p.y())));
    ++total;
  }
  EXPECT_GE(inside, total - 2) << "pixels inside the post in its colour";
  // Outside the post, a radius and a half from its centre on the side away from the rope: not.
  const Eigen::Vector2d away = post.pose.translation().head<2>() + Eigen::Vector2d(0.6, -0.6);
  const Eigen::Vector2d pa = layout.scene.Pixel(away.data());
  EXPECT_FALSE(IsColliderColor(
      PixelOf(dir.Path("rope.png"), static_cast<int>(pa.x()), static_cast<int>(pa.y()))));
  // Without the collider, the post's centre is not in its colour.
  rope.colliders.clear();
  WriteSnapshotFigure(rope, options, dir.Path("free.png"));
  const render::SnapshotLayout free_layout = render::LayoutSnapshot(rope, options);
  const Eigen::Vector2d c = free_layout.scene.Pixel(post.pose.translation().data());
  EXPECT_FALSE(IsColliderColor(
      PixelOf(dir.Path("free.png"), static_cast<int>(c.x()), static_cast<int>(c.y()))));
}

// The axes hold every finite collider, and a half-plane shades the side below its line.
TEST(ResultColliders, FigureExtentAndHalfPlane2d) {
  TempDir dir;
  const ResultFile file = SceneWithColliders(2);
  FigureOptions options;
  options.width = 800;
  options.show_legend = false;
  WriteSnapshotFigure(file, options, dir.Path("all.png"));
  const render::SnapshotLayout layout = render::LayoutSnapshot(file, options);
  const render::Rect& plot = layout.scene.plot();
  for (size_t k = 0; k + 1 < file.colliders.size(); ++k) {
    const Eigen::Vector3d t = file.colliders[k].pose.translation();
    const Eigen::Vector2d p = layout.scene.Pixel(t.data());
    EXPECT_TRUE(p.x() > plot.x && p.x() < plot.right() && p.y() > plot.y && p.y() < plot.bottom())
        << "collider " << k;
    EXPECT_TRUE(IsColliderColor(
        PixelOf(dir.Path("all.png"), static_cast<int>(p.x()), static_cast<int>(p.y()))))
        << "collider " << k << "'s centre";
  }
  // The half-plane (point (0, -5), normal (0.2, 1)): its line is in view, the side below shaded.
  const Collider& floor = file.colliders.back();
  const Eigen::Vector3d below = floor.pose.translation() - 0.3 * floor.pose.linear().col(2);
  const Eigen::Vector3d above = floor.pose.translation() + 0.3 * floor.pose.linear().col(2);
  const Eigen::Vector2d pb = layout.scene.Pixel(below.data()),
                        pa = layout.scene.Pixel(above.data());
  ASSERT_LT(pb.y(), plot.bottom());
  EXPECT_TRUE(IsColliderColor(
      PixelOf(dir.Path("all.png"), static_cast<int>(pb.x()), static_cast<int>(pb.y()))));
  EXPECT_FALSE(IsColliderColor(
      PixelOf(dir.Path("all.png"), static_cast<int>(pa.x()), static_cast<int>(pa.y()))));
  // SVG and PDF draw them too.
  WriteSnapshotFigure(file, options, dir.Path("all.svg"));
  EXPECT_NE(ReadFile(dir.Path("all.svg")).find("rgb(80%,80%,78%)"), std::string::npos);
}

// 3D: each finite shape's silhouette covers the projection of its centre.
TEST(ResultColliders, FigureSilhouettes3d) {
  TempDir dir;
  ResultFile file = SceneWithColliders(3);
  file.colliders.pop_back();  // the floor would cover the centres seen from above
  FigureOptions options;
  options.width = 900;
  options.show_legend = false;
  WriteSnapshotFigure(file, options, dir.Path("all3.png"));
  const render::SnapshotLayout layout = render::LayoutSnapshot(file, options);
  for (size_t k = 0; k < file.colliders.size(); ++k) {
    const Eigen::Vector2d p = layout.scene.Pixel(file.colliders[k].pose.translation().data());
    EXPECT_TRUE(IsColliderColor(
        PixelOf(dir.Path("all3.png"), static_cast<int>(p.x()), static_cast<int>(p.y()))))
        << "collider " << k;
  }
  file = SceneWithColliders(3);
  WriteSnapshotFigure(file, options, dir.Path("floor.png"));  // the floor's plane in the box
}

// A .glb file's JSON and binary chunks.
struct Glb {
  nlohmann::json json;
  std::string bin;
};
Glb ReadGlb(const std::string& path) {
  const std::string bytes = ReadFile(path);
  Glb glb;
  uint32_t json_length = 0;
  std::memcpy(&json_length, bytes.data() + 12, 4);
  glb.json = nlohmann::json::parse(bytes.substr(20, json_length));
  uint32_t bin_length = 0;
  std::memcpy(&bin_length, bytes.data() + 20 + json_length, 4);
  glb.bin = bytes.substr(28 + json_length, bin_length);
  return glb;
}

TEST(ResultColliders, GltfMeshNodesOnTheSurfaces) {
  TempDir dir;
  for (const int dim : {2, 3}) {
    const ResultFile file = SceneWithColliders(dim);
    WriteGltf(file, GltfOptions(), dir.Path("c.glb"));
    const Glb glb = ReadGlb(dir.Path("c.glb"));
    const nlohmann::json& nodes = glb.json["nodes"];
    ASSERT_EQ(nodes[0]["name"], "flexkin");
    size_t found = 0;
    for (const int child : nodes[0]["children"]) {
      const nlohmann::json& node = nodes[child];
      const std::string name = node["name"];
      if (name.rfind("collider_", 0) != 0) continue;
      const size_t k = std::stoul(name.substr(9));
      ASSERT_LT(k, file.colliders.size());
      ++found;
      EXPECT_FALSE(node.contains("translation") || node.contains("rotation"));
      const nlohmann::json& primitive =
          glb.json["meshes"][node["mesh"].get<int>()]["primitives"][0];
      const nlohmann::json& accessor =
          glb.json["accessors"][primitive["attributes"]["POSITION"].get<int>()];
      const nlohmann::json& view = glb.json["bufferViews"][accessor["bufferView"].get<int>()];
      const size_t count = accessor["count"];
      const size_t offset = view.value("byteOffset", 0) + accessor.value("byteOffset", 0);
      EXPECT_GE(count, 4u);
      EXPECT_GT(glb.json["accessors"][primitive["indices"].get<int>()]["count"].get<int>(), 5);
      double worst = 0.0;
      for (size_t v = 0; v < count; ++v) {
        float xyz[3];
        std::memcpy(xyz, glb.bin.data() + offset + 12 * v, 12);
        const Eigen::Vector3d x(xyz[0], xyz[1], xyz[2]);
        worst = std::max(worst, std::abs(QuerySurface(file.colliders[k], x).distance));
      }
      EXPECT_LT(worst, 1e-6) << dim << "D collider " << k;
    }
    EXPECT_EQ(found, file.colliders.size());
  }
  // The .gltf form passes through the same writer; it has the nodes too.
  WriteGltf(SceneWithColliders(3), GltfOptions(), dir.Path("c.gltf"));
  EXPECT_NE(ReadFile(dir.Path("c.gltf")).find("\"collider_5\""), std::string::npos);
}

TEST(ResultColliders, ViewerHoldsTheColliders) {
  TempDir dir;
  const ResultFile rope = RopeRoundPost(dir.Path("rope.npz"));
  WriteViewerHtml(rope, ViewerOptions(), dir.Path("rope.html"));
  const std::string html = ReadFile(dir.Path("rope.html"));
  EXPECT_NE(html.find("\"colliders\":[{\"shape\": \"sphere\", \"center\": [-0.34999999999999998, "
                      "1.6499999999999999], \"radius\": 0.29999999999999999"),
            std::string::npos);
  EXPECT_NE(html.find("function drawColliders"), std::string::npos);
  for (const int dim : {2, 3}) {
    WriteViewerHtml(SceneWithColliders(dim), ViewerOptions(), dir.Path("all.html"));
    const std::string page = ReadFile(dir.Path("all.html"));
    for (const char* shape : {"sphere", "capsule", "cylinder", "box", "ellipsoid", "half_space"}) {
      EXPECT_NE(page.find(std::string("{\"shape\": \"") + shape + "\""), std::string::npos)
          << dim << "D " << shape;
    }
  }
  // Without colliders the page has no "colliders" key.
  WriteViewerHtml(SmallScene(2), ViewerOptions(), dir.Path("plain.html"));
  EXPECT_EQ(ReadFile(dir.Path("plain.html")).find("\"colliders\":"), std::string::npos);
}

// A keyframed collider (docs/colliders.md, "Moving colliders") in everything that shows a run:
// the result file carries its motion (read back, the same solid at every time), glTF animates its
// node (each frame's vertices on the collider where its motion has it at that frame's step), and
// the viewer's page carries each frame's move.
TEST(ResultColliders, AKeyframedColliderMovesInTheFileGltfAndViewer) {
  TempDir dir;
  ResultFile file = SmallScene(3);
  std::vector<Collider> colliders = Colliders(R"([
    {"shape": "box", "center": [3, 0.5, 1], "half_extents": [0.4, 0.2, 0.3],
     "motion": {"interpolation": "linear", "keyframes": [
       {"time": 1, "translation": [0, 0, 0]},
       {"time": 5, "translation": [-1, 2, 0.5],
        "rotation": {"axis": [1, 1, 0], "angle_deg": 70}}]}}])",
                                              3);
  ASSERT_EQ(colliders.size(), 1u);
  ASSERT_NE(colliders[0].motion, nullptr);
  EXPECT_EQ(colliders[0].motion->keyframes.size(), 2u);
  file.colliders = colliders;
  for (const char* name : {"m.json", "m.npz"}) {
    const std::string path = dir.Path(name);
    WriteResultFile(file, path, ResultFileFormatOfPath(path));
    const ResultFile back = ReadResultFile(path);
    ASSERT_EQ(back.colliders.size(), 1u);
    ASSERT_NE(back.colliders[0].motion, nullptr) << name;
    for (const double t : {0.0, 1.0, 2.5, 4.0, 5.0, 6.0}) {
      ExpectSameColliders({ColliderAt(colliders[0], t)}, {ColliderAt(back.colliders[0], t)}, 3);
    }
  }

  WriteGltf(file, GltfOptions(), dir.Path("m.glb"));
  const Glb glb = ReadGlb(dir.Path("m.glb"));
  const nlohmann::json& nodes = glb.json["nodes"];
  int node = -1;
  for (size_t i = 0; i < nodes.size(); ++i) {
    if (nodes[i]["name"] == "collider_0") node = static_cast<int>(i);
  }
  ASSERT_GE(node, 0);
  const auto floats = [&](int accessor_index, int components) {
    const nlohmann::json& accessor = glb.json["accessors"][accessor_index];
    const nlohmann::json& view = glb.json["bufferViews"][accessor["bufferView"].get<int>()];
    const size_t offset = view.value("byteOffset", 0) + accessor.value("byteOffset", 0);
    std::vector<float> values(accessor["count"].get<size_t>() * components);
    std::memcpy(values.data(), glb.bin.data() + offset, 4 * values.size());
    return values;
  };
  std::vector<float> translation, rotation;
  for (const nlohmann::json& channel : glb.json["animations"][0]["channels"]) {
    if (channel["target"]["node"] != node) continue;
    const nlohmann::json& sampler =
        glb.json["animations"][0]["samplers"][channel["sampler"].get<int>()];
    if (channel["target"]["path"] == "translation") translation = floats(sampler["output"], 3);
    if (channel["target"]["path"] == "rotation") rotation = floats(sampler["output"], 4);
  }
  const size_t frames = file.result.frames.size();
  ASSERT_EQ(translation.size(), 3 * frames);
  ASSERT_EQ(rotation.size(), 4 * frames);
  const nlohmann::json& primitive =
      glb.json["meshes"][nodes[node]["mesh"].get<int>()]["primitives"][0];
  const std::vector<float> vertices = floats(primitive["attributes"]["POSITION"], 3);
  double worst = 0.0;
  for (size_t f = 0; f < frames; ++f) {
    const Eigen::Quaterniond q(rotation[4 * f + 3], rotation[4 * f], rotation[4 * f + 1],
                               rotation[4 * f + 2]);
    const Eigen::Vector3d t(translation[3 * f], translation[3 * f + 1], translation[3 * f + 2]);
    const Collider at = ColliderAt(colliders[0], double(file.result.frames[f].step));
    for (size_t v = 0; v < vertices.size(); v += 3) {
      const Eigen::Vector3d x(vertices[v], vertices[v + 1], vertices[v + 2]);
      worst = std::max(worst, std::abs(QuerySurface(at, q.normalized() * x + t).distance));
    }
  }
  EXPECT_LT(worst, 1e-5);

  WriteViewerHtml(file, ViewerOptions(), dir.Path("m.html"));
  const std::string page = ReadFile(dir.Path("m.html"));
  const size_t moves = page.find("\"moves\":[");
  ASSERT_NE(moves, std::string::npos);
  const std::string list = page.substr(moves + 9, page.find(']', moves) - moves - 9);
  EXPECT_EQ(std::count(list.begin(), list.end(), ',') + 1, static_cast<long>(12 * frames));
  EXPECT_NE(page.find("movingColliders"), std::string::npos);
}

// The one call that draws a file: every format of a chain result takes the colliders.
TEST(ResultColliders, DrawFileEveryStillFormat) {
  TempDir dir;
  RopeRoundPost(dir.Path("rope.json"));
  DrawOptions options;
  options.formats = {OutputFormat::kSvg,   OutputFormat::kPng,  OutputFormat::kPdf,
                     OutputFormat::kPlots, OutputFormat::kHtml, OutputFormat::kGltf,
                     OutputFormat::kGlb};
  options.base = dir.Path("out/rope");
  const std::vector<std::string> written = DrawFile(dir.Path("rope.json"), options);
  EXPECT_GE(written.size(), 7u);
  EXPECT_NE(ReadFile(dir.Path("out/rope.gltf")).find("collider_0"), std::string::npos);
}

// A robot trajectory's colliders (docs/robot-format.md): the file carries them as the scenario
// gave them, reads them back, and its figure and viewer draw them as a chain run's; without them
// the figure has none of their colour.
TEST(ResultColliders, RobotTrajectoryCarriesAndDrawsItsColliders) {
  TempDir dir;
  const RobotScenario scenario = ParseRobotScenarioText(
      R"({"format": "flexkin-robot", "arm": {"links": 16, "link_length": 0.1},
          "colliders": [{"shape": "sphere", "center": [0.8, 0.3], "radius": 0.1},
                        {"shape": "box", "center": [0.2, 0.9], "half_extents": [0.2, 0.1]}],
          "path": {"type": "line", "to": [1.2, 0.6], "steps": 40}})");
  TrackToFiles(scenario, dir.Path("arm.json"), "");
  RobotTrajectoryFile t = ReadRobotTrajectoryFile(dir.Path("arm.json"));
  ASSERT_EQ(t.colliders.size(), 2u);
  EXPECT_EQ(t.colliders[0].shape, ColliderShape::kSphere);
  EXPECT_EQ(t.colliders[0].radius, 0.1);
  EXPECT_EQ(t.colliders[0].pose.translation(), Eigen::Vector3d(0.8, 0.3, 0.0));
  EXPECT_EQ(t.colliders[1].shape, ColliderShape::kBox);
  EXPECT_EQ(RobotTrajectoryAsResult(t).colliders.size(), 2u);
  FigureOptions options;
  options.width = 480;
  options.show_legend = false;
  WriteSnapshotFigure(t, options, dir.Path("arm.png"));
  const int drawn = ColliderPixels(dir.Path("arm.png"));
  EXPECT_GT(drawn, 100);
  WriteViewerHtml(t, ViewerOptions(), dir.Path("arm.html"));
  const std::string html = ReadFile(dir.Path("arm.html"));
  EXPECT_NE(html.find("\"colliders\":[{\"shape\": \"sphere\""), std::string::npos);
  t.colliders.clear();
  WriteSnapshotFigure(t, options, dir.Path("bare.png"));
  EXPECT_EQ(ColliderPixels(dir.Path("bare.png")), 0);
  std::printf("robot trajectory figure: %d pixels in the colliders' colour\n", drawn);
}

}  // namespace
}  // namespace flexkin
