// Tests of groom scenarios (include/flexkin/groom.h, docs/groom-format.md): every form of the file
// is read with its defaults, every invalid field is a problem at its JSON pointer and all of them
// are listed at once, the schema lists the keys the reader accepts, the examples load; grown roots
// lie on the scalp and in the region, uniformly by area, the same for the same seed; link lengths
// and the direction field are as documented; the keyframed motion passes through its keyframes,
// slerps along the shorter arc and (smooth) rests at every keyframe.
#include "flexkin/groom.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <ostream>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/robot_scenario.h"
#include "flexkin/scenario.h"
#include "flexkin/strands.h"
#include "io/json_file.h"  // ReadJsonFile, ReadTextFile
#include "schema_test_util.h"
#include "test_util.h"

namespace flexkin {
namespace {

using nlohmann::json;

constexpr double kPi = 3.14159265358979323846;

std::string Example(const std::string& name) {
  return std::string(FLEXKIN_SOURCE_DIR) + "/examples/" + name;
}

std::vector<std::string> Fields(const Problems& problems) {
  std::vector<std::string> fields;
  for (const Problem& p : problems) fields.push_back(p.field);
  return fields;
}

std::string AllText(const Problems& problems) {
  std::string text;
  for (const Problem& p : problems) text += p.Text() + "\n";
  return text;
}

// A small valid groom on a sphere, and motion; tests change what they need.
json SphereDoc() {
  return json::parse(R"({
    "groom": {"scalp": {"shape": "sphere", "center": [0, 0, 0], "radius": 1}, "roots": 20,
              "links": 4, "link_length": 0.1},
    "motion": {"keyframes": [{"time": 0}, {"time": 1, "translation": [1, 0, 0]}]}})");
}

json Strands2dDoc() {
  return json::parse(R"({
    "strands": [{"points": [[0, 0], [0, 1]]}, {"points": [[1, 0], [1, 1], [1, 2]]}],
    "motion": {"keyframes": [{"time": 0}, {"time": 1, "translation": [1, 0], "angle_deg": 90}]}})");
}

// ---------------------------------------------------------------------------------------------
// Reading

TEST(GroomParseTest, SphereGroomWithDefaults) {
  const GroomScenario s = ParseGroomText(SphereDoc().dump());
  EXPECT_EQ(s.dim, 3);
  EXPECT_EQ(s.name, "");
  ASSERT_EQ(s.strands.size(), 20u);
  for (const Points& p : s.strands) {
    EXPECT_EQ(p.rows(), 5);
    EXPECT_EQ(p.cols(), 3);
  }
  EXPECT_EQ(s.scalp.shape, "sphere");
  EXPECT_EQ(s.scalp.radii, Eigen::Vector3d::Ones());
  EXPECT_EQ(s.scalp.center, Eigen::Vector3d::Zero());
  EXPECT_EQ(s.motion.fps, 30.0);
  EXPECT_EQ(s.motion.interpolation, KeyframeInterpolation::kSmooth);
  ASSERT_EQ(s.motion.keyframes.size(), 2u);
  EXPECT_EQ(s.motion.keyframes[0].pose.rotation, Eigen::Matrix3d::Identity());
  EXPECT_EQ(s.motion.keyframes[0].pose.translation, Eigen::Vector3d::Zero());
  EXPECT_EQ(s.motion.keyframes[1].pose.translation, Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(s.motion.num_frames(), 31);
  EXPECT_EQ(s.options.method, Method::kTractrix);
  EXPECT_EQ(s.options.substeps, 1);
  EXPECT_EQ(s.options.pinned, 1);
  EXPECT_EQ(s.options.threads, 0);
  EXPECT_EQ(s.record_every, 1);
  EXPECT_TRUE(s.float32);
  // Defaults of the spec: whole surface, droop 0, no variation, seed 1.
  GrowSpec spec;
  spec.scalp = s.scalp;
  spec.roots = 20;
  spec.links = 4;
  spec.link_length = 0.1;
  const std::vector<Points> grown = GrowStrands(spec);
  for (size_t i = 0; i < grown.size(); ++i) EXPECT_EQ(grown[i], s.strands[i]) << i;
}

TEST(GroomParseTest, EveryKeyIsRead) {
  const GroomScenario s = ParseGroomText(R"({
    "$schema": "x", "name": "n", "description": "d",
    "groom": {"scalp": {"shape": "ellipsoid", "center": [1, 2, 3], "radii": [0.1, 0.2, 0.3]},
              "roots": 7, "region": {"axis": [1, 0, 0], "max_angle_deg": 90}, "links": 3,
              "link_length": 0.01, "length_variation": 0.5,
              "direction": {"droop": 0.25, "gravity": [0, -2, 0]}, "seed": 42},
    "motion": {"fps": 24, "interpolation": "linear", "keyframes": [
      {"time": 0.5, "translation": [1, 2, 3], "rotation": {"axis": [0, 0, 2], "angle_deg": 90}},
      {"time": 2, "rotation": {"quaternion": [0, 0, 0, 2]}}]},
    "method": "ftl", "substeps": 3, "pinned": 2, "threads": 5,
    "record": {"every": 4, "precision": "float64"}})");
  EXPECT_EQ(s.name, "n");
  EXPECT_EQ(s.description, "d");
  EXPECT_EQ(s.scalp.shape, "ellipsoid");
  EXPECT_EQ(s.scalp.center, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(s.scalp.radii, Eigen::Vector3d(0.1, 0.2, 0.3));
  ASSERT_EQ(s.strands.size(), 7u);
  EXPECT_EQ(s.strands[0].rows(), 4);
  GrowSpec spec;
  spec.scalp = s.scalp;
  spec.roots = 7;
  spec.region_axis = Eigen::Vector3d(1, 0, 0);
  spec.max_angle_deg = 90;
  spec.links = 3;
  spec.link_length = 0.01;
  spec.length_variation = 0.5;
  spec.droop = 0.25;
  spec.gravity = Eigen::Vector3d(0, -2, 0);
  spec.seed = 42;
  const std::vector<Points> grown = GrowStrands(spec);
  for (size_t i = 0; i < grown.size(); ++i) EXPECT_EQ(grown[i], s.strands[i]) << i;

  EXPECT_EQ(s.motion.fps, 24.0);
  EXPECT_EQ(s.motion.interpolation, KeyframeInterpolation::kLinear);
  ASSERT_EQ(s.motion.keyframes.size(), 2u);
  EXPECT_EQ(s.motion.keyframes[0].time, 0.5);
  EXPECT_EQ(s.motion.keyframes[0].pose.translation, Eigen::Vector3d(1, 2, 3));
  const Eigen::Matrix3d quarter_turn =
      Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitZ()).matrix();
  EXPECT_LT((s.motion.keyframes[0].pose.rotation - quarter_turn).norm(), 1e-15);
  // The quaternion (0, 0, 0, 2), normalized: a half turn about z.
  const Eigen::Matrix3d half_turn = BodyPose::FromQuaternion(0, 0, 0, 1, {}).rotation;
  EXPECT_EQ(s.motion.keyframes[1].pose.rotation, half_turn);
  EXPECT_EQ(s.motion.keyframes[1].pose.translation, Eigen::Vector3d::Zero());
  EXPECT_EQ(s.motion.num_frames(), 37);  // 1.5 s at 24 fps
  EXPECT_EQ(s.options.method, Method::kFollowTheLeader);
  EXPECT_EQ(s.options.substeps, 3);
  EXPECT_EQ(s.options.pinned, 2);
  EXPECT_EQ(s.options.threads, 5);
  EXPECT_EQ(s.record_every, 4);
  EXPECT_FALSE(s.float32);
}

TEST(GroomParseTest, ExplicitStrands2dAnd3d) {
  const GroomScenario s = ParseGroomText(Strands2dDoc().dump());
  EXPECT_EQ(s.dim, 2);
  EXPECT_EQ(s.scalp.shape, "");
  ASSERT_EQ(s.strands.size(), 2u);
  Points first(2, 2), second(3, 2);
  first << 0, 0, 0, 1;
  second << 1, 0, 1, 1, 1, 2;
  EXPECT_EQ(s.strands[0], first);
  EXPECT_EQ(s.strands[1], second);
  const BodyPose last = s.motion.keyframes[1].pose;
  EXPECT_EQ(last.rotation, BodyPose::Planar(kPi / 2, 1, 0).rotation);
  EXPECT_EQ(last.translation, Eigen::Vector3d(1, 0, 0));

  const GroomScenario s3 = ParseGroomText(R"({
    "strands": [{"points": [[0, 0, 0], [0, 0, 1]]}],
    "motion": {"keyframes": [{"time": 0, "rotation": {"quaternion": [1, 0, 0, 0]}}]}})");
  EXPECT_EQ(s3.dim, 3);
  ASSERT_EQ(s3.strands.size(), 1u);
  EXPECT_EQ(s3.strands[0].rows(), 2);
  EXPECT_EQ(s3.motion.num_frames(), 1);
}

TEST(GroomParseTest, IntegersMayBeWrittenWithAPoint) {
  json doc = SphereDoc();
  doc["groom"]["roots"] = 3.0;
  doc["groom"]["links"] = 2.0;
  doc["record"] = {{"every", 2.0}};
  const GroomScenario s = ParseGroomText(doc.dump());
  EXPECT_EQ(s.strands.size(), 3u);
  EXPECT_EQ(s.strands[0].rows(), 3);
  EXPECT_EQ(s.record_every, 2);
}

TEST(GroomParseTest, TellsGroomsFromOtherScenarios) {
  EXPECT_TRUE(IsGroomText(SphereDoc().dump()));
  EXPECT_TRUE(IsGroomText(Strands2dDoc().dump()));
  EXPECT_TRUE(IsGroomText(R"({"strands": 1})"));  // a groom, if a wrong one
  EXPECT_FALSE(IsGroomText("[1]"));
  EXPECT_FALSE(IsGroomText("{\"groom\": "));
  EXPECT_FALSE(IsGroomText(R"({"curve": {}, "leader": {}})"));
  for (const char* name : {"fig10_planar_curve.json", "robot_planar_8link.json"}) {
    EXPECT_FALSE(IsGroomFile(Example(name))) << name;
    EXPECT_FALSE(IsGroomText(ReadTextFile(Example(name)))) << name;
  }
  EXPECT_TRUE(IsGroomFile(Example("groom_head.json")));
  EXPECT_TRUE(IsGroomFile(Example("groom_grass_2d.json")));
  EXPECT_FALSE(IsGroomFile("/nonexistent-dir/groom.json"));
  // And the other readers do not take grooms for theirs.
  EXPECT_FALSE(IsRobotScenarioText(SphereDoc().dump()));
}

TEST(GroomExampleTest, ExamplesLoadWithTheirDocumentedSizes) {
  const GroomScenario head = LoadGroomFile(Example("groom_head.json"));
  EXPECT_EQ(head.dim, 3);
  EXPECT_EQ(head.strands.size(), 5000u);
  EXPECT_EQ(head.strands[0].rows(), 25);
  EXPECT_EQ(head.scalp.shape, "sphere");
  EXPECT_EQ(head.scalp.radii, Eigen::Vector3d::Constant(0.1));
  EXPECT_EQ(head.motion.num_frames(), 121);  // 4 s at 30 fps
  EXPECT_EQ(head.motion.interpolation, KeyframeInterpolation::kSmooth);
  EXPECT_EQ(head.record_every, 2);
  EXPECT_TRUE(head.float32);
  EXPECT_EQ(head.options.method, Method::kTractrix);
  EXPECT_TRUE(ValidateGroomFile(Example("groom_head.json")).empty());
  EXPECT_EQ(GroomSummary(head),
            "3D, 5000 strands of 24 links (125000 points, mean length 0.144, on a sphere of "
            "radius 0.1), 121 frames at 30 fps (4 s, 7 keyframes, smooth), method tractrix, 1 "
            "sub-step, recording 61 frames (every 2) as float32");

  const GroomScenario grass = LoadGroomFile(Example("groom_grass_2d.json"));
  EXPECT_EQ(grass.dim, 2);
  EXPECT_EQ(grass.strands.size(), 12u);
  std::set<Eigen::Index> links;
  for (const Points& p : grass.strands) {
    links.insert(p.rows() - 1);
    EXPECT_EQ(p(0, 1), 0.0);  // rooted on the ground
  }
  EXPECT_EQ(*links.begin(), 3);
  EXPECT_EQ(*links.rbegin(), 8);
  EXPECT_EQ(grass.motion.num_frames(), 91);
  EXPECT_EQ(grass.options.method, Method::kFollowTheLeader);
  EXPECT_TRUE(ValidateGroomFile(Example("groom_grass_2d.json")).empty());
  EXPECT_NE(GroomSummary(grass).find("2D, 12 strands of 3 to 8 links"), std::string::npos)
      << GroomSummary(grass);
}

// ---------------------------------------------------------------------------------------------
// Problems

// Every problem of a document, each at its JSON pointer; parsing throws the first.
TEST(GroomValidateTest, ListsEveryProblemAtOnce) {
  const std::string text = R"({
    "colour": 1,
    "groom": {"scalp": {"shape": "ellipsoid", "radii": [1, 0, 1]}, "roots": 0, "links": 2.5,
              "link_lenght": 1, "direction": {"droop": 2, "gravity": [0, 0]},
              "region": {"max_angle_deg": -1}, "seed": -3},
    "motion": {"fps": 0, "interpolation": "cubic", "keyframes": [
      {"time": 1}, {"time": 0.5, "angle_deg": 3}, {"time": 2, "rotation": {"axis": [0, 0, 0],
       "angle_deg": 1}}]},
    "method": "overall", "substeps": 0, "record": {"every": 0, "precision": "half"}})";
  const Problems problems = ValidateGroomText(text);
  const std::vector<std::string> fields = Fields(problems);
  for (const char* expected :
       {"/colour", "/groom/scalp/radii/1", "/groom/roots", "/groom/links", "/groom/link_lenght",
        "/groom/link_length", "/groom/direction/droop", "/groom/direction/gravity",
        "/groom/region/max_angle_deg", "/groom/seed", "/motion/fps", "/motion/interpolation",
        "/motion/keyframes/1/time", "/motion/keyframes/1/angle_deg",
        "/motion/keyframes/2/rotation/axis", "/method", "/substeps", "/record/every",
        "/record/precision"}) {
    EXPECT_NE(std::find(fields.begin(), fields.end(), expected), fields.end())
        << expected << " not in\n"
        << AllText(problems);
  }
  const std::string all = AllText(problems);
  EXPECT_NE(all.find("/groom/link_lenght: unknown key \"link_lenght\"; valid keys here are"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("(did you mean \"link_length\"?)"), std::string::npos) << all;
  EXPECT_NE(all.find("/groom/direction/gravity: value [0,0] has 2 coordinates; expected an array "
                     "of 3 numbers (the scenario is 3D)"),
            std::string::npos)
      << all;
  try {
    ParseGroomText(text);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem().Text(), problems.front().Text());
  }
}

struct BadCase {
  const char* what;
  const char* text;     // the scenario
  const char* pointer;  // expected field of the first problem
  const char* message;  // expected in its message
};
// The case's name in test listings (ctest's names of the parameterized tests).
void PrintTo(const BadCase& c, std::ostream* os) { *os << c.what; }

#define GROOM_OPEN \
  R"({"groom": {"scalp": {"shape": "sphere", "radius": 1}, "roots": 3, "links": 2,)"
#define GROOM \
  R"("groom": {"scalp": {"shape": "sphere", "radius": 1}, "roots": 3, "links": 2, "link_length": 0.1})"
#define MOTION R"("motion": {"keyframes": [{"time": 0}]})"
#define MOTION_OPEN R"("motion": {"keyframes": [{"time": 0}],)"
#define KEYS R"({)" GROOM R"(, "motion": {"keyframes": [)"
#define KEYS_2D R"({"strands": [{"points": [[0, 0], [0, 1]]}], "motion": {"keyframes": [)"
#define STRANDS R"({"strands": [{"points": [[0, 0, 0], [0, 0, 1]]}, )"

const BadCase kBadCases[] = {
    {"root not an object", "[1]", "", "(an array) is not valid; expected an object"},
    {"not JSON", "{\"groom\": ", "", ": invalid JSON: "},
    {"neither groom nor strands", "{" MOTION "}", "/groom", "missing; expected an object"},
    {"both groom and strands",
     "{" GROOM R"(, "strands": [{"points": [[0, 0], [1, 0]]}], )" MOTION "}", "/strands",
     "not both"},
    {"missing motion", "{" GROOM "}", "/motion", "missing; expected an object"},
    {"unknown key", "{" GROOM "," MOTION R"(, "metod": "ftl"})", "/metod",
     "(did you mean \"method\"?)"},
    {"name not a string", "{" GROOM "," MOTION R"(, "name": 3})", "/name",
     "value 3 (a number) is not valid; expected a string"},
    // The groom.
    {"groom not an object", R"({"groom": [], )" MOTION "}", "/groom",
     "value [] (an array) is not valid; expected an object"},
    {"missing scalp", R"({"groom": {"roots": 3, "links": 2, "link_length": 1}, )" MOTION "}",
     "/groom/scalp", "missing; expected an object"},
    {"scalp shape",
     R"({"groom": {"scalp": {"shape": "cube", "radius": 1}, "roots": 3, "links": 2, "link_length": 1}, )" MOTION
     "}",
     "/groom/scalp/shape", R"(value "cube" is not valid; expected one of "sphere" or "ellipsoid")"},
    {"scalp without shape",
     R"({"groom": {"scalp": {"radius": 1}, "roots": 3, "links": 2, "link_length": 1}, )" MOTION "}",
     "/groom/scalp/shape", "missing; expected \"sphere\" or \"ellipsoid\""},
    {"sphere radius zero",
     R"({"groom": {"scalp": {"shape": "sphere", "radius": 0}, "roots": 3, "links": 2, "link_length": 1}, )" MOTION
     "}",
     "/groom/scalp/radius", "value 0 is not valid; expected a finite number > 0"},
    {"sphere without radius",
     R"({"groom": {"scalp": {"shape": "sphere"}, "roots": 3, "links": 2, "link_length": 1}, )" MOTION
     "}",
     "/groom/scalp/radius", "missing; expected a finite number > 0"},
    {"sphere given radii",
     R"({"groom": {"scalp": {"shape": "sphere", "radius": 1, "radii": [1, 1, 1]}, "roots": 3, "links": 2, "link_length": 1}, )" MOTION
     "}",
     "/groom/scalp/radii",
     "unknown key \"radii\"; valid keys here are \"shape\", \"center\" or \"radius\""},
    {"ellipsoid radius zero",
     R"({"groom": {"scalp": {"shape": "ellipsoid", "radii": [1, 0, 1]}, "roots": 3, "links": 2, "link_length": 1}, )" MOTION
     "}",
     "/groom/scalp/radii/1", "value 0 is not valid; expected a finite number > 0"},
    {"ellipsoid two radii",
     R"({"groom": {"scalp": {"shape": "ellipsoid", "radii": [1, 1]}, "roots": 3, "links": 2, "link_length": 1}, )" MOTION
     "}",
     "/groom/scalp/radii",
     "has 2 coordinates; expected an array of 3 numbers (the scenario is 3D)"},
    {"ellipsoid given radius",
     R"({"groom": {"scalp": {"shape": "ellipsoid", "radius": 1, "radii": [1, 1, 1]}, "roots": 3, "links": 2, "link_length": 1}, )" MOTION
     "}",
     "/groom/scalp/radius", "unknown key \"radius\""},
    {"planar center",
     R"({"groom": {"scalp": {"shape": "sphere", "radius": 1, "center": [0, 0]}, "roots": 3, "links": 2, "link_length": 1}, )" MOTION
     "}",
     "/groom/scalp/center", "expected an array of 3 numbers (the scenario is 3D)"},
    {"roots zero",
     R"({"groom": {"scalp": {"shape": "sphere", "radius": 1}, "roots": 0, "links": 2, "link_length": 1}, )" MOTION
     "}",
     "/groom/roots", "value 0 is not valid; expected an integer >= 1"},
    {"roots too many",
     R"({"groom": {"scalp": {"shape": "sphere", "radius": 1}, "roots": 10000001, "links": 2, "link_length": 1}, )" MOTION
     "}",
     "/groom/roots", "expected an integer from 1 to 10000000"},
    {"roots not an integer",
     R"({"groom": {"scalp": {"shape": "sphere", "radius": 1}, "roots": 5.5, "links": 2, "link_length": 1}, )" MOTION
     "}",
     "/groom/roots", "value 5.5 is not valid; expected an integer from 1 to"},
    {"too many points",
     R"({"groom": {"scalp": {"shape": "sphere", "radius": 1}, "roots": 10000000, "links": 100, "link_length": 1}, )" MOTION
     "}",
     "/groom/roots", "makes 1010000000 points; expected roots x (links + 1) <= 200000000"},
    {"missing roots",
     R"({"groom": {"scalp": {"shape": "sphere", "radius": 1}, "links": 2, "link_length": 1}, )" MOTION
     "}",
     "/groom/roots", "missing; expected an integer >= 1"},
    {"links zero",
     R"({"groom": {"scalp": {"shape": "sphere", "radius": 1}, "roots": 2, "links": 0, "link_length": 1}, )" MOTION
     "}",
     "/groom/links", "value 0 is not valid; expected an integer >= 1"},
    {"link length zero", GROOM_OPEN R"( "link_length": 0}, )" MOTION "}", "/groom/link_length",
     "value 0 is not valid; expected a finite number > 0"},
    {"link length missing", GROOM_OPEN R"( "seed": 1}, )" MOTION "}", "/groom/link_length",
     "missing; expected a finite number > 0"},
    {"length variation 1", GROOM_OPEN R"( "link_length": 1, "length_variation": 1}, )" MOTION "}",
     "/groom/length_variation", "value 1 is not valid; expected a number >= 0 and < 1"},
    {"length variation negative",
     GROOM_OPEN R"( "link_length": 1, "length_variation": -0.1}, )" MOTION "}",
     "/groom/length_variation", "value -0.1 is not valid; expected a number >= 0 and < 1"},
    {"droop above 1", GROOM_OPEN R"( "link_length": 1, "direction": {"droop": 1.5}}, )" MOTION "}",
     "/groom/direction/droop", "value 1.5 is not valid; expected a number from 0 to 1"},
    {"droop a string",
     GROOM_OPEN R"( "link_length": 1, "direction": {"droop": "0.5"}}, )" MOTION "}",
     "/groom/direction/droop", "value \"0.5\" (a string) is not valid"},
    {"gravity zero",
     GROOM_OPEN R"( "link_length": 1, "direction": {"gravity": [0, 0, 0]}}, )" MOTION "}",
     "/groom/direction/gravity", "is zero; expected a non-zero vector"},
    {"direction key", GROOM_OPEN R"( "link_length": 1, "direction": {"drop": 0.5}}, )" MOTION "}",
     "/groom/direction/drop", "(did you mean \"droop\"?)"},
    {"region axis zero",
     GROOM_OPEN R"( "link_length": 1, "region": {"axis": [0, 0, 0]}}, )" MOTION "}",
     "/groom/region/axis", "is zero; expected a non-zero vector"},
    {"region angle zero",
     GROOM_OPEN R"( "link_length": 1, "region": {"max_angle_deg": 0}}, )" MOTION "}",
     "/groom/region/max_angle_deg", "value 0 is not valid; expected a finite number > 0"},
    {"region angle above 180",
     GROOM_OPEN R"( "link_length": 1, "region": {"max_angle_deg": 181}}, )" MOTION "}",
     "/groom/region/max_angle_deg", "value 181 is not valid; expected a number > 0 and <= 180"},
    {"region too small",
     GROOM_OPEN R"( "link_length": 1, "region": {"max_angle_deg": 0.01}}, )" MOTION "}",
     "/groom/region", "expected a region covering at least about 1/10000 of the scalp"},
    {"region not an object", GROOM_OPEN R"( "link_length": 1, "region": 90}, )" MOTION "}",
     "/groom/region", "value 90 (a number) is not valid; expected an object"},
    {"seed negative", GROOM_OPEN R"( "link_length": 1, "seed": -1}, )" MOTION "}", "/groom/seed",
     "value -1 is not valid; expected an integer >= 0"},
    {"seed fraction", GROOM_OPEN R"( "link_length": 1, "seed": 0.5}, )" MOTION "}", "/groom/seed",
     "value 0.5 is not valid; expected an integer from 0 to 9007199254740992"},
    // Explicit strands.
    {"strands not an array", R"({"strands": {"points": []}, )" MOTION "}", "/strands",
     "(an object) is not valid; expected an array of at least 1 strand"},
    {"no strands", R"({"strands": [], )" MOTION "}", "/strands", "has 0 strands"},
    {"strand without points", R"({"strands": [{"pts": [[0, 0], [1, 0]]}], )" MOTION "}",
     "/strands/0/pts", "unknown key \"pts\""},
    {"strand of one point", STRANDS R"({"points": [[0, 0, 0]]}], )" MOTION "}", "/strands/1/points",
     "has 1 point; expected an array of at least 2 points"},
    {"strands of two dimensions", STRANDS R"({"points": [[0, 0], [0, 1]]}], )" MOTION "}",
     "/strands/1/points/0",
     "has 2 coordinates; expected an array of 3 numbers (the scenario is 3D)"},
    {"point of four coordinates",
     R"({"strands": [{"points": [[0, 0, 0, 0], [0, 1, 0, 0]]}], )" MOTION "}",
     "/strands/0/points/0", "has 4 coordinates; expected an array of 2 or 3 numbers"},
    {"zero-length link", STRANDS R"({"points": [[0, 0, 0], [0, 0, 1], [0, 0, 1]]}], )" MOTION "}",
     "/strands/1/points/2", "link 2 has length 0 (points 1 and 2)"},
    {"coordinate a string", STRANDS R"({"points": [[0, 0, 0], [0, "1", 1]]}], )" MOTION "}",
     "/strands/1/points/1/1", "value \"1\" (a string) is not valid; expected a finite number"},
    // The motion.
    {"motion not an object", "{" GROOM R"(, "motion": []})", "/motion",
     "(an array) is not valid; expected an object"},
    {"fps zero", "{" GROOM "," MOTION_OPEN R"( "fps": 0}})", "/motion/fps",
     "value 0 is not valid; expected a finite number > 0"},
    {"fps a string", "{" GROOM "," MOTION_OPEN R"( "fps": "30"}})", "/motion/fps",
     "value \"30\" (a string) is not valid; expected a finite number > 0"},
    {"too many frames",
     "{" GROOM R"(, "motion": {"fps": 1e7, "keyframes": [{"time": 0}, {"time": 10}]}})",
     "/motion/fps", "makes 100000001 frames; expected at most 10000000 frames"},
    {"interpolation", "{" GROOM "," MOTION_OPEN R"( "interpolation": "cubic"}})",
     "/motion/interpolation", R"(expected one of "smooth" or "linear")"},
    {"missing keyframes", "{" GROOM R"(, "motion": {"fps": 30}})", "/motion/keyframes",
     "missing; expected an array of at least 1 keyframe"},
    {"no keyframes", "{" GROOM R"(, "motion": {"keyframes": []}})", "/motion/keyframes",
     "has 0 keyframes; expected an array of at least 1 keyframe"},
    {"keyframe without time", KEYS R"({"translation": [0, 0, 0]}]}})", "/motion/keyframes/0/time",
     "missing; expected a finite number (seconds)"},
    {"keyframe not an object", KEYS R"(0]}})", "/motion/keyframes/0",
     "value 0 (a number) is not valid; expected an object"},
    {"times decrease", KEYS R"({"time": 0}, {"time": 2}, {"time": 1}]}})",
     "/motion/keyframes/2/time",
     "value 1 is not above 2, the time of /motion/keyframes/1/time; expected keyframe times that "
     "increase strictly"},
    {"times repeat", KEYS R"({"time": 0}, {"time": 0}]}})", "/motion/keyframes/1/time",
     "value 0 is not above 0, the time of /motion/keyframes/0/time"},
    {"translation of 2 in 3D", KEYS R"({"time": 0, "translation": [1, 2]}]}})",
     "/motion/keyframes/0/translation",
     "has 2 coordinates; expected an array of 3 numbers (the scenario is 3D)"},
    {"translation of 3 in 2D", KEYS_2D R"({"time": 0, "translation": [1, 2, 3]}]}})",
     "/motion/keyframes/0/translation",
     "has 3 coordinates; expected an array of 2 numbers (the scenario is 2D)"},
    {"rotation in 2D", KEYS_2D R"({"time": 0, "rotation": {"quaternion": [1, 0, 0, 0]}}]}})",
     "/motion/keyframes/0/rotation",
     "is only valid in 3D scenarios; a 2D keyframe turns about z by \"angle_deg\""},
    {"angle in 3D", KEYS R"({"time": 0, "angle_deg": 30}]}})", "/motion/keyframes/0/angle_deg",
     "is only valid in 2D scenarios; a 3D keyframe turns by \"rotation\""},
    {"angle a string in 2D", KEYS_2D R"({"time": 0, "angle_deg": "30"}]}})",
     "/motion/keyframes/0/angle_deg", "value \"30\" (a string) is not valid"},
    {"rotation axis zero",
     KEYS R"({"time": 0, "rotation": {"axis": [0, 0, 0], "angle_deg": 1}}]}})",
     "/motion/keyframes/0/rotation/axis", "is zero; expected a non-zero vector"},
    {"rotation without angle", KEYS R"({"time": 0, "rotation": {"axis": [0, 0, 1]}}]}})",
     "/motion/keyframes/0/rotation/angle_deg", "missing; expected a finite number (degrees)"},
    {"rotation without axis", KEYS R"({"time": 0, "rotation": {"angle_deg": 1}}]}})",
     "/motion/keyframes/0/rotation/axis", "missing; expected an array of 3 numbers"},
    {"quaternion zero", KEYS R"({"time": 0, "rotation": {"quaternion": [0, 0, 0, 0]}}]}})",
     "/motion/keyframes/0/rotation/quaternion",
     "value [0,0,0,0] is not valid; expected an array of 4 numbers [w, x, y, z], not all zero"},
    {"quaternion of 3", KEYS R"({"time": 0, "rotation": {"quaternion": [1, 0, 0]}}]}})",
     "/motion/keyframes/0/rotation/quaternion", "has 3 numbers; expected an array of 4 numbers"},
    {"quaternion and axis",
     KEYS R"({"time": 0, "rotation": {"quaternion": [1, 0, 0, 0], "axis": [0, 0, 1]}}]}})",
     "/motion/keyframes/0/rotation/axis", "is not valid with \"quaternion\""},
    {"rotation key", KEYS R"({"time": 0, "rotation": {"axes": [0, 0, 1], "angle_deg": 1}}]}})",
     "/motion/keyframes/0/rotation/axes", "(did you mean \"axis\"?)"},
    {"rotation not an object", KEYS R"({"time": 0, "rotation": 30}]}})",
     "/motion/keyframes/0/rotation", "value 30 (a number) is not valid; expected an object"},
    // The options.
    {"method not for strands", "{" GROOM "," MOTION R"(, "method": "overall"})", "/method",
     R"(value "overall" is not valid; expected "tractrix" or "ftl")"},
    {"method unknown", "{" GROOM "," MOTION R"(, "method": "tractrx"})", "/method",
     R"(unknown method "tractrx"; expected "tractrix" or "ftl" (did you mean "tractrix"?))"},
    {"substeps zero", "{" GROOM "," MOTION R"(, "substeps": 0})", "/substeps",
     "value 0 is not valid; expected an integer >= 1"},
    {"pinned zero", "{" GROOM "," MOTION R"(, "pinned": 0})", "/pinned",
     "value 0 is not valid; expected an integer >= 1"},
    {"threads negative", "{" GROOM "," MOTION R"(, "threads": -1})", "/threads",
     "value -1 is not valid; expected an integer >= 0"},
    {"threads too many", "{" GROOM "," MOTION R"(, "threads": 2000})", "/threads",
     "expected an integer from 0 to 1024"},
    {"record every zero", "{" GROOM "," MOTION R"(, "record": {"every": 0}})", "/record/every",
     "value 0 is not valid; expected an integer >= 1"},
    {"record precision", "{" GROOM "," MOTION R"(, "record": {"precision": "float16"}})",
     "/record/precision", R"(unknown precision "float16"; expected "float32" or "float64")"},
    {"record key", "{" GROOM "," MOTION R"(, "record": {"evrey": 2}})", "/record/evrey",
     "(did you mean \"every\"?)"},
};

class BadGroomTest : public testing::TestWithParam<BadCase> {};

TEST_P(BadGroomTest, FirstProblemNamesTheField) {
  const BadCase& c = GetParam();
  const Problems problems = ValidateGroomText(c.text);
  ASSERT_FALSE(problems.empty()) << "accepted: " << c.text;
  EXPECT_EQ(problems.front().field, c.pointer) << AllText(problems);
  EXPECT_NE(problems.front().message.find(c.message), std::string::npos) << AllText(problems);
  try {
    ParseGroomText(c.text);
    FAIL() << "accepted: " << c.text;
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem().Text(), problems.front().Text());
  }
}

INSTANTIATE_TEST_SUITE_P(Groom, BadGroomTest, testing::ValuesIn(kBadCases),
                         [](const testing::TestParamInfo<BadCase>& info) {
                           std::string name = info.param.what;
                           for (char& ch : name) ch = std::isalnum(ch) ? ch : '_';
                           return name;
                         });

// A fresh directory, removed with its files at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::string pattern =
        (std::filesystem::temp_directory_path() / "flexkin_groom_XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string operator/(const std::string& name) const { return path_ + "/" + name; }
  void Write(const std::string& name, const std::string& text) const {
    std::ofstream(*this / name) << text;
  }

 private:
  std::string path_;
};

// Files: the problems of their text, by pointer (a front end prefixes the path, as for chain and
// robot scenarios); a file that cannot be read is a system error naming it.
TEST(GroomFileTest, FilesAgreeWithTheirTextAndNameTheMissingFile) {
  TempDir dir;
  json doc = SphereDoc();
  doc["groom"]["roots"] = 0;
  doc["motion"]["fps"] = -1;
  dir.Write("bad.json", doc.dump());
  const Problems from_file = ValidateGroomFile(dir / "bad.json");
  const Problems from_text = ValidateGroomText(doc.dump());
  ASSERT_EQ(from_file.size(), 2u) << AllText(from_file);
  ASSERT_EQ(from_file.size(), from_text.size());
  for (size_t i = 0; i < from_file.size(); ++i) EXPECT_EQ(from_file[i].Text(), from_text[i].Text());
  EXPECT_EQ(from_file[0].field, "/groom/roots");
  EXPECT_EQ(from_file[1].field, "/motion/fps");
  try {
    LoadGroomFile(dir / "bad.json");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem().Text(), from_text[0].Text());
  }
  dir.Write("not_json.json", "{\"groom\": [1,");
  const Problems syntax = ValidateGroomFile(dir / "not_json.json");
  ASSERT_EQ(syntax.size(), 1u);
  EXPECT_EQ(syntax[0].message.rfind("line 1, column ", 0), 0u) << syntax[0].message;

  const std::string missing = dir / "missing.json";
  for (const auto& load : {+[](const std::string& p) { LoadGroomFile(p); },
                           +[](const std::string& p) { ValidateGroomFile(p); }}) {
    try {
      load(missing);
      ADD_FAILURE() << "no error";
    } catch (const std::system_error& e) {
      EXPECT_EQ(e.code(), std::errc::no_such_file_or_directory);
      EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
    }
  }
  dir.Write("good.json", SphereDoc().dump());
  EXPECT_EQ(LoadGroomFile(dir / "good.json").strands, ParseGroomText(SphereDoc().dump()).strands);
}

// ---------------------------------------------------------------------------------------------
// The schema

// The keys the reader accepts at `pointer` of `doc`.
std::set<std::string> AcceptedKeys(const json& doc, const std::string& pointer) {
  return test_util::AcceptedKeys(doc, pointer,
                                 [](const std::string& text) { return ValidateGroomText(text); });
}
using test_util::SchemaKeys;

// docs/schema/groom.schema.json lists exactly the keys the parser accepts, everywhere.
TEST(GroomSchemaTest, SchemaAndParserAcceptTheSameKeys) {
  const json schema =
      ReadJsonFile(std::string(FLEXKIN_SOURCE_DIR) + "/docs/schema/groom.schema.json");
  EXPECT_EQ(schema["$schema"], "https://json-schema.org/draft/2020-12/schema");
  const json& defs = schema["$defs"];
  json doc = SphereDoc();
  doc["groom"]["region"] = json::object();
  doc["groom"]["direction"] = json::object();
  doc["record"] = json::object();
  doc["motion"]["keyframes"][0]["rotation"] = {{"axis", {0, 0, 1}}, {"angle_deg", 0}};
  EXPECT_EQ(AcceptedKeys(doc, ""), SchemaKeys(schema));
  const json& groom = schema["properties"]["groom"];
  EXPECT_EQ(AcceptedKeys(doc, "/groom"), SchemaKeys(groom));
  EXPECT_EQ(AcceptedKeys(doc, "/groom/region"), SchemaKeys(groom["properties"]["region"]));
  EXPECT_EQ(AcceptedKeys(doc, "/groom/direction"), SchemaKeys(groom["properties"]["direction"]));
  EXPECT_EQ(AcceptedKeys(doc, "/record"), SchemaKeys(schema["properties"]["record"]));
  EXPECT_EQ(AcceptedKeys(doc, "/motion"), SchemaKeys(schema["properties"]["motion"]));
  EXPECT_EQ(AcceptedKeys(doc, "/motion/keyframes/0"), SchemaKeys(defs["keyframe"]));
  EXPECT_EQ(AcceptedKeys(doc, "/motion/keyframes/0/rotation"), SchemaKeys(defs["rotation"]));
  // The scalp: one branch of the schema per shape.
  for (const json& branch : groom["properties"]["scalp"]["oneOf"]) {
    const std::string shape = branch["properties"]["shape"]["const"];
    doc["groom"]["scalp"] = {{"shape", shape}};
    EXPECT_EQ(AcceptedKeys(doc, "/groom/scalp"), SchemaKeys(branch)) << shape;
  }
  const json strands = Strands2dDoc();
  EXPECT_EQ(AcceptedKeys(strands, "/strands/0"),
            SchemaKeys(schema["properties"]["strands"]["items"]));
  // The enums are the parser's choices.
  EXPECT_EQ(schema["properties"]["method"]["enum"], json({"tractrix", "ftl"}));
  EXPECT_EQ(schema["properties"]["record"]["properties"]["precision"]["enum"],
            json({"float32", "float64"}));
  EXPECT_EQ(schema["properties"]["motion"]["properties"]["interpolation"]["enum"],
            json({"smooth", "linear"}));
  EXPECT_EQ(groom["properties"]["roots"]["maximum"], kMaxGroomRoots);
}

// ---------------------------------------------------------------------------------------------
// Growing strands

GrowSpec EllipsoidSpec(int roots) {
  GrowSpec spec;
  spec.scalp.shape = "ellipsoid";
  spec.scalp.center = Eigen::Vector3d(0.5, -1, 2);
  spec.scalp.radii = Eigen::Vector3d(0.1, 0.15, 0.25);
  spec.roots = roots;
  spec.links = 6;
  spec.link_length = 0.01;
  return spec;
}

// The outward unit normal of the ellipsoid at p: the gradient of sum ((p - c) / r)^2.
Eigen::Vector3d EllipsoidNormal(const ScalpShape& s, const Eigen::Vector3d& p) {
  return (p - s.center).cwiseQuotient(s.radii.cwiseProduct(s.radii)).normalized();
}

TEST(GrowTest, RootsLieOnTheSurfaceWithinTheRegion) {
  GrowSpec spec = EllipsoidSpec(3000);
  spec.region_axis = Eigen::Vector3d(1, 1, 0);
  spec.max_angle_deg = 70;
  const std::vector<Points> strands = GrowStrands(spec);
  ASSERT_EQ(strands.size(), 3000u);
  const Eigen::Vector3d axis = spec.region_axis.normalized();
  double largest_angle = 0.0;
  for (const Points& p : strands) {
    const Eigen::Vector3d root = p.row(0).transpose();
    const double level = (root - spec.scalp.center).cwiseQuotient(spec.scalp.radii).squaredNorm();
    EXPECT_NEAR(level, 1.0, 1e-12);
    const double angle =
        std::acos(std::clamp(EllipsoidNormal(spec.scalp, root).dot(axis), -1.0, 1.0)) * 180 / kPi;
    EXPECT_LE(angle, 70 + 1e-9);
    largest_angle = std::max(largest_angle, angle);
  }
  EXPECT_GT(largest_angle, 69.0);  // the region is filled up to its edge
}

// The fraction of N roots in a zone of the surface against the zone's share of the area, within
// 5 standard deviations of the binomial count.
void ExpectFraction(int in_zone, int n, double area_fraction, const std::string& what) {
  const double sigma = std::sqrt(area_fraction * (1 - area_fraction) / n);
  EXPECT_NEAR(double(in_zone) / n, area_fraction, 5 * sigma) << what;
}

TEST(GrowTest, RootsAreUniformByArea) {
  constexpr int kN = 200000;
  // A sphere: a zone between two heights has area in proportion to its height (Archimedes); in the
  // cap within 90 degrees of +z, the zone z in [0, r/2] is half of it.
  GrowSpec sphere;
  sphere.scalp.shape = "sphere";
  sphere.scalp.radii = Eigen::Vector3d::Constant(2.0);
  sphere.roots = kN;
  sphere.links = 1;
  sphere.max_angle_deg = 90;
  int low = 0;
  for (const Points& p : GrowStrands(sphere)) {
    ASSERT_GE(p(0, 2), -1e-12);
    low += p(0, 2) < 1.0;
  }
  ExpectFraction(low, kN, 0.5, "sphere cap, z < r/2");

  // A triaxial ellipsoid: the area of {z > c/2} and of {x > a/2}, by integrating the area element
  // |dp/dtheta x dp/dphi| of p = (a sin t cos f, b sin t sin f, c cos t) on a fine grid.
  GrowSpec spec = EllipsoidSpec(kN);
  spec.links = 1;
  const Eigen::Vector3d r = spec.scalp.radii;
  double total = 0, top = 0, side = 0;
  const int nt = 1000, nf = 2000;
  for (int i = 0; i < nt; ++i) {
    const double t = kPi * (i + 0.5) / nt;
    for (int j = 0; j < nf; ++j) {
      const double f = 2 * kPi * (j + 0.5) / nf;
      const Eigen::Vector3d dt(r[0] * std::cos(t) * std::cos(f), r[1] * std::cos(t) * std::sin(f),
                               -r[2] * std::sin(t));
      const Eigen::Vector3d df(-r[0] * std::sin(t) * std::sin(f), r[1] * std::sin(t) * std::cos(f),
                               0);
      const double area = dt.cross(df).norm();
      total += area;
      if (std::cos(t) > 0.5) top += area;
      if (std::sin(t) * std::cos(f) > 0.5) side += area;
    }
  }
  int in_top = 0, in_side = 0;
  for (const Points& p : GrowStrands(spec)) {
    const Eigen::Vector3d q = (p.row(0).transpose() - spec.scalp.center).cwiseQuotient(r);
    in_top += q[2] > 0.5;
    in_side += q[0] > 0.5;
  }
  ExpectFraction(in_top, kN, top / total, "ellipsoid, z > c/2");
  ExpectFraction(in_side, kN, side / total, "ellipsoid, x > a/2");
  // Sampling the parameter sphere uniformly without the area test would be off by far more.
  EXPECT_GT(std::fabs(top / total - 0.25), 10 * std::sqrt(0.25 * 0.75 / kN));
}

// The documented method, step by step: std::mt19937_64 (fixed by the standard: its 10000th
// output from the default seed is 9981545732273789042), bits to doubles by (x >> 11) * 2^-53, a
// point uniform in the cube kept inside the ball, then one number for the length.
TEST(GrowTest, TheSameSeedGivesTheSameBitsByTheDocumentedMethod) {
  std::mt19937_64 reference;
  reference.discard(9999);
  EXPECT_EQ(reference(), 9981545732273789042ull);

  GrowSpec spec;
  spec.scalp.shape = "sphere";
  spec.scalp.radii = Eigen::Vector3d::Constant(0.5);
  spec.scalp.center = Eigen::Vector3d(1, 2, 3);
  spec.roots = 50;
  spec.links = 3;
  spec.link_length = 0.1;
  spec.length_variation = 0.3;
  spec.seed = 7;
  const std::vector<Points> a = GrowStrands(spec), b = GrowStrands(spec);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(std::memcmp(a[i].data(), b[i].data(), sizeof(double) * a[i].size()), 0) << i;
  }
  std::mt19937_64 generator(7);
  const auto uniform = [&generator] { return double(generator() >> 11) * 0x1p-53; };
  for (int i = 0; i < 50; ++i) {
    Eigen::Vector3d u;
    for (;;) {
      // One statement each: the order of a call's arguments is unspecified.
      u.x() = 2 * uniform() - 1;
      u.y() = 2 * uniform() - 1;
      u.z() = 2 * uniform() - 1;
      const double r2 = u.squaredNorm();
      if (r2 > 0 && r2 <= 1) {
        u /= std::sqrt(r2);
        break;
      }
    }
    const double length = 0.1 * (1 + 0.3 * (2 * uniform() - 1));
    const Eigen::Vector3d root = spec.scalp.center + 0.5 * u;
    EXPECT_EQ(Eigen::Vector3d(a[i].row(0).transpose()), root) << i;
    EXPECT_NEAR((a[i].row(1) - a[i].row(0)).norm(), length, 4e-15) << i;
  }
  spec.seed = 8;
  const std::vector<Points> c = GrowStrands(spec);
  int same = 0;
  for (size_t i = 0; i < a.size(); ++i) same += a[i] == c[i];
  EXPECT_EQ(same, 0);
}

TEST(GrowTest, LinkLengthsAreAsSpecified) {
  GrowSpec spec = EllipsoidSpec(2000);
  spec.droop = 0.7;
  spec.links = 10;
  spec.link_length = 0.02;
  for (const Points& p : GrowStrands(spec)) {
    for (int j = 1; j <= spec.links; ++j) {
      // Points about 2 from the origin: differences carry rounding of about 4e-16.
      EXPECT_NEAR((p.row(j) - p.row(j - 1)).norm(), 0.02, 2e-15);
    }
  }
  spec.length_variation = 0.25;
  double shortest = 1, longest = 0;
  for (const Points& p : GrowStrands(spec)) {
    const double first = (p.row(1) - p.row(0)).norm();
    for (int j = 2; j <= spec.links; ++j) {
      EXPECT_NEAR((p.row(j) - p.row(j - 1)).norm(), first, 4e-15);
    }
    EXPECT_GE(first, 0.02 * 0.75 - 4e-15);
    EXPECT_LE(first, 0.02 * 1.25 + 4e-15);
    shortest = std::min(shortest, first);
    longest = std::max(longest, first);
  }
  // 2000 uniform draws reach within 0.5% of either end of the range.
  EXPECT_LT(shortest, 0.02 * 0.76);
  EXPECT_GT(longest, 0.02 * 1.24);
}

TEST(GrowTest, DroopZeroGrowsAlongTheNormalAndDroopOneEndsAlongGravity) {
  GrowSpec spec = EllipsoidSpec(500);
  spec.gravity = Eigen::Vector3d(0.3, 0, -1);
  const Eigen::Vector3d g = spec.gravity.normalized();
  for (const Points& p : GrowStrands(spec)) {
    const Eigen::Vector3d root = p.row(0).transpose();
    const Eigen::Vector3d n = EllipsoidNormal(spec.scalp, root);
    for (int j = 1; j <= spec.links; ++j) {
      const Eigen::Vector3d q = p.row(j).transpose();
      EXPECT_LT((q - root - (q - root).dot(n) * n).norm(), 4e-15);  // on the normal's line
      EXPECT_NEAR((q - root).dot(n), j * 0.01, 4e-15);              // outward
    }
  }
  spec.droop = 1;
  for (const Points& p : GrowStrands(spec)) {
    const Eigen::Vector3d root = p.row(0).transpose();
    const Eigen::Vector3d n = EllipsoidNormal(spec.scalp, root);
    const Eigen::Vector3d last = (p.row(6) - p.row(5)).transpose().normalized();
    EXPECT_LT((last - g).norm(), 1e-12);
    // Each link turns by the same angle, angle(n, g) / links, in the plane of n and g.
    const double step = std::acos(std::clamp(n.dot(g), -1.0, 1.0)) / 6;
    Eigen::Vector3d previous = n;
    for (int j = 1; j <= 6; ++j) {
      const Eigen::Vector3d d = (p.row(j) - p.row(j - 1)).transpose().normalized();
      EXPECT_NEAR(std::acos(std::clamp(d.dot(previous), -1.0, 1.0)), step, 1e-7);
      EXPECT_NEAR(d.dot(n.cross(g).normalized()), 0, 1e-12);
      previous = d;
    }
  }
  // Half the droop: the last link halfway between the normal and gravity.
  spec.droop = 0.5;
  for (const Points& p : GrowStrands(spec)) {
    const Eigen::Vector3d n = EllipsoidNormal(spec.scalp, p.row(0).transpose());
    const Eigen::Vector3d last = (p.row(6) - p.row(5)).transpose().normalized();
    const double half = std::acos(std::clamp(n.dot(g), -1.0, 1.0)) / 2;
    EXPECT_NEAR(std::acos(std::clamp(last.dot(n), -1.0, 1.0)), half, 1e-7);
    EXPECT_NEAR(std::acos(std::clamp(last.dot(g), -1.0, 1.0)), half, 1e-7);
  }
}

// Gravity straight against a root's normal: the strand turns in the plane of the normal and the
// coordinate axis least aligned with it, and with droop 1 still ends along gravity.
TEST(GrowTest, GravityAgainstTheNormalTurnsTowardAFixedAxis) {
  GrowSpec spec;
  spec.scalp.shape = "sphere";
  spec.scalp.radii = Eigen::Vector3d::Ones();
  spec.roots = 3;
  spec.links = 8;
  spec.link_length = 0.1;
  spec.droop = 1;
  const Eigen::Vector3d n = GrowStrands(spec)[0].row(0).transpose().normalized();
  spec.gravity = -n;  // the roots do not depend on gravity
  const Points p = GrowStrands(spec)[0];
  EXPECT_LT((Eigen::Vector3d(p.row(0).transpose()) - n).norm(), 1e-15);
  int k = 0;  // the axis least aligned with n
  for (int i = 1; i < 3; ++i) k = std::fabs(n[i]) < std::fabs(n[k]) ? i : k;
  const Eigen::Vector3d side =
      (Eigen::Vector3d::Unit(k) - n[k] * n).normalized();  // perpendicular to n
  // Link 4 of 8 has turned by a quarter turn: along `side`; the last one along gravity.
  const Eigen::Vector3d quarter = (p.row(4) - p.row(3)).transpose().normalized();
  EXPECT_LT((quarter - side).norm(), 1e-9) << quarter.transpose() << " vs " << side.transpose();
  const Eigen::Vector3d last = (p.row(8) - p.row(7)).transpose().normalized();
  EXPECT_LT((last + n).norm(), 1e-9);
  for (int j = 1; j <= 8; ++j) {
    EXPECT_NEAR((p.row(j) - p.row(0)).dot(n.cross(side)), 0, 1e-14);  // in the plane
  }
}

// The strands of the examples go into the strand engine as they are, in 2D and 3D, and keep their
// link lengths over the keyframed motion.
TEST(GroomExampleTest, ExamplesStepThroughTheStrandEngine) {
  for (const char* name : {"groom_head.json", "groom_grass_2d.json"}) {
    const GroomScenario s = LoadGroomFile(Example(name));
    StrandOptions options = s.options;
    options.threads = 1;
    const size_t count = std::min<size_t>(s.strands.size(), 200);  // the head's first 200
    const std::vector<Points> strands(s.strands.begin(), s.strands.begin() + count);
    StrandBatch batch(strands, options);  // body coordinates: at the identity pose
    EXPECT_EQ(batch.dim(), s.dim) << name;
    const int64_t frames = s.motion.num_frames();
    for (int64_t f = 0; f < frames; ++f) StepStrands(&batch, s.motion.PoseAt(f));
    const BodyPose end = s.motion.PoseAt(frames - 1);
    for (size_t i = 0; i < strands.size(); ++i) {
      const Points now = batch.strand(static_cast<int>(i));
      const Eigen::VectorXd root =
          (end.rotation.topLeftCorner(s.dim, s.dim) * strands[i].row(0).transpose() +
           end.translation.head(s.dim));
      EXPECT_LT((now.row(0).transpose() - root).norm(), 1e-12) << name << " strand " << i;
      for (Eigen::Index j = 1; j < now.rows(); ++j) {
        const double rest = (strands[i].row(j) - strands[i].row(j - 1)).norm();
        EXPECT_NEAR((now.row(j) - now.row(j - 1)).norm(), rest, 1e-9 * rest) << name << " " << i;
      }
    }
  }
}

TEST(GrowTest, InvalidSpecsAndTinyRegionsAreRefused) {
  GrowSpec spec = EllipsoidSpec(10);
  spec.scalp.shape = "sphere";  // with unequal radii
  spec.links = 0;
  spec.droop = -1;
  spec.gravity.setZero();
  const Problems problems = ValidateGrowSpec(spec);
  EXPECT_EQ(Fields(problems),
            std::vector<std::string>({"scalp.radii", "links", "droop", "gravity"}))
      << AllText(problems);
  EXPECT_THROW(GrowStrands(spec), InputError);

  spec = EllipsoidSpec(10);
  spec.max_angle_deg = 0.05;
  try {
    GrowStrands(spec);
    FAIL() << "grew";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "region");
  }
  EXPECT_TRUE(ValidateGrowSpec(EllipsoidSpec(10)).empty());
}

// ---------------------------------------------------------------------------------------------
// Motion

BodyKeyframe Keyframe(double time, const Eigen::Vector3d& translation, const Eigen::Vector3d& axis,
                      double angle) {
  const Eigen::Quaterniond q(Eigen::AngleAxisd(angle, axis.normalized()));
  return {time, BodyPose::FromQuaternion(q.w(), q.x(), q.y(), q.z(), translation)};
}

// The rotation angle and axis taking a to b.
Eigen::AngleAxisd Turn(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b);
}

TEST(MotionTest, FrameCountsAndTimes) {
  BodyMotion m;
  EXPECT_EQ(m.num_frames(), 0);
  m.keyframes = {{2.5, {}}};
  EXPECT_EQ(m.num_frames(), 1);
  EXPECT_EQ(m.TimeOf(0), 2.5);
  EXPECT_EQ(m.TimeOf(5), 2.5);
  m.keyframes = {{0, {}}, {1, {}}};
  EXPECT_EQ(m.num_frames(), 31);
  EXPECT_EQ(m.TimeOf(15), 0.5);
  EXPECT_EQ(m.TimeOf(30), 1.0);
  EXPECT_EQ(m.TimeOf(31), 1.0);  // clamped
  m.keyframes = {{0, {}}, {1.05, {}}};
  m.fps = 10;
  EXPECT_EQ(m.num_frames(), 11);  // a part frame at the end is not one
  // (1.4 - 1.1) * 10 is 2.9999999999999982, short of 3: the 1e-9 counts frame 3 (at 1.4).
  m.keyframes = {{1.1, {}}, {1.4, {}}};
  ASSERT_LT((1.4 - 1.1) * 10, 3.0);
  EXPECT_EQ(m.num_frames(), 4);
  EXPECT_NEAR(m.TimeOf(2), 1.3, 1e-15);
  EXPECT_EQ(m.TimeOf(3), 1.4);  // 1.1 + 0.3 rounds above 1.4: clamped
  m.fps = 1e-3;
  EXPECT_EQ(m.num_frames(), 1);
}

TEST(MotionTest, PassesThroughEveryKeyframe) {
  BodyMotion m;
  m.fps = 4;
  m.keyframes = {Keyframe(0, {1, 2, 3}, {1, 2, 3}, 0.3), Keyframe(0.5, {0, 0, 1}, {0, 1, 0}, -2),
                 Keyframe(1.25, {0, 0, 0}, {1, 0, 0}, 3), Keyframe(2, {4, 0, 0}, {1, 1, 1}, 1)};
  // Frames 0, 2, 5 and 8 are at the keyframes' times.
  const int frames[] = {0, 2, 5, 8};
  for (int k = 0; k < 4; ++k) {
    const BodyPose pose = m.PoseAt(frames[k]);
    EXPECT_EQ(pose.rotation, m.keyframes[k].pose.rotation) << k;
    EXPECT_EQ(pose.translation, m.keyframes[k].pose.translation) << k;
  }
  for (const auto interpolation :
       {KeyframeInterpolation::kSmooth, KeyframeInterpolation::kLinear}) {
    m.interpolation = interpolation;
    for (int f = 0; f <= 8; ++f) {
      const Eigen::Matrix3d r = m.PoseAt(f).rotation;
      EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-14) << f;
      EXPECT_NEAR(r.determinant(), 1, 1e-14) << f;
    }
  }
  // A planar motion's keyframes are the planar poses.
  BodyMotion planar;
  planar.keyframes = {{0, BodyPose::Planar(0.4, 1, 2)}, {1, BodyPose::Planar(-0.4, 3, 2)}};
  EXPECT_EQ(planar.PoseAt(30).rotation, BodyPose::Planar(-0.4, 3, 2).rotation);
  const BodyPose middle = planar.PoseAt(15);
  EXPECT_LT((middle.rotation - Eigen::Matrix3d::Identity()).norm(), 1e-15);
  EXPECT_LT((middle.translation - Eigen::Vector3d(2, 2, 0)).norm(), 1e-15);
}

TEST(MotionTest, SlerpTurnsHalfTheAngleAtTheMiddleAlongTheShorterArc) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 3).normalized();
  for (const auto interpolation :
       {KeyframeInterpolation::kSmooth, KeyframeInterpolation::kLinear}) {
    BodyMotion m;
    m.interpolation = interpolation;
    m.fps = 2;
    m.keyframes = {Keyframe(0, {0, 0, 0}, axis, 0.2), Keyframe(1, {2, 4, 6}, axis, 0.2 + 2.0)};
    const BodyPose middle = m.PoseAt(1);
    const Eigen::AngleAxisd turn = Turn(m.keyframes[0].pose.rotation, middle.rotation);
    EXPECT_NEAR(turn.angle(), 1.0, 1e-12);
    EXPECT_LT((turn.axis() - axis).norm(), 1e-12);
    EXPECT_LT((middle.translation - Eigen::Vector3d(1, 2, 3)).norm(), 1e-15);
    // From 10 to 350 degrees about z: the shorter way, through 0 (360).
    m.keyframes = {Keyframe(0, {0, 0, 0}, {0, 0, 1}, 10 * kPi / 180),
                   Keyframe(1, {0, 0, 0}, {0, 0, 1}, 350 * kPi / 180)};
    const Eigen::AngleAxisd at_middle(m.PoseAt(1).rotation);
    EXPECT_NEAR(at_middle.angle(), 0, 1e-12);
    const Eigen::AngleAxisd quarter(m.keyframes[0].pose.rotation.transpose() *
                                    m.PoseAt(1).rotation);
    EXPECT_NEAR(quarter.angle(), 10 * kPi / 180, 1e-12);
    EXPECT_NEAR(quarter.axis().z(), -1, 1e-12);
  }
}

TEST(MotionTest, SmoothRestsAtKeyframesAndLinearDoesNot) {
  const double fps = 1000;  // frames of 1 ms: finite differences
  BodyMotion m;
  m.fps = fps;
  m.keyframes = {Keyframe(0, {0, 0, 0}, {0, 0, 1}, 0), Keyframe(1, {1, 0, 0}, {0, 0, 1}, 1),
                 Keyframe(2, {1, 1, 0}, {0, 1, 0}, 0.5)};
  // Speed (translation per second, rotation angle per second) over the frame from `frame`.
  const auto speeds = [&m, fps](int64_t from, int64_t to) {
    const BodyPose a = m.PoseAt(from), b = m.PoseAt(to);
    return std::pair<double, double>{(b.translation - a.translation).norm() * fps,
                                     Turn(a.rotation, b.rotation).angle() * fps};
  };
  m.interpolation = KeyframeInterpolation::kSmooth;
  for (const auto& [from, to] :
       {std::pair<int, int>{0, 1}, {999, 1000}, {1000, 1001}, {1999, 2000}}) {
    const auto [move, turn] = speeds(from, to);
    EXPECT_LT(move, 0.005) << from;  // 3 h |dT| = 0.003 at most
    EXPECT_LT(turn, 0.005) << from;
  }
  // In the middle of a segment smooth moves 1.5 times as fast as linear.
  EXPECT_NEAR(speeds(500, 501).first, 1.5, 1e-5);
  m.interpolation = KeyframeInterpolation::kLinear;
  for (const auto& [from, to] : {std::pair<int, int>{0, 1}, {999, 1000}, {1000, 1001}}) {
    const auto [move, turn] = speeds(from, to);
    EXPECT_NEAR(move, 1.0, 1e-9) << from;
  }
  EXPECT_NEAR(speeds(0, 1).second, 1.0, 1e-9);
  EXPECT_NEAR(speeds(500, 501).first, 1.0, 1e-9);
}

}  // namespace
}  // namespace flexkin
