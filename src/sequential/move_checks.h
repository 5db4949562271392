#pragma once
// The checks of a move's arguments that MoveLeader (propagate.cc) and MoveTreePoint (tree.cc)
// share.

#include <Eigen/Core>

namespace flexkin::internal {

// Throws InputError on a target of another size than `dim` ("has 3 coordinates; the chain is
// 2D", `body` naming what moves) or with a non-finite value, or on substeps < 1.
void CheckMove(const Eigen::Ref<const Eigen::VectorXd>& target, int dim, int substeps,
               const char* body);

}  // namespace flexkin::internal
