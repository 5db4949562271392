#pragma once
// The scenes of the tests (tests/), the benchmarks (bench/) and the example programs, defined
// once (as Box2D's shared/ folder of benchmark scenes): chains with their leader paths
// (scenes/chains.cc) and fixed-base arms with their end-effector paths (scenes/arms.cc).
// Lengths are in link lengths of the scene (unit links unless a length is given), angles in
// radians. Point 0 of a chain is its leading end; row 0 of an arm's points is its base.
// Every scene is deterministic: the tests and benchmarks compare numbers computed from them.

#include <Eigen/Core>
#include <random>
#include <vector>

#include "flexkin/arm.h"
#include "flexkin/chain.h"
#include "flexkin/tree.h"

namespace flexkin::scenes {

// ----- Chains (scenes/chains.cc) -------------------------------------------------------------

// The paper's parabola (Sec. 5.1, Figs 6 and 11): y = x^2 from the vertex (point 0, the leading
// end) toward +x, 20 links of 0.25 (total length 5); MakeParabola(ParabolaDef{}), every link
// length exactly 0.25 (MakeEqualLinkChain).
Chain PaperParabola();

// The same 21 points sampled the other way: point i the point of y = x^2 whose distance from
// point i-1 is 0.25, x found by 200 bisections on [x_{i-1}, x_{i-1} + 0.25] (the largest x whose
// chord is below 0.25). Within about 1e-16 of PaperParabola's points but not bit for bit: kept
// for tests/overall_l2_test.cc, whose pinned inputs were sampled so. 21 by 2.
Points PaperParabolaByBisection();

// The paper's move of the leading end (Sec. 5.1): `distance` at 45 degrees, (d/sqrt 2, d/sqrt 2)
// (0.7 in one step; 5 steps of 0.14 in the multi-step runs).
Eigen::Vector2d PaperPull(double distance = 0.7);

// A curved chain of `links` links: points on a circle of `radius` in the x-y plane, point i at
// angle turn * i (rad); in 3D lifted along z by 0.02 radius i + 0.01 radius sin(3 turn i), so
// that the link lengths (about radius * turn) are not all equal. (links + 1) by dim (2 or 3).
Points CurvedPoints(int dim, int links, double radius, double turn);
// The same as a chain (MakeChain: the lengths are the distances between the points).
Chain CurvedChain(int dim, int links, double radius, double turn);

// (Straight chains are the library's MakeLine, include/flexkin/curves.h.)

// A straight pull of the leading end: `steps` leader targets, target s (1..steps) =
// start + (distance * s / steps) * direction; `direction` should be a unit vector for `distance`
// to be the length of the pull. steps by start.size().
Points StraightPull(const Eigen::VectorXd& start, const Eigen::VectorXd& direction, double distance,
                    int steps);

// A random smooth chain from the origin, first along +x: link i has length 1 + 0.5 u (u uniform
// in [-1, 1]: lengths in [0.5, 1.5]) and the direction of link i-1 plus `bend` times t,
// normalized, t a random vector (components uniform in [-1, 1]) less its part along that
// direction: a turn of atan(bend |t|), |t| <= sqrt(dim), so the chain is curved but never folds
// back. For each link, dim draws for t then one for the length, from `rng`. The lengths are
// those drawn, not recomputed from the points.
Chain RandomSmoothChain(int dim, int links, double bend, std::mt19937* rng);

// A helix about the z axis: radius 1, rising 0.5 per turn, `links` links of exactly 0.25 (about
// 25 links per turn); MakeHelix, lengths exactly 0.25. The overall benchmark's scaling scene.
Chain Helix(int links);

// A coil sampled by angle rather than by chord: point i = (cos 0.3 i, sin 0.3 i, 0.05 i), links
// of about 0.30 (a helix of radius 1, 21 points per turn). The lengths are the distances
// (MakeChain). The propagation benchmark's scene.
Chain Coil(int links);

// ----- Fixed-base arms (scenes/arms.cc) ------------------------------------------------------

// An arm of `links` unit links from the origin along +x (StraightArm) bent into a circular arc:
// every joint turned by `turn` (rad). dim 2: planar, revolute joints; dim 3: spherical joints,
// every bend about the same `azimuth` (rad; 0: the arc lies in the x-y plane).
ArmModel ArcArm(int dim, int links, double turn, double azimuth = 0.0);

// The turn per joint that puts the end effector of ArcArm(dim, links, turn) at about
// `reach_fraction` (in (0, 1)) of the reach (`links`) from the base: a continuous arc of total
// turn phi has chord reach * sin(phi/2) / (phi/2), solved for phi by 200 bisections on
// (0, 2 pi), divided by links. (The arm, a polygon of unit links, reaches
// sin(phi/2) / sin(phi / (2 links)) links: farther, by about phi^2 / (24 links^2) relative.)
double ArcTurnForReach(int links, double reach_fraction);

// A gently curled arm of `links` unit links. dim 2: ArcArm(2, links, turn). dim 3: every joint
// bent by |turn| about azimuth 0.3 j, reduced into [0, pi), so the arm curls out of any plane.
ArmModel CurledArm(int dim, int links, double turn);

// A pitch/yaw snake of `links` unit links (dim 3, revolute joints): joint axes alternately y and
// z, limits +-0.6 rad, gently curled (0.15 rad about y, 0.1 about z).
ArmModel RevoluteSnake(int links);

// `links` unit links with limits, every joint turned by `turn`. dim 2: revolute limits
// +-`limit`; dim 3: spherical, bend cone `limit`, joint j about azimuth 0.5 j (reduced into
// [-pi, pi] by std::remainder).
ArmModel LimitedArm(int dim, int links, double limit, double turn);

// Where a circle of targets of a spatial arm (dim 3) leaves the x-y plane; planar arms ignore it.
enum class CircleTilt {
  kFlat,      // in the x-y plane: start + r (cos a - 1, sin a, 0)
  kRising,    // r (cos a - 1, sin a, 0.5 sin a): z rises with y
  kTilted45,  // r (cos a - 1, sqrt(1/2) sin a, sqrt(1/2) sin a): turned 45 degrees about x
};

// `count` end-effector targets on a circle of `radius` (link lengths) through the end effector of
// model.initial, `turns` times around: target i at angle a = 2 pi turns (i + 1) / count, so the
// last one is back at the start. count by model.dim.
Points CircleOfTargets(const ArmModel& model, double radius, int count,
                       CircleTilt tilt = CircleTilt::kFlat, int turns = 1);

// `count` targets of a LimitedArm(dim, n, limit, ...) whose joints swing beyond their limits
// and are held there: each joint a sine of amplitude up to 1.6 x the limit (random phase and
// rate), clamped into the limits (spherical: the bend, about a slowly turning random azimuth),
// 0.05 rad of phase a step. Reachable by construction: end effectors of angles within the
// limits. Draws 4 numbers per joint from `rng`. count by model.dim.
Points SaturatingPath(const ArmModel& model, double limit, int count, std::mt19937* rng);

// ----- Trees (scenes/trees.cc) -----------------------------------------------------------------

// TheComet/ik's shapes, of unit links, rooted at the origin (point 0): a chain of 10 links; two
// arms of 5 links on a shoulder (point 2) at the end of a spine of 2 links from the root; a binary
// tree of depth 10 (2,047 points). In 2D, the same construction in the x-z plane.
enum class TreeKind { kChain10, kTwoArms, kBinary10 };
Tree TreeShape(TreeKind kind, int dim = 3);
// The points the several-targets tests and benchmarks drive: the chain's tip, the two hands, four
// leaves of the binary tree.
std::vector<int> TreeTips(TreeKind kind);

// The tips' targets of an animation: frame f (0..frames-1) puts tip k at its point plus 0.3 (cos(a
// + k) - cos k, sin(a + k) - sin k) in the first two coordinates, a = 2 pi (f + 1) / frames: each
// tip round a circle of radius 0.3, a turn in `frames` frames, the phases a radian apart.
std::vector<Points> TipCircles(const Tree& tree, const std::vector<int>& tips, int frames);

// A random tree of `count` points: point i > 0 hangs from a random earlier point (so the root is
// 0), at a random direction and a length in [0.5, 1.5).
Tree RandomTree(int count, int dim, unsigned seed);

}  // namespace flexkin::scenes
