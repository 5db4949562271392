// Mesh colliders against the shape they tessellate (docs/colliders.md "Meshes", docs/BENCHMARKS.md
// section 18): a 3D tractrix chain of 64 links dragged round a post, the post a capsule
// (closed form) or the same capsule as a mesh of 10,000 triangles (FCL's hierarchy, the contact
// search marching past a non-convex shape), and, for scale, the same run without the post. Time
// per run of 200 leader steps, 2 sub-steps each; counters: the contact link steps and the least
// clearance (relative to a link) of the run. Beside them the other convex shapes of the post's
// size, whose contact steps are searches over the link's directions with the clearance of each
// found by golden-section search along the link: an ellipsoid (semi-axes 0.1, 0.1, 0.6), a
// cylinder (radius 0.1, half length 0.6) and a box (half extents 0.1, 0.1, 0.6).
// Run: build/bench/mesh_colliders_benchmark --benchmark_repetitions=5
//        --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "flexkin/colliders.h"
#include "flexkin/curves.h"
#include "flexkin/run.h"

namespace flexkin {
namespace {

using Eigen::Vector3d;

constexpr int kLinks = 64;
constexpr double kLinkLength = 0.05;
constexpr double kRadius = 0.1, kHalfLength = 0.5;
const Vector3d kPost(0.22, -0.22, 0.0);

// The capsule's surface: a surface of revolution about z, `around` segments round and `half`
// rings per hemisphere; 2 * around * (2 * half) triangles.
std::shared_ptr<const ColliderMeshData> CapsuleMesh(int around, int half) {
  std::vector<std::pair<double, double>> profile;  // (rho, z), top pole to bottom pole
  for (int i = 0; i <= half; ++i) {
    const double a = 0.5 * M_PI * i / half;
    profile.emplace_back(kRadius * std::sin(a), kHalfLength + kRadius * std::cos(a));
  }
  for (int i = half; i >= 0; --i) {
    const double a = 0.5 * M_PI * i / half;
    profile.emplace_back(kRadius * std::sin(a), -kHalfLength - kRadius * std::cos(a));
  }
  const int rings = static_cast<int>(profile.size()) - 2;
  MeshVertices v(2 + rings * around, 3);
  v.row(0) << 0.0, 0.0, profile.front().second;
  v.row(1) << 0.0, 0.0, profile.back().second;
  for (int r = 1; r <= rings; ++r) {
    for (int j = 0; j < around; ++j) {
      const double a = 2.0 * M_PI * j / around;
      v.row(2 + (r - 1) * around + j) << profile[r].first * std::cos(a),
          profile[r].first * std::sin(a), profile[r].second;
    }
  }
  const auto at = [&](int r, int j) { return 2 + (r - 1) * around + (j % around); };
  MeshTriangles t(2 * around * rings, 3);
  int f = 0;
  for (int j = 0; j < around; ++j) {
    t.row(f++) << 0, at(1, j), at(1, j + 1);
    for (int r = 1; r < rings; ++r) {
      t.row(f++) << at(r, j), at(r + 1, j), at(r + 1, j + 1);
      t.row(f++) << at(r, j), at(r + 1, j + 1), at(r, j + 1);
    }
    t.row(f++) << 1, at(rings, j + 1), at(rings, j);
  }
  std::vector<Problem> problems;
  return MakeColliderMesh(std::move(v), std::move(t), "", "post", &problems);
}

// 0: no post; 1: the capsule; 2: the capsule as a 10,000-triangle mesh; 3: an ellipsoid; 4: a
// cylinder; 5: a box.
void BM_ChainRoundAPost(benchmark::State& state) {
  LineDef line;
  line.start = Vector3d::Zero();
  line.direction = Vector3d(0.0, -1.0, 0.0);
  line.links = kLinks;
  line.link_length = kLinkLength;
  const Chain chain = MakeChain(MakeLine(line));
  constexpr int kSteps = 200;
  Points path(kSteps, 3);
  for (int s = 0; s < kSteps; ++s) path.row(s) << 4.0 * (s + 1.0) / kSteps, 0.0, 0.0;
  RunOptions options;
  options.method = Method::kTractrix;
  options.substeps = 2;
  options.record_every = kSteps;
  Collider post;
  post.pose.translation() = kPost;
  if (state.range(0) == 1) {
    post.shape = ColliderShape::kCapsule;
    post.radius = kRadius;
    post.half_length = kHalfLength;
  } else if (state.range(0) == 2) {
    post.shape = ColliderShape::kMesh;
    post.mesh = CapsuleMesh(100, 25);
    state.counters["triangles"] = static_cast<double>(post.mesh->triangles.rows());
  } else if (state.range(0) == 3) {
    post.shape = ColliderShape::kEllipsoid;
    post.extents = Vector3d(kRadius, kRadius, kHalfLength + kRadius);
  } else if (state.range(0) == 4) {
    post.shape = ColliderShape::kCylinder;
    post.radius = kRadius;
    post.half_length = kHalfLength + kRadius;
  } else if (state.range(0) == 5) {
    post.shape = ColliderShape::kBox;
    post.extents = Vector3d(kRadius, kRadius, kHalfLength + kRadius);
  }
  if (state.range(0) > 0) options.colliders = {post};
  RunResult result;
  for (auto _ : state) {
    result = Run(chain, path, options);
    benchmark::DoNotOptimize(result.frames.size());
  }
  state.counters["contact_link_steps"] = static_cast<double>(result.contacts.contact_link_steps);
  state.counters["least_clearance"] = result.contacts.least_clearance;
  constexpr const char* kLabels[] = {"no post", "capsule", "mesh", "ellipsoid", "cylinder", "box"};
  state.SetLabel(kLabels[state.range(0)]);
}
BENCHMARK(BM_ChainRoundAPost)->DenseRange(0, 5)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace flexkin

BENCHMARK_MAIN();
