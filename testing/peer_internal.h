#pragma once
// Helpers shared by the peer adapters (peer_solvers.cc, l2_peer.cc); not for the tests.

#include <Eigen/Core>
#include <chrono>

#include "flexkin/chain.h"
#include "peer_solvers.h"

namespace Ipopt {
class OptionsList;
}

namespace flexkin::peers::internal {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start);

// Largest |(|D_i|^2 - L_i^2)| / (2 L_i^2): OverallReport::constraint_violation's measure.
double ConstraintViolation(const Eigen::VectorXd& lengths, const Points& x);

// Throws InputError as OverallStep does: the chain, the head's size and values, the options.
void ValidateInput(const Eigen::VectorXd& lengths, const Eigen::Ref<const Eigen::VectorXd>& head,
                   const PeerOptions& options, const Points& old_points);

// The options both IPOPT adapters set from `options`: silent (no output, no banner), tol,
// max_iter, MUMPS, exact or limited-memory Hessian, and the CPU time limit if any.
void SetCommonIpoptOptions(const PeerOptions& options, Ipopt::OptionsList* o);

// The name of an Ipopt::ApplicationReturnStatus, e.g. "Solve_Succeeded"; "unknown" for others.
const char* IpoptStatusName(int status);

}  // namespace flexkin::peers::internal
