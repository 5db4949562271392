// One sweep of a sequential rule with colliders (sequential/sweep.h, docs/colliders.md): each
// link's rule step as without colliders, kept where the link stays outside every collider (the
// same operations: bit for bit the sweep without colliders); where it would enter one, the
// least-motion position of its trailing end that keeps it outside (world/contact.h).
#include <cmath>
#include <string>

#include "flexkin/colliders.h"
#include "flexkin/error.h"
#include "sequential/link_rules.h"
#include "sequential/rule_table.h"
#include "sequential/sweep.h"
#include "world/contact.h"

namespace flexkin::internal {
namespace {

template <int Dim>
Eigen::Vector3d In3d(const double* p) {
  return Eigen::Vector3d(p[0], p[1], Dim == 3 ? p[2] : 0.0);
}

// Broad phase: every point after the sweep lies within the chain's length `total` of the new
// head, so a collider whose surface is farther than that from the head can neither be entered
// nor block a direction of any link's contact step (the same steps, bit for bit). It is left out
// only where it also cannot lower the least clearance measured so far (its clearance, at least
// its distance less `total`, relative to the longest link, is no less): the report stays exact.
// `near` holds the colliders kept, in their order; returns `colliders` itself when none is left
// out.
template <int Dim>
const std::vector<Collider>& NearColliders(const double* head, double total, double longest,
                                           const std::vector<Collider>& colliders,
                                           const ContactStats& stats, std::vector<Collider>* near) {
  if (colliders.size() < 2 || !std::isfinite(stats.least_clearance)) return colliders;
  const Eigen::Vector3d h = In3d<Dim>(head);
  near->clear();
  for (const Collider& c : colliders) {
    const double beyond = QuerySurface(c, h).distance - total;
    if (!(beyond > 0.0 && beyond / longest >= stats.least_clearance)) near->push_back(c);
  }
  return near->size() == colliders.size() ? colliders : *near;
}

template <class Rule, int Dim>
void ContactSweepOf(const double* head, const double* lengths, const double* inv_lengths, int n,
                    double* pts, const std::vector<Collider>& all, ContactStats* stats) {
  double total = 0.0, longest = 0.0;
  for (int i = 0; i < n; ++i) total += lengths[i], longest = std::fmax(longest, lengths[i]);
  thread_local std::vector<Collider> near;
  const std::vector<Collider>& colliders =
      NearColliders<Dim>(head, total * (1.0 + 1e-12), longest, all, *stats, &near);
  double lead_old[Dim], lead_new[Dim];
  for (int k = 0; k < Dim; ++k) {
    lead_old[k] = pts[k];
    pts[k] = lead_new[k] = head[k];
  }
  for (int i = 1; i <= n; ++i) {
    double* tail = pts + i * Dim;
    double tail_old[Dim];
    for (int k = 0; k < Dim; ++k) tail_old[k] = tail[k];
    ApplyScalar<Rule, Dim>(lead_old, lead_new, tail, lengths[i - 1], inv_lengths[i - 1]);
    const Eigen::Vector3d lead = In3d<Dim>(lead_new);
    double clearance = SegmentClearance(colliders, lead, In3d<Dim>(tail));
    if (clearance < -kContactSlack * lengths[i - 1]) {
      Eigen::Vector3d x;
      if (!ContactTail(Dim, lead, In3d<Dim>(tail_old), lengths[i - 1], colliders, &x)) {
        throw InputError("colliders", "leave no room for link " + std::to_string(i) +
                                          ": every position of point " + std::to_string(i) +
                                          " at its link's length from point " +
                                          std::to_string(i - 1) + " lies in a collider");
      }
      for (int k = 0; k < Dim; ++k) tail[k] = x[k];
      clearance = SegmentClearance(colliders, lead, x);
      ++stats->contact_link_steps;
    }
    stats->least_clearance = std::fmin(stats->least_clearance, clearance * inv_lengths[i - 1]);
    for (int k = 0; k < Dim; ++k) lead_old[k] = tail_old[k], lead_new[k] = tail[k];
  }
}

}  // namespace

void ContactSweep(Method method, int dim, const double* head, const double* lengths,
                  const double* inv_lengths, int n, double* points,
                  const std::vector<Collider>& colliders, ContactStats* stats) {
  DispatchRule<kSweepsEngine>(method, [&](auto rule) {
    using Rule = decltype(rule);
    dim == 2 ? ContactSweepOf<typename Rule::template Step<2>, 2>(head, lengths, inv_lengths, n,
                                                                  points, colliders, stats)
             : ContactSweepOf<typename Rule::template Step<3>, 3>(head, lengths, inv_lengths, n,
                                                                  points, colliders, stats);
  });
}

}  // namespace flexkin::internal
