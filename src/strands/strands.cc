#include "flexkin/strands.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
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
#include "strands/strand_engine.h"

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
  int n = 0;                                 // links of every strand of the block
  int pinned = 0;                            // points set from the body: min(k, n + 1)
  size_t points = 0, lengths = 0, body = 0;  // offsets into the batch's arrays
  int source[L] = {};  // the strand each lane carries (padding lanes repeat the first)
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
  std::vector<int> first_block;         // thread t steps blocks [first_block[t], first_block[t+1])
  StrandSweepsFn sweeps = StrandSweepsScalar;
  const char* engine = "scalar";
  std::unique_ptr<WorkerPool> pool;

  // The frame being stepped (read by every thread).
  const BodyPose* pose = nullptr;
  const double* roots = nullptr;
  Eigen::Index roots_stride = 0;

  void StepBlock(int b, double* scratch_heads);
  static void Job(void* self, int t) {
    auto* impl = static_cast<StrandBatchImpl*>(self);
    for (int b = impl->first_block[t]; b < impl->first_block[t + 1]; ++b) {
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

// One frame of one block: the pinned points, then the sweeps of the free links.
void StrandBatchImpl::StepBlock(int b, double* scratch_heads) {
  const Block& block = blocks[b];
  const int S = options.substeps;
  const int head = block.pinned - 1;
  double* pts = points.data() + block.points;
  double* target = scratch_heads + static_cast<size_t>(S) * dim * L;  // dim x L
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
  return problems;
}

BodyPose BodyPose::FromQuaternion(double w, double x, double y, double z,
                                  const Eigen::Vector3d& translation) {
  const double norm = std::sqrt(w * w + x * x + y * y + z * z);
  if (!(norm > 0.0) || !std::isfinite(norm)) {
    throw InputError("quaternion", "must be finite and not zero");
  }
  w /= norm, x /= norm, y /= norm, z /= norm;
  BodyPose pose;
  pose.rotation << 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
      2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x), 2 * (x * z - w * y),
      2 * (y * z + w * x), 1 - 2 * (x * x + y * y);
  pose.translation = translation;
  return pose;
}

BodyPose BodyPose::Planar(double angle, double tx, double ty) {
  BodyPose pose;
  const double c = std::cos(angle), s = std::sin(angle);
  pose.rotation << c, -s, 0, s, c, 0, 0, 0, 1;
  pose.translation << tx, ty, 0.0;
  return pose;
}

namespace {

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

}  // namespace

StrandBatch::StrandBatch(const std::vector<Points>& strands, const StrandOptions& options,
                         const BodyPose& rest)
    : impl_(std::make_unique<internal::StrandBatchImpl>()) {
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
  m.links.resize(count);
  for (int i = 0; i < count; ++i) m.links[i] = static_cast<int>(strands[i].rows()) - 1;
  // Strands of one link count side by side, in the order given.
  std::vector<int> order(count);
  for (int i = 0; i < count; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return m.links[a] < m.links[b]; });
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
  for (const auto& block : m.blocks) {
    for (int lane = 0; lane < L; ++lane) {
      const Points& p = strands[block.source[lane]];
      // The link lengths as MakeChain and MakeStepper compute them.
      const Eigen::VectorXd lengths = MakeChain(p).lengths;
      for (int i = 0; i <= block.n; ++i) {
        for (int k = 0; k < dim; ++k)
          m.points.data()[block.points + (i * dim + k) * L + lane] = p(i, k);
      }
      for (int i = 0; i < block.n; ++i) {
        m.lengths.data()[block.lengths + i * L + lane] = lengths[i];
        m.inv_lengths.data()[block.lengths + i * L + lane] = 1.0 / lengths[i];
      }
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
    m.engine = "avx512";
  } else if (internal::AllowedSimd().avx2_fma) {
    m.sweeps = internal::StrandSweepsAvx2;
    m.engine = "avx2";
  }
#endif
  // Threads: contiguous runs of blocks of about equal work (links times sub-steps).
  int threads = options.threads == 0
                    ? std::max(1, static_cast<int>(std::thread::hardware_concurrency()))
                    : options.threads;
  threads = std::max(1, std::min(threads, static_cast<int>(m.blocks.size())));
  double total = 0.0;
  for (const auto& block : m.blocks) total += block.n + 1;
  m.first_block.assign(threads + 1, static_cast<int>(m.blocks.size()));
  m.first_block[0] = 0;
  double done = 0.0;
  int t = 1;
  for (int b = 0; b < static_cast<int>(m.blocks.size()) && t < threads; ++b) {
    done += m.blocks[b].n + 1;
    if (done >= total * t / threads) m.first_block[t++] = b + 1;
  }
  for (int i = 0; i < threads; ++i) {
    m.scratch.emplace_back(static_cast<size_t>(options.substeps + 1) * std::max(dim, 1) * L);
  }
  m.pool = std::make_unique<internal::WorkerPool>(threads);
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
  auto& m = batch->impl();
  if (m.blocks.empty()) return;
  ValidatePose(pose, m.dim);
  m.pose = &pose;
  m.roots = nullptr;
  m.pool->Run(internal::StrandBatchImpl::Job, &m);
  m.pose = nullptr;
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
  m.roots = roots.data();
  m.roots_stride = roots.outerStride();
  m.pose = nullptr;
  m.pool->Run(internal::StrandBatchImpl::Job, &m);
  m.roots = nullptr;
}

}  // namespace flexkin

namespace flexkin::internal {

bool SetStrandEngine(StrandBatch* batch, const char* name) {
  const std::string engine = name;
  StrandSweepsFn fn = nullptr;
  if (engine == "scalar") fn = StrandSweepsScalar;
#if FLEXKIN_HAVE_WAVEFRONT
  if (engine == "avx2" && CpuSimd().avx2_fma) fn = StrandSweepsAvx2;
  if (engine == "avx512" && CpuSimd().avx512) fn = StrandSweepsAvx512;
#endif
  if (fn == nullptr) return false;
  batch->impl().sweeps = fn;
  batch->impl().engine = engine == "scalar" ? "scalar" : engine == "avx2" ? "avx2" : "avx512";
  return true;
}

}  // namespace flexkin::internal
