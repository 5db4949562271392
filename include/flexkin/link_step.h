#pragma once

#include <Eigen/Core>

namespace flexkin {

// One rigid link of length `length` whose leading end moves along the straight segment from
// `head_old` to `head_new`; both functions return the new position of the trailing end, which
// is at `tail` before the move. Units are the caller's; `length` > 0.

// Tractrix step: the trailing end's velocity is along the link at every instant, which is the
// motion of least velocity (paper, Sec. 2). Closed form, no integration; exact to rounding for
// pulling, sideways and pushing moves, any displacement and any length. The new tail is at
// distance `length` from `head_new` to rounding and has moved no farther than the head.
// If the head moves exactly toward the tail (the unstable equilibrium) the link translates.
Eigen::Vector2d TractrixStep(const Eigen::Vector2d& head_old, const Eigen::Vector2d& head_new,
                             const Eigen::Vector2d& tail, double length);
Eigen::Vector3d TractrixStep(const Eigen::Vector3d& head_old, const Eigen::Vector3d& head_new,
                             const Eigen::Vector3d& tail, double length);

// Follow-the-leader step (FABRIK, hair strands): the tail is put on the sphere of radius
// `length` around `head_new`, at the point nearest its old position. If `head_new` lands exactly
// on the old tail the link keeps its old direction (tail - head_old). `head_old` is otherwise
// unused; it is taken so that both rules share one signature.
Eigen::Vector2d FollowTheLeaderStep(const Eigen::Vector2d& head_old,
                                    const Eigen::Vector2d& head_new, const Eigen::Vector2d& tail,
                                    double length);
Eigen::Vector3d FollowTheLeaderStep(const Eigen::Vector3d& head_old,
                                    const Eigen::Vector3d& head_new, const Eigen::Vector3d& tail,
                                    double length);

}  // namespace flexkin
