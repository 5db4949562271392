#pragma once
// flexkin: natural, length-preserving motion of chains of rigid links (ropes, chains, hair, tails,
// snakes, hyper-redundant arms) whose leading end is moved along a prescribed path. One include
// for the whole core library; docs/architecture.md says what each header holds.
//
//   #include <flexkin/flexkin.h>
//   flexkin::Chain chain = flexkin::MakeEqualLinkChain(flexkin::MakeParabola({}), 0.25);
//   flexkin::RunResult result = flexkin::Run(chain, leader_steps, flexkin::RunOptions{});
//
// Threads: every function of the library may be called from several threads at once on different
// objects (chains, arms, options, results, files); it keeps no mutable global state (scratch space
// is per thread; urdfdom's process-wide error handler is taken under a lock by ArmFromUrdf). An
// object that one thread changes (a Chain being moved, an OverallWorkspace, a writer) must not be
// used by another at the same time; const objects (a model, options, a path) may be shared.
// Results do not depend on which threads run them, bit for bit (tests/thread_safety_test.cc runs
// every example scenario in four threads at once, under ThreadSanitizer in make test).

#include "flexkin/any_scenario.h"    // the front door: a scenario file of any kind, read once
#include "flexkin/arm.h"             // fixed-base arms: models, forward kinematics, TrackPath
#include "flexkin/chain.h"           // Chain, Points, MakeChain
#include "flexkin/colliders.h"       // colliders: spheres, capsules, boxes, ... and their geometry
#include "flexkin/curves.h"          // generated initial curves: line, parabola, arc, helix
#include "flexkin/dynamics.h"        // dynamic chains: inertia, gravity and three projections
#include "flexkin/error.h"           // Problem, Problems, InputError
#include "flexkin/groom.h"           // groom scenarios (strands on a moving body) and their runs
#include "flexkin/leader.h"          // leader paths: pulls, resampling
#include "flexkin/link_step.h"       // the single link step: tractrix, follow-the-leader
#include "flexkin/overall.h"         // the whole-curve (overall) step and its metric
#include "flexkin/propagate.h"       // methods, sequential propagation (MoveLeader)
#include "flexkin/result_io.h"       // result files and frame CSV
#include "flexkin/robot_scenario.h"  // robot scenario files and trajectories
#include "flexkin/run.h"             // Run: a chain through a list of targets, with metrics
#include "flexkin/scenario.h"        // scenario files
#include "flexkin/scenario_kind.h"   // the kinds of scenario file
#include "flexkin/strand_file.h"     // strand files (.npz): every strand at every frame
#include "flexkin/strands.h"         // many strands (hair, fur) stepped together
#include "flexkin/tree.h"            // bodies that branch: driven at one point, several targets
#include "flexkin/tree_overall.h"    // the exact least-motion step of a tree with several targets
#include "flexkin/tree_scenario.h"   // tree scenario files and results
#include "flexkin/vocabulary.h"      // the names of every enumerated choice
