#pragma once
// The dynamic strands' sub-step in the lanes (flexkin/strands.h `dynamics`, docs/dynamics.md):
// the inertial prediction of the free points, the sequential projections (tractrix, dftl) and the
// velocities, over one block's lanes, in the block's layout (strand_engine.h). Written once for
// any lane type B: `double` (one lane: the scalar engine, the very operations of SimulateChain)
// or an xsimd batch (strands_isa.cc, compiled per instruction set).
//
// Included by translation units built for different instruction sets: everything here has
// internal linkage.

#include <cmath>
#include <cstdint>

#include "dynamics/least_constraint.h"
#include "dynamics/shake.h"
#include "sequential/link_rules.h"
#include "strands/strand_engine.h"

namespace flexkin::internal {
namespace {

// The prediction of the free points (SimulateChain: p = x + h (v + h (g + c (w - v)))), and
// their start kept in x_old.
template <class B, int Dim>
inline void PredictLanes(const DynamicLaneStep& q, int lane0) {
  constexpr int L = kStrandLanes;
  const B h(q.h), c(q.damping);
  for (int i = q.head + 1; i <= q.n; ++i) {
    for (int k = 0; k < Dim; ++k) {
      const size_t at = static_cast<size_t>(i * Dim + k) * L + lane0;
      const B vel = LoadLanes(q.v + at, B());
      const B predicted = vel + h * (B(q.gravity[k]) + c * (B(q.wind[k]) - vel));
      const B x = LoadLanes(q.x + at, B());
      StoreLanes(x, q.x_old + at);
      StoreLanes(x + h * predicted, q.p + at);
    }
  }
  for (int i = 0; i <= q.head; ++i) {
    for (int k = 0; k < Dim; ++k) {
      const size_t at = static_cast<size_t>(i * Dim + k) * L + lane0;
      StoreLanes(LoadLanes(q.x + at, B()), q.p + at);
    }
  }
}

// The sequential projection of the prediction, link by link from the pinned points.
// `contact(lead, out, i, lane0)` may move `out`, link i's trailing end behind its leading end
// `lead`, out of a collider (the SIMD engines' sphere in the lanes; nothing for the scalar one).
template <class B, int Dim, class Step, class Contact>
inline void ProjectLanes(const DynamicLaneStep& q, int lane0, Step&& tractrix_step,
                         Contact&& contact) {
  constexpr int L = kStrandLanes;
  using std::sqrt;
  for (int i = q.head + 1; i <= q.n; ++i) {
    B lead_p[Dim], lead_x[Dim], pi[Dim];
    for (int k = 0; k < Dim; ++k) {
      lead_p[k] = LoadLanes(q.p + static_cast<size_t>((i - 1) * Dim + k) * L + lane0, B());
      lead_x[k] = LoadLanes(q.x + static_cast<size_t>((i - 1) * Dim + k) * L + lane0, B());
      pi[k] = LoadLanes(q.p + static_cast<size_t>(i * Dim + k) * L + lane0, B());
    }
    const double* len = q.lengths + static_cast<size_t>(i - 1) * L + lane0;
    const B length = LoadLanes(len, B());
    B out[Dim];
    if (q.tractrix) {
      // The predicted link put back to its length about its leading end's prediction, then the
      // leading end's correction carried by the tractrix step.
      B d[Dim], dd(0.0);
      for (int k = 0; k < Dim; ++k) {
        d[k] = pi[k] - lead_p[k];
        dd += d[k] * d[k];
      }
      const B f = length / sqrt(dd);
      for (int k = 0; k < Dim; ++k) out[k] = lead_p[k] + f * d[k];
      tractrix_step(lead_p, lead_x, out, len,
                    q.inv_lengths + static_cast<size_t>(i - 1) * L + lane0);
    } else {
      // Follow-the-leader: the point of the sphere about the new leading end nearest the
      // prediction.
      B d[Dim], dd(0.0);
      for (int k = 0; k < Dim; ++k) {
        d[k] = pi[k] - lead_x[k];
        dd += d[k] * d[k];
      }
      const B f = length / sqrt(dd);
      for (int k = 0; k < Dim; ++k) out[k] = lead_x[k] + f * d[k];
    }
    contact(lead_x, out, i, lane0);
    for (int k = 0; k < Dim; ++k) {
      StoreLanes(out[k], q.x + static_cast<size_t>(i * Dim + k) * L + lane0);
    }
  }
}

// The velocities of the free points: the change over the sub-step, and for the sequential
// projections Mueller et al.'s correction v_j -= s (x_{j+1} - p_{j+1}) / h (`correct`; else, if
// q.correct_lanes is set, in the lanes where it is 1).
template <class B, int Dim>
inline void VelocitiesLanes(const DynamicLaneStep& q, int lane0, bool correct) {
  constexpr int L = kStrandLanes;
  const B h(q.h);
  const B s = correct ? B(q.dftl_damping)
              : q.correct_lanes != nullptr
                  ? B(q.dftl_damping) * LoadLanes(q.correct_lanes + lane0, B())
                  : B(0.0);
  const bool any = correct || q.correct_lanes != nullptr;
  for (int i = q.head + 1; i <= q.n; ++i) {
    for (int k = 0; k < Dim; ++k) {
      const size_t at = static_cast<size_t>(i * Dim + k) * L + lane0;
      B vel = (LoadLanes(q.x + at, B()) - LoadLanes(q.x_old + at, B())) / h;
      if (any && i < q.n) {
        const size_t next = at + static_cast<size_t>(Dim) * L;
        vel = vel - (s * (LoadLanes(q.x + next, B()) - LoadLanes(q.p + next, B()))) / h;
      }
      StoreLanes(vel, q.v + at);
    }
  }
}

// The overall projection of the lanes (dynamics/least_constraint.h), from their tractrix
// projection in q.x: q.converged[lane] 1 where it converged, else 0 (that lane keeps the tractrix
// projection).
template <class B, int Dim>
inline void OverallLanes(const DynamicLaneStep& q, int lane0) {
  LeastConstraintProblem problem;
  problem.n = q.n;
  problem.head = q.head;
  problem.stride = kStrandLanes;
  problem.p = q.p + lane0;
  problem.x = q.x + lane0;
  problem.mass = q.mass + lane0;
  problem.lengths = q.lengths + lane0;
  problem.inv_lengths = q.inv_lengths + lane0;
  problem.work = q.work + lane0;
  problem.multipliers = q.multipliers + lane0;
  if (q.ignore != nullptr) problem.ignore = q.ignore + lane0;
  StoreLanes(SolveLeastConstraint<B, Dim>(problem), q.converged + lane0);
}

// The SHAKE projection of the lanes (dynamics/shake.h) from the prediction q.p and the sub-step's
// start q.x_old, into q.x: q.converged[lane] 1 where it converged, else 0 (q.x is then not
// meaningful in that lane).
template <class B, int Dim>
inline void ShakeLanes(const DynamicLaneStep& q, int lane0) {
  ShakeProblem problem;
  problem.n = q.n;
  problem.head = q.head;
  problem.stride = kStrandLanes;
  problem.p = q.p + lane0;
  problem.old = q.x_old + lane0;
  problem.x = q.x + lane0;
  problem.mass = q.mass + lane0;
  problem.lengths = q.lengths + lane0;
  problem.work = q.work + lane0;
  if (q.ignore != nullptr) problem.ignore = q.ignore + lane0;
  StoreLanes(SolveShake<B, Dim>(problem), q.converged + lane0);
}

// The whole block (lanes 0 .. kStrandLanes) for stage 1 (PredictLanes, ProjectLanes), 2
// (VelocitiesLanes, corrected for the sequential projections where q.correct), 3 (OverallLanes)
// or 4 (ShakeLanes).
template <class B, int Dim, class Step, class Contact>
inline void DynamicBlock(const DynamicLaneStep& q, int stage, Step&& tractrix_step,
                         Contact&& contact) {
  for (int lane0 = 0; lane0 < kStrandLanes; lane0 += LanesOf<B>()) {
    if (stage == 1) {
      PredictLanes<B, Dim>(q, lane0);
      ProjectLanes<B, Dim>(q, lane0, tractrix_step, contact);
    } else if (stage == 3) {
      OverallLanes<B, Dim>(q, lane0);
    } else if (stage == 4) {
      ShakeLanes<B, Dim>(q, lane0);
    } else {
      VelocitiesLanes<B, Dim>(q, lane0, q.correct);
    }
  }
}

}  // namespace
}  // namespace flexkin::internal
