#pragma once
// Dynamic chains (docs/dynamics.md): a chain with inertia under gravity, its first point driven
// along a path, stepped at a frame rate with sub-steps. Each sub-step predicts every free point
// inertially (velocity, gravity, linear damping) and then puts the links back to their lengths by
// one of three projections:
//  - overall: the least mass-weighted motion from the prediction that keeps every length (the
//    paper's overall optimization measured from the prediction: a discrete Gauss principle of least
//    constraint, the projection of SHAKE and of Goldenthal et al.'s fast projection solved
//    exactly), by the banded Newton solver of the overall method;
//  - tractrix: link by link from the driven end, the predicted link is put back to its length
//    about its leading end's prediction, then the leading end's correction is carried to the
//    trailing end by the tractrix step (the least-velocity motion for a straight move of the point
//    ahead): the sequential approximation of the overall projection;
//  - dftl: Mueller et al. 2012's dynamic follow-the-leader: each trailing end put on the sphere
//    about its leading end's new position nearest its prediction, and the velocities corrected by
//    -s d_{j+1} / h (d the next point's correction, s the DFTL damping), as the baseline. (The
//    tractrix projection takes the same correction: without it both sequential projections gain
//    energy without bound, docs/dynamics.md.)
//  - shake: the correction along the links' directions at the start of the sub-step (SHAKE,
//    Ryckaert et al. 1977: with the inertial prediction, Verlet's method with constraints,
//    symplectic), its n multipliers by Newton's method on the lengths (a tridiagonal system).
//    Explicit: stable for sub-steps shorter than about 2 / the chain's highest frequency (long
//    chains need more sub-steps); a sub-step past it is projected by `overall` and counted.
// Velocities are the positions' change over the sub-step. Kinematic runs (flexkin/run.h) are
// unchanged by this.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/colliders.h"
#include "flexkin/error.h"
#include "flexkin/vocabulary.h"

namespace flexkin {

enum class Projection {
  kOverall,   // "overall": the exact least mass-weighted correction
  kTractrix,  // "tractrix": sequential, tractrix carry of the leading end's correction
  kDftl,      // "dftl": dynamic follow-the-leader with its velocity correction
  kShake,     // "shake": the correction along the old link directions (symplectic)
};

// The projection names, defined once (flexkin/vocabulary.h). (Not yet in any file form.)
template <>
struct Vocabulary<Projection> {
  static constexpr const char* kKind = "projection";
  static constexpr NamedValue<Projection> kEntries[] = {
      {Projection::kOverall, "overall",
       "the least mass-weighted motion from the prediction that keeps every length"},
      {Projection::kTractrix, "tractrix",
       "sequential: the leading end's correction carried by the tractrix step, DFTL's velocity "
       "correction"},
      {Projection::kDftl, "dftl", "dynamic follow-the-leader (Mueller et al. 2012)"},
      {Projection::kShake, "shake",
       "the correction along the links' old directions (SHAKE; symplectic)"},
  };
};
inline const char* ProjectionName(Projection projection) { return NameOf(projection); }

struct DynamicOptions {
  Projection projection = Projection::kOverall;
  // Gravity (length units per s^2), in the chain's dimension (2 or 3 entries).
  Eigen::VectorXd gravity;
  // Linear damping rate (1/s), the drag of the air: each sub-step's predicted velocity is
  // v + h (g + damping (wind - v)). 0: none.
  double damping = 0.0;
  // The air's velocity (uniform, constant), in the chain's dimension; empty: still air. It acts
  // through the damping: without damping the wind does nothing.
  Eigen::VectorXd wind;
  // A keyframed wind: the air's velocity at given times (seconds from the run's start, frame f at
  // f / frame_rate; strictly increasing), linear between keys and held before the first and after
  // the last. When given it replaces `wind`. See WindAt.
  struct WindKey {
    double time = 0.0;
    Eigen::VectorXd velocity;  // the chain's dimension
  };
  std::vector<WindKey> wind_keys;
  // Frames per second (the driven end's path has one row per frame) and sub-steps per frame.
  double frame_rate = 60.0;
  int substeps = 1;
  // The points' masses: false, every free point the same mass; true, each point the mass of
  // half of each link it touches (a uniform density along the chain: the last point half).
  bool mass_by_length = true;
  // Given masses of the free points 1 .. n (n entries, each finite and > 0; single chains only,
  // SimulateChain): they replace mass_by_length. Only their ratios matter (normalized to a total
  // of 1, as the others).
  Eigen::VectorXd masses;
  // Colliders the free points and links stay outside of (flexkin/colliders.h, docs/colliders.md):
  // static, or placed by their keyframed motion at each sub-step's time (seconds from the run's
  // start). Single chains (SimulateChain); the strand engine takes StrandOptions' colliders.
  std::vector<Collider> colliders;
  // The sequential projections' (dftl, tractrix) velocity correction factor s (0 to 1; Mueller
  // et al. suggest about 0.9).
  double dftl_damping = 0.9;

  // Every problem (empty if valid), each naming its member ("gravity", "substeps",
  // "wind_keys[2].time", "masses[4]"). `masses` is checked by SimulateChain against the chain.
  Problems ValidateFor(int dim) const;
  // The air's velocity at `time` (seconds from the run's start): the keyframed wind where given,
  // else `wind`, else zero; `dim` entries.
  Eigen::VectorXd WindAt(double time, int dim) const;
};

struct DynamicResult {
  // Frame f (0 .. frames): the points after f frames (row-major n+1 by dim each).
  std::vector<Points> frames;
  // The energy at each frame: kinetic (1/2 sum m |v|^2) plus potential (-sum m g . x), masses
  // as DynamicOptions::mass_by_length says, the free points' total 1. Taken at the middle of the
  // frame's last sub-step: v is that sub-step's mean velocity, x the mean of its two positions.
  Eigen::VectorXd energy;
  double max_relative_length_error = 0.0;  // over every frame
  // Projections "overall" and "shake": sub-steps whose Newton solve did not converge (overall
  // then keeps the tractrix projection; shake, past its stability limit, takes the overall
  // projection for that sub-step).
  int failures = 0;
  // Sub-steps in which a collider moved a point (DynamicOptions::colliders): the projection left
  // a point or link inside one and the contact step put it out (docs/dynamics.md, "Colliders").
  int contact_substeps = 0;
  // Projection "overall" with colliders: the contact sub-steps solved exactly (the projection
  // with the contacts as constraints of its own solve), and those whose solve did not converge
  // (they took the pushed re-projection, docs/dynamics.md "Colliders").
  int contact_solves = 0;
  int contact_solve_failures = 0;
};

// Simulates `chain` from rest (its points, velocities 0) with point 0 at `root_path` row f at frame
// f (rows: frames 1 .. F; linearly interpolated at sub-steps; the path's first row is frame 1).
// Throws InputError (by field) for a chain, path or options that are not valid.
DynamicResult SimulateChain(const Chain& chain, const Points& root_path,
                            const DynamicOptions& options);

}  // namespace flexkin
