// Triangle-mesh colliders (flexkin/colliders.h kMesh, world/mesh_collider.h, docs/colliders.md
// "Meshes"): signed distances and segment clearances against the test's own brute force over
// every triangle (the side by the generalized winding number, not the pseudo-normals the library
// uses); a 12-triangle box mesh moves a chain as the box does; a tessellated capsule keeps every
// link of a dragged chain outside; a U-shaped mesh's least motion lies in its slot; meshes read
// from STL and OBJ files through a scenario, round-trip through result files, and every bad
// mesh is refused by JSON pointer; strands take a mesh collider.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "flexkin/any_scenario.h"
#include "flexkin/colliders.h"
#include "flexkin/curves.h"
#include "flexkin/result_io.h"
#include "flexkin/run.h"
#include "flexkin/strands.h"
#include "mesh_test_util.h"
#include "world/contact.h"

namespace flexkin {
namespace {

using Eigen::Vector3d;

using namespace mesh_test;  // NOLINT(build/namespaces): the tests' meshes and brute force

TestMesh UShape() {
  // Cells x in 0..2, z in 0..2, y in 0..4: a bar along the bottom (z = 0) and two arms (x = 0
  // and x = 2) up to z = 3, leaving the slot 1 < x < 2, z > 1, open along y and upward.
  std::vector<std::array<int, 3>> cells;
  for (int y = 0; y < 5; ++y) {
    for (int x = 0; x < 3; ++x) cells.push_back({x, y, 0});
    for (int z = 1; z < 3; ++z) {
      cells.push_back({0, y, z});
      cells.push_back({2, y, z});
    }
  }
  return Voxels(cells, 1.0, Vector3d::Zero());
}

Eigen::Isometry3d SomePose() {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  pose.translation() = Vector3d(0.3, -1.2, 0.8);
  return pose;
}

TEST(MeshColliderTest, SignedDistanceIsTheBruteForceOverEveryTriangle) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const std::vector<std::pair<const char*, Collider>> cases = {
      {"U", MeshCollider(UShape(), SomePose(), 0.5)},
      {"capsule", MeshCollider(CapsuleMesh(0.5, 0.4, 24, 6), SomePose(), 1.3)},
  };
  for (const auto& [name, c] : cases) {
    const World w = Placed(c);
    Vector3d lo = Vector3d::Constant(HUGE_VAL), hi = -lo;
    for (const auto& t : w.triangles) {
      for (const Vector3d& v : t) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
    }
    const Vector3d mid = 0.5 * (lo + hi), half = 0.8 * (hi - lo);
    int inside = 0;
    for (int i = 0; i < 1500; ++i) {
      const Vector3d p = mid + half.cwiseProduct(Vector3d(unit(rng), unit(rng), unit(rng)));
      const SurfaceQuery q = QuerySurface(c, p);
      const double expected = BruteSigned(w, p);
      ASSERT_NEAR(q.distance, expected, 1e-12) << name << " at " << p.transpose();
      inside += expected < 0.0;
      // The nearest point is on the surface, at that distance, and the normal points out.
      double on = HUGE_VAL;
      for (const auto& t : w.triangles) on = std::min(on, PointTriangle(q.nearest, t));
      EXPECT_LT(on, 1e-12) << name;
      EXPECT_NEAR((p - q.nearest).norm(), std::fabs(expected), 1e-12) << name;
      EXPECT_NEAR(q.normal.norm(), 1.0, 1e-12);
      if (std::fabs(expected) > 1e-6) {
        EXPECT_GT(BruteSigned(w, q.nearest + 1e-6 * q.normal), 0.0) << name;
      }
    }
    EXPECT_GT(inside, 40) << name << ": the sample must reach inside";
  }
}

TEST(MeshColliderTest, SegmentClearanceHasTheExactSignAndTheBruteForceDistance) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Collider c = MeshCollider(UShape(), SomePose(), 0.5);
  const World w = Placed(c);
  const Vector3d center = c.pose * Vector3d(0.75, 1.25, 0.75);
  int negative = 0, positive = 0;
  for (int i = 0; i < 300; ++i) {
    const Vector3d a = center + 1.6 * Vector3d(unit(rng), unit(rng), unit(rng));
    const Vector3d b = a + 0.8 * Vector3d(unit(rng), unit(rng), unit(rng));
    const double clearance = internal::SegmentClearance(c, a, b);
    // Inside anywhere along it (1,001 points, by the winding number)?
    bool enters = false;
    for (int s = 0; s <= 1000 && !enters; ++s)
      enters = Winding(w, a + (s / 1000.0) * (b - a)) > 0.5;
    if (enters) {
      EXPECT_LT(clearance, 0.0) << a.transpose() << " -> " << b.transpose();
      ++negative;
    } else {
      EXPECT_GE(clearance, -1e-12);
      EXPECT_NEAR(clearance, BruteSegmentDistance(w, a, b), 1e-12)
          << a.transpose() << " -> " << b.transpose();
      ++positive;
    }
  }
  EXPECT_GT(negative, 30);
  EXPECT_GT(positive, 30);
  // A segment crossing the thin wall of an arm, both ends outside: negative.
  const Vector3d a = c.pose * (0.5 * Vector3d(-0.5, 2.5, 2.5)),
                 b = c.pose * (0.5 * Vector3d(1.5, 2.5, 2.5));
  EXPECT_LT(internal::SegmentClearance(c, a, b), -0.2);
  // Grown by a margin: the clearance less the margin.
  Collider grown = c;
  grown.margin = 0.01;
  const Vector3d p = c.pose * (0.5 * Vector3d(1.5, 2.5, 2.0)),
                 q = c.pose * (0.5 * Vector3d(1.5, 2.5, 4.0));
  EXPECT_NEAR(internal::SegmentClearance(grown, p, q), internal::SegmentClearance(c, p, q) - 0.01,
              1e-15);
  EXPECT_NEAR(QuerySurface(grown, p).distance, QuerySurface(c, p).distance - 0.01, 1e-15);
}

// A 3D chain hanging along -y from the origin, its leading end pulled along `path`.
struct Drag {
  Chain chain;
  Points path;
};

Drag DragOver(int links, double link_length, int steps, const Vector3d& to) {
  Drag d;
  LineDef line;
  line.start = Vector3d::Zero();
  line.direction = Vector3d(0.0, -1.0, 0.0);
  line.links = links;
  line.link_length = link_length;
  d.chain = MakeChain(MakeLine(line));
  d.path.resize(steps, 3);
  for (int s = 0; s < steps; ++s) d.path.row(s) = ((s + 1.0) / steps) * to.transpose();
  return d;
}

TEST(MeshColliderTest, ABoxMeshMovesAChainAsTheBoxDoes) {
  // A chain along -y dragged along +x: its links sweep into a box standing beside it.
  const Drag drag = DragOver(24, 0.1, 60, Vector3d(3.0, 0.0, 0.0));
  Collider box;
  box.shape = ColliderShape::kBox;
  box.extents = Vector3d(0.08, 0.08, 0.5);
  box.pose.translation() = Vector3d(0.25, -0.25, 0.05);
  box.pose.linear() = Eigen::AngleAxisd(0.3, Vector3d::UnitZ()).toRotationMatrix();
  // The same box as 12 triangles.
  const Collider mesh = BoxMesh(box.extents, box.pose);
  RunOptions options;
  options.method = Method::kTractrix;
  options.substeps = 2;
  options.colliders = {box};
  const RunResult a = flexkin::Run(drag.chain, drag.path, options);
  options.colliders = {mesh};
  const RunResult b = flexkin::Run(drag.chain, drag.path, options);
  EXPECT_GT(a.contacts.contact_link_steps, 30);
  EXPECT_EQ(a.contacts.contact_link_steps, b.contacts.contact_link_steps);
  ASSERT_EQ(a.frames.size(), b.frames.size());
  double worst = 0.0;
  for (size_t f = 0; f < a.frames.size(); ++f) {
    worst = std::max(worst, (a.frames[f].points - b.frames[f].points).cwiseAbs().maxCoeff());
  }
  // The two searches bisect the same boundary (the mesh's march only brackets it first) and the
  // clearances agree to rounding; the direction of departure is the minimum of the exit angle,
  // found to about 1e-10 (docs/colliders.md), where that function is flat, so that rounding moves
  // it: the points agree to 2e-8 (measured 4.2e-9, links of 0.1).
  EXPECT_LT(worst, 2e-8) << "largest difference of a point";
  std::printf("box mesh vs box: largest difference of a point %.3g\n", worst);
  EXPECT_GE(b.contacts.least_clearance, -1e-12);
}

double SampledClearance(const Collider& c, const Vector3d& a, const Vector3d& b, int samples) {
  double least = HUGE_VAL;
  for (int i = 0; i <= samples; ++i) {
    least =
        std::min(least, QuerySurface(c, a + (static_cast<double>(i) / samples) * (b - a)).distance);
  }
  return least;
}

TEST(MeshColliderTest, NoLinkEntersATessellatedCapsuleAndLengthsAreKept) {
  // A chain along -y dragged along +x past a post (a capsule along z, 240 triangles) standing in
  // its way: without the post it cuts through it.
  const Drag drag = DragOver(20, 0.1, 50, Vector3d(3.0, 0.0, 0.0));
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Vector3d(0.22, -0.22, 0.1);
  pose.linear() = Eigen::AngleAxisd(0.2, Vector3d::UnitX()).toRotationMatrix();
  const Collider post = MeshCollider(CapsuleMesh(0.1, 0.5, 20, 5), pose);
  for (Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
    RunOptions options;
    options.method = method;
    options.substeps = 3;
    options.colliders = {post};
    const RunResult result = flexkin::Run(drag.chain, drag.path, options);
    EXPECT_GT(result.contacts.contact_link_steps, 20) << NameOf(method);
    // The run measures its links with SegmentClearance, whose depths are sampled at other
    // points than the contact search's test: a hair beyond the slack (1e-13 of a link) can show
    // (measured 1.5e-13); the issue's bound is 1e-12.
    EXPECT_GE(result.contacts.least_clearance, -1e-12);
    EXPECT_LE(result.metrics.max_relative_length_error, 1e-13) << NameOf(method);
    double least = HUGE_VAL;
    for (const Frame& frame : result.frames) {
      for (Eigen::Index i = 1; i < frame.points.rows(); ++i) {
        const Vector3d a = frame.points.row(i - 1).transpose(), b = frame.points.row(i).transpose();
        least = std::min(least, SampledClearance(post, a, b, 500) / drag.chain.lengths[i - 1]);
        EXPECT_NEAR((a - b).norm(), drag.chain.lengths[i - 1], 1e-13);
      }
    }
    EXPECT_GE(least, -1e-12) << NameOf(method);
    EXPECT_LT(least, 1e-3) << NameOf(method) << ": the chain must touch the post";
    options.colliders.clear();
    const RunResult free = flexkin::Run(drag.chain, drag.path, options);
    double free_least = HUGE_VAL;
    for (const Frame& frame : free.frames) {
      for (Eigen::Index i = 0; i < frame.points.rows(); ++i) {
        free_least =
            std::min(free_least, QuerySurface(post, frame.points.row(i).transpose()).distance);
      }
    }
    EXPECT_LT(free_least, -0.02) << "the scene must push the free chain into the post";
  }
}

TEST(MeshColliderTest, TheLeastMotionIsInTheConcavity) {
  // Head above the U's slot (1 < x < 2, open along y), the old tail straight down in the bar:
  // the link of length 1.8 reaches the slot's floor (z = 1) when it leans by
  // acos(1.5 / 1.8) along y, within the slot; leaning along x meets an arm sooner.
  const Collider u = MeshCollider(UShape());
  const Vector3d head(1.5, 2.5, 2.5), tail(1.5, 2.5, 0.5);
  const double length = 1.8, c = 1.5 / 1.8, s = std::sqrt(1.0 - c * c);
  Vector3d x;
  ASSERT_TRUE(internal::ContactTail(3, head, tail, length, {u}, &x));
  const Vector3d up = head + length * Vector3d(0.0, s, -c),
                 down = head + length * Vector3d(0.0, -s, -c);
  const double error = std::min((x - up).norm(), (x - down).norm());
  EXPECT_LT(error, 1e-6) << x.transpose();
  EXPECT_GT(x.x(), 1.0);
  EXPECT_LT(x.x(), 2.0);
  EXPECT_GE(internal::SegmentClearance(u, head, x), -1e-13 * length);
  // No clear direction on a grid of the cap about the old direction is nearer the old tail.
  const double best = (x - tail).norm();
  for (int i = 1; i <= 20; ++i) {
    const double theta = std::acos(c) * i / 20.0;
    for (int j = 0; j < 72; ++j) {
      const double psi = 2.0 * M_PI * j / 72;
      const Vector3d d(std::sin(theta) * std::cos(psi), std::sin(theta) * std::sin(psi),
                       -std::cos(theta));
      const Vector3d y = head + length * d;
      if ((y - tail).norm() < best - 1e-9) {
        EXPECT_LT(SampledClearance(u, head, y, 400), 0.0) << theta << " " << psi;
      }
    }
  }
}

// ---- Files: STL and OBJ through a scenario; result files; bad input. ----

std::string Stl(const TestMesh& m) {
  std::ostringstream out;
  out.precision(17);
  out << "solid test\n";
  for (Eigen::Index f = 0; f < m.triangles.rows(); ++f) {
    out << " facet normal 0 0 0\n  outer loop\n";
    for (int k = 0; k < 3; ++k) {
      const auto v = m.vertices.row(m.triangles(f, k));
      out << "   vertex " << v[0] << " " << v[1] << " " << v[2] << "\n";
    }
    out << "  endloop\n endfacet\n";
  }
  out << "endsolid test\n";
  return out.str();
}

std::string Obj(const TestMesh& m) {
  std::ostringstream out;
  out.precision(17);
  for (Eigen::Index i = 0; i < m.vertices.rows(); ++i) {
    out << "v " << m.vertices(i, 0) << " " << m.vertices(i, 1) << " " << m.vertices(i, 2) << "\n";
  }
  for (Eigen::Index f = 0; f < m.triangles.rows(); ++f) {
    out << "f " << m.triangles(f, 0) + 1 << " " << m.triangles(f, 1) + 1 << " "
        << m.triangles(f, 2) + 1 << "\n";
  }
  return out.str();
}

struct TempDir {
  std::filesystem::path path;
  TempDir() {
    path = std::filesystem::temp_directory_path() /
           ("flexkin_mesh_test_" + std::to_string(std::random_device()()));
    std::filesystem::create_directories(path);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
  std::string Write(const std::string& name, const std::string& text) const {
    std::ofstream(path / name) << text;
    return (path / name).string();
  }
};

std::string Scenario(const std::string& colliders, int dim = 3) {
  const std::string start = dim == 3 ? "[3, 0, 0]" : "[3, 0]";
  const std::string pull = dim == 3 ? "[0.1, 0, 0]" : "[0.1, 0]";
  return R"({"curve": {"shape": "line", "start": )" + start + R"(, "direction": )" +
         (dim == 3 ? std::string("[0, -1, 0]") : std::string("[0, -1]")) +
         R"(, "links": 5, "link_length": 0.1}, "leader": {"pull": )" + pull +
         R"(, "steps": 3}, "colliders": )" + colliders + "}";
}

TEST(MeshColliderTest, MeshFilesAreReadFromTheScenariosDirectory) {
  TempDir dir;
  const TestMesh u = UShape();
  dir.Write("u.stl", Stl(u));
  dir.Write("u.obj", Obj(u));
  for (const char* file : {"u.stl", "u.obj"}) {
    const std::string path = dir.Write(
        "scenario.json",
        Scenario(std::string(R"([{"shape": "mesh", "file": ")") + file +
                 R"(", "scale": 0.5, "position": [0, 1, 2], "rotation": [0, 0, 0, 1]}])"));
    const AnyScenario s = ReadScenarioFile(path);
    ASSERT_TRUE(s.problems.empty()) << s.problems.front().Text();
    const Collider& c = s.chain->options.colliders.at(0);
    ASSERT_EQ(c.shape, ColliderShape::kMesh);
    EXPECT_EQ(c.mesh->file, file);
    EXPECT_EQ(c.mesh->triangles.rows(), u.triangles.rows()) << file;
    EXPECT_EQ(c.mesh->vertices.rows(), u.vertices.rows()) << file << ": vertices joined";
    EXPECT_EQ(c.scale, 0.5);
    // The U's slot floor (1.5, 2.5, 1) scaled and turned half round z, then moved.
    const Vector3d floor = Vector3d(0, 1, 2) + Vector3d(-0.75, -1.25, 0.5);
    EXPECT_NEAR(QuerySurface(c, floor + Vector3d(0, 0, 0.2)).distance, 0.2, 1e-12) << file;
  }
}

TEST(MeshColliderTest, AMeshRoundTripsThroughResultFiles) {
  TempDir dir;
  const std::string scenario = dir.Write(
      "scenario.json", (dir.Write("u.obj", Obj(UShape())),
                        Scenario(R"([{"shape": "mesh", "file": "u.obj", "scale": 0.5}])")));
  const AnyScenario s = ReadScenarioFile(scenario);
  ASSERT_TRUE(s.problems.empty()) << s.problems.front().Text();
  ResultFile file;
  file.dim = 3;
  file.colliders = s.chain->options.colliders;
  file.result = flexkin::Run(s.chain->chain, s.chain->leader_steps, s.chain->options);
  std::filesystem::remove(dir.path / "u.obj");  // the result stands alone
  for (const char* name : {"result.json", "result.npz"}) {
    const std::string out = (dir.path / name).string();
    WriteResultFile(file, out, ResultFileFormatOfPath(out));
    const ResultFile back = ReadResultFile(out);
    ASSERT_EQ(back.colliders.size(), 1u) << name;
    const Collider& a = file.colliders[0];
    const Collider& b = back.colliders[0];
    EXPECT_EQ(b.shape, ColliderShape::kMesh);
    EXPECT_EQ(b.mesh->file, "u.obj");
    EXPECT_EQ(b.scale, a.scale);
    EXPECT_TRUE(b.pose.matrix() == a.pose.matrix());
    EXPECT_TRUE(b.mesh->vertices == a.mesh->vertices) << name;
    EXPECT_TRUE(b.mesh->triangles == a.mesh->triangles) << name;
  }
}

// The problem of the first collider of a scenario with `colliders` (files in `dir`).
Problem RefusalOf(const TempDir& dir, const std::string& colliders, int dim = 3) {
  const AnyScenario s = ReadScenarioFile(dir.Write("bad.json", Scenario(colliders, dim)));
  EXPECT_FALSE(s.problems.empty()) << colliders;
  return s.problems.empty() ? Problem() : s.problems.front();
}

TEST(MeshColliderTest, BadMeshesAreRefusedByPointerWithTheValue) {
  TempDir dir;
  TestMesh cube = Voxels({{0, 0, 0}}, 1.0, Vector3d::Zero());
  const auto mesh = [](const std::string& file, const std::string& more = "") {
    return R"([{"shape": "mesh", "file": ")" + file + "\"" + more + "}]";
  };
  // Missing file: the system's reason.
  Problem p = RefusalOf(dir, mesh("nowhere.stl"));
  EXPECT_EQ(p.field, "/colliders/0/file");
  EXPECT_NE(p.message.find("No such file"), std::string::npos) << p.Text();
  EXPECT_EQ(p.value, "\"nowhere.stl\"");
  // Not a mesh assimp reads.
  dir.Write("junk.stl", "this is not a mesh\n");
  p = RefusalOf(dir, mesh("junk.stl"));
  EXPECT_EQ(p.field, "/colliders/0/file");
  EXPECT_NE(p.message.find("assimp"), std::string::npos) << p.Text();
  // Open: one triangle of the cube left out leaves 3 boundary edges.
  TestMesh open = cube;
  open.triangles.conservativeResize(11, 3);
  dir.Write("open.stl", Stl(open));
  p = RefusalOf(dir, mesh("open.stl"));
  EXPECT_EQ(p.field, "/colliders/0/file");
  EXPECT_NE(p.message.find("open mesh: 3 boundary edges"), std::string::npos) << p.Text();
  EXPECT_NE(p.message.find("e.g. between vertices"), std::string::npos) << p.Text();
  // One triangle turned: its 3 edges run the same way as its neighbours'.
  TestMesh turned = cube;
  std::swap(turned.triangles(4, 1), turned.triangles(4, 2));
  dir.Write("turned.obj", Obj(turned));
  p = RefusalOf(dir, mesh("turned.obj"));
  EXPECT_NE(p.message.find("not consistently oriented: 3 edges"), std::string::npos) << p.Text();
  // A vertex that is not finite (a number beyond a double's range in the file).
  std::string text = Obj(cube);
  text.replace(text.find("v ") + 2, 1, "1e999");
  dir.Write("infinite.obj", text);
  p = RefusalOf(dir, mesh("infinite.obj"));
  EXPECT_EQ(p.field, "/colliders/0/file");
  EXPECT_NE(p.message.find("not finite"), std::string::npos) << p.Text();
  // Empty (inline, as a result file carries a mesh).
  p = RefusalOf(dir, R"([{"shape": "mesh", "vertices": [], "triangles": []}])");
  EXPECT_EQ(p.field, "/colliders/0/vertices");
  EXPECT_NE(p.message.find("empty mesh"), std::string::npos) << p.Text();
  // Scale.
  dir.Write("cube.stl", Stl(cube));
  for (const char* scale : {"0", "-1"}) {
    p = RefusalOf(dir, mesh("cube.stl", std::string(R"(, "scale": )") + scale));
    EXPECT_EQ(p.field, "/colliders/0/scale");
    EXPECT_EQ(p.value, scale);
  }
  // No file.
  p = RefusalOf(dir, R"([{"shape": "mesh"}])");
  EXPECT_EQ(p.field, "/colliders/0/file");
  // 2D.
  p = RefusalOf(dir, mesh("cube.stl"), 2);
  EXPECT_EQ(p.field, "/colliders/0/shape");
  EXPECT_NE(p.message.find("3D"), std::string::npos) << p.Text();
}

TEST(MeshColliderTest, StrandsStayOutsideAMesh) {
  // Strands hanging along -y from roots pulled along +x past a tessellated post.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Vector3d(0.2, -0.2, 0.0);
  const Collider post = MeshCollider(CapsuleMesh(0.08, 0.4, 16, 4), pose);
  std::vector<Points> strands;
  for (int k = 0; k < 3; ++k) {
    Points p(11, 3);
    for (int i = 0; i <= 10; ++i) p.row(i) << 0.0, -0.1 * i, 0.1 * (k - 1);
    strands.push_back(p);
  }
  StrandOptions options;
  options.colliders = {post};
  StrandBatch batch(strands, options);
  double least = HUGE_VAL;
  for (int f = 1; f <= 30; ++f) {
    Points roots(3, 3);
    for (int k = 0; k < 3; ++k) roots.row(k) << 0.05 * f, 0.0, 0.1 * (k - 1);
    StepStrands(&batch, roots);
    for (int k = 0; k < 3; ++k) {
      const Points s = batch.strand(k);
      for (Eigen::Index i = 1; i < s.rows(); ++i) {
        const Vector3d a = s.row(i - 1).transpose(), b = s.row(i).transpose();
        least = std::min(least, SampledClearance(post, a, b, 200) / 0.1);
        EXPECT_NEAR((a - b).norm(), 0.1, 1e-12);
      }
    }
  }
  EXPECT_GE(least, -1e-12);
  EXPECT_LT(least, 1e-3) << "the strands must touch the post";
}

}  // namespace
}  // namespace flexkin
