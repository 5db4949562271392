#pragma once
// Internal entry points of the overall step for callers that validate their input once for many
// steps (Run): OverallStep without its checks.

#include <Eigen/Core>

#include "flexkin/overall.h"

namespace flexkin::internal {

// Throws InputError if `options` do not suit a chain in `dim` dimensions (the joint-angle term is
// planar only). OverallStep's check of the options against the chain, beside
// OverallOptions::Validate.
void CheckOverallOptionsForChain(const OverallOptions& options, int dim);

// OverallStep for a chain (`lengths`, `*points`), head and options that the caller has checked
// (ValidateChain, finite head of the chain's dimension, OverallOptions::Validate,
// CheckOverallOptionsForChain). `*report` is overwritten; its `start` text reuses its storage, so
// that a report kept from step to step, like the workspace, allocates nothing once warmed up.
void OverallStepUnchecked(const Eigen::VectorXd& lengths,
                          const Eigen::Ref<const Eigen::VectorXd>& head,
                          const OverallOptions& options, Points* points,
                          OverallWorkspace* workspace, OverallReport* report);

}  // namespace flexkin::internal
