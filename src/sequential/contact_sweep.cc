// One sweep of a sequential rule with colliders (sequential/sweep.h, docs/colliders.md): each
// link's rule step as without colliders, kept where the link stays outside every collider (the
// same operations: bit for bit the sweep without colliders); where it would enter one, the
// least-motion position of its trailing end that keeps it outside (world/contact.h). The
// whole-chain rules (min_rotation, min_joint_angle) are swept link by link here the same way,
// their rule's tail of each link computed as metric_rules.cc computes it until a link meets a
// collider, and from there on relative to where that link now lies.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "flexkin/colliders.h"
#include "flexkin/error.h"
#include "sequential/joint_rotation.h"
#include "sequential/link_rules.h"
#include "sequential/rule_table.h"
#include "sequential/sweep.h"
#include "world/contact.h"
#include "world/mesh_collider.h"

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
    // A lower bound of the distance: a collider it cannot leave out is kept, which changes no
    // step (one farther than the chain reaches blocks nothing) and no clearance (measured).
    const double beyond = DistanceLowerBound(c, h) - total;
    if (!(beyond > 0.0 && beyond / longest >= stats.least_clearance)) near->push_back(c);
  }
  return near->size() == colliders.size() ? colliders : *near;
}

// SweepSet (sweep.h): a link whose distance to a collider's ball, bounded from below by its
// midpoint's less half its length, leaves the link clear and cannot lower the least clearance
// measured so far is not measured against the collider (the same steps and the same report, bit
// for bit: see KeepOutside).

// Whether the link [a, b] is beyond mesh collider `c` (see BeyondBall) by the box that holds its
// triangles (MeshSegmentLowerBound: tighter than the ball round a long or flat mesh), with a
// margin of 1e-9 of the link and the mesh's size and place for the rounding.
inline bool BeyondMeshBox(const Collider& c, const Eigen::Isometry3d& to_local,
                          const Eigen::Vector3d& a, const Eigen::Vector3d& b, double length,
                          double least) {
  if (!(least < std::numeric_limits<double>::infinity())) return false;
  const double floor = least > 0.0 ? least * length : 0.0;
  const double bound =
      c.scale * MeshSegmentLowerBound(*c.mesh, to_local * a / c.scale, to_local * b / c.scale) -
      c.margin;
  const double guard =
      1e-9 * (length + c.scale * c.mesh->radius + c.pose.translation().norm() + a.norm());
  return bound - guard > floor;
}

// Whether the link [a, b] of length `length`, measured against the collider of `ball`, can
// neither enter it nor lower `least` (the least clearance so far, relative to the link): the
// link's clearance is at least |m - centre| - length / 2 - radius (m its midpoint), and the pair
// is skipped only where that bound is positive and no less than least x length, with a margin
// of 1e-9 of the bound's terms for the rounding of this test and of the exact clearance.
inline bool BeyondBall(const Eigen::Vector4d& ball, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b, double length, double least) {
  if (ball[3] < 0.0 || !(least < std::numeric_limits<double>::infinity())) return false;
  const double floor = least > 0.0 ? least * length : 0.0;
  const double reach = (0.5 * length + ball[3] + floor) * (1.0 + 1e-9);
  const Eigen::Vector3d m = 0.5 * (a + b) - ball.head<3>();
  return m.squaredNorm() > reach * reach;
}

// The same for a sphere (the ball is the sphere, margin included), with the segment's own
// distance to its centre instead of the midpoint's bound: d^2 |ab|^2 = |ac|^2 |ab|^2 - (ac.ab)^2
// where the nearest point is inside the segment, without a division or a root.
inline bool BeyondSphere(const Eigen::Vector4d& ball, const Eigen::Vector3d& a,
                         const Eigen::Vector3d& b, double length, double least) {
  if (!(least < std::numeric_limits<double>::infinity())) return false;
  const double floor = least > 0.0 ? least * length : 0.0;
  const double reach = (ball[3] + floor) * (1.0 + 1e-9);
  const Eigen::Vector3d ac = ball.head<3>() - a, ab = b - a;
  const double along = ac.dot(ab), ab2 = ab.squaredNorm();
  if (along <= 0.0) return ac.squaredNorm() > reach * reach;
  if (along >= ab2) return (ball.head<3>() - b).squaredNorm() > reach * reach;
  return ac.squaredNorm() * ab2 - along * along > reach * reach * ab2 * (1.0 + 1e-9);
}

// Link i (1-based) from its leading end `lead` (already placed) to the rule's position of its
// trailing end `tail`: kept where the link stays outside every collider; else `tail` becomes the
// clear position at the link's length from `lead` whose direction is nearest in angle to that from
// `lead` to `toward` (world/contact.h). Counts the contact and the clearance in `stats`; returns
// whether the link met a collider. A collider the link is beyond (BeyondBall) is not measured:
// its clearance is then positive and no less than the least so far, so the smallest of the
// others' decides the contact and the report as the smallest of all would.
template <int Dim>
bool KeepOutside(int i, const double* lead, const double* toward, double* tail, double length,
                 double inv_length, const SweepSet& set, ContactStats* stats) {
  const std::vector<Collider>& colliders = *set.colliders;
  const Eigen::Vector3d head = In3d<Dim>(lead), rule = In3d<Dim>(tail);
  double clearance = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < colliders.size(); ++k) {
    const bool beyond = set.spheres[k]
                            ? BeyondSphere(set.balls[k], head, rule, length, stats->least_clearance)
                            : BeyondBall(set.balls[k], head, rule, length, stats->least_clearance);
    if (beyond) continue;
    if (colliders[k].shape == ColliderShape::kMesh &&
        BeyondMeshBox(colliders[k], set.to_local[k], head, rule, length, stats->least_clearance)) {
      continue;
    }
    clearance = std::min(clearance, SegmentClearance(colliders[k], head, rule));
  }
  const bool contact = clearance < -kContactSlack * length;
  if (contact) {
    Eigen::Vector3d x;
    if (!ContactTail(Dim, head, In3d<Dim>(toward), length, colliders, &x, &clearance)) {
      throw InputError("colliders", "leave no room for link " + std::to_string(i) +
                                        ": every position of point " + std::to_string(i) +
                                        " at its link's length from point " +
                                        std::to_string(i - 1) + " lies in a collider");
    }
    for (int k = 0; k < Dim; ++k) tail[k] = x[k];
    ++stats->contact_link_steps;
  }
  stats->least_clearance = std::fmin(stats->least_clearance, clearance * inv_length);
  return contact;
}

// Fills `set` with the colliders sweeps whose points lie within `reach` of `head` may meet
// (NearColliders), with their balls.
template <int Dim>
void FillSweepSet(const double* head, double reach, double longest,
                  const std::vector<Collider>& all, const ContactStats& stats,
                  std::vector<Collider>* near, SweepSet* set) {
  set->colliders = &NearColliders<Dim>(head, reach, longest, all, stats, near);
  set->balls.resize(set->colliders->size());
  set->spheres.resize(set->colliders->size());
  for (size_t k = 0; k < set->colliders->size(); ++k) {
    const Collider& c = (*set->colliders)[k];
    set->spheres[k] = c.shape == ColliderShape::kSphere;
    if (c.shape == ColliderShape::kMesh) {
      if (set->to_local.size() < set->colliders->size()) {
        set->to_local.resize(set->colliders->size());
      }
      set->to_local[k] = c.pose.inverse(Eigen::Isometry);
    }
    set->balls[k] << c.pose.translation(),
        c.shape == ColliderShape::kHalfSpace ? -1.0 : BoundingRadius(c);
  }
}

// The chain's length (with a margin of 1e-12 of it for the rounding) and its longest link.
inline void ChainReach(const double* lengths, int n, double* reach, double* longest) {
  double total = 0.0;
  *longest = 0.0;
  for (int i = 0; i < n; ++i) total += lengths[i], *longest = std::fmax(*longest, lengths[i]);
  *reach = total * (1.0 + 1e-12);
}

// The colliders a sweep from the new head `head` may meet (NearColliders over the chain's length),
// with their balls.
template <int Dim>
const SweepSet& SweepColliders(const double* head, const double* lengths, int n,
                               const std::vector<Collider>& all, const ContactStats& stats) {
  double reach, longest;
  ChainReach(lengths, n, &reach, &longest);
  thread_local std::vector<Collider> near;
  thread_local SweepSet set;
  FillSweepSet<Dim>(head, reach, longest, all, stats, &near, &set);
  return set;
}

template <class Rule, int Dim>
void ContactSweepOf(const double* head, const double* lengths, const double* inv_lengths, int n,
                    double* pts, const std::vector<Collider>& all, ContactStats* stats) {
  const SweepSet& colliders = SweepColliders<Dim>(head, lengths, n, all, *stats);
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
    KeepOutside<Dim>(i, lead_new, tail_old, tail, lengths[i - 1], inv_lengths[i - 1], colliders,
                     stats);
    for (int k = 0; k < Dim; ++k) lead_old[k] = tail_old[k], lead_new[k] = tail[k];
  }
}

// Minimum rotation with colliders: every point moves by the head's shift (SweepsMinRotation's
// operations) until a link meets a collider; that link's tail takes the clear direction nearest
// its old one, and every later link keeps its old direction from its new leading end (no
// rotation), unless it too meets a collider.
template <int Dim>
void MinRotationContactSweep(const double* head, const double* lengths, const double* inv_lengths,
                             int n, double* pts, const std::vector<Collider>& all,
                             ContactStats* stats) {
  double shift[Dim], lead_old[Dim];
  for (int k = 0; k < Dim; ++k) {
    shift[k] = head[k] - pts[k];
    lead_old[k] = pts[k];
    pts[k] += shift[k];
  }
  const SweepSet& colliders = SweepColliders<Dim>(pts, lengths, n, all, *stats);
  bool shifted = true;  // no link of this sweep has met a collider yet
  for (int i = 1; i <= n; ++i) {
    double* tail = pts + i * Dim;
    const double* lead = tail - Dim;
    double tail_old[Dim], rule[Dim];
    for (int k = 0; k < Dim; ++k) {
      tail_old[k] = tail[k];
      tail[k] = shifted ? tail[k] + shift[k] : lead[k] + (tail_old[k] - lead_old[k]);
      rule[k] = tail[k];
    }
    if (KeepOutside<Dim>(i, lead, rule, tail, lengths[i - 1], inv_lengths[i - 1], colliders,
                         stats)) {
      shifted = false;
    }
    for (int k = 0; k < Dim; ++k) lead_old[k] = tail_old[k];
  }
}

// Minimum joint-angle change with colliders: the first link by the tractrix step (where it would
// enter a collider, the contact step from its old tail, as the tractrix's), the chain behind it
// turned rigidly by the rotation R of its direction (MinJointAngle's operations), p_i <- a_new +
// R (p_i - a_old) with a = point 1. A later link i whose turned position enters a collider takes
// the clear direction nearest the turned one; R is then composed with the rotation from the
// turned direction to the new one and a becomes point i: the links behind it keep their joint
// angles to it.
template <int Dim>
void MinJointAngleContactSweep(const double* head, const double* lengths, const double* inv_lengths,
                               int n, double* pts, const std::vector<Collider>& all,
                               ContactStats* stats) {
  using Vec = Eigen::Matrix<double, Dim, 1>;
  Eigen::Map<Eigen::Matrix<double, Dim, Eigen::Dynamic>> p(pts, Dim, n + 1);
  const SweepSet& colliders = SweepColliders<Dim>(head, lengths, n, all, *stats);
  const Vec head_old = p.col(0), first_old = p.col(1);
  const Vec head_new = Eigen::Map<const Vec>(head);
  Vec first_new = first_old;
  TractrixStep<Dim>(head_old.data(), head_new.data(), first_new.data(), lengths[0], inv_lengths[0]);
  KeepOutside<Dim>(1, head_new.data(), first_old.data(), first_new.data(), lengths[0],
                   inv_lengths[0], colliders, stats);
  const Vec u = first_old - head_old, v = first_new - head_new;
  Eigen::Matrix<double, Dim, Dim> rotation = RotationBetween<Dim>(u, v);
  p.col(0) = head_new;
  p.col(1) = first_new;
  Vec from = first_old, to = first_new, tail, rule;
  for (int i = 2; i <= n; ++i) {
    const Vec tail_old = p.col(i);
    tail = to + rotation * (p.col(i) - from);
    rule = tail;
    const Vec lead = p.col(i - 1);
    if (KeepOutside<Dim>(i, lead.data(), rule.data(), tail.data(), lengths[i - 1],
                         inv_lengths[i - 1], colliders, stats)) {
      const Vec turned = rule - lead, moved = tail - lead;
      rotation = (RotationBetween<Dim>(turned, moved) * rotation).eval();
      from = tail_old;
      to = tail;
    }
    p.col(i) = tail;
  }
}

}  // namespace

void NearSweepSet(int dim, const double* head, double spread, const double* lengths, int n,
                  SweepContact* contact) {
  double reach, longest;
  ChainReach(lengths, n, &reach, &longest);
  reach += spread;
  dim == 2 ? FillSweepSet<2>(head, reach, longest, *contact->colliders, contact->stats,
                             &contact->near, &contact->set)
           : FillSweepSet<3>(head, reach, longest, *contact->colliders, contact->stats,
                             &contact->near, &contact->set);
}

bool KeepLinkOutside(int dim, int i, const double* lead, const double* toward, double* tail,
                     double length, double inv_length, SweepContact* contact) {
  return dim == 2 ? KeepOutside<2>(i, lead, toward, tail, length, inv_length, contact->set,
                                   &contact->stats)
                  : KeepOutside<3>(i, lead, toward, tail, length, inv_length, contact->set,
                                   &contact->stats);
}

void ContactSweep(Method method, int dim, const double* head, const double* lengths,
                  const double* inv_lengths, int n, double* points,
                  const std::vector<Collider>& colliders, ContactStats* stats) {
  // The whole-chain rules are no per-link rules of the sweeps engine: swept here link by link.
  if (method == Method::kMinRotation) {
    dim == 2 ? MinRotationContactSweep<2>(head, lengths, inv_lengths, n, points, colliders, stats)
             : MinRotationContactSweep<3>(head, lengths, inv_lengths, n, points, colliders, stats);
    return;
  }
  if (method == Method::kMinJointAngle) {
    dim == 2
        ? MinJointAngleContactSweep<2>(head, lengths, inv_lengths, n, points, colliders, stats)
        : MinJointAngleContactSweep<3>(head, lengths, inv_lengths, n, points, colliders, stats);
    return;
  }
  DispatchRule<kSweepsEngine>(method, [&](auto rule) {
    using Rule = decltype(rule);
    dim == 2 ? ContactSweepOf<typename Rule::template Step<2>, 2>(head, lengths, inv_lengths, n,
                                                                  points, colliders, stats)
             : ContactSweepOf<typename Rule::template Step<3>, 3>(head, lengths, inv_lengths, n,
                                                                  points, colliders, stats);
  });
}

}  // namespace flexkin::internal
