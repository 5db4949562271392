// OverallStep: input checks, then the continuation that reaches the minimizer continuously
// connected to the old configuration (the sub-problems solved by newton.h, or by active_set.h
// under an L2 metric); the options' checks and the report's vocabulary; OverallWorkspace.

#include "flexkin/overall.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "chain/substep.h"
#include "flexkin/error.h"
#include "flexkin/propagate.h"
#include "overall/active_set.h"
#include "overall/newton.h"
#include "overall/step.h"
#include "overall/workspace.h"
#include "sequential/sweep.h"

namespace flexkin {
namespace {

void ValidateInput(const Eigen::Ref<const Eigen::VectorXd>& head, const OverallOptions& options,
                   const Chain& chain) {
  ValidateChain(chain, "points");
  if (head.size() != chain.points.cols()) {
    throw InputError("head", "has " + std::to_string(head.size()) + " coordinates; the chain is " +
                                 std::to_string(chain.points.cols()) + "D");
  }
  for (Eigen::Index k = 0; k < head.size(); ++k) {
    if (!std::isfinite(head[k])) {
      throw InputError("head[" + std::to_string(k) + "]",
                       "value " + FormatNumber(head[k]) + " is not a finite number");
    }
  }
  ThrowIfAny(options.Validate());
  internal::CheckOverallOptionsForChain(options, chain.dim());
}

}  // namespace

Problems OverallOptions::Validate() const {
  Problems problems;
  AppendNested("weights", weights.Validate(), &problems);
  if (!(constraint_tolerance > 0.0) || !std::isfinite(constraint_tolerance)) {
    problems.emplace_back("constraint_tolerance",
                          FormatNumber(constraint_tolerance) +
                              " is not valid; must be a finite number > 0 (typical 1e-14)",
                          FormatNumber(constraint_tolerance), "a finite number > 0");
  }
  if (!(optimality_tolerance > 0.0) || !std::isfinite(optimality_tolerance)) {
    problems.emplace_back("optimality_tolerance",
                          FormatNumber(optimality_tolerance) +
                              " is not valid; must be a finite number > 0 (typical 1e-10)",
                          FormatNumber(optimality_tolerance), "a finite number > 0");
  }
  if (max_iterations < 1) {
    problems.emplace_back("max_iterations",
                          std::to_string(max_iterations) + " is not valid; must be >= 1",
                          std::to_string(max_iterations), ">= 1");
  }
  return problems;
}

const char* OverallStatusName(OverallStatus status) {
  switch (status) {
    case OverallStatus::kConverged:
      return "converged";
    case OverallStatus::kMaxIterations:
      return "max_iterations";
    case OverallStatus::kStalled:
      return "stalled";
    case OverallStatus::kFailed:
      return "failed";
  }
  return "unknown";
}

std::string OverallReport::BriefReport() const {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "%s after %d iterations: objective %.12g, constraint violation %.2g, optimality "
                "%.2g (start: %s)",
                OverallStatusName(status), iterations, objective, constraint_violation, optimality,
                start.c_str());
  return buf;
}

OverallWorkspace::OverallWorkspace() : buffers_(std::make_unique<internal::OverallBuffers>()) {}
OverallWorkspace::~OverallWorkspace() = default;
OverallWorkspace::OverallWorkspace(OverallWorkspace&&) noexcept = default;
OverallWorkspace& OverallWorkspace::operator=(OverallWorkspace&&) noexcept = default;

namespace internal {
namespace {

// How the returned minimizer was reached (OverallReport::start).
enum class Start {
  kStillHead,     // the head did not move (L2 metric): nothing moves
  kDirect,        // one Newton run from the tractrix step of the whole move
  kContinuation,  // Newton runs along the head's sub-steps (one sub-step: from the tractrix step)
};

// The longest text of OverallReport::start, with room to spare.
constexpr int kStartTextSize = 160;

// The text of OverallReport::start, into `*start` (reusing its storage).
void DescribeStart(Start how, int sub_steps, bool l2, std::string* start) {
  switch (how) {
    case Start::kStillHead:
      start->assign("the old configuration (the head did not move)");
      return;
    case Start::kDirect:
      start->assign("sequential tractrix step (a strict local minimizer: KKT inertia checked)");
      return;
    case Start::kContinuation:
      if (sub_steps == 1) {
        start->assign(l2 ? "the old configuration, on an active set of moving points"
                         : "sequential tractrix step");
        return;
      }
      char text[kStartTextSize];
      std::snprintf(text, sizeof text,
                    "continuation in %d head sub-steps from the old configuration, each from %s",
                    sub_steps, l2 ? "the last sub-step's solution" : "its tractrix step");
      start->assign(text);
      return;
  }
}

// The tractrix step of the whole chain for the head moving to `head` in one sub-step: the sweep
// MoveLeader runs for one sub-step (so the same numbers), without its checks (the chain was
// validated once) and its buffer of head positions.
void TractrixStep(const Eigen::VectorXd& lengths, const Eigen::VectorXd& inv_lengths,
                  const double* head, Points* points) {
  SweepsScalar(Method::kTractrix, static_cast<int>(points->cols()), head, 1, lengths.data(),
               inv_lengths.data(), static_cast<int>(lengths.size()), points->data());
}

// Without an L2 term: one Newton run from the sequential tractrix step of the whole move, into
// `b->direct`. Kept (true) if it converges to a strict local minimizer (the inertia of the KKT
// matrix says so), which is the usual case and several times cheaper than the continuation.
bool SolveDirectly(const Eigen::VectorXd& lengths, const Eigen::Ref<const Eigen::VectorXd>& head,
                   const OverallOptions& options, OverallBuffers* b, OverallReport* report) {
  const int n = static_cast<int>(lengths.size());
  b->direct = b->old_points;
  TractrixStep(lengths, b->inv_lengths, head.data(), &b->direct);
  NewtonSolver solver(lengths, b->old_points, options, n, 0.0, &b->newton);
  *report = solver.Solve(&b->direct);
  return report->converged() && solver.IsStrictMinimizer(*report);
}

// Continuation: the head advances to its target in `sub_steps` equal sub-steps; each
// sub-problem (the same metric, measured from the old configuration, with the head part of the
// way) starts from the tractrix step of the previous solution (with an L2 term: from the previous
// solution, on its active set) and is solved by Newton's method. At the old head position the old
// configuration is the global minimizer, so this follows the minimizer continuously connected to
// it, rather than whichever stationary point (possibly a saddle) a single Newton run from far away
// would reach. `*points` is the old configuration on entry. Stops at a sub-step that does not
// converge; the report's iterations are those of this continuation.
OverallReport Continue(const Eigen::VectorXd& lengths,
                       const Eigen::Ref<const Eigen::VectorXd>& head, const OverallOptions& options,
                       int sub_steps, bool l2, OverallBuffers* b, Points* points) {
  const int n = static_cast<int>(lengths.size());
  int moving = l2 ? 0 : n;  // the active set, carried from sub-step to sub-step
  OverallReport report;
  int iterations = 0;
  for (int s = 1; s <= sub_steps; ++s) {
    for (Eigen::Index k = 0; k < head.size(); ++k) {
      b->target[k] = internal::SubstepHead(b->from[k], head[k], s, sub_steps);
    }
    if (l2) {
      report = SolveActiveSet(lengths, b->old_points, options, b->target, &moving, points,
                              &b->active_set, &b->newton);
    } else {
      TractrixStep(lengths, b->inv_lengths, b->target.data(), points);
      report = NewtonSolver(lengths, b->old_points, options, n, 0.0, &b->newton).Solve(points);
    }
    iterations += report.iterations;
    if (!report.converged()) break;
  }
  report.iterations = iterations;
  return report;
}

}  // namespace

void OverallBuffers::Reserve(int n, int dim, const ObjectiveWeights& weights) {
  for (Points* p : {&old_points, &direct}) p->resize(n + 1, dim);
  inv_lengths.resize(n);
  from.resize(dim);
  target.resize(dim);
  newton.Reserve(n, dim, weights);
  if (weights.l2 > 0.0 || weights.l2_weighted > 0.0) {
    ActiveSetBuffers& a = active_set;
    for (Points* p : {&a.current, &a.trial}) p->resize(n + 1, dim);
    a.rested.reserve(n + 1);
    a.sink.offset.reserve(n + 1);
    internal::Reserve(&a.gradient, static_cast<Eigen::Index>(n) * dim);
    for (Eigen::VectorXd* v : {&a.u, &a.v, &a.link, &a.force, &a.rest, &a.unheld, &a.pull}) {
      v->resize(dim);
    }
    a.difference.resize(dim);
    a.friction.lo.reserve(n + 2);
    a.friction.hi.reserve(n + 2);
    a.friction.w.reserve(n + 1);
    a.friction.e.resize(n, dim);
  }
}

void CheckOverallOptionsForChain(const OverallOptions& options, int dim) {
  if (options.weights.joint_angle > 0.0 && dim != 2) {
    throw InputError("weights.joint_angle",
                     "the joint-angle term is defined for planar (2D) chains only; this chain is "
                     "3D: set it to 0");
  }
}

void OverallStepUnchecked(const Eigen::VectorXd& lengths,
                          const Eigen::Ref<const Eigen::VectorXd>& head,
                          const OverallOptions& options, Points* points,
                          OverallWorkspace* workspace, OverallReport* report) {
  OverallBuffers& b = workspace->buffers();
  const int n = static_cast<int>(lengths.size());
  b.Reserve(n, static_cast<int>(points->cols()), options.weights);
  b.old_points = *points;
  b.inv_lengths = lengths.cwiseInverse();
  b.from = b.old_points.row(0).transpose();
  // Sub-steps no longer than half the shortest link (see Continue).
  const double distance = (head - b.from).norm();
  const int sub_steps =
      std::max(1, static_cast<int>(std::ceil(distance / (0.5 * lengths.minCoeff()))));
  const bool l2 = options.weights.l2 > 0.0 || options.weights.l2_weighted > 0.0;
  // (`result.start` stays empty: moved into *report, it keeps report->start's storage.)
  OverallReport result;
  Start how = Start::kContinuation;
  if (l2 && distance == 0.0) {  // nothing moves: the minimizer is the old configuration
    result.status = OverallStatus::kConverged;
    how = Start::kStillHead;
  } else {
    // With an L2 term, the sub-problems are solved on an active set: the points after the last
    // moving one held still (their friction bound checked), from the last sub-step's solution.
    if (l2) MakeTailFriction(options.weights, lengths, b.old_points, &b.active_set);
    int direct_iterations = 0;
    if (!l2 && sub_steps > 1) {
      if (SolveDirectly(lengths, head, options, &b, &result)) {
        how = Start::kDirect;
        *points = b.direct;
      }
      direct_iterations = result.iterations;
    }
    if (how == Start::kContinuation) {
      result = Continue(lengths, head, options, sub_steps, l2, &b, points);
      result.iterations += direct_iterations;
    }
  }
  *report = std::move(result);
  report->start.reserve(kStartTextSize);  // allocated once for a report kept across steps
  DescribeStart(how, sub_steps, l2, &report->start);
}

}  // namespace internal

OverallReport OverallStep(const Eigen::Ref<const Eigen::VectorXd>& head,
                          const OverallOptions& options, Chain* chain,
                          OverallWorkspace* workspace) {
  ValidateInput(head, options, *chain);
  std::optional<OverallWorkspace> temporary;
  if (workspace == nullptr) workspace = &temporary.emplace();
  OverallReport report;
  internal::OverallStepUnchecked(chain->lengths, head, options, &chain->points, workspace, &report);
  return report;
}

}  // namespace flexkin
