// The strand engine's SIMD sweeps compiled for one instruction set. CMakeLists.txt builds this
// file once per instruction set with its flags and FLEXKIN_ISA set to 2 (AVX2+FMA) or 3
// (AVX-512); strands.cc calls it only after checking at run time that the CPU has it.
//
// Lanes run across strands: every register holds one coordinate of one point of several strands,
// and all kStrandLanes / W registers of a block are stepped together, so that the latencies of
// their (independent) rule evaluations overlap. The per-link formula is the wavefront engine's:
// the rules of sequential/link_rules.h with the vector exp of sequential/wavefront.h, and the
// scalar reference form for the rare flagged lanes.
#include <limits>
#include <xsimd/xsimd.hpp>

#include "sequential/link_rules.h"
#include "sequential/rule_table.h"
#include "sequential/wavefront.h"
#include "strands/dynamic_lanes.h"
#include "strands/strand_engine.h"

namespace flexkin::internal {

#if FLEXKIN_ISA == 2
#define FLEXKIN_STRAND_ENTRY StrandSweepsAvx2
#define FLEXKIN_SPHERE_ENTRY StrandSphereSweepAvx2
#define FLEXKIN_BOUNDS_ENTRY StrandBoundsAvx2
#define FLEXKIN_CHECK_ENTRY StrandSphereCheckAvx2
#define FLEXKIN_DYNAMIC_ENTRY StrandDynamicAvx2
using Arch = xsimd::fma3<xsimd::avx2>;
#elif FLEXKIN_ISA == 3
#define FLEXKIN_STRAND_ENTRY StrandSweepsAvx512
#define FLEXKIN_SPHERE_ENTRY StrandSphereSweepAvx512
#define FLEXKIN_BOUNDS_ENTRY StrandBoundsAvx512
#define FLEXKIN_CHECK_ENTRY StrandSphereCheckAvx512
#define FLEXKIN_DYNAMIC_ENTRY StrandDynamicAvx512
using Arch = xsimd::avx512f;
#else
#error "FLEXKIN_ISA must be 2 or 3"
#endif

namespace {

// One link's rule step in W lanes: `tail` (holding the old trailing end `old`) moved behind its
// leading end from `lead_old` to `lead_new`. The per-link formula is the wavefront engine's; rare
// lanes it flags (degenerate or extreme moves) are redone with the scalar reference.
template <class Rule, class B, int Dim>
inline void RuleStep(const B* lead_old, const B* lead_new, const B* old, const double* len,
                     const double* inv, B* tail) {
  constexpr int W = B::size;
  const B length = B::load_aligned(len);
  const B neg_inv_length = -B::load_aligned(inv);
  const auto fix = Rule::Apply(lead_old, lead_new, tail, length, neg_inv_length);
  if (!xsimd::any(fix)) return;
  alignas(64) double lo[Dim][W], ln[Dim][W], was[Dim][W], out[Dim][W], mask[W];
  for (int k = 0; k < Dim; ++k) {
    lead_old[k].store_aligned(lo[k]);
    lead_new[k].store_aligned(ln[k]);
    old[k].store_aligned(was[k]);
    tail[k].store_aligned(out[k]);
  }
  xsimd::select(fix, B(1.0), B(0.0)).store_aligned(mask);
  for (int j = 0; j < W; ++j) {
    if (mask[j] == 0.0) continue;
    double a[Dim], b[Dim], c[Dim];
    for (int k = 0; k < Dim; ++k) a[k] = lo[k][j], b[k] = ln[k][j], c[k] = was[k][j];
    Rule::Reference(a, b, c, len[j]);
    for (int k = 0; k < Dim; ++k) out[k][j] = c[k];
  }
  for (int k = 0; k < Dim; ++k) tail[k] = B::load_aligned(out[k]);
}

template <class Rule, int Dim>
void BlockSweeps(int n, int head, int num_sweeps, const double* heads, const double* lengths,
                 const double* inv_lengths, double* points) {
  using B = xsimd::batch<double, Arch>;
  constexpr int W = B::size;
  constexpr int U = kStrandLanes / W;
  constexpr int L = kStrandLanes;
  for (int s = 0; s < num_sweeps; ++s) {
    B lead_old[U][Dim], lead_new[U][Dim];
    double* lead = points + head * Dim * L;
    for (int u = 0; u < U; ++u) {
      for (int k = 0; k < Dim; ++k) {
        lead_old[u][k] = B::load_aligned(lead + k * L + u * W);
        lead_new[u][k] = B::load_aligned(heads + (s * Dim + k) * L + u * W);
        lead_new[u][k].store_aligned(lead + k * L + u * W);
      }
    }
    for (int i = head + 1; i <= n; ++i) {
      double* tail_ptr = points + i * Dim * L;
      const double* len_ptr = lengths + (i - 1) * L;
      const double* inv_ptr = inv_lengths + (i - 1) * L;
      for (int u = 0; u < U; ++u) {
        B old[Dim], tail[Dim];
        for (int k = 0; k < Dim; ++k) {
          old[k] = tail[k] = B::load_aligned(tail_ptr + k * L + u * W);
        }
        RuleStep<Rule, B, Dim>(lead_old[u], lead_new[u], old, len_ptr + u * W, inv_ptr + u * W,
                               tail);
        for (int k = 0; k < Dim; ++k) {
          tail[k].store_aligned(tail_ptr + k * L + u * W);
          lead_old[u][k] = old[k];
          lead_new[u][k] = tail[k];
        }
      }
    }
  }
}

// The least distance of the segment [h, h + ab] to `c`, less `r`: the sphere's clearance.
template <class B, int Dim>
__attribute__((always_inline)) inline B SphereClearance(const B* h, const B* ab, const B* c,
                                                        const B& r) {
  B dot(0.0), ab2(0.0);
  for (int k = 0; k < Dim; ++k) {
    dot += ab[k] * (c[k] - h[k]);
    ab2 += ab[k] * ab[k];
  }
  const B t = xsimd::max(B(0.0), xsimd::min(dot / ab2, B(1.0)));
  B d2(0.0);
  for (int k = 0; k < Dim; ++k) {
    const B e = h[k] + t * ab[k] - c[k];
    d2 += e * e;
  }
  return xsimd::sqrt(d2) - r;
}

// The segment [h, h + ab] against a sphere's centre `c`, without a division or a root: its
// least squared distance to the centre times |ab|^2 (`scaled`, the nearest point at t = dot / ab2
// clamped to the segment), and what it is made from.
template <class B>
struct SegmentMeasure {
  B ab2, e2, scaled;
};
template <class B, int Dim>
__attribute__((always_inline)) inline SegmentMeasure<B> MeasureSegment(const B* h, const B* ab,
                                                                       const B* c) {
  B dot(0.0), ab2(0.0), e2(0.0), f2(0.0);
  for (int k = 0; k < Dim; ++k) {
    const B e = c[k] - h[k];  // the centre from the segment's start
    const B f = e - ab[k];    // and from its end
    dot += ab[k] * e;
    ab2 += ab[k] * ab[k];
    e2 += e * e;
    f2 += f * f;
  }
  const B scaled = xsimd::select(dot <= B(0.0), e2 * ab2,
                                 xsimd::select(dot >= ab2, f2 * ab2, e2 * ab2 - dot * dot));
  return {ab2, e2, scaled};
}

// Whether the measured segment comes nearer the centre than `inner` (the sphere's radius less the
// slack: the lanes where its clearance is below -slack), NaN lanes included: its least squared
// distance times |ab|^2 against inner^2 |ab|^2.
template <class B>
__attribute__((always_inline)) inline typename B::batch_bool_type SphereEnters(
    const SegmentMeasure<B>& m, const B& inner) {
  return (inner > B(0.0)) & !(m.scaled >= inner * inner * m.ab2);
}
template <class B, int Dim>
__attribute__((always_inline)) inline typename B::batch_bool_type SphereEnters(const B* h,
                                                                               const B* ab,
                                                                               const B* c,
                                                                               const B& inner) {
  return SphereEnters<B>(MeasureSegment<B, Dim>(h, ab, c), inner);
}

// The contact step of lanes `enter` of one link against the sphere (strand_engine.h): the new
// trailing end into `tail`, the lanes it could not step in `bad`.
template <class B, int Dim>
void SphereContact(const B* h, const B* old, const B& length, const B& inv_length, const B* c,
                   const B& r, const B& slack, B* tail, typename B::batch_bool_type* bad) {
  using Bool = typename B::batch_bool_type;
  const B inner = r - slack * length;
  // The direction of the old trailing end.
  B d0[Dim], n0(0.0);
  for (int k = 0; k < Dim; ++k) {
    d0[k] = old[k] - h[k];
    n0 += d0[k] * d0[k];
  }
  n0 = xsimd::sqrt(n0);
  Bool no = !(n0 > B(0.0));
  const B inv_n0 = B(1.0) / n0;
  for (int k = 0; k < Dim; ++k) d0[k] *= inv_n0;
  B along[Dim], step[Dim];
  for (int k = 0; k < Dim; ++k) {
    along[k] = h[k] + length * d0[k];
    step[k] = along[k] - h[k];
  }
  const Bool blocked = SphereEnters<B, Dim>(h, step, c, inner);
  // The cone the sphere blocks, about u, the direction of its centre.
  B u[Dim], D2(0.0);
  for (int k = 0; k < Dim; ++k) {
    u[k] = c[k] - h[k];
    D2 += u[k] * u[k];
  }
  const B D = xsimd::sqrt(D2);
  const B inv_D = B(1.0) / D;
  for (int k = 0; k < Dim; ++k) u[k] *= inv_D;
  const Bool on_surface = D <= r;
  no = no | (on_surface & (r - D > slack * length)) | !(D > B(0.0));
  const B tangent = xsimd::sqrt(xsimd::max((D - r) * (D + r), B(0.0)));
  const Bool reach = length >= tangent;
  B sin_a = xsimd::select(on_surface, B(1.0), r * inv_D);
  B cos_a = xsimd::select(on_surface, B(0.0), tangent * inv_D);
  const Bool far = !(on_surface | reach);
  if (xsimd::any(far)) {
    // The link cannot reach the tangent point: the cone of the directions whose end touches the
    // sphere.
    const B cos_far = xsimd::max(
        B(-1.0),
        xsimd::min((D2 + length * length - r * r) * (B(0.5) * inv_length * inv_D), B(1.0)));
    const B sin_far = xsimd::sqrt((B(1.0) - cos_far) * (B(1.0) + cos_far));
    sin_a = xsimd::select(far, sin_far, sin_a);
    cos_a = xsimd::select(far, cos_far, cos_a);
  }
  B du(0.0);
  for (int k = 0; k < Dim; ++k) du += d0[k] * u[k];
  B w[Dim], wn(0.0), wu(0.0);
  for (int k = 0; k < Dim; ++k) w[k] = d0[k] - du * u[k];
  // Again (Gram-Schmidt twice): where the old direction points nearly at the centre, w is small
  // and its first pass leaves it off the perpendicular by eps / |w|, which would change the
  // link's length by as much.
  for (int k = 0; k < Dim; ++k) wu += w[k] * u[k];
  for (int k = 0; k < Dim; ++k) {
    w[k] -= wu * u[k];
    wn += w[k] * w[k];
  }
  wn = xsimd::sqrt(wn);
  no = no | (blocked & !(wn > B(1e-300)));
  const B sin_w = sin_a / wn;
  B x[Dim];
  for (int k = 0; k < Dim; ++k) {
    const B exit = h[k] + length * (cos_a * u[k] + sin_w * w[k]);
    x[k] = xsimd::select(blocked, exit, along[k]);
    step[k] = x[k] - h[k];
  }
  no = no | SphereEnters<B, Dim>(h, step, c, inner);
  for (int k = 0; k < Dim; ++k) tail[k] = xsimd::select(no, old[k], x[k]);
  *bad = no;
}

// The check of one sphere after a sweep (StrandSphereCheckFn) for the W lanes of a register, link
// by link: what it has found so far, and the next link.
template <class B, int Dim>
struct SphereCheckLanes {
  using Bool = typename B::batch_bool_type;
  B c[Dim], r, slack;
  B least, first;                                      // as the caller's arrays
  B own = B(std::numeric_limits<double>::infinity());  // this sphere's least so far
  Bool near = B(0.0) != B(0.0);

  // From the answers so far (other colliders'), at `least` and `first_enter`.
  void Init(const double* center, double radius, double slack_value, const double* least_in,
            const int* first_enter) {
    for (int k = 0; k < Dim; ++k) c[k] = B(center[k]);
    r = B(radius);
    slack = B(slack_value);
    alignas(64) double first_in[B::size];
    for (int j = 0; j < B::size; ++j) first_in[j] = first_enter[j];
    least = B::load_unaligned(least_in);
    first = B::load_aligned(first_in);
  }
  // Link i, from pa along ab (measured in m); its length and inverse at len and inv.
  __attribute__((always_inline)) void Link(int i, const B* pa, const B* ab,
                                           const SegmentMeasure<B>& m, const double* len_ptr,
                                           const double* inv_ptr) {
    const B len = B::load_aligned(len_ptr);
    // The squared distance times |ab|^2, as SphereEnters, against the least this sphere can
    // still lower (its own least, or the length before any), widened past the rounding of both
    // (the cancellation e2 ab2 - dot^2 loses up to a few ulps of e2 ab2).
    const B reach = r + len * xsimd::min(own, B(1.0));
    const auto skip = (reach > B(0.0)) &
                      (m.scaled > reach * reach * m.ab2 * B(1.0 + 1e-9) + B(1e-12) * m.e2 * m.ab2);
    if (xsimd::all(skip)) return;
    const B clear = SphereClearance<B, Dim>(pa, ab, c, r);
    const B rel = clear * B::load_aligned(inv_ptr);
    const auto is_near = clear < len;
    near = near | is_near;
    first = xsimd::select(is_near & (clear < -slack * len) & (B(static_cast<double>(i)) < first),
                          B(static_cast<double>(i)), first);
    least = xsimd::select(is_near & (rel < least), rel, least);
    own = xsimd::select(is_near & (rel < own), rel, own);
  }
  void Store(double* least_out, int* first_enter, uint8_t* near_out) const {
    alignas(64) double first_out[B::size], near_lanes[B::size];
    least.store_unaligned(least_out);
    first.store_aligned(first_out);
    xsimd::select(near, B(1.0), B(0.0)).store_aligned(near_lanes);
    for (int j = 0; j < B::size; ++j) {
      first_enter[j] = static_cast<int>(first_out[j]);
      near_out[j] = near_lanes[j] != 0.0;
    }
  }
};

template <class Rule, int Dim>
void BlockSphereSweep(int n, int head, const double* heads, const double* lengths,
                      const double* inv_lengths, double* points, const StrandSphere& sphere,
                      uint8_t* contact, int* fallback, double* saved, StrandSphereFound* found) {
  using B = xsimd::batch<double, Arch>;
  constexpr int W = B::size;
  constexpr int U = kStrandLanes / W;
  constexpr int L = kStrandLanes;
  B c[Dim];
  for (int k = 0; k < Dim; ++k) c[k] = B(sphere.center[k]);
  const B r(sphere.radius), slack(sphere.slack);
  // The check after the sweep, link by link as the sweep leaves each.
  for (int j = 0; j < L; ++j) {
    found->least[j] = std::numeric_limits<double>::infinity();
    found->first_enter[j] = n + 1;
  }
  SphereCheckLanes<B, Dim> checks[U];
  for (int u = 0; u < U; ++u) {
    checks[u].Init(sphere.center, sphere.radius, sphere.slack, found->least + u * W,
                   found->first_enter + u * W);
  }
  B contacts[U];  // per lane, the links that took the contact step
  for (int u = 0; u < U; ++u) contacts[u] = B(0.0);
  B lead_old[U][Dim], lead_new[U][Dim];
  double* lead = points + head * Dim * L;
  for (int u = 0; u < U; ++u) {
    for (int k = 0; k < Dim; ++k) {
      lead_old[u][k] = B::load_aligned(lead + k * L + u * W);
      lead_old[u][k].store_unaligned(saved + k * L + u * W);
      lead_new[u][k] = B::load_aligned(heads + k * L + u * W);
      lead_new[u][k].store_aligned(lead + k * L + u * W);
    }
  }
  for (int i = head + 1; i <= n; ++i) {
    double* tail_ptr = points + i * Dim * L;
    const double* len_ptr = lengths + (i - 1) * L;
    const double* inv_ptr = inv_lengths + (i - 1) * L;
    uint8_t* flags = contact + i * L;
    double* saved_ptr = saved + (i - head) * Dim * L;
    // The rule steps of the registers first, side by side (independent: their latencies overlap),
    // then the sphere's test and contact step of each.
    B old[U][Dim], tail[U][Dim];
    for (int u = 0; u < U; ++u) {
      for (int k = 0; k < Dim; ++k) {
        old[u][k] = tail[u][k] = B::load_aligned(tail_ptr + k * L + u * W);
        old[u][k].store_unaligned(saved_ptr + k * L + u * W);
      }
      RuleStep<Rule, B, Dim>(lead_old[u], lead_new[u], old[u], len_ptr + u * W, inv_ptr + u * W,
                             tail[u]);
    }
    // The sphere: lanes whose rule step enters it take the contact step. The registers' tests
    // first, then their contact steps one after another (independent: their latencies overlap),
    // then the check of each link as it stands.
    SegmentMeasure<B> m[U];
    typename B::batch_bool_type enter[U];
    bool any_enter[U];
    for (int u = 0; u < U; ++u) {
      const B length = B::load_aligned(len_ptr + u * W);
      B step[Dim];
      for (int k = 0; k < Dim; ++k) step[k] = tail[u][k] - lead_new[u][k];
      m[u] = MeasureSegment<B, Dim>(lead_new[u], step, c);
      enter[u] = SphereEnters<B>(m[u], r - slack * length);
      any_enter[u] = xsimd::any(enter[u]);
      const B entered_lanes = xsimd::select(enter[u], B(1.0), B(0.0));
      contacts[u] += entered_lanes;
      alignas(64) double entered[W];
      entered_lanes.store_aligned(entered);
      for (int j = 0; j < W; ++j) flags[u * W + j] = entered[j] != 0.0;
    }
    for (int u = 0; u < U; ++u) {
      if (!any_enter[u]) continue;
      B moved[Dim];
      typename B::batch_bool_type bad;
      SphereContact<B, Dim>(lead_new[u], old[u], B::load_aligned(len_ptr + u * W),
                            B::load_aligned(inv_ptr + u * W), c, r, slack, moved, &bad);
      for (int k = 0; k < Dim; ++k) tail[u][k] = xsimd::select(enter[u], moved[k], tail[u][k]);
      alignas(64) double failed[W];
      xsimd::select(enter[u] & bad, B(1.0), B(0.0)).store_aligned(failed);
      for (int j = 0; j < W; ++j) {
        if (failed[j] != 0.0 && fallback[u * W + j] > i) fallback[u * W + j] = i;
      }
    }
    for (int u = 0; u < U; ++u) {
      // The check takes the link as it stands: the rule step's, measured above, unless a lane
      // took the contact step.
      B ab[Dim];
      for (int k = 0; k < Dim; ++k) {
        tail[u][k].store_aligned(tail_ptr + k * L + u * W);
        ab[k] = tail[u][k] - lead_new[u][k];
      }
      if (any_enter[u]) m[u] = MeasureSegment<B, Dim>(lead_new[u], ab, c);
      checks[u].Link(i, lead_new[u], ab, m[u], len_ptr + u * W, inv_ptr + u * W);
      for (int k = 0; k < Dim; ++k) {
        lead_old[u][k] = old[u][k];
        lead_new[u][k] = tail[u][k];
      }
    }
  }
  for (int u = 0; u < U; ++u) {
    checks[u].Store(found->least + u * W, found->first_enter + u * W, found->near + u * W);
    alignas(64) double counted[W];
    contacts[u].store_aligned(counted);
    for (int j = 0; j < W; ++j) found->contacts[u * W + j] = static_cast<int>(counted[j]);
  }
}

template <int Dim>
void LinkBounds(int n, int head, const double* points, const ColliderBound* bounds, int num_bounds,
                double* clearances) {
  using B = xsimd::batch<double, Arch>;
  constexpr int W = B::size;
  constexpr int L = kStrandLanes;
  for (int i = head + 1; i <= n; ++i) {
    const double* a = points + (i - 1) * Dim * L;
    const double* b = points + i * Dim * L;
    double* out = clearances + static_cast<size_t>(i - head - 1) * num_bounds * L;
    for (int u = 0; u < L; u += W) {
      B pa[Dim], ab[Dim];
      for (int k = 0; k < Dim; ++k) {
        pa[k] = B::load_aligned(a + k * L + u);
        ab[k] = B::load_aligned(b + k * L + u) - pa[k];
      }
      for (int c = 0; c < num_bounds; ++c) {
        const ColliderBound& bound = bounds[c];
        B clear;
        if (bound.half_space) {
          B da(0.0), db(0.0);
          for (int k = 0; k < Dim; ++k) {
            const B h = pa[k] - B(bound.center[k]);
            da += B(bound.up[k]) * h;
            db += B(bound.up[k]) * (h + ab[k]);
          }
          clear = xsimd::min(da, db);
        } else {
          B center[Dim];
          for (int k = 0; k < Dim; ++k) center[k] = B(bound.center[k]);
          clear = SphereClearance<B, Dim>(pa, ab, center, B(bound.radius));
        }
        clear.store_unaligned(out + c * L + u);
      }
    }
  }
}

template <int Dim>
void SphereCheck(int n, int head, const double* points, const double* lengths,
                 const double* inv_lengths, const ColliderBound& bound, double slack, double* least,
                 int* first_enter, uint8_t* near) {
  using B = xsimd::batch<double, Arch>;
  constexpr int W = B::size;
  constexpr int L = kStrandLanes;
  for (int u = 0; u < L; u += W) {
    SphereCheckLanes<B, Dim> check;
    check.Init(bound.center, bound.radius, slack, least + u, first_enter + u);
    for (int i = head + 1; i <= n; ++i) {
      const double* a = points + (i - 1) * Dim * L + u;
      const double* b = points + i * Dim * L + u;
      B pa[Dim], ab[Dim];
      for (int k = 0; k < Dim; ++k) {
        pa[k] = B::load_aligned(a + k * L);
        ab[k] = B::load_aligned(b + k * L) - pa[k];
      }
      const SegmentMeasure<B> m = MeasureSegment<B, Dim>(pa, ab, check.c);
      check.Link(i, pa, ab, m, lengths + (i - 1) * L + u, inv_lengths + (i - 1) * L + u);
    }
    check.Store(least + u, first_enter + u, near + u);
  }
}

}  // namespace

void FLEXKIN_CHECK_ENTRY(int dim, int n, int head, const double* points, const double* lengths,
                         const double* inv_lengths, const ColliderBound& bound, double slack,
                         double* least, int* first_enter, uint8_t* near) {
  dim == 2 ? SphereCheck<2>(n, head, points, lengths, inv_lengths, bound, slack, least, first_enter,
                            near)
           : SphereCheck<3>(n, head, points, lengths, inv_lengths, bound, slack, least, first_enter,
                            near);
}

void FLEXKIN_BOUNDS_ENTRY(int dim, int n, int head, const double* points,
                          const ColliderBound* bounds, int num_bounds, double* clearances) {
  dim == 2 ? LinkBounds<2>(n, head, points, bounds, num_bounds, clearances)
           : LinkBounds<3>(n, head, points, bounds, num_bounds, clearances);
}

void FLEXKIN_SPHERE_ENTRY(Method method, int dim, int n, int head, const double* heads,
                          const double* lengths, const double* inv_lengths, double* points,
                          const StrandSphere& sphere, uint8_t* contact, int* fallback,
                          double* saved, StrandSphereFound* found) {
  DispatchRule<kStrandEngine>(method, [&](auto rule) {
    using Rule = decltype(rule);
    dim == 2
        ? BlockSphereSweep<typename Rule::template Step<2, BatchExp>, 2>(
              n, head, heads, lengths, inv_lengths, points, sphere, contact, fallback, saved, found)
        : BlockSphereSweep<typename Rule::template Step<3, BatchExp>, 3>(
              n, head, heads, lengths, inv_lengths, points, sphere, contact, fallback, saved,
              found);
  });
}

void FLEXKIN_STRAND_ENTRY(Method method, int dim, int n, int head, int num_sweeps,
                          const double* heads, const double* lengths, const double* inv_lengths,
                          double* points) {
  DispatchRule<kStrandEngine>(method, [&](auto rule) {
    using Rule = decltype(rule);
    dim == 2 ? BlockSweeps<typename Rule::template Step<2, BatchExp>, 2>(
                   n, head, num_sweeps, heads, lengths, inv_lengths, points)
             : BlockSweeps<typename Rule::template Step<3, BatchExp>, 3>(
                   n, head, num_sweeps, heads, lengths, inv_lengths, points);
  });
}

void FLEXKIN_DYNAMIC_ENTRY(int dim, const DynamicLaneStep& q, int stage) {
  using B = xsimd::batch<double, Arch>;
  constexpr int W = B::size;
  constexpr int L = kStrandLanes;
  const auto run = [&](auto dim_tag) {
    constexpr int Dim = decltype(dim_tag)::value;
    const auto step = [](const B* lead_old, const B* lead_new, B* tail, const double* len,
                         const double* inv) {
      B old[Dim];
      for (int k = 0; k < Dim; ++k) old[k] = tail[k];
      RuleStep<TractrixRule<Dim, BatchExp>, B, Dim>(lead_old, lead_new, old, len, inv, tail);
    };
    // The sphere's contact step in the lanes: where the projected link enters the sphere, the
    // clear direction nearest the projection's (ContactTail's, in closed form).
    const auto contact = [&](const B* lead, B* out, int i, int lane0) {
      if (q.sphere == nullptr) return;
      B c[Dim];
      for (int k = 0; k < Dim; ++k) c[k] = B(q.sphere->center[k]);
      const B r(q.sphere->radius), slack(q.sphere->slack);
      const B length = B::load_aligned(q.lengths + static_cast<size_t>(i - 1) * L + lane0);
      B step[Dim];
      for (int k = 0; k < Dim; ++k) step[k] = out[k] - lead[k];
      const auto enter = SphereEnters<B, Dim>(lead, step, c, r - slack * length);
      alignas(64) double entered[W], failed[W];
      xsimd::select(enter, B(1.0), B(0.0)).store_aligned(entered);
      if (xsimd::any(enter)) {
        B candidate[Dim], moved[Dim];
        for (int k = 0; k < Dim; ++k) candidate[k] = out[k];
        typename B::batch_bool_type bad;
        const B inv_length =
            B::load_aligned(q.inv_lengths + static_cast<size_t>(i - 1) * L + lane0);
        SphereContact<B, Dim>(lead, candidate, length, inv_length, c, r, slack, moved, &bad);
        for (int k = 0; k < Dim; ++k) out[k] = xsimd::select(enter, moved[k], out[k]);
        xsimd::select(enter & bad, B(1.0), B(0.0)).store_aligned(failed);
        for (int j = 0; j < W; ++j) {
          if (failed[j] != 0.0 && q.fallback[lane0 + j] > i) q.fallback[lane0 + j] = i;
        }
      }
      for (int j = 0; j < W; ++j) q.contact[i * L + lane0 + j] = entered[j] != 0.0;
    };
    DynamicBlock<B, Dim>(q, stage, step, contact);
  };
  dim == 2 ? run(std::integral_constant<int, 2>()) : run(std::integral_constant<int, 3>());
}

}  // namespace flexkin::internal
