#pragma once
// flexkin: natural, length-preserving motion of chains of rigid links (ropes, chains, hair, tails,
// snakes, hyper-redundant arms) whose leading end is moved along a prescribed path. One include
// for the whole core library; docs/architecture.md says what each header holds.
//
//   #include <flexkin/flexkin.h>
//   flexkin::Chain chain = flexkin::MakeEqualLinkChain(flexkin::MakeParabola({}), 0.25);
//   flexkin::RunResult result = flexkin::Run(chain, leader_steps, flexkin::RunOptions{});

#include "flexkin/arm.h"             // fixed-base arms: models, forward kinematics, TrackPath
#include "flexkin/chain.h"           // Chain, Points, MakeChain
#include "flexkin/curves.h"          // generated initial curves: line, parabola, arc, helix
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
#include "flexkin/strand_file.h"     // strand files (.npz): every strand at every frame
#include "flexkin/strands.h"         // many strands (hair, fur) stepped together
#include "flexkin/vocabulary.h"      // the names of every enumerated choice
