#include "flexkin/propagate.h"

#include <cassert>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "chain/denormals.h"
#include "chain/simd.h"
#include "chain/substep.h"
#include "flexkin/error.h"
#include "sequential/link_rules.h"
#include "sequential/move_checks.h"
#include "sequential/rule_table.h"
#include "sequential/sweep.h"
#include "sequential/whole_chain.h"

namespace flexkin {
namespace {

template <class Rule, int Dim>
void Sweeps(const double* heads, int64_t num_sweeps, const double* lengths,
            const double* inv_lengths, int n, double* pts) {
  for (int64_t s = 0; s < num_sweeps; ++s) {
    double lead_old[Dim], lead_new[Dim];
    for (int k = 0; k < Dim; ++k) {
      lead_old[k] = pts[k];
      pts[k] = lead_new[k] = heads[s * Dim + k];
    }
    // Link i's leading end (point i-1) has just moved from lead_old to lead_new.
    for (int i = 1; i <= n; ++i) {
      double* tail = pts + i * Dim;
      double tail_old[Dim];
      for (int k = 0; k < Dim; ++k) tail_old[k] = tail[k];
      internal::ApplyScalar<Rule, Dim>(lead_old, lead_new, tail, lengths[i - 1],
                                       inv_lengths[i - 1]);
      for (int k = 0; k < Dim; ++k) lead_old[k] = tail_old[k], lead_new[k] = tail[k];
    }
  }
}

// The one-pass loop, observed (SweepTrace). The distance a point moves and a link's length are
// computed as (d0 d0 + d1 d1) + d2 d2, the order Eigen's norm() uses for these rows, so that the
// exact accounting gives the metrics of the sub-step by sub-step run bit for bit.
template <int Dim>
inline double Distance(const double* a, const double* b) {
  double q = 0.0;
  for (int k = 0; k < Dim; ++k) q += (a[k] - b[k]) * (a[k] - b[k]);
  return std::sqrt(q);
}

template <class Rule, int Dim>
void TracedSweeps(const double* heads, int64_t first, int64_t num_sweeps, const double* lengths,
                  const double* inv_lengths, int n, double* pts, internal::SweepTrace* trace) {
  const bool exact = trace->moved != nullptr;
  internal::SweepContact* contact = trace->contact;
  for (int64_t s = first; s < num_sweeps; ++s) {
    const uint8_t flag = trace->flags[s];
    const bool check_lengths = !exact && (flag & internal::SweepTrace::kStepEnd);
    double lead_old[Dim], lead_new[Dim];
    for (int k = 0; k < Dim; ++k) {
      lead_old[k] = pts[k];
      pts[k] = lead_new[k] = heads[s * Dim + k];
    }
    // With colliders, the set ContactSweep takes for this sweep, and its steps.
    if (contact != nullptr) internal::NearSweepSet(Dim, heads + s * Dim, 0.0, lengths, n, contact);
    double l2 = 0.0, l2w = 0.0, worst = trace->max_length_error;
    auto account = [&](int j, const double* before, const double* after) {
      const double moved = Distance<Dim>(after, before);
      if (exact) {
        trace->moved[j] += moved;
      } else {
        l2 += moved;
        l2w += moved * trace->weights[j];
        trace->path_length[j] += moved;
      }
    };
    account(0, lead_old, lead_new);
    for (int i = 1; i <= n; ++i) {
      double* tail = pts + i * Dim;
      double tail_old[Dim];
      for (int k = 0; k < Dim; ++k) tail_old[k] = tail[k];
      internal::ApplyScalar<Rule, Dim>(lead_old, lead_new, tail, lengths[i - 1],
                                       inv_lengths[i - 1]);
      if (contact != nullptr) {
        internal::KeepLinkOutside(Dim, i, lead_new, tail_old, tail, lengths[i - 1],
                                  inv_lengths[i - 1], contact);
      }
      account(i, tail_old, tail);
      if (check_lengths) {
        const double error = std::fabs(Distance<Dim>(tail, lead_new) - lengths[i - 1]);
        worst = std::fmax(worst, error * inv_lengths[i - 1]);
      }
      for (int k = 0; k < Dim; ++k) lead_old[k] = tail_old[k], lead_new[k] = tail[k];
    }
    if (!exact) {
      trace->sweep_l2[s] = l2;
      trace->sweep_l2w[s] = l2w;
      trace->max_length_error = worst;
    }
    if (flag & internal::SweepTrace::kCapture) trace->capture(trace->context, s, -1);
  }
}

}  // namespace

namespace internal {

void TracedSweepsScalarFrom(Method method, int dim, const double* heads, int64_t first,
                            int64_t num_sweeps, const double* lengths, const double* inv_lengths,
                            int n, double* pts, SweepTrace* trace) {
  const SubnormalsAsZero subnormals;
  DispatchRule<kSweepsEngine>(method, [&](auto rule) {
    using Rule = decltype(rule);
    dim == 2 ? TracedSweeps<typename Rule::template Step<2>, 2>(heads, first, num_sweeps, lengths,
                                                                inv_lengths, n, pts, trace)
             : TracedSweeps<typename Rule::template Step<3>, 3>(heads, first, num_sweeps, lengths,
                                                                inv_lengths, n, pts, trace);
  });
}

void TracedSweepsScalar(Method method, int dim, const double* heads, int64_t num_sweeps,
                        const double* lengths, const double* inv_lengths, int n, double* pts,
                        SweepTrace* trace) {
  TracedSweepsScalarFrom(method, dim, heads, 0, num_sweeps, lengths, inv_lengths, n, pts, trace);
}

#if FLEXKIN_HAVE_WAVEFRONT
void SweepsWavefrontAvx2(Method, int, const double*, int64_t, const double*, const double*, int,
                         double*);
void SweepsWavefrontAvx512(Method, int, const double*, int64_t, const double*, const double*, int,
                           double*);
void Atan2OfSqrtAvx2(const double*, const double*, int64_t, double*);
void Atan2OfSqrtAvx512(const double*, const double*, int64_t, double*);
void TracedSweepsWavefrontAvx2(Method, int, const double*, int64_t, const double*, const double*,
                               int, double*, SweepTrace*);
void TracedSweepsWavefrontAvx512(Method, int, const double*, int64_t, const double*, const double*,
                                 int, double*, SweepTrace*);
void WholeChainSweepsAvx2(int64_t, WholeChainWork*, double*, SweepTrace*);
void WholeChainSweepsAvx512(int64_t, WholeChainWork*, double*, SweepTrace*);

namespace {
struct WavefrontChoice {
  SweepsFn fn;
  TracedSweepsFn traced;
  void (*atan2_of_sqrt)(const double*, const double*, int64_t, double*);
  WholeChainKernelFn whole_chain;
  int lanes;
};
// The widest engine AllowedSimd() permits (src/chain/simd.h). Without AVX2 and FMA there is no
// wavefront (lanes = 1) and every move takes the one-pass loop.
WavefrontChoice ChooseWavefront() {
  if (AllowedSimd().avx512) {
    return {SweepsWavefrontAvx512, TracedSweepsWavefrontAvx512, Atan2OfSqrtAvx512,
            WholeChainSweepsAvx512, 8};
  }
  if (AllowedSimd().avx2_fma) {
    return {SweepsWavefrontAvx2, TracedSweepsWavefrontAvx2, Atan2OfSqrtAvx2, WholeChainSweepsAvx2,
            4};
  }
  return {nullptr, nullptr, nullptr, nullptr, 1};
}
const WavefrontChoice& Wavefront() {
  static const WavefrontChoice choice = ChooseWavefront();
  return choice;
}
}  // namespace
#endif

void SweepsScalar(Method method, int dim, const double* heads, int64_t num_sweeps,
                  const double* lengths, const double* inv_lengths, int n, double* pts) {
  const SubnormalsAsZero subnormals;
  DispatchRule<kSweepsEngine>(method, [&](auto rule) {
    using Rule = decltype(rule);
    dim == 2 ? Sweeps<typename Rule::template Step<2>, 2>(heads, num_sweeps, lengths, inv_lengths,
                                                          n, pts)
             : Sweeps<typename Rule::template Step<3>, 3>(heads, num_sweeps, lengths, inv_lengths,
                                                          n, pts);
  });
}

void SweepsWavefront(Method method, int dim, const double* heads, int64_t num_sweeps,
                     const double* lengths, const double* inv_lengths, int n, double* pts) {
#if FLEXKIN_HAVE_WAVEFRONT
  if (Wavefront().fn != nullptr) {
    const SubnormalsAsZero subnormals;
    Wavefront().fn(method, dim, heads, num_sweeps, lengths, inv_lengths, n, pts);
    return;
  }
#endif
  SweepsScalar(method, dim, heads, num_sweeps, lengths, inv_lengths, n, pts);
}

void TracedSweepsWavefront(Method method, int dim, const double* heads, int64_t num_sweeps,
                           const double* lengths, const double* inv_lengths, int n, double* pts,
                           SweepTrace* trace) {
#if FLEXKIN_HAVE_WAVEFRONT
  if (Wavefront().traced != nullptr && trace->moved == nullptr) {
    const SubnormalsAsZero subnormals;
    Wavefront().traced(method, dim, heads, num_sweeps, lengths, inv_lengths, n, pts, trace);
    return;
  }
#endif
  TracedSweepsScalar(method, dim, heads, num_sweeps, lengths, inv_lengths, n, pts, trace);
}

void Atan2OfSqrt(const double* across2, const double* along, int64_t count, double* out) {
#if FLEXKIN_HAVE_WAVEFRONT
  if (Wavefront().atan2_of_sqrt != nullptr) {
    Wavefront().atan2_of_sqrt(across2, along, count, out);
    return;
  }
#endif
  for (int64_t i = 0; i < count; ++i) out[i] = std::atan2(std::sqrt(across2[i]), along[i]);
}

std::vector<WavefrontEngine> AvailableWavefronts() {
  std::vector<WavefrontEngine> engines;
#if FLEXKIN_HAVE_WAVEFRONT
  if (CpuSimd().avx2_fma)
    engines.push_back({"avx2", SweepsWavefrontAvx2, TracedSweepsWavefrontAvx2, 4});
  if (CpuSimd().avx512)
    engines.push_back({"avx512", SweepsWavefrontAvx512, TracedSweepsWavefrontAvx512, 8});
#endif
  return engines;
}

WholeChainKernelFn WholeChainKernel() {
#if FLEXKIN_HAVE_WAVEFRONT
  return Wavefront().whole_chain;
#else
  return nullptr;
#endif
}

bool WholeChainOnSimd() { return WholeChainKernel() != nullptr; }

int WavefrontLanes() {
#if FLEXKIN_HAVE_WAVEFRONT
  return Wavefront().lanes;
#else
  return 1;
#endif
}

}  // namespace internal

int MethodOrder(Method method) { return internal::RuleOrder(method); }

Stepper MakeStepper(Method method, const Chain& chain) {
  ValidateChain(chain);
  if (!internal::RuleRunsOn(method, ~0u)) {
    throw InputError("method", std::string("\"") + MethodName(method) +
                                   "\" is not a link rule; move the chain with Run (\"overall\" "
                                   "also with OverallStep, overall.h), or use " +
                                   QuotedList(internal::RuleNamesOn(~0u)));
  }
  return internal::MakeStepperUnchecked(method, chain);
}

Stepper internal::MakeStepperUnchecked(Method method, const Chain& chain) {
  assert(internal::RuleRunsOn(method, ~0u));
  Stepper s;
  s.method = method;
  s.dim = chain.dim();
  s.lengths = chain.lengths;
  s.inv_lengths = chain.lengths.cwiseInverse();
  return s;
}

namespace internal {

void CheckMove(const Eigen::Ref<const Eigen::VectorXd>& target, int dim, int substeps,
               const char* body) {
  if (target.size() != dim) {
    throw InputError("target", "has " + std::to_string(target.size()) + " coordinates; the " +
                                   body + " is " + std::to_string(dim) + "D");
  }
  for (int k = 0; k < dim; ++k) {
    if (!std::isfinite(target[k])) {
      throw InputError("target[" + std::to_string(k) + "]", "is not a finite number");
    }
  }
  if (substeps < 1) {
    throw InputError("substeps", "is " + std::to_string(substeps) + "; must be at least 1");
  }
}

}  // namespace internal

void MoveLeader(const Stepper& stepper, const Eigen::Ref<const Eigen::VectorXd>& target,
                int substeps, Points* points) {
  internal::CheckMove(target, stepper.dim, substeps, "chain");
  if (points->rows() != stepper.lengths.size() + 1 || points->cols() != stepper.dim) {
    throw InputError("points", "shape " + std::to_string(points->rows()) + "x" +
                                   std::to_string(points->cols()) +
                                   " does not match the stepper's chain");
  }
  // Head positions of the sub-steps, interpolated from the start of the move so that the last
  // one is exactly the target.
  // (On the stack for a few sub-steps, so that a run stepping one sub-step at a time allocates
  // nothing.)
  const int dim = stepper.dim;
  const size_t count = static_cast<size_t>(substeps) * dim;
  constexpr size_t kStackHeads = 48;
  double stack_heads[kStackHeads];
  std::vector<double> heap_heads(count > kStackHeads ? count : 0);
  double* heads = count > kStackHeads ? heap_heads.data() : stack_heads;
  for (int j = 1; j <= substeps; ++j) {
    for (int k = 0; k < dim; ++k) {
      heads[(j - 1) * dim + k] = internal::SubstepHead((*points)(0, k), target[k], j, substeps);
    }
  }
  const int n = static_cast<int>(stepper.lengths.size());
  if (internal::RuleRunsOn(stepper.method, internal::kWholeChainEngine)) {
    internal::DispatchRule<internal::kWholeChainEngine>(stepper.method, [&](auto rule) {
      decltype(rule)::WholeChainSweeps(dim, heads, substeps, stepper.lengths.data(),
                                       stepper.inv_lengths.data(), n, points->data());
    });
    return;
  }
  // The wavefront pays for a copy of the chain; it wins once several sweeps share it.
  const int lanes = internal::WavefrontLanes();
  const bool wavefront = internal::RuleRunsOn(stepper.method, internal::kWavefrontEngine) &&
                         lanes > 1 && substeps >= 2 * lanes && n >= 8;
  (wavefront ? internal::SweepsWavefront : internal::SweepsScalar)(
      stepper.method, dim, heads, substeps, stepper.lengths.data(), stepper.inv_lengths.data(), n,
      points->data());
}

void MoveLeader(Method method, const Eigen::Ref<const Eigen::VectorXd>& target, int substeps,
                Chain* chain) {
  MoveLeader(MakeStepper(method, *chain), target, substeps, &chain->points);
}

}  // namespace flexkin
