#include "flexkin/strands.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <new>
#include <string>
#include <thread>
#include <utility>

#include "chain/denormals.h"
#include "chain/simd.h"
#include "chain/substep.h"
#include "sequential/link_rules.h"
#include "sequential/rule_table.h"
#include "sequential/sweep.h"
#include "strands/dynamic_lanes.h"
#include "strands/strand_engine.h"
#include "world/contact.h"

namespace flexkin {
namespace internal {
namespace {

constexpr int L = kStrandLanes;

// 64-byte aligned doubles (the SIMD engines load whole cache lines), zero-initialized.
class AlignedDoubles {
 public:
  AlignedDoubles() = default;
  explicit AlignedDoubles(size_t size) : size_(size) {
    if (size == 0) return;
    const size_t bytes = (size * sizeof(double) + 63) / 64 * 64;
    data_.reset(static_cast<double*>(std::aligned_alloc(64, bytes)));
    if (!data_) throw std::bad_alloc();
    std::fill(data_.get(), data_.get() + size, 0.0);
  }
  double* data() { return data_.get(); }
  const double* data() const { return data_.get(); }
  size_t size() const { return size_; }

 private:
  struct Free {
    void operator()(double* p) const { std::free(p); }
  };
  std::unique_ptr<double, Free> data_;
  size_t size_ = 0;
};

// A fixed set of worker threads that run one job at a time: job(context, t) for every t in
// [0, threads), t = 0 on the calling thread. Waking and waiting allocate nothing.
//
// Frames come back to back in an animation loop, and waking a sleeping thread through the kernel
// costs tens of microseconds on a virtual machine: a few percent of a 0.3 ms frame, twice per
// frame. So a worker that finished its part spins for kSpin before it sleeps, watching for the
// next job, and the caller spins as long waiting for the workers to finish; only then do they
// block on the condition variables. The mutex orders the sleeping side: a job is published
// (generation_) under it, and a thread goes to sleep only after checking under it.
class WorkerPool {
 public:
  explicit WorkerPool(int threads) {
    for (int t = 1; t < threads; ++t) workers_.emplace_back([this, t] { Work(t); });
  }
  ~WorkerPool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_.store(true, std::memory_order_release);
    }
    start_.notify_all();
    for (auto& w : workers_) w.join();
  }
  int threads() const { return static_cast<int>(workers_.size()) + 1; }
  void Run(void (*job)(void*, int), void* context) {
    if (workers_.empty()) {
      job(context, 0);
      return;
    }
    bool wake = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job_ = job;
      context_ = context;
      pending_.store(static_cast<int>(workers_.size()), std::memory_order_relaxed);
      generation_.fetch_add(1, std::memory_order_release);
      wake = sleepers_ > 0;
    }
    if (wake) start_.notify_all();
    job(context, 0);
    if (SpinUntil([this] { return pending_.load(std::memory_order_acquire) == 0; })) return;
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return pending_.load(std::memory_order_acquire) == 0; });
  }

 private:
  static constexpr std::chrono::microseconds kSpin{100};

  // Spins until ready() or kSpin has passed; returns ready().
  template <class Ready>
  static bool SpinUntil(Ready ready) {
    const auto until = std::chrono::steady_clock::now() + kSpin;
    for (int i = 1;; ++i) {
      if (ready()) return true;
      if (i % 64 == 0 && std::chrono::steady_clock::now() > until) return ready();
#if defined(__x86_64__) || defined(__i386__)
      __builtin_ia32_pause();
#endif
    }
  }

  void Work(int t) {
    uint64_t seen = 0;
    for (;;) {
      auto published = [&] {
        return stop_.load(std::memory_order_acquire) ||
               generation_.load(std::memory_order_acquire) != seen;
      };
      void (*job)(void*, int);
      void* context;
      if (!SpinUntil(published)) {
        std::unique_lock<std::mutex> lock(mutex_);
        ++sleepers_;
        start_.wait(lock, published);
        --sleepers_;
      }
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (stop_.load(std::memory_order_relaxed)) return;
        seen = generation_.load(std::memory_order_relaxed);
        job = job_;
        context = context_;
      }
      job(context, t);
      if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) {
        std::lock_guard<std::mutex> lock(mutex_);
        done_.notify_one();
      }
    }
  }
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_, done_;
  std::atomic<uint64_t> generation_{0};
  std::atomic<int> pending_{0};
  std::atomic<bool> stop_{false};
  int sleepers_ = 0;  // workers blocked on start_ (under mutex_)
  void (*job_)(void*, int) = nullptr;
  void* context_ = nullptr;
};

struct Block {
  int n = 0;       // links of every strand of the block
  int pinned = 0;  // points set from the body: min(k, n + 1)
  // How far a free point (and a link's bound test) can reach from the leading end: the most,
  // over the lanes, of the free links' total length and two longest links.
  double reach = 0.0;
  size_t points = 0, lengths = 0, body = 0;  // offsets into the batch's arrays
  int source[L] = {};  // the strand each lane carries (padding lanes repeat the first)
};

ColliderBound BoundOf(const Collider& c) {
  ColliderBound b;
  const Eigen::Vector3d t = c.pose.translation();
  for (int k = 0; k < 3; ++k) b.center[k] = t[k];
  switch (c.shape) {
    case ColliderShape::kHalfSpace: {
      b.half_space = true;
      const Eigen::Vector3d up = c.pose.linear().col(2);
      for (int k = 0; k < 3; ++k) b.up[k] = up[k];
      // The plane raised by the margin.
      for (int k = 0; k < 3; ++k) b.center[k] += c.margin * up[k];
      break;
    }
    default:
      b.exact = c.shape == ColliderShape::kSphere;
      b.radius = BoundingRadius(c);
      break;
  }
  return b;
}

// Per thread: what the contact steps need, made once.
struct ContactScratch {
  std::vector<double> start;    // the leading ends of a block at the frame's start (dim x L)
  std::vector<double> saved;    // a block's points before a sub-step's sweep
  std::vector<double> chain;    // one lane's points, point by point
  std::vector<double> lengths;  // one lane's link lengths and their inverses
  std::vector<double> inv_lengths;
  std::vector<double> least;             // per lane: least relative clearance of the sub-step
  std::vector<int> first_enter;          // per lane: the first link that entered a collider
  std::vector<int> fallback;             // per lane: the first link the lanes' step left
  std::vector<double> clearances;        // per link, bound and lane: the bound's clearance
  std::vector<ColliderBound> active;     // the bounds some lane of a block can come near
  std::vector<int> active_index;         // their colliders' indices
  std::vector<uint8_t> contact_flags;    // per link and lane: the lanes' contact step taken
  StrandSphereFound found;               // the sphere sweep's own check
  std::vector<uint64_t> near;            // per lane: the colliders a link came near (bits)
  std::vector<Collider> near_colliders;  // one lane's near colliders
  ContactStats stats;
  // The contact step that found no room of the lowest-numbered strand this thread stepped (the
  // same whatever the threads and the blocks' order).
  std::string error;
  int error_strand = std::numeric_limits<int>::max();
  void NoteError(int strand, std::string text) {
    if (strand >= error_strand) return;
    error_strand = strand;
    error = std::move(text);
  }
};

// Per thread: what the dynamic sub-steps need, made once (the overall projection's solver state
// made for each sub-chain length when first met).
struct DynamicScratch {
  AlignedDoubles x_old, predicted;  // a block's points at the sub-step's start; the prediction
  std::vector<double> pin_from;     // the pinned points at the frame's start (dim x L each)
  AlignedDoubles work;              // the overall projection's (LeastConstraintWork)
  AlignedDoubles sequential;  // the overall projection's start (with the lanes' contact steps)
  AlignedDoubles shaken;      // SHAKE's projection, while its failed lanes take the overall one
  alignas(64) double converged[kStrandLanes];  // its lanes' outcome
  alignas(64) double ignore[kStrandLanes];     // its lanes not wanted (1)
  alignas(64) double corrected[kStrandLanes];  // its lanes that took the sequential one (1)
  int64_t failures = 0, contact_substeps = 0;
};

}  // namespace

struct StrandBatchImpl {
  StrandOptions options;
  int dim = 0;
  std::vector<int> links;     // per strand
  std::vector<int> block_of;  // per strand
  std::vector<int> lane_of;   // per strand
  std::vector<Block> blocks;
  AlignedDoubles points, lengths, inv_lengths, body;
  std::vector<AlignedDoubles> scratch;  // per thread: the heads of the sub-steps and the target
  // Threads take runs of job_blocks blocks in turn (Job): an eighth of a thread's share, at least
  // 16: short enough that a patch of contacts is shared out, long enough that each thread streams
  // through memory as with one run per thread.
  int job_blocks = 16;
  std::atomic<int> next_job{0};  // the next run a thread takes
  StrandSweepsFn sweeps = StrandSweepsScalar;
  // The SIMD engines' sweep with the contact step against one sphere in the lanes (null: the
  // scalar engine, whose lanes take the contact sweep link by link).
  StrandSphereSweepFn sphere_sweep = nullptr;
  StrandBoundsFn measure_bounds = StrandBoundsScalar;
  // The SIMD engines' check of a sphere after the sweep (null: the scalar engine, which measures
  // it as any bound).
  StrandSphereCheckFn check_sphere = nullptr;
  const char* engine = "scalar";
  std::unique_ptr<WorkerPool> pool;

  // The frame being stepped (read by every thread).
  const BodyPose* pose = nullptr;
  const double* roots = nullptr;
  Eigen::Index roots_stride = 0;

  // Colliders: at every sub-step s (1 .. substeps) of the frame being stepped, all of them
  // placed in the world (placed[s - 1]) and their bounds; the body's pose at each sub-step
  // (body colliders with sub-steps > 1); the pose of the frame before.
  bool has_colliders = false;
  std::vector<std::vector<Collider>> placed;
  std::vector<std::vector<ColliderBound>> bounds;
  std::vector<BodyPose> substep_poses;
  // Per sub-step: the one sphere among the colliders, if there is exactly one (a scalp), for
  // the lanes' own contact step.
  std::vector<char> lone_sphere;
  std::vector<StrandSphere> spheres;
  std::vector<int> sphere_index;  // its index among the colliders
  BodyPose last_pose;
  // The last frame's time and the one being stepped (keyframed world colliders).
  double last_time = 0.0, frame_time = 0.0;
  std::vector<ContactScratch> contact;  // per thread
  StrandContacts contacts;

  // Dynamics (options.dynamics): the velocities (laid out as the points), the points' masses
  // ((n + 1) x L per block, the free points' total 1 per lane), per thread scratch, per block the
  // energy of the last frame, and per frame the pinned points' poses and the wind at each
  // sub-step's start; the overall projection's multipliers (as the masses), where the next
  // sub-step's Newton starts.
  bool dynamic = false;
  AlignedDoubles velocity, mass, multipliers;
  std::vector<size_t> mass_offset;
  std::vector<DynamicScratch> dynamic_scratch;
  std::vector<double> block_energy;
  std::vector<BodyPose> dynamic_poses;
  std::vector<Eigen::Vector3d> winds;
  int64_t substeps_done = 0;
  StrandDynamicFn dynamic_step = StrandDynamicScalar;
  StrandDynamics dynamics_report;
  void StepBlockDynamic(int b, int thread);
  // The pinned points of block b at sub-step s of S, into rows 0 .. pinned - 1 of `pts`.
  void PinnedAt(const Block& block, int s, const double* from, double* pts) const;
  // Before a dynamic frame: the pinned points' poses (`pose` null: roots given as points) and the
  // wind at each sub-step; after it: the energy and the threads' counts.
  void BeginDynamicFrame(const BodyPose* pose);
  void EndDynamicFrame();
  void ContactLane(const Block& block, int lane, int first, int s, DynamicScratch& ds, double* pts,
                   ContactScratch* cs);

  void StepBlock(int b, double* scratch_heads);
  void StepBlockWithColliders(int b, double* scratch_heads, ContactScratch* cs);
  // The pinned points of a block at the frame's end: all but the last into the points, the last
  // (the sweeps' leading end) into `target` (dim x L).
  void PlacePinned(const Block& block, double* pts, double* target) const;
  void PlaceColliders(const BodyPose* pose);
  // Adds the threads' contact counts to `contacts`; throws the first contact step that found no
  // room (InputError "colliders").
  void GatherContacts() {
    std::string error;
    int error_strand = std::numeric_limits<int>::max();
    for (ContactScratch& cs : contact) {
      contacts.contact_link_steps += cs.stats.contact_link_steps;
      contacts.least_clearance = std::min(contacts.least_clearance, cs.stats.least_clearance);
      cs.stats = ContactStats();
      if (cs.error_strand < error_strand) {
        error_strand = cs.error_strand;
        error = cs.error;
      }
      cs.error.clear();
      cs.error_strand = std::numeric_limits<int>::max();
    }
    if (!error.empty()) throw InputError("colliders", error);
  }
  // Each thread takes the next run of job_blocks blocks not yet taken: blocks hold strands rooted
  // near each other (docs/strands.md, "Layout"), so their work comes in patches (the contacts),
  // which one fixed run of blocks per thread would split unevenly. Each block is stepped by one
  // thread from start to end, and what is summed over blocks is summed in block order, so the
  // results are the same whichever thread takes which block.
  static void Job(void* self, int t) {
    auto* impl = static_cast<StrandBatchImpl*>(self);
    const int count = static_cast<int>(impl->blocks.size());
    const int run = impl->job_blocks;
    for (int first = run * impl->next_job.fetch_add(1, std::memory_order_relaxed); first < count;
         first = run * impl->next_job.fetch_add(1, std::memory_order_relaxed)) {
      for (int b = first; b < std::min(first + run, count); ++b) StepBlockOf(impl, b, t);
    }
  }
  static void StepBlockOf(StrandBatchImpl* impl, int b, int t) {
    if (impl->dynamic) {
      impl->StepBlockDynamic(b, t);
    } else if (impl->has_colliders) {
      impl->StepBlockWithColliders(b, impl->scratch[t].data(), &impl->contact[t]);
    } else {
      impl->StepBlock(b, impl->scratch[t].data());
    }
  }
};

namespace {

// Body coordinates of a point at pose (R, t): q = R^T (p - t).
void ToBody(const BodyPose& pose, int dim, const double* p, double* q) {
  double d[3];
  for (int r = 0; r < dim; ++r) d[r] = p[r] - pose.translation[r];
  for (int c = 0; c < dim; ++c) {
    double s = pose.rotation(0, c) * d[0];
    for (int r = 1; r < dim; ++r) s += pose.rotation(r, c) * d[r];
    q[c] = s;
  }
}

// A point at the pose from its body coordinates: p = R q + t, summed in this order.
inline double FromBody(const BodyPose& pose, int dim, int r, const double* body, size_t stride) {
  double s = pose.rotation(r, 0) * body[0];
  for (int c = 1; c < dim; ++c) s += pose.rotation(r, c) * body[c * stride];
  return s + pose.translation[r];
}

}  // namespace

void StrandBatchImpl::PlacePinned(const Block& block, double* pts, double* target) const {
  const int head = block.pinned - 1;
  // From the last pinned point to the root: the root's old position is read before it moves.
  for (int j = block.pinned - 1; j >= 0; --j) {
    for (int k = 0; k < dim; ++k) {
      double* out = j == head ? target + k * L : pts + (j * dim + k) * L;
      for (int lane = 0; lane < L; ++lane) {
        double value;
        if (pose != nullptr) {
          const double* q = body.data() + block.body + (j * dim) * L + lane;
          value = FromBody(*pose, dim, k, q, L);
        } else {
          const double root = roots[block.source[lane] * roots_stride + k];
          // The root goes exactly to its point; the other pinned points translate with it.
          value = j == 0 ? root : pts[(j * dim + k) * L + lane] + (root - pts[k * L + lane]);
        }
        out[lane] = value;
      }
    }
  }
}

// One frame of one block: the pinned points, then the sweeps of the free links.
void StrandBatchImpl::StepBlock(int b, double* scratch_heads) {
  const Block& block = blocks[b];
  const int S = options.substeps;
  const int head = block.pinned - 1;
  double* pts = points.data() + block.points;
  double* target = scratch_heads + static_cast<size_t>(S) * dim * L;  // dim x L
  PlacePinned(block, pts, target);
  // The sub-steps' heads, from the old position of point `head` to its target.
  const double* from = pts + head * dim * L;
  for (int s = 1; s <= S; ++s) {
    for (int k = 0; k < dim; ++k) {
      double* h = scratch_heads + ((s - 1) * dim + k) * L;
      for (int lane = 0; lane < L; ++lane) {
        h[lane] = SubstepHead(from[k * L + lane], target[k * L + lane], s, S);
      }
    }
  }
  const SubnormalsAsZero subnormals;  // as every sweep engine (src/chain/denormals.h)
  sweeps(options.method, dim, block.n, head, S, scratch_heads, lengths.data() + block.lengths,
         inv_lengths.data() + block.lengths, pts);
}

namespace {

// Finds, per lane, the first free link (head + 1 .. n) that enters a collider after a sweep
// (first_enter: n + 1 for none), the colliders some link comes near (near: bit c for collider c;
// all bits from the 64th collider on) and lowers `least` to the relative clearance of the links
// near one. Each link is first
// measured against every collider's bound in a loop over the lanes (the compiler's vector
// code); only links within a link's length of a bound are measured exactly.
template <int Dim>
void LinkBoundsOf(int n, int head, const double* points, const ColliderBound* bounds,
                  int num_bounds, double* clearances) {
  for (int i = head + 1; i <= n; ++i) {
    const double* a = points + (i - 1) * Dim * L;
    const double* b = points + i * Dim * L;
    double* out = clearances + static_cast<size_t>(i - head - 1) * num_bounds * L;
    for (int c = 0; c < num_bounds; ++c) {
      const ColliderBound& bound = bounds[c];
      for (int lane = 0; lane < L; ++lane) {
        double clear;
        if (bound.half_space) {
          double da = 0.0, db = 0.0;
          for (int k = 0; k < Dim; ++k) {
            da += bound.up[k] * (a[k * L + lane] - bound.center[k]);
            db += bound.up[k] * (b[k * L + lane] - bound.center[k]);
          }
          clear = std::min(da, db);
        } else {
          double ab[3], dot = 0.0, ab2 = 0.0;
          for (int k = 0; k < Dim; ++k) {
            ab[k] = b[k * L + lane] - a[k * L + lane];
            dot += ab[k] * (bound.center[k] - a[k * L + lane]);
            ab2 += ab[k] * ab[k];
          }
          const double t = std::clamp(dot / ab2, 0.0, 1.0);
          double d2 = 0.0;
          for (int k = 0; k < Dim; ++k) {
            const double d = a[k * L + lane] + t * ab[k] - bound.center[k];
            d2 += d * d;
          }
          clear = std::sqrt(d2) - bound.radius;
        }
        out[c * L + lane] = clear;
      }
    }
  }
}

// Collider c's bit in a lane's set of near colliders (the 64th and later share all bits: a lane
// near one of them is taken as near every collider).
inline uint64_t ColliderBit(size_t c) { return c < 64 ? uint64_t{1} << c : ~uint64_t{0}; }

void CheckLanes(StrandBoundsFn measure, StrandSphereCheckFn check_sphere,
                const StrandSphereFound* found, int found_collider, int dim, int n, int head,
                double reach, const double* pts, const double* lengths, const double* inv_lengths,
                const std::vector<Collider>& colliders, const std::vector<ColliderBound>& bounds,
                ContactScratch* cs) {
  // A collider whose bound is further than the block's reach from every lane's leading end is
  // far from every link (each link lies within the reach less its length of the leading end):
  // it is not measured.
  cs->active.clear();
  cs->active_index.clear();
  const double* h = pts + static_cast<size_t>(head) * dim * L;
  for (size_t c = 0; c < bounds.size(); ++c) {
    const ColliderBound& bound = bounds[c];
    if (found != nullptr && static_cast<int>(c) == found_collider) {
      // The sweep's own check of its sphere (the same answers as check_sphere's).
      const uint64_t bit = ColliderBit(c);
      for (int lane = 0; lane < L; ++lane) {
        cs->near[lane] |= found->near[lane] ? bit : uint64_t{0};
        cs->first_enter[lane] = std::min(cs->first_enter[lane], found->first_enter[lane]);
        cs->least[lane] = std::min(cs->least[lane], found->least[lane]);
      }
      continue;
    }
    bool near = false;
    for (int lane = 0; lane < L && !near; ++lane) {
      double clear = 0.0;
      if (bound.half_space) {
        for (int k = 0; k < dim; ++k) clear += bound.up[k] * (h[k * L + lane] - bound.center[k]);
      } else {
        double d2 = 0.0;
        for (int k = 0; k < dim; ++k) {
          const double d = h[k * L + lane] - bound.center[k];
          d2 += d * d;
        }
        clear = std::sqrt(d2) - bound.radius;
      }
      near = !(clear > reach);
    }
    if (!near) continue;
    if (check_sphere != nullptr && bound.exact && !bound.half_space) {
      // A sphere: checked in the lanes, its exact clearance only where it can matter.
      uint8_t near_lanes[L];
      check_sphere(dim, n, head, pts, lengths, inv_lengths, bound, kContactSlack, cs->least.data(),
                   cs->first_enter.data(), near_lanes);
      const uint64_t bit = ColliderBit(c);
      for (int lane = 0; lane < L; ++lane) cs->near[lane] |= near_lanes[lane] ? bit : uint64_t{0};
      continue;
    }
    cs->active.push_back(bound);
    cs->active_index.push_back(static_cast<int>(c));
  }
  const int nb = static_cast<int>(cs->active.size());
  if (nb == 0) return;
  double* clearances = cs->clearances.data();
  measure(dim, n, head, pts, cs->active.data(), nb, clearances);
  for (int i = head + 1; i <= n; ++i) {
    const double* a = pts + (i - 1) * dim * L;
    const double* b = pts + i * dim * L;
    const double* len = lengths + (i - 1) * L;
    const double* inv = inv_lengths + (i - 1) * L;
    const double* clear = clearances + static_cast<size_t>(i - head - 1) * nb * L;
    for (int j = 0; j < nb; ++j, clear += L) {
      const ColliderBound& bound = cs->active[j];
      const int c = cs->active_index[j];
      const uint64_t bit = ColliderBit(c);
      if (bound.exact || bound.half_space) {
        // The bound's clearance is the collider's: the same as below with no exact measure, in a
        // loop without branches (the compiler's vector code).
        for (int lane = 0; lane < L; ++lane) {
          const double c_lane = clear[lane];
          const bool near = c_lane < len[lane];
          cs->near[lane] |= near ? bit : uint64_t{0};
          const bool enters = near && c_lane < -kContactSlack * len[lane];
          cs->first_enter[lane] =
              enters ? std::min(cs->first_enter[lane], i) : cs->first_enter[lane];
          cs->least[lane] = near ? std::min(cs->least[lane], c_lane * inv[lane]) : cs->least[lane];
        }
        continue;
      }
      for (int lane = 0; lane < L; ++lane) {
        double c_lane = clear[lane];
        if (c_lane >= len[lane]) continue;  // far: not near this collider
        cs->near[lane] |= bit;
        const Eigen::Vector3d pa(a[lane], a[L + lane], dim == 3 ? a[2 * L + lane] : 0.0);
        const Eigen::Vector3d pb(b[lane], b[L + lane], dim == 3 ? b[2 * L + lane] : 0.0);
        c_lane = SegmentClearance(colliders[c], pa, pb);
        if (c_lane < -kContactSlack * len[lane]) {
          cs->first_enter[lane] = std::min(cs->first_enter[lane], i);
        }
        cs->least[lane] = std::min(cs->least[lane], c_lane * inv[lane]);
      }
    }
  }
}

// Whether a link of the chain `points` (m links, point by point) enters, beyond the slack, a
// collider not among those in `skip` (bits, as CheckLanes' near): each link measured against the
// collider's bound first, exactly only where it reaches into the bound.
bool EntersOther(int dim, int m, const double* points, const double* lengths,
                 const std::vector<Collider>& colliders, const std::vector<ColliderBound>& bounds,
                 uint64_t skip) {
  for (size_t c = 0; c < colliders.size(); ++c) {
    if (skip & ColliderBit(c)) continue;
    const ColliderBound& bound = bounds[c];
    for (int i = 1; i <= m; ++i) {
      const double* a = points + (i - 1) * dim;
      const double* b = points + i * dim;
      const Eigen::Vector3d pa(a[0], a[1], dim == 3 ? a[2] : 0.0);
      const Eigen::Vector3d pb(b[0], b[1], dim == 3 ? b[2] : 0.0);
      if (!bound.half_space) {
        const Eigen::Vector3d center(bound.center[0], bound.center[1], bound.center[2]);
        const Eigen::Vector3d ab = pb - pa;
        const double t = std::clamp((center - pa).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
        if ((pa + t * ab - center).norm() >= bound.radius) continue;
      }
      if (SegmentClearance(colliders[c], pa, pb) < -kContactSlack * lengths[i - 1]) return true;
    }
  }
  return false;
}

}  // namespace

// One frame of one block with colliders: sub-step by sub-step, the sweep of the engine, kept for
// every lane whose links stay outside the colliders; a lane whose links would enter one is
// stepped again from where it was by the contact sweep (sequential/sweep.h), link by link.
void StrandBatchImpl::StepBlockWithColliders(int b, double* scratch_heads, ContactScratch* cs) {
  const Block& block = blocks[b];
  const int S = options.substeps;
  const int head = block.pinned - 1;
  const int n = block.n;
  double* pts = points.data() + block.points;
  double* heads = scratch_heads;                                      // dim x L
  double* target = scratch_heads + static_cast<size_t>(S) * dim * L;  // dim x L
  PlacePinned(block, pts, target);
  const double* block_lengths = lengths.data() + block.lengths;
  const double* block_inv = inv_lengths.data() + block.lengths;
  const size_t free_begin = static_cast<size_t>(head) * dim * L;
  const size_t free_size = static_cast<size_t>(n + 1 - head) * dim * L;
  const SubnormalsAsZero subnormals;
  // Where the leading end starts the frame (the sweeps move it).
  std::copy(pts + head * dim * L, pts + (head + 1) * dim * L, cs->start.data());
  for (int s = 1; s <= S; ++s) {
    const bool on_body = !substep_poses.empty() && s < S;
    for (int k = 0; k < dim; ++k) {
      double* h = heads + k * L;
      const double* from = cs->start.data() + k * L;
      for (int lane = 0; lane < L; ++lane) {
        if (on_body) {
          const double* q = body.data() + block.body + (head * dim) * L + lane;
          h[lane] = FromBody(substep_poses[s - 1], dim, k, q, L);
        } else {
          // As the engine without colliders: the last sub-step ends on the target.
          h[lane] = SubstepHead(from[lane], target[k * L + lane], s, S);
        }
      }
    }
    const bool in_lanes = sphere_sweep != nullptr && lone_sphere[s - 1];
    if (in_lanes) {
      // The sweep keeps the points it moves in `saved` itself.
      std::fill(cs->fallback.begin(), cs->fallback.end(), n + 1);
      sphere_sweep(options.method, dim, n, head, heads, block_lengths, block_inv, pts,
                   spheres[s - 1], cs->contact_flags.data(), cs->fallback.data(), cs->saved.data(),
                   &cs->found);
    } else {
      std::copy(pts + free_begin, pts + free_begin + free_size, cs->saved.data());
      sweeps(options.method, dim, n, head, 1, heads, block_lengths, block_inv, pts);
    }
    std::fill(cs->least.begin(), cs->least.end(), std::numeric_limits<double>::infinity());
    std::fill(cs->first_enter.begin(), cs->first_enter.end(), n + 1);
    std::fill(cs->near.begin(), cs->near.end(), 0);
    const std::vector<Collider>& all = placed[s - 1];
    CheckLanes(measure_bounds, check_sphere, in_lanes ? &cs->found : nullptr,
               in_lanes ? sphere_index[s - 1] : -1, dim, n, head, block.reach, pts, block_lengths,
               block_inv, all, bounds[s - 1], cs);
    for (int lane = 0; lane < L; ++lane) {
      int first = cs->first_enter[lane];
      if (in_lanes) {
        // The lanes' own contact steps stand up to the first link stepped again.
        first = std::min(first, cs->fallback[lane]);
        if (first > n) {
          cs->stats.contact_link_steps += cs->found.contacts[lane];
        } else {
          for (int i = head + 1; i < first; ++i) {
            cs->stats.contact_link_steps += cs->contact_flags[i * L + lane];
          }
        }
      }
      if (first > n) {
        cs->stats.least_clearance = std::min(cs->stats.least_clearance, cs->least[lane]);
        continue;
      }
      // The links before the first that entered stand as swept; from its leading end on, the
      // contact sweep from where the lane was, first against the colliders the lane came near.
      const int from = first - 1;  // the point the contact sweep leads from
      const int m = n - from;
      double lead[3];
      for (int k = 0; k < dim; ++k) {
        lead[k] = from == head ? heads[k * L + lane] : pts[(from * dim + k) * L + lane];
      }
      for (int i = 0; i < m; ++i) {
        cs->lengths[i] = block_lengths[(from + i) * L + lane];
        cs->inv_lengths[i] = block_inv[(from + i) * L + lane];
      }
      cs->near_colliders.clear();
      for (size_t c = 0; c < all.size(); ++c) {
        if (cs->near[lane] & ColliderBit(c)) {
          cs->near_colliders.push_back(all[c]);
        }
      }
      const bool some = cs->near_colliders.size() < all.size();
      ContactStats stats;
      for (int pass = some ? 0 : 1; pass < 2; ++pass) {
        const std::vector<Collider>& against = pass == 0 ? cs->near_colliders : all;
        for (int i = 0; i <= m; ++i) {
          for (int k = 0; k < dim; ++k) {
            cs->chain[i * dim + k] = cs->saved[((from - head + i) * dim + k) * L + lane];
          }
        }
        stats = ContactStats();
        try {
          ContactSweep(options.method, dim, lead, cs->lengths.data(), cs->inv_lengths.data(), m,
                       cs->chain.data(), against, &stats);
        } catch (const InputError& e) {
          // No room: the lane stays where it was; the frame reports it.
          for (int i = 0; i <= m; ++i) {
            for (int k = 0; k < dim; ++k) {
              cs->chain[i * dim + k] = cs->saved[((from - head + i) * dim + k) * L + lane];
            }
          }
          cs->NoteError(block.source[lane], "strands[" + std::to_string(block.source[lane]) +
                                                "]: " + e.problem().Text());
          break;
        }
        // Against the near colliders only: kept if no link entered another one, else again
        // against all.
        if (pass == 0 && !EntersOther(dim, m, cs->chain.data(), cs->lengths.data(), all,
                                      bounds[s - 1], cs->near[lane])) {
          break;
        }
      }
      cs->stats.contact_link_steps += stats.contact_link_steps;
      cs->stats.least_clearance = std::min(cs->stats.least_clearance, stats.least_clearance);
      for (int i = 0; i <= m; ++i) {
        for (int k = 0; k < dim; ++k) {
          pts[((from + i) * dim + k) * L + lane] = cs->chain[i * dim + k];
        }
      }
    }
  }
}

namespace {

template <class Rule, int Dim>
void LaneSweeps(int lane, int n, int head, int num_sweeps, const double* heads,
                const double* lengths, const double* inv_lengths, double* points) {
  for (int s = 0; s < num_sweeps; ++s) {
    double lead_old[Dim], lead_new[Dim];
    for (int k = 0; k < Dim; ++k) {
      double& p = points[(head * Dim + k) * L + lane];
      lead_old[k] = p;
      p = lead_new[k] = heads[(s * Dim + k) * L + lane];
    }
    for (int i = head + 1; i <= n; ++i) {
      double tail[Dim], tail_old[Dim];
      for (int k = 0; k < Dim; ++k) tail[k] = tail_old[k] = points[(i * Dim + k) * L + lane];
      ApplyScalar<Rule, Dim>(lead_old, lead_new, tail, lengths[(i - 1) * L + lane],
                             inv_lengths[(i - 1) * L + lane]);
      for (int k = 0; k < Dim; ++k) {
        points[(i * Dim + k) * L + lane] = tail[k];
        lead_old[k] = tail_old[k];
        lead_new[k] = tail[k];
      }
    }
  }
}

}  // namespace

void StrandBoundsScalar(int dim, int n, int head, const double* points, const ColliderBound* bounds,
                        int num_bounds, double* clearances) {
  dim == 2 ? LinkBoundsOf<2>(n, head, points, bounds, num_bounds, clearances)
           : LinkBoundsOf<3>(n, head, points, bounds, num_bounds, clearances);
}

void StrandSweepsScalar(Method method, int dim, int n, int head, int num_sweeps,
                        const double* heads, const double* lengths, const double* inv_lengths,
                        double* points) {
  DispatchRule<kStrandEngine>(method, [&](auto rule) {
    using Rule = decltype(rule);
    for (int lane = 0; lane < L; ++lane) {
      dim == 2 ? LaneSweeps<typename Rule::template Step<2>, 2>(lane, n, head, num_sweeps, heads,
                                                                lengths, inv_lengths, points)
               : LaneSweeps<typename Rule::template Step<3>, 3>(lane, n, head, num_sweeps, heads,
                                                                lengths, inv_lengths, points);
    }
  });
}

}  // namespace internal

bool IsStrandMethod(Method method) { return internal::RuleRunsOn(method, internal::kStrandEngine); }

std::vector<std::string> StrandMethodNames() {
  return internal::RuleNamesOn(internal::kStrandEngine);
}

Method ParseStrandMethod(std::string_view name, const std::string& field) {
  const NamedValue<Method>* entry = FindName<Method>(name);
  if (entry == nullptr) {
    throw InputError(UnknownName(field, Vocabulary<Method>::kKind, name, StrandMethodNames()));
  }
  if (!IsStrandMethod(entry->value)) {
    throw InputError(internal::RuleRefused(field, entry->value, internal::kStrandEngine));
  }
  return entry->value;
}

Problems StrandOptions::Validate() const {
  Problems problems;
  if (!internal::RuleRunsOn(method, internal::kStrandEngine)) {
    problems.push_back(internal::RuleRefused("method", method, internal::kStrandEngine));
  }
  if (substeps < 1) {
    problems.push_back(Problem::Invalid("substeps", std::to_string(substeps), "an integer >= 1"));
  }
  if (pinned < 1) {
    problems.push_back(Problem::Invalid("pinned", std::to_string(pinned), "an integer >= 1"));
  }
  if (threads < 0 || threads > 1024) {
    problems.push_back(
        Problem::Invalid("threads", std::to_string(threads), "an integer from 0 to 1024"));
  }
  const auto check = [&](const std::vector<Collider>& list, const std::string& name) {
    for (size_t i = 0; i < list.size(); ++i) {
      const std::string field = name + "[" + std::to_string(i) + "]";
      for (Problem& p : CheckCollider(list[i], field)) problems.push_back(std::move(p));
      if (list[i].motion && &list == &body_colliders) {
        problems.emplace_back(field + ".motion",
                              "is not valid for a body collider, which moves with the body; "
                              "keyframed colliders are world colliders (\"colliders\")",
                              "a motion", "a body collider without \"motion\"");
      }
    }
  };
  check(colliders, "colliders");
  check(body_colliders, "body_colliders");
  if (dynamics) {
    if (dynamics->substeps != 1 && dynamics->substeps != substeps) {
      problems.push_back(Problem::Invalid("dynamics.substeps", std::to_string(dynamics->substeps),
                                          "1 or the strands' substeps (" +
                                              std::to_string(substeps) +
                                              "), which the strand engine takes"));
    }
    if (!dynamics->colliders.empty()) {
      problems.emplace_back("dynamics.colliders",
                            "are given; the strand engine takes its colliders from "
                            "\"colliders\" and \"body_colliders\"");
    }
  }
  return problems;
}

namespace {

// Given masses against the strands: dynamics.masses (one profile) needs every strand to have as
// many links as it has entries; StrandOptions::masses one entry per strand, each empty or one
// finite mass > 0 per free point of that strand.
Problems CheckStrandMasses(const std::vector<Points>& strands, const StrandOptions& options) {
  Problems problems;
  const Eigen::VectorXd& profile = options.dynamics->masses;
  const size_t count = strands.size();
  if (!options.masses.empty() && options.masses.size() != count) {
    problems.push_back(Problem::Invalid(
        "masses", std::to_string(options.masses.size()) + " entries",
        "none or one per strand (" + std::to_string(count) + "), each empty or n_i masses"));
    return problems;
  }
  for (size_t i = 0; i < count; ++i) {
    const Eigen::Index n = strands[i].rows() - 1;
    const bool own = !options.masses.empty() && options.masses[i].size() != 0;
    if (own) {
      const Eigen::VectorXd& m = options.masses[i];
      const std::string field = "masses[" + std::to_string(i) + "]";
      if (m.size() != n) {
        problems.push_back(Problem::Invalid(
            field, std::to_string(m.size()) + " entries",
            std::to_string(n) + ", one per free point of strands[" + std::to_string(i) + "]"));
        continue;
      }
      for (Eigen::Index j = 0; j < n; ++j) {
        if (!(m[j] > 0.0 && std::isfinite(m[j]))) {
          problems.push_back(Problem::Invalid(field + "[" + std::to_string(j) + "]",
                                              FormatNumber(m[j]), "a finite number > 0"));
        }
      }
    } else if (profile.size() != 0 && profile.size() != n) {
      problems.push_back(Problem::Invalid(
          "dynamics.masses", std::to_string(profile.size()) + " entries",
          "one per free point of every strand; strands[" + std::to_string(i) + "] has " +
              std::to_string(n) + " links (give strands of other link counts their own masses)"));
      break;
    }
  }
  return problems;
}

void ValidatePose(const BodyPose& pose, int dim) {
  if (!pose.rotation.allFinite()) throw InputError("pose.rotation", "is not finite");
  if (!pose.translation.allFinite()) throw InputError("pose.translation", "is not finite");
  const int d = dim == 2 ? 2 : 3;
  const Eigen::MatrixXd r = pose.rotation.topLeftCorner(d, d);
  const double off = (r.transpose() * r - Eigen::MatrixXd::Identity(d, d)).cwiseAbs().maxCoeff();
  const Eigen::Matrix3d& m = pose.rotation;
  const double det =
      d == 2 ? m(0, 0) * m(1, 1) - m(0, 1) * m(1, 0) : m.col(0).dot(m.col(1).cross(m.col(2)));
  if (off > 1e-9 || det < 0.0) {
    throw InputError("pose.rotation",
                     "is not a rotation (orthonormal with determinant +1, to 1e-9)");
  }
}

// The rigid motion x -> R x + t of a body pose as an isometry (in 2D: the rotation's top-left
// 2x2 block, about z).
Eigen::Isometry3d IsometryOf(const BodyPose& pose, int dim) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  if (dim == 2) {
    m.linear().topLeftCorner<2, 2>() = pose.rotation.topLeftCorner<2, 2>();
    m.translation().head<2>() = pose.translation.head<2>();
  } else {
    m.linear() = pose.rotation;
    m.translation() = pose.translation;
  }
  return m;
}

// The body's pose a fraction u of the way from `from` to `to`: the rotation by slerp (the shorter
// arc), the translation linearly.
BodyPose Between(const BodyPose& from, const BodyPose& to, double u, int dim) {
  const Eigen::Isometry3d a = IsometryOf(from, dim), b = IsometryOf(to, dim);
  const Eigen::Quaterniond qa(a.linear()), qb(b.linear());
  BodyPose pose;
  pose.rotation = qa.slerp(u, qb).toRotationMatrix();
  pose.translation = a.translation() + u * (b.translation() - a.translation());
  return pose;
}

}  // namespace

namespace internal {

// All colliders placed for the frame's sub-steps: the world's as they are, the body's at the
// body's pose (at each sub-step's pose with sub-steps > 1, else at `pose`). `pose` null: the
// roots are stepped as points, and only world colliders exist.
void StrandBatchImpl::PlaceColliders(const BodyPose* frame_pose) {
  const int S = options.substeps;
  const auto& world = options.colliders;
  const auto& attached = options.body_colliders;
  for (int s = 1; s <= S; ++s) {
    BodyPose at = frame_pose != nullptr ? *frame_pose : last_pose;
    if (!substep_poses.empty()) {
      if (s < S) at = Between(last_pose, *frame_pose, static_cast<double>(s) / S, dim);
      substep_poses[s - 1] = at;
    }
    const Eigen::Isometry3d body_to_world = IsometryOf(at, dim);
    std::vector<Collider>& out = placed[s - 1];
    const double time = s == S ? frame_time : last_time + (frame_time - last_time) * s / S;
    for (size_t j = 0; j < world.size(); ++j) {
      out[j] = world[j].motion ? ColliderAt(world[j], time) : world[j];
    }
    for (size_t j = 0; j < attached.size(); ++j) {
      out[world.size() + j] = attached[j];
      out[world.size() + j].pose = body_to_world * attached[j].pose;
    }
    int count = 0;
    for (size_t j = 0; j < out.size(); ++j) {
      bounds[s - 1][j] = BoundOf(out[j]);
      if (out[j].shape != ColliderShape::kSphere) continue;
      ++count;
      StrandSphere& sphere = spheres[s - 1];
      sphere_index[s - 1] = static_cast<int>(j);
      for (int k = 0; k < 3; ++k) sphere.center[k] = out[j].pose.translation()[k];
      sphere.radius = out[j].radius + out[j].margin;
      sphere.slack = kContactSlack;
    }
    lone_sphere[s - 1] = count == 1;
  }
}

}  // namespace internal

namespace internal {

void StrandDynamicScalar(int dim, const DynamicLaneStep& q, int stage) {
  const auto step = [](auto dim_tag) {
    constexpr int Dim = decltype(dim_tag)::value;
    return [](const double* lead_old, const double* lead_new, double* tail, const double* len,
              const double* inv) { TractrixStep<Dim>(lead_old, lead_new, tail, *len, *inv); };
  };
  // Contacts: left to the caller (StepBlockDynamic's ContactLane).
  const auto no_contact = [](const double*, double*, int, int) {};
  dim == 2 ? DynamicBlock<double, 2>(q, stage, step(std::integral_constant<int, 2>()), no_contact)
           : DynamicBlock<double, 3>(q, stage, step(std::integral_constant<int, 3>()), no_contact);
}

void StrandBatchImpl::BeginDynamicFrame(const BodyPose* frame_pose) {
  const int S = options.substeps;
  const DynamicOptions& dyn = *options.dynamics;
  for (int s = 1; s <= S; ++s) {
    if (frame_pose != nullptr) {
      dynamic_poses[s - 1] =
          s < S ? Between(last_pose, *frame_pose, static_cast<double>(s) / S, dim) : *frame_pose;
    }
    // The wind at the sub-step's middle (seconds from the batch's making), as SimulateChain.
    const Eigen::VectorXd wind =
        dyn.WindAt((static_cast<double>(substeps_done) + (s - 0.5)) / (dyn.frame_rate * S), dim);
    winds[s - 1].setZero();
    for (int k = 0; k < dim; ++k) winds[s - 1][k] = wind[k];
  }
}

void StrandBatchImpl::EndDynamicFrame() {
  substeps_done += options.substeps;
  double energy = 0.0;
  for (double e : block_energy) energy += e;  // in block order: the same for any thread count
  dynamics_report.energy = energy;
  for (DynamicScratch& ds : dynamic_scratch) {
    dynamics_report.failures += ds.failures;
    dynamics_report.contact_substeps += ds.contact_substeps;
    ds.failures = ds.contact_substeps = 0;
  }
}

void StrandBatchImpl::PinnedAt(const Block& block, int s, const double* from, double* pts) const {
  const int S = options.substeps;
  for (int j = 0; j < block.pinned; ++j) {
    for (int k = 0; k < dim; ++k) {
      double* out = pts + (j * dim + k) * L;
      for (int lane = 0; lane < L; ++lane) {
        if (pose != nullptr) {
          const double* q = body.data() + block.body + (j * dim) * L + lane;
          out[lane] = FromBody(dynamic_poses[s - 1], dim, k, q, L);
        } else {
          // The root moves linearly to its point; the other pinned points translate with it.
          const double root = roots[block.source[lane] * roots_stride + k];
          const double at = SubstepHead(from[k * L + lane], root, s, S);
          out[lane] = j == 0 ? at : from[(j * dim + k) * L + lane] + (at - from[k * L + lane]);
        }
      }
    }
  }
}

// A lane whose projection left link `first` (or a later one) inside a collider: projected again
// from that link on, link by link, each link that would enter one taking the nearest clear
// direction (ContactTail). The overall projection's lanes are projected again from the first free
// link by the tractrix projection.
void StrandBatchImpl::ContactLane(const Block& block, int lane, int first, int s,
                                  DynamicScratch& ds, double* pts, ContactScratch* cs) {
  const Projection projection = options.dynamics->projection;
  const int head = block.pinned - 1;
  double* p = ds.predicted.data();
  const double* block_lengths = lengths.data() + block.lengths;
  const double* block_inv = inv_lengths.data() + block.lengths;
  const std::vector<Collider>& all = placed[s - 1];
  if (projection == Projection::kOverall) first = head + 1;
  const auto at = [&](const double* base, int i) {
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int k = 0; k < dim; ++k) x[k] = base[(i * dim + k) * L + lane];
    return x;
  };
  for (int i = first; i <= block.n; ++i) {
    const double length = block_lengths[(i - 1) * L + lane];
    const Eigen::Vector3d lead = at(pts, i - 1);
    const Eigen::Vector3d pi = at(p, i);
    Eigen::Vector3d x;
    if (projection == Projection::kDftl) {
      x = lead + (length / (pi - lead).norm()) * (pi - lead);
    } else {
      const Eigen::Vector3d lead_p = at(p, i - 1);
      x = lead_p + (length / (pi - lead_p).norm()) * (pi - lead_p);
      double tail[3] = {x[0], x[1], x[2]};
      const double inv = block_inv[(i - 1) * L + lane];
      dim == 2 ? TractrixStep<2>(lead_p.data(), lead.data(), tail, length, inv)
               : TractrixStep<3>(lead_p.data(), lead.data(), tail, length, inv);
      x = Eigen::Vector3d(tail[0], tail[1], tail[2]);
    }
    double clearance = SegmentClearance(all, lead, x);
    if (clearance < -kContactSlack * length) {
      Eigen::Vector3d clear;
      if (ContactTail(dim, lead, projection == Projection::kDftl ? pi : x, length, all, &clear)) {
        SettleTail(dim, lead, length, all, &clear);
        x = clear;
        clearance = SegmentClearance(all, lead, x);  // measured again only where it moved
        ++cs->stats.contact_link_steps;
        // A point a collider placed takes no DFTL velocity correction (its correction is the
        // contact's, not the link's): its prediction is made its place.
        for (int k = 0; k < dim; ++k) p[(i * dim + k) * L + lane] = x[k];
      } else {
        cs->NoteError(block.source[lane],
                      "strands[" + std::to_string(block.source[lane]) + "]: link " +
                          std::to_string(i) +
                          " finds no direction clear of the colliders (its leading end is "
                          "wedged between them)");
      }
    }
    cs->stats.least_clearance = std::min(cs->stats.least_clearance, clearance / length);
    for (int k = 0; k < dim; ++k) pts[(i * dim + k) * L + lane] = x[k];
  }
}

// One frame of one block with dynamics: sub-step by sub-step, the pinned points placed, the
// prediction and its projection (dynamic_lanes.h; the overall projection lane by lane by the
// overall method's Newton solver), the colliders' contacts, the velocities; the block's energy
// after the last sub-step.
void StrandBatchImpl::StepBlockDynamic(int b, int thread) {
  const Block& block = blocks[b];
  const DynamicOptions& dyn = *options.dynamics;
  const int S = options.substeps;
  const int head = block.pinned - 1;
  const int n = block.n;
  DynamicScratch& ds = dynamic_scratch[thread];
  double* pts = points.data() + block.points;
  const size_t size = static_cast<size_t>(n + 1) * dim * L;
  const size_t pinned_size = static_cast<size_t>(block.pinned) * dim * L;
  std::copy(pts, pts + pinned_size, ds.pin_from.data());
  DynamicLaneStep q;
  q.n = n;
  q.head = head;
  q.tractrix = dyn.projection != Projection::kDftl;
  q.correct = dyn.projection == Projection::kTractrix || dyn.projection == Projection::kDftl;
  q.h = 1.0 / (dyn.frame_rate * S);
  q.damping = dyn.damping;
  q.dftl_damping = dyn.dftl_damping;
  for (int k = 0; k < dim; ++k) q.gravity[k] = dyn.gravity[k];
  q.lengths = lengths.data() + block.lengths;
  q.inv_lengths = inv_lengths.data() + block.lengths;
  q.x = pts;
  q.x_old = ds.x_old.data();
  q.p = ds.predicted.data();
  q.v = velocity.data() + block.points;
  q.mass = mass.data() + mass_offset[b];
  if (multipliers.size() > 0) q.multipliers = multipliers.data() + mass_offset[b];
  q.work = ds.work.data();
  q.converged = ds.converged;
  const SubnormalsAsZero subnormals;
  ContactScratch* cs = has_colliders ? &contact[thread] : nullptr;
  for (int s = 1; s <= S; ++s) {
    // The pinned points' start; the free points' is kept by stage 1.
    std::copy(pts, pts + pinned_size, ds.x_old.data());
    PinnedAt(block, s, ds.pin_from.data(), pts);
    for (int k = 0; k < dim; ++k) q.wind[k] = winds[s - 1][k];
    // The SIMD engines take the contact step against a lone sphere (a scalp) in the lanes.
    const bool in_lanes =
        cs != nullptr && dynamic_step != StrandDynamicScalar && lone_sphere[s - 1];
    q.sphere = in_lanes ? &spheres[s - 1] : nullptr;
    if (in_lanes) {
      q.contact = cs->contact_flags.data();
      q.fallback = cs->fallback.data();
      std::fill(cs->fallback.begin(), cs->fallback.end(), n + 1);
    }
    dynamic_step(dim, q, 1);
    // Lanes whose points are the sequential projection's with the lanes' contact steps: every
    // lane for the sequential projections; for the solved ones, the lanes where that projection
    // touched the sphere. The solved projections (overall, SHAKE) know no colliders: they are
    // solved for the lanes the sphere did not touch, and a lane they leave inside a collider is put
    // back to the sequential projection too.
    const bool shake = dyn.projection == Projection::kShake;
    const bool solved = shake || dyn.projection == Projection::kOverall;
    const auto padding = [&](int lane) {
      return lane > 0 && block.source[lane] == block.source[0];
    };
    bool sequential[L];
    bool failed[L] = {};  // no solved projection converged: the tractrix one kept
    std::fill(sequential, sequential + L, in_lanes && !solved);
    // A lane's free points from `source` (a block's layout).
    const auto put_back = [&](int lane, const double* source) {
      for (int i = head + 1; i <= n; ++i) {
        for (int k = 0; k < dim; ++k) {
          const size_t at = static_cast<size_t>(i * dim + k) * L + lane;
          pts[at] = source[at];
        }
      }
    };
    const auto restore = [&](int lane) {
      put_back(lane, ds.sequential.data());
      sequential[lane] = true;
    };
    if (solved) {
      bool all_touched = in_lanes;
      if (in_lanes) {
        for (int lane = 0; lane < L; ++lane) {
          bool touched = cs->fallback[lane] <= n;
          for (int i = head + 1; i <= n && !touched; ++i) touched = cs->contact_flags[i * L + lane];
          sequential[lane] = touched;
          all_touched = all_touched && touched;
        }
      }
      if (!all_touched) {
        // The tractrix projection kept: the overall projection's start, SHAKE's fallback.
        if (in_lanes || shake) std::copy(pts, pts + size, ds.sequential.data());
        for (int lane = 0; lane < L; ++lane) ds.ignore[lane] = sequential[lane] ? 1.0 : 0.0;
        q.ignore = ds.ignore;
        bool overall_lanes[L];
        bool any_overall = !shake;
        std::fill(overall_lanes, overall_lanes + L, !shake);
        if (shake) {
          // SHAKE in the lanes; where it does not converge (past its stability limit), that
          // lane's sub-step takes the overall projection from the tractrix projection, as
          // SimulateChain's.
          dynamic_step(dim, q, 4);
          for (int lane = 0; lane < L; ++lane) {
            overall_lanes[lane] = !sequential[lane] && ds.converged[lane] == 0.0;
            if (!overall_lanes[lane]) continue;
            if (!padding(lane)) ++ds.failures;
            put_back(lane, ds.sequential.data());
            any_overall = true;
          }
          for (int lane = 0; lane < L; ++lane) ds.ignore[lane] = overall_lanes[lane] ? 0.0 : 1.0;
        }
        if (any_overall) {
          // The overall projection from the tractrix projection, in the lanes; a lane where it
          // does not converge keeps the tractrix projection. (It moves the lanes it ignores too:
          // SHAKE's are kept aside.)
          if (shake) std::copy(pts, pts + size, ds.shaken.data());
          dynamic_step(dim, q, 3);
          for (int lane = 0; lane < L; ++lane) {
            failed[lane] = overall_lanes[lane] && !sequential[lane] && ds.converged[lane] == 0.0;
            if (!shake && failed[lane] && !padding(lane)) ++ds.failures;
          }
          for (int lane = 0; lane < L && shake; ++lane) {
            if (!overall_lanes[lane] && !sequential[lane]) put_back(lane, ds.shaken.data());
          }
        }
        for (int lane = 0; lane < L; ++lane) {
          if (sequential[lane]) restore(lane);
        }
      }
    }
    if (cs != nullptr) {
      const auto check = [&]() {
        std::fill(cs->least.begin(), cs->least.end(), std::numeric_limits<double>::infinity());
        std::fill(cs->first_enter.begin(), cs->first_enter.end(), n + 1);
        std::fill(cs->near.begin(), cs->near.end(), 0);
        CheckLanes(measure_bounds, check_sphere, nullptr, -1, dim, n, head, block.reach, pts,
                   q.lengths, q.inv_lengths, placed[s - 1], bounds[s - 1], cs);
      };
      check();
      if (in_lanes && solved) {
        bool any = false;
        for (int lane = 0; lane < L; ++lane) {
          if (sequential[lane] || cs->first_enter[lane] > n) continue;
          restore(lane);
          any = true;
        }
        if (any) check();
        for (int lane = 0; lane < L && !padding(lane); ++lane)
          ds.contact_substeps += sequential[lane];
      }
      // The lanes' own contact steps stand up to the first link projected again: each point
      // they placed takes no velocity correction (its prediction is made its place). Lane by
      // lane in the inner loops, without branches (the compiler's vector code).
      int first_lane[L], stood[L];
      for (int lane = 0; lane < L; ++lane) {
        first_lane[lane] = sequential[lane] ? std::min(cs->first_enter[lane], cs->fallback[lane])
                                            : cs->first_enter[lane];
        stood[lane] = sequential[lane] ? first_lane[lane] : head + 1;
        stood[lane] = std::min(stood[lane], n + 1);
      }
      int64_t contact_steps = 0;
      for (int i = head + 1; i <= n; ++i) {
        const uint8_t* flags = cs->contact_flags.data() + i * L;
        // All ones where the lane's contact step placed point i and stands, else 0: the
        // selection below is a bitwise one, which compiles to vector code, not branches.
        uint64_t take[L];
        int taken = 0;
        for (int lane = 0; lane < L; ++lane) {
          const int contact = (flags[lane] != 0) & (i < stood[lane]);
          take[lane] = uint64_t{0} - static_cast<uint64_t>(contact);
          taken += contact;
        }
        if (taken == 0) continue;
        contact_steps += taken;
        for (int k = 0; k < dim; ++k) {
          const size_t at = static_cast<size_t>(i * dim + k) * L;
          double* predicted = ds.predicted.data() + at;
          const double* placed = pts + at;
          for (int lane = 0; lane < L; ++lane) {
            uint64_t a, b;
            std::memcpy(&a, placed + lane, sizeof a);
            std::memcpy(&b, predicted + lane, sizeof b);
            b = (a & take[lane]) | (b & ~take[lane]);
            std::memcpy(predicted + lane, &b, sizeof b);
          }
        }
      }
      cs->stats.contact_link_steps += contact_steps;
      for (int lane = 0; lane < L; ++lane) {
        const int first = first_lane[lane];
        if (first > n) {
          cs->stats.least_clearance = std::min(cs->stats.least_clearance, cs->least[lane]);
          continue;
        }
        if (solved && !sequential[lane] && !padding(lane)) ++ds.contact_substeps;
        if (solved) sequential[lane] = true;  // ContactLane's projection is the tractrix one
        ContactLane(block, lane, first, s, ds, pts, cs);
      }
    }
    if (solved) {
      // A lane that kept or took the tractrix projection (with contacts, or where the overall one
      // did not converge) takes its velocity correction too (without it that projection gains
      // energy: docs/dynamics.md).
      bool any = false;
      for (int lane = 0; lane < L; ++lane) {
        const bool tractrix = (cs != nullptr && sequential[lane]) || failed[lane];
        ds.corrected[lane] = tractrix ? 1.0 : 0.0;
        any = any || tractrix;
      }
      q.correct_lanes = any ? ds.corrected : nullptr;
    }
    dynamic_step(dim, q, 2);
  }
  // The energy at the middle of the last sub-step, each lane's free points weighing 1 (summed
  // lane by lane, the lanes in the inner loop).
  double lane_energy[L] = {};
  const double* mass_of = mass.data() + mass_offset[b];
  const double* x_old = ds.x_old.data();
  for (int i = head + 1; i <= n; ++i) {
    double kinetic[L] = {}, height[L] = {};
    for (int k = 0; k < dim; ++k) {
      const double* v = q.v + static_cast<size_t>(i * dim + k) * L;
      const double* x = pts + static_cast<size_t>(i * dim + k) * L;
      const double* xo = x_old + static_cast<size_t>(i * dim + k) * L;
      const double g = dyn.gravity[k];
      for (int lane = 0; lane < L; ++lane) {
        kinetic[lane] += v[lane] * v[lane];
        height[lane] += g * (x[lane] + xo[lane]);
      }
    }
    for (int lane = 0; lane < L; ++lane) {
      lane_energy[lane] += mass_of[i * L + lane] * (0.5 * kinetic[lane] - 0.5 * height[lane]);
    }
  }
  double energy = 0.0;
  for (int lane = 0; lane < L; ++lane) {
    if (lane > 0 && block.source[lane] == block.source[0]) break;  // padding lanes
    energy += lane_energy[lane];
  }
  block_energy[b] = energy;
}

}  // namespace internal

namespace {

// Refuses strands that start inside a collider, naming the strand, the point or link, the
// collider and the depth.
void CheckStart(const std::vector<Points>& strands, const StrandOptions& options,
                const BodyPose& rest, double time) {
  const std::optional<StrandInside> inside = FindStrandInside(strands, options, rest, time);
  if (!inside) return;
  const StrandInside& in = *inside;
  const std::vector<Collider>& list = in.body ? options.body_colliders : options.colliders;
  const std::string collider = std::string(in.body ? "body_colliders[" : "colliders[") +
                               std::to_string(in.collider) + "] (a " +
                               ColliderShapeName(list[in.collider].shape) + ")";
  const std::string what =
      in.link ? "link " + std::to_string(in.point) + " (points " + std::to_string(in.point - 1) +
                    " to " + std::to_string(in.point) + ") passes through " + collider
              : "point " + std::to_string(in.point) + " lies inside " + collider;
  throw InputError("strands[" + std::to_string(in.strand) + "]",
                   what + " by " + FormatNumber(in.depth) + " at the start (" +
                       FormatNumber(in.relative) +
                       " of the link's length); a strand must start outside every collider");
}

// Per strand, its root's place along a Z-order (Morton) curve through the roots' bounding box:
// strands whose roots lie near each other have near keys, and sorted by them they share blocks.
// Contacts with the body come in patches (the side of the head the hair is laid against), so
// grouped strands take the lanes' contact step in fewer blocks. On the scalar engine the order
// changes no result; on the SIMD engines a strand's last bits depend on its register's other
// lanes (docs/strands.md, "Layout").
std::vector<uint64_t> RootOrder(const std::vector<Points>& strands, int dim) {
  const size_t count = strands.size();
  std::vector<uint64_t> key(count, 0);
  if (count == 0) return key;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const Points& p : strands) {
    for (int k = 0; k < dim; ++k) {
      lo[k] = std::min(lo[k], p(0, k));
      hi[k] = std::max(hi[k], p(0, k));
    }
  }
  const int bits = dim == 2 ? 31 : 21;  // per coordinate, into 62 or 63 bits
  const double cells = static_cast<double>((uint64_t{1} << bits) - 1);
  for (size_t s = 0; s < count; ++s) {
    uint64_t code = 0;
    for (int k = 0; k < dim; ++k) {
      const double span = hi[k] - lo[k];
      const double t = span > 0.0 ? (strands[s](0, k) - lo[k]) / span : 0.0;
      const uint64_t cell = static_cast<uint64_t>(std::clamp(t, 0.0, 1.0) * cells);
      for (int b = 0; b < bits; ++b) code |= ((cell >> b) & 1u) << (b * dim + k);
    }
    key[s] = code;
  }
  return key;
}

}  // namespace

StrandBatch::StrandBatch(const std::vector<Points>& strands, const StrandOptions& options,
                         const BodyPose& rest, double time)
    : impl_(std::make_unique<internal::StrandBatchImpl>()) {
  if (!std::isfinite(time)) throw InputError("time", "is not finite");
  impl_->last_time = impl_->frame_time = time;
  using internal::L;
  ThrowIfAny(options.Validate());
  auto& m = *impl_;
  m.options = options;
  const int count = static_cast<int>(strands.size());
  for (int i = 0; i < count; ++i) {
    const std::string field = "strands[" + std::to_string(i) + "]";
    try {
      ValidateChain(MakeChain(strands[i]));
    } catch (const InputError& e) {
      throw InputError(field, e.problem().Text());
    }
    const int d = static_cast<int>(strands[i].cols());
    if (i == 0) m.dim = d;
    if (d != m.dim) {
      throw InputError(field, "is " + std::to_string(d) + "D; strands[0] is " +
                                  std::to_string(m.dim) + "D: every strand must have one dim");
    }
  }
  if (count > 0) ValidatePose(rest, m.dim);
  const int dim = m.dim;
  if (options.dynamics && count > 0) {
    Problems problems = options.dynamics->ValidateFor(dim);
    for (Problem& p : problems) p.field = "dynamics." + p.field;
    ThrowIfAny(problems);
    ThrowIfAny(CheckStrandMasses(strands, options));
  } else if (!options.masses.empty()) {
    throw InputError("masses",
                     "are given without dynamics; masses are for dynamic strands "
                     "(StrandOptions::dynamics)");
  }
  m.links.resize(count);
  for (int i = 0; i < count; ++i) m.links[i] = static_cast<int>(strands[i].rows()) - 1;
  // Strands of one link count side by side, neighbours by their roots in one block (RootOrder).
  const std::vector<uint64_t> near_key = RootOrder(strands, dim);
  std::vector<int> order(count);
  for (int i = 0; i < count; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    if (m.links[a] != m.links[b]) return m.links[a] < m.links[b];
    if (near_key[a] != near_key[b]) return near_key[a] < near_key[b];
    return a < b;
  });
  m.block_of.resize(count);
  m.lane_of.resize(count);
  size_t num_points = 0, num_lengths = 0, num_body = 0;
  for (int at = 0; at < count;) {
    internal::Block block;
    block.n = m.links[order[at]];
    block.pinned = std::min(options.pinned, block.n + 1);
    block.points = num_points;
    block.lengths = num_lengths;
    block.body = num_body;
    int lane = 0;
    for (; lane < L && at < count && m.links[order[at]] == block.n; ++lane, ++at) {
      block.source[lane] = order[at];
      m.block_of[order[at]] = static_cast<int>(m.blocks.size());
      m.lane_of[order[at]] = lane;
    }
    for (; lane < L; ++lane) block.source[lane] = block.source[0];
    num_points += static_cast<size_t>(block.n + 1) * dim * L;
    num_lengths += static_cast<size_t>(block.n) * L;
    num_body += static_cast<size_t>(block.pinned) * dim * L;
    m.blocks.push_back(block);
  }
  m.points = internal::AlignedDoubles(num_points);
  m.lengths = internal::AlignedDoubles(num_lengths);
  m.inv_lengths = internal::AlignedDoubles(num_lengths);
  m.body = internal::AlignedDoubles(num_body);
  for (auto& block : m.blocks) {
    for (int lane = 0; lane < L; ++lane) {
      const Points& p = strands[block.source[lane]];
      // The link lengths as MakeChain and MakeStepper compute them.
      const Eigen::VectorXd lengths = MakeChain(p).lengths;
      for (int i = 0; i <= block.n; ++i) {
        for (int k = 0; k < dim; ++k)
          m.points.data()[block.points + (i * dim + k) * L + lane] = p(i, k);
      }
      double total = 0.0, longest = 0.0;
      for (int i = 0; i < block.n; ++i) {
        m.lengths.data()[block.lengths + i * L + lane] = lengths[i];
        m.inv_lengths.data()[block.lengths + i * L + lane] = 1.0 / lengths[i];
        if (i < block.pinned - 1) continue;  // a pinned link: not free
        total += lengths[i];
        longest = std::max(longest, lengths[i]);
      }
      block.reach = std::max(block.reach, total + 2.0 * longest);
      for (int j = 0; j < block.pinned; ++j) {
        double q[3];
        internal::ToBody(rest, dim, p.row(j).data(), q);
        for (int k = 0; k < dim; ++k) m.body.data()[block.body + (j * dim + k) * L + lane] = q[k];
      }
    }
  }
  // The engine: the widest instruction set allowed (FLEXKIN_SIMD caps it).
#if FLEXKIN_HAVE_WAVEFRONT
  if (internal::AllowedSimd().avx512) {
    m.sweeps = internal::StrandSweepsAvx512;
    m.sphere_sweep = internal::StrandSphereSweepAvx512;
    m.measure_bounds = internal::StrandBoundsAvx512;
    m.check_sphere = internal::StrandSphereCheckAvx512;
    m.engine = "avx512";
  } else if (internal::AllowedSimd().avx2_fma) {
    m.sweeps = internal::StrandSweepsAvx2;
    m.sphere_sweep = internal::StrandSphereSweepAvx2;
    m.measure_bounds = internal::StrandBoundsAvx2;
    m.check_sphere = internal::StrandSphereCheckAvx2;
    m.engine = "avx2";
  }
#endif
  // Threads: each takes the next block not yet taken (Job).
  int threads = options.threads == 0
                    ? std::max(1, static_cast<int>(std::thread::hardware_concurrency()))
                    : options.threads;
  threads = std::max(1, std::min(threads, static_cast<int>(m.blocks.size())));
  m.job_blocks = std::max(16, static_cast<int>(m.blocks.size()) / (8 * threads));
  for (int i = 0; i < threads; ++i) {
    m.scratch.emplace_back(static_cast<size_t>(options.substeps + 1) * std::max(dim, 1) * L);
  }
  m.pool = std::make_unique<internal::WorkerPool>(threads);
  m.last_pose = rest;
  if (options.dynamics && count > 0) {
    m.dynamic = true;
    const DynamicOptions& dyn = *options.dynamics;
    m.velocity = internal::AlignedDoubles(num_points);
    size_t num_mass = 0;
    for (const auto& block : m.blocks) {
      m.mass_offset.push_back(num_mass);
      num_mass += static_cast<size_t>(block.n + 1) * L;
    }
    m.mass = internal::AlignedDoubles(num_mass);
    const bool solved =
        dyn.projection == Projection::kOverall || dyn.projection == Projection::kShake;
    if (solved) {
      m.multipliers = internal::AlignedDoubles(num_mass);  // 0: the first sub-step's start
    }
    int most_links = 0, most_pinned = 1;
    for (size_t b = 0; b < m.blocks.size(); ++b) {
      const internal::Block& block = m.blocks[b];
      most_links = std::max(most_links, block.n);
      most_pinned = std::max(most_pinned, block.pinned);
      const double* len = m.lengths.data() + block.lengths;
      double* mass = m.mass.data() + m.mass_offset[b];
      for (int lane = 0; lane < L; ++lane) {
        // As SimulateChain (the same operations): half of each link a point touches (or 1), the
        // free points' total 1.
        // Given masses: the strand's own, else the one profile of dynamics.masses.
        const int source = block.source[lane];
        const Eigen::VectorXd& given = options.masses.empty() || options.masses[source].size() == 0
                                           ? dyn.masses
                                           : options.masses[source];
        Eigen::VectorXd mj = Eigen::VectorXd::Zero(block.n + 1);
        for (int j = 1; j <= block.n; ++j) {
          mj[j] = given.size() == block.n ? given[j - 1]
                  : dyn.mass_by_length
                      ? 0.5 * (len[(j - 1) * L + lane] + (j < block.n ? len[j * L + lane] : 0.0))
                      : 1.0;
        }
        mj /= mj.sum();
        for (int j = 1; j <= block.n; ++j) mass[j * L + lane] = mj[j];
      }
    }
    m.dynamic_scratch.resize(threads);
    for (auto& ds : m.dynamic_scratch) {
      ds.x_old = internal::AlignedDoubles(static_cast<size_t>(most_links + 1) * dim * L);
      ds.predicted = internal::AlignedDoubles(static_cast<size_t>(most_links + 1) * dim * L);
      ds.pin_from.resize(static_cast<size_t>(most_pinned) * dim * L);
      if (solved) {
        ds.work = internal::AlignedDoubles(internal::LeastConstraintWork(dim, most_links) * L);
        ds.sequential = internal::AlignedDoubles(static_cast<size_t>(most_links + 1) * dim * L);
        if (dyn.projection == Projection::kShake)
          ds.shaken = internal::AlignedDoubles(ds.sequential.size());
      }
    }
    m.block_energy.assign(m.blocks.size(), 0.0);
    m.dynamic_poses.resize(options.substeps);
    m.winds.resize(options.substeps);
#if FLEXKIN_HAVE_WAVEFRONT
    if (std::string(m.engine) == "avx512") m.dynamic_step = internal::StrandDynamicAvx512;
    if (std::string(m.engine) == "avx2") m.dynamic_step = internal::StrandDynamicAvx2;
#endif
  }
  m.has_colliders = !options.colliders.empty() || !options.body_colliders.empty();
  if (m.has_colliders && count > 0) {
    const int S = options.substeps;
    const size_t num = options.colliders.size() + options.body_colliders.size();
    m.placed.assign(S, std::vector<Collider>(num));
    m.bounds.assign(S, std::vector<internal::ColliderBound>(num));
    m.lone_sphere.assign(S, 0);
    m.spheres.assign(S, internal::StrandSphere());
    m.sphere_index.assign(S, -1);
    if (!options.body_colliders.empty() && S > 1) m.substep_poses.resize(S);
    m.PlaceColliders(&rest);
    CheckStart(strands, options, rest, time);
    int most_links = 0;
    for (int n : m.links) most_links = std::max(most_links, n);
    m.contact.resize(threads);
    for (auto& cs : m.contact) {
      cs.start.resize(static_cast<size_t>(dim) * L);
      cs.saved.resize(static_cast<size_t>(most_links + 1) * dim * L);
      cs.chain.resize(static_cast<size_t>(most_links + 1) * dim);
      cs.lengths.resize(most_links);
      cs.inv_lengths.resize(most_links);
      cs.least.resize(L);
      cs.first_enter.resize(L);
      cs.fallback.resize(L);
      cs.clearances.resize(static_cast<size_t>(most_links) * num * L);
      cs.active.reserve(num);
      cs.active_index.reserve(num);
      cs.contact_flags.resize(static_cast<size_t>(most_links + 1) * L);
      cs.near.resize(L);
      cs.near_colliders.reserve(m.placed.back().size());
    }
  }
}

std::optional<StrandInside> FindStrandInside(const std::vector<Points>& strands,
                                             const StrandOptions& options, const BodyPose& rest,
                                             double time) {
  const size_t num_world = options.colliders.size();
  std::vector<Collider> colliders = CollidersAt(options.colliders, time);
  for (const Collider& c : options.body_colliders) {
    colliders.push_back(c);
    const int dim = strands.empty() ? 3 : static_cast<int>(strands[0].cols());
    colliders.back().pose = IsometryOf(rest, dim) * c.pose;
  }
  for (size_t i = 0; i < strands.size(); ++i) {
    const Points& p = strands[i];
    const int n = static_cast<int>(p.rows()) - 1;
    const int head = std::min(options.pinned, n + 1) - 1;
    const auto at = [&](int j) {
      return Eigen::Vector3d(p(j, 0), p(j, 1), p.cols() == 3 ? p(j, 2) : 0.0);
    };
    for (int j = head + 1; j <= n; ++j) {
      const double length = (at(j) - at(j - 1)).norm();
      for (size_t c = 0; c < colliders.size(); ++c) {
        const double through = -internal::SegmentClearance(colliders[c], at(j - 1), at(j));
        if (!(through > internal::kContactSlack * length)) continue;
        const double inside = -QuerySurface(colliders[c], at(j)).distance;
        StrandInside in;
        in.strand = static_cast<int>(i);
        in.point = j;
        in.link = !(inside > internal::kContactSlack * length);
        in.body = c >= num_world;
        in.collider = static_cast<int>(in.body ? c - num_world : c);
        in.depth = in.link ? through : inside;
        in.relative = in.depth / length;
        return in;
      }
    }
  }
  return std::nullopt;
}

StrandBatch::StrandBatch(StrandBatch&&) noexcept = default;
StrandBatch& StrandBatch::operator=(StrandBatch&&) noexcept = default;
StrandBatch::~StrandBatch() = default;

int StrandBatch::size() const { return static_cast<int>(impl_->links.size()); }
int StrandBatch::dim() const { return impl_->dim; }
int StrandBatch::num_links(int strand) const {
  if (strand < 0 || strand >= size()) {
    throw InputError("strand", std::to_string(strand) + " is out of range; the batch has " +
                                   std::to_string(size()) + " strands");
  }
  return impl_->links[strand];
}
const StrandOptions& StrandBatch::options() const { return impl_->options; }
const char* StrandBatch::engine() const { return impl_->engine; }
StrandContacts StrandBatch::contacts() const { return impl_->contacts; }
StrandDynamics StrandBatch::dynamics() const { return impl_->dynamics_report; }

void StrandBatch::CopyStrand(int strand, Points* out) const {
  using internal::L;
  const int n = num_links(strand);
  const auto& m = *impl_;
  const internal::Block& block = m.blocks[m.block_of[strand]];
  const int lane = m.lane_of[strand];
  out->resize(n + 1, m.dim);
  for (int i = 0; i <= n; ++i) {
    for (int k = 0; k < m.dim; ++k) {
      (*out)(i, k) = m.points.data()[block.points + (i * m.dim + k) * L + lane];
    }
  }
}

Points StrandBatch::strand(int strand) const {
  Points out;
  CopyStrand(strand, &out);
  return out;
}

void StepStrands(StrandBatch* batch, const BodyPose& pose) {
  StepStrands(batch, pose, batch->impl().last_time);
}

void StepStrands(StrandBatch* batch, const BodyPose& pose, double time) {
  auto& m = batch->impl();
  if (!std::isfinite(time)) throw InputError("time", "is not finite");
  if (m.blocks.empty()) return;
  ValidatePose(pose, m.dim);
  m.pose = &pose;
  m.roots = nullptr;
  m.frame_time = time;
  if (m.has_colliders) m.PlaceColliders(&pose);
  if (m.dynamic) m.BeginDynamicFrame(&pose);
  m.next_job.store(0, std::memory_order_relaxed);
  m.pool->Run(internal::StrandBatchImpl::Job, &m);
  m.pose = nullptr;
  m.last_pose = pose;
  m.last_time = time;
  if (m.dynamic) m.EndDynamicFrame();
  m.GatherContacts();
}

void StepStrands(StrandBatch* batch, const Eigen::Ref<const Points>& roots) {
  auto& m = batch->impl();
  if (roots.rows() != batch->size() || (batch->size() > 0 && roots.cols() != m.dim)) {
    throw InputError("roots", "shape " + std::to_string(roots.rows()) + "x" +
                                  std::to_string(roots.cols()) + "; expected " +
                                  std::to_string(batch->size()) + "x" + std::to_string(m.dim) +
                                  " (one row per strand)");
  }
  if (m.blocks.empty()) return;
  if (!roots.allFinite()) throw InputError("roots", "has a value that is not finite");
  if (!m.options.body_colliders.empty()) {
    throw InputError("roots",
                     "cannot move a batch with body colliders: it has no body pose to place them "
                     "at; step it by the body's pose (StepStrands(batch, pose))");
  }
  m.roots = roots.data();
  m.roots_stride = roots.outerStride();
  m.pose = nullptr;
  if (m.dynamic) m.BeginDynamicFrame(nullptr);
  m.next_job.store(0, std::memory_order_relaxed);
  m.pool->Run(internal::StrandBatchImpl::Job, &m);
  m.roots = nullptr;
  if (m.dynamic) m.EndDynamicFrame();
  m.GatherContacts();
}

}  // namespace flexkin

namespace flexkin::internal {

bool StrandEngineOf(const char* name, StrandEngineEntries* out) {
  const std::string engine = name;
  StrandEngineEntries e;
  if (engine == "scalar") e.sweeps = StrandSweepsScalar;
#if FLEXKIN_HAVE_WAVEFRONT
  if (engine == "avx2" && CpuSimd().avx2_fma) {
    e = {StrandSweepsAvx2, StrandSphereSweepAvx2, StrandBoundsAvx2, StrandSphereCheckAvx2,
         StrandDynamicAvx2};
  }
  if (engine == "avx512" && CpuSimd().avx512) {
    e = {StrandSweepsAvx512, StrandSphereSweepAvx512, StrandBoundsAvx512, StrandSphereCheckAvx512,
         StrandDynamicAvx512};
  }
#endif
  if (e.sweeps == nullptr) return false;
  *out = e;
  return true;
}

bool SetStrandEngine(StrandBatch* batch, const char* name) {
  StrandEngineEntries e;
  if (!StrandEngineOf(name, &e)) return false;
  const std::string engine = name;
  batch->impl().dynamic_step = e.dynamic;
  batch->impl().sweeps = e.sweeps;
  batch->impl().sphere_sweep = e.sphere_sweep;
  batch->impl().measure_bounds = e.bounds;
  batch->impl().check_sphere = e.check_sphere;
  batch->impl().engine = engine == "scalar" ? "scalar" : engine == "avx2" ? "avx2" : "avx512";
  return true;
}

}  // namespace flexkin::internal
