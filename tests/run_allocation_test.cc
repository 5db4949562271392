// Run's loop allocates nothing per sub-step and nothing per leader step that is not recorded: the
// number of heap allocations of a run does not grow with the sub-steps or the unrecorded steps
// (the overall method's workspace and every buffer are sized once). Counted by replacing the
// global operator new of this test program.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "flexkin/run.h"
#include "scenes/scenes.h"

namespace {
std::atomic<long> allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  ++allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace flexkin {
namespace {

// Counts the frames without keeping them.
class CountingSink : public FrameSink {
 public:
  void Add(int64_t, const PointsRef&, const VectorRef&) override { ++frames; }
  int frames = 0;
};

// Allocations of one run of the paper's parabola pulled `steps` leader steps of 0.05 along
// (1, 1) / sqrt 2, with `substeps` sub-steps each, recording only the first and last frames.
long AllocationsOfRun(Method method, int steps, int substeps, int record_every = 1 << 20,
                      bool link_angles = true) {
  const Chain chain = scenes::PaperParabola();
  const Points targets = scenes::StraightPull(
      chain.points.row(0).transpose(), Eigen::Vector2d(1.0, 1.0).normalized(), 0.05 * steps, steps);
  RunOptions options;
  options.method = method;
  options.substeps = substeps;
  options.record_every = record_every;
  options.link_angles = link_angles;
  CountingSink sink;
  const long before = allocations.load();
  const RunResult result = Run(chain, targets, options, &sink);
  const long count = allocations.load() - before;
  EXPECT_EQ(sink.frames, record_every == 1 ? steps + 1 : 2);
  EXPECT_LE(result.metrics.max_relative_length_error, 1e-12);
  return count;
}

TEST(RunAllocation, NothingPerSubstep) {
  for (const Method method : {Method::kTractrix, Method::kFollowTheLeader, Method::kOverall}) {
    const long one = AllocationsOfRun(method, 10, 1);
    const long many = AllocationsOfRun(method, 10, 40);
    EXPECT_EQ(many, one) << MethodName(method) << ": " << one << " allocations with 1 sub-step, "
                         << many << " with 40";
  }
}

TEST(RunAllocation, NothingPerUnrecordedLeaderStep) {
  for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
    const long few = AllocationsOfRun(method, 10, 4);
    const long more = AllocationsOfRun(method, 200, 4);
    EXPECT_EQ(more, few) << MethodName(method) << ": " << few << " allocations for 10 leader "
                         << "steps, " << more << " for 200";
  }
}

// A recorded frame costs a copy into a buffer the run keeps (and its link angles, computed into
// a vector sized once): recording 200 frames allocates no more than recording 40.
TEST(RunAllocation, NothingPerRecordedFrame) {
  for (const Method method : {Method::kTractrix, Method::kFollowTheLeader}) {
    for (const bool link_angles : {true, false}) {
      const long few = AllocationsOfRun(method, 40, 1, 1, link_angles);
      const long more = AllocationsOfRun(method, 200, 1, 1, link_angles);
      EXPECT_EQ(more, few) << MethodName(method) << (link_angles ? " with" : " without")
                           << " link angles: " << few << " allocations for 40 recorded frames, "
                           << more << " for 200";
    }
  }
}

}  // namespace
}  // namespace flexkin
