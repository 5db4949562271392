#pragma once
// The one table of link rules. Each sequential rule of the paper (tractrix, follow-the-leader,
// minimum body rotation, minimum joint-angle change) is declared here once: the Method it is
// (whose name is in the vocabulary, flexkin/propagate.h), its convergence order, the forms it has
// and the engines that run it. Every engine takes its rule from this table with DispatchRule:
//
//   DispatchRule<kSweepsEngine>(method, [&](auto rule) {
//     using Rule = decltype(rule);
//     Sweeps<typename Rule::template Step<2>, 2>(...);  // a per-link rule's scalar/batch form
//   });
//
// A method whose entry does not list the engine is refused there with an InputError naming the
// methods that do run on it; an entry that lists an engine without the form that engine calls
// is a compile error. Nothing anywhere else decides "tractrix, else follow-the-leader".
//
// Adding a rule: its enumerator and vocabulary line in flexkin/propagate.h, its struct below
// (forms in link_rules.h or metric_rules.cc), and its name in LinkRules. Every engine whose bit
// it lists then runs it; every other engine refuses it by name.

#include <cstdint>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/propagate.h"
#include "sequential/link_rules.h"
#include "sequential/sweep.h"
#include "sequential/tree_sweep.h"

namespace flexkin::internal {
// Internal linkage, as link_rules.h: translation units built for different instruction sets each
// have their own copy of the rules' forms.
namespace {

// The engines. A rule lists those that run it; each engine calls one form of the rule.
enum RuleEngine : unsigned {
  // One chain, link after link, one sweep per sub-step (propagate.cc: Sweeps, TracedSweeps, the
  // accuracy control's traced sweeps). Calls Rule::Step<Dim> on doubles.
  kSweepsEngine = 1u << 0,
  // One chain, several sweeps in flight in SIMD lanes (wavefront.h). Calls Rule::Step<Dim, Exp>
  // on xsimd batches.
  kWavefrontEngine = 1u << 1,
  // Many strands, one per lane (strands.cc scalar lanes, strands_isa.cc SIMD blocks). Calls
  // Rule::Step<Dim> on doubles and Rule::Step<Dim, Exp> on batches.
  kStrandEngine = 1u << 2,
  // One chain moved as a whole per sub-step (metric_rules.cc). Calls Rule::WholeChainSweeps.
  kWholeChainEngine = 1u << 3,
  // A tree driven at one point, link after link outward from it (tree.cc). Calls Rule::Step<Dim>
  // on doubles.
  kTreeEngine = 1u << 4,
  // A tree driven at one point, moved as a whole per sub-step (tree.cc). Calls
  // Rule::WholeTreeSweeps.
  kWholeTreeEngine = 1u << 5,
};

// The engine's name in messages ("the strand engine").
inline const char* RuleEngineName(RuleEngine engine) {
  switch (engine) {
    case kSweepsEngine:
      return "the sequential sweep";
    case kWavefrontEngine:
      return "the SIMD wavefront";
    case kStrandEngine:
      return "the strand engine";
    case kWholeChainEngine:
      return "the whole-chain sweep";
    case kTreeEngine:
      return "trees";
    case kWholeTreeEngine:
      return "trees moved whole";
  }
  return "?";
}

// Tractrix (paper Sec. 2-3): the closed-form least-velocity step of one link; second order.
struct TractrixLinkRule {
  static constexpr Method kMethod = Method::kTractrix;
  static constexpr int kOrder = 2;
  static constexpr unsigned kEngines =
      kSweepsEngine | kWavefrontEngine | kStrandEngine | kTreeEngine;
  template <int Dim, class Exp = StdExp>
  using Step = TractrixRule<Dim, Exp>;
};

// Follow-the-leader (FABRIK, hair): the nearest point on the sphere around the new head; first
// order.
struct FollowTheLeaderLinkRule {
  static constexpr Method kMethod = Method::kFollowTheLeader;
  static constexpr int kOrder = 1;
  static constexpr unsigned kEngines =
      kSweepsEngine | kWavefrontEngine | kStrandEngine | kTreeEngine;
  template <int Dim, class Exp = StdExp>
  using Step = FollowTheLeaderRule<Dim>;
};

// Minimum body rotation (Sec. 4.1): every link translates, so the whole chain does. No
// convergence order is established (accuracy control is not offered).
struct MinRotationLinkRule {
  static constexpr Method kMethod = Method::kMinRotation;
  static constexpr int kOrder = 0;
  static constexpr unsigned kEngines = kWholeChainEngine | kWholeTreeEngine;
  // (sweep.h, metric_rules.cc)
  static void WholeChainSweeps(int dim, const double* heads, int64_t num_sweeps,
                               const double* /*lengths*/, const double* /*inv_lengths*/, int n,
                               double* points) {
    SweepsMinRotation(dim, heads, num_sweeps, n, points);
  }
  // (tree_sweep.h, tree.cc)
  static void WholeTreeSweeps(int dim, const double* heads, int64_t num_sweeps,
                              const TreeLinks& tree, double* points) {
    TreeSweepsMinRotation(dim, heads, num_sweeps, tree, points);
  }
};

// Minimum joint-angle change (Sec. 4.2): the first link by the tractrix step, the chain behind
// it rigidly with it.
struct MinJointAngleLinkRule {
  static constexpr Method kMethod = Method::kMinJointAngle;
  static constexpr int kOrder = 0;
  static constexpr unsigned kEngines = kWholeChainEngine | kWholeTreeEngine;
  static void WholeChainSweeps(int dim, const double* heads, int64_t num_sweeps,
                               const double* lengths, const double* inv_lengths, int n,
                               double* points) {
    SweepsMinJointAngle(dim, heads, num_sweeps, lengths, inv_lengths, n, points);
  }
  static void WholeTreeSweeps(int dim, const double* heads, int64_t num_sweeps,
                              const TreeLinks& tree, double* points) {
    TreeSweepsMinJointAngle(dim, heads, num_sweeps, tree, points);
  }
};

template <class... Rules>
struct RuleList {};

// The table.
using LinkRules =
    RuleList<TractrixLinkRule, FollowTheLeaderLinkRule, MinRotationLinkRule, MinJointAngleLinkRule>;

namespace rule_table_detail {

template <class... Rules>
constexpr bool RunsOn(Method method, unsigned engines, RuleList<Rules...>) {
  return ((method == Rules::kMethod && (Rules::kEngines & engines) != 0) || ...);
}

template <class... Rules>
constexpr int OrderOf(Method method, RuleList<Rules...>) {
  int order = 0;
  static_cast<void>(((method == Rules::kMethod ? (order = Rules::kOrder, true) : false) || ...));
  return order;
}

template <class... Rules>
std::vector<std::string> NamesOn(unsigned engines, RuleList<Rules...>) {
  std::vector<std::string> names;
  static_cast<void>(
      ((Rules::kEngines & engines ? names.emplace_back(NameOf(Rules::kMethod)), 0 : 0), ...));
  return names;
}

template <unsigned Engine, class F, class... Rules>
bool Dispatch(Method method, F& f, RuleList<Rules...>) {
  bool done = false;
  (
      [&] {
        if constexpr ((Rules::kEngines & Engine) != 0) {
          if (!done && method == Rules::kMethod) {
            f(Rules{});
            done = true;
          }
        }
      }(),
      ...);
  return done;
}

}  // namespace rule_table_detail

// Whether `method` is a link rule that runs on any of `engines` (a bit mask of RuleEngine).
constexpr bool RuleRunsOn(Method method, unsigned engines) {
  return rule_table_detail::RunsOn(method, engines, LinkRules{});
}

// Convergence order of a rule's multi-step motion to the continuous one (0: not established, or
// not a link rule).
constexpr int RuleOrder(Method method) { return rule_table_detail::OrderOf(method, LinkRules{}); }

// The names of the methods that run on any of `engines`, in the table's order.
inline std::vector<std::string> RuleNamesOn(unsigned engines) {
  return rule_table_detail::NamesOn(engines, LinkRules{});
}

// The problem of a method that does not run on `engine`: field `field`, e.g.
//   "min_rotation" is not a method of the strand engine; expected "tractrix" or "ftl"
inline Problem RuleRefused(const std::string& field, Method method, RuleEngine engine) {
  return Problem::Invalid(
      field, std::string("\"") + NameOf(method) + "\"",
      QuotedList(RuleNamesOn(engine)) + " (the methods of " + RuleEngineName(engine) + ")");
}

// Calls f(Rule{}) with the table's entry of `method`, instantiated only for the rules that run on
// `Engine`; throws InputError (RuleRefused, field "method") for a method that does not.
template <RuleEngine Engine, class F>
void DispatchRule(Method method, F&& f) {
  if (!rule_table_detail::Dispatch<Engine>(method, f, LinkRules{})) {
    throw InputError(RuleRefused("method", method, Engine));
  }
}

}  // namespace
}  // namespace flexkin::internal
