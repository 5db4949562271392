// Dynamic chains (flexkin/dynamics.h, docs/dynamics.md): inertial prediction, then one of three
// projections onto the length constraints.
#include "flexkin/dynamics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "chain/substep.h"
#include "dynamics/least_constraint.h"
#include "dynamics/shake.h"
#include "overall/contact_step.h"
#include "sequential/link_rules.h"
#include "world/contact.h"

namespace flexkin {

Problems DynamicOptions::ValidateFor(int dim) const {
  Problems problems;
  if (gravity.size() != dim || !gravity.allFinite()) {
    problems.emplace_back(
        "gravity", "has " + std::to_string(gravity.size()) + " finite entries or fewer; expected " +
                       std::to_string(dim) + " finite numbers (the chain's dimension)");
  }
  if (wind.size() != 0 && (wind.size() != dim || !wind.allFinite())) {
    problems.emplace_back("wind", "has " + std::to_string(wind.size()) +
                                      " entries or one that is not finite; expected none (still "
                                      "air) or " +
                                      std::to_string(dim) + " finite numbers (a velocity)");
  }
  for (size_t i = 0; i < wind_keys.size(); ++i) {
    const std::string at = "wind_keys[" + std::to_string(i) + "]";
    const WindKey& key = wind_keys[i];
    if (!std::isfinite(key.time) || (i > 0 && !(key.time > wind_keys[i - 1].time))) {
      problems.push_back(Problem::Invalid(at + ".time", FormatNumber(key.time),
                                          i > 0 ? "a finite time after the previous key's (" +
                                                      FormatNumber(wind_keys[i - 1].time) + " s)"
                                                : "a finite time (s)"));
    }
    if (key.velocity.size() != dim || !key.velocity.allFinite()) {
      problems.emplace_back(at + ".velocity", "has " + std::to_string(key.velocity.size()) +
                                                  " entries or one that is not finite; expected " +
                                                  std::to_string(dim) +
                                                  " finite numbers (a velocity)");
    }
  }
  for (Eigen::Index i = 0; i < masses.size(); ++i) {
    if (!(masses[i] > 0.0 && std::isfinite(masses[i]))) {
      problems.push_back(Problem::Invalid("masses[" + std::to_string(i) + "]",
                                          FormatNumber(masses[i]), "a finite number > 0"));
    }
  }
  if (!(damping >= 0.0 && std::isfinite(damping))) {
    problems.push_back(
        Problem::Invalid("damping", FormatNumber(damping), "a finite number >= 0 (1/s)"));
  }
  if (!(frame_rate > 0.0 && std::isfinite(frame_rate))) {
    problems.push_back(
        Problem::Invalid("frame_rate", FormatNumber(frame_rate), "a finite number > 0 (1/s)"));
  }
  if (substeps < 1) {
    problems.push_back(Problem::Invalid("substeps", std::to_string(substeps), ">= 1"));
  }
  for (size_t i = 0; i < colliders.size(); ++i) {
    const std::string at = "colliders[" + std::to_string(i) + "]";
    for (Problem& p : CheckCollider(colliders[i], at)) problems.push_back(std::move(p));
    if (colliders[i].shape == ColliderShape::kMesh && dim != 3) {
      problems.push_back(Problem::Invalid(at + ".shape", "\"mesh\"",
                                          "a convex shape: a mesh collider takes 3D chains only"));
    }
  }
  if (!(dftl_damping >= 0.0 && dftl_damping <= 1.0)) {
    problems.push_back(
        Problem::Invalid("dftl_damping", FormatNumber(dftl_damping), "a number in [0, 1]"));
  }
  return problems;
}

Eigen::VectorXd DynamicOptions::WindAt(double time, int dim) const {
  if (wind_keys.empty()) return wind.size() == dim ? wind : Eigen::VectorXd::Zero(dim);
  if (time <= wind_keys.front().time) return wind_keys.front().velocity;
  if (time >= wind_keys.back().time) return wind_keys.back().velocity;
  size_t i = 1;
  while (wind_keys[i].time < time) ++i;
  const WindKey& a = wind_keys[i - 1];
  const WindKey& b = wind_keys[i];
  const double u = (time - a.time) / (b.time - a.time);
  // a + u (b - a): a key held (equal velocities) is its velocity exactly.
  return a.velocity + u * (b.velocity - a.velocity);
}

namespace {

Eigen::Vector3d At(const Points& x, int j) {
  return Eigen::Vector3d(x(j, 0), x(j, 1), x.cols() == 3 ? x(j, 2) : 0.0);
}

// How the sequential contact sweep (Projector::Sequential) places each link's trailing end before
// the colliders are looked at.
enum class SweepRule {
  kFollowTheLeader,  // on the sphere about its leading end's new place, nearest the prediction
  kTractrix,         // the predicted link restored about its leading end's prediction, carried
  kCarry,            // the (already projected) link carried by the tractrix step
};

// The projections of the prediction `p` (row 0 the driven end's new place) onto the lengths, into
// `x`.
class Projector {
 public:
  // `mass`: the points' masses (n + 1, [0] unused), the overall projection's weights.
  Projector(const Eigen::VectorXd& lengths, int dim, const Eigen::VectorXd& mass)
      : lengths_(lengths),
        inv_lengths_(lengths.cwiseInverse()),
        n_(static_cast<int>(lengths.size())),
        dim_(dim),
        mass_(mass),
        work_(internal::LeastConstraintWork(dim, n_)),
        multipliers_(n_ + 1, 0.0) {
    contact_.assign(n_ + 1, 0);
  }

  void FollowTheLeader(const Points& p, Points* x) const {
    x->row(0) = p.row(0);
    for (int j = 1; j <= n_; ++j) {
      const Eigen::RowVectorXd d = p.row(j) - x->row(j - 1);
      x->row(j) = x->row(j - 1) + (lengths_[j - 1] / d.norm()) * d;
    }
  }

  void Tractrix(const Points& p, Points* x) const {
    x->row(0) = p.row(0);
    for (int j = 1; j <= n_; ++j) TractrixLink(p, SweepRule::kTractrix, j, x);
  }

  // SHAKE (dynamics/shake.h): the correction along the links of `old`, with the multipliers that
  // give every link its length. False if it did not converge.
  bool Shake(const Points& old, const Points& p, Points* x) {
    internal::ShakeProblem problem;
    problem.n = n_;
    problem.head = 0;
    problem.p = p.data();
    problem.old = old.data();
    problem.x = x->data();
    problem.mass = mass_.data();
    problem.lengths = lengths_.data();
    problem.work = work_.data();
    const double ok = dim_ == 2 ? internal::SolveShake<double, 2>(problem)
                                : internal::SolveShake<double, 3>(problem);
    return ok != 0.0;
  }

  // The least mass-weighted correction: Newton on the overall problem measured from `p` (point j
  // weighted by its mass; dynamics/least_constraint.h), from the tractrix projection and the last
  // call's multipliers. False if it did not converge (`x` then holds that projection).
  bool Overall(const Points& p, Points* x) {
    Tractrix(p, x);
    internal::LeastConstraintProblem problem;
    problem.n = n_;
    problem.head = 0;
    problem.p = p.data();
    problem.x = x->data();
    problem.mass = mass_.data();
    problem.lengths = lengths_.data();
    problem.inv_lengths = inv_lengths_.data();
    problem.work = work_.data();
    problem.multipliers = multipliers_.data();
    const double ok = dim_ == 2 ? internal::SolveLeastConstraint<double, 2>(problem)
                                : internal::SolveLeastConstraint<double, 3>(problem);
    return ok != 0.0;
  }

  // Whether every link of `x` lies outside every one of `colliders` (to kContactSlack of its
  // length).
  bool Clear(const Points& x, const std::vector<Collider>& colliders) const {
    for (int i = 1; i <= n_; ++i) {
      if (internal::SegmentClearance(colliders, At(x, i - 1), At(x, i)) <
          -internal::kContactSlack * lengths_[i - 1]) {
        return false;
      }
    }
    return true;
  }

  // A sequential sweep with colliders: link by link from the driven end, the trailing end placed
  // by `rule` (from `p`) and kept where the link lies outside every collider; else it takes the
  // clear direction nearest that place (ContactTail, world/contact.h): for follow-the-leader the
  // direction nearest the prediction (the same place), for the tractrix rules nearest the rule's
  // result. Points that took the contact step are flagged in contact(j). Returns whether any did.
  bool Sequential(const Points& p, SweepRule rule, const std::vector<Collider>& colliders,
                  Points* x) {
    x->row(0) = p.row(0);
    bool any = false;
    for (int j = 1; j <= n_; ++j) {
      if (rule == SweepRule::kFollowTheLeader) {
        const Eigen::RowVectorXd d = p.row(j) - x->row(j - 1);
        x->row(j) = x->row(j - 1) + (lengths_[j - 1] / d.norm()) * d;
      } else {
        TractrixLink(p, rule, j, x);
      }
      contact_[j] = 0;
      const Eigen::Vector3d head = At(*x, j - 1);
      if (internal::SegmentClearance(colliders, head, At(*x, j)) >=
          -internal::kContactSlack * lengths_[j - 1]) {
        continue;
      }
      Eigen::Vector3d tail;
      if (!internal::ContactTail(dim_, head, At(*x, j), lengths_[j - 1], colliders, &tail)) {
        throw InputError("colliders", "leave no room for link " + std::to_string(j) +
                                          ": every position of point " + std::to_string(j) +
                                          " at its link's length from point " +
                                          std::to_string(j - 1) + " lies in a collider");
      }
      internal::SettleTail(dim_, head, lengths_[j - 1], colliders, &tail);
      for (int k = 0; k < dim_; ++k) (*x)(j, k) = tail[k];
      contact_[j] = 1;
      any = true;
    }
    return any;
  }
  bool contact(int j) const { return contact_[j] != 0; }

  // Moves the prediction `*q` out by the penetrations of its projection `x`: each point inside a
  // collider by its depth along the normal; each link whose interior enters a convex one (both
  // its free ends) by the depth along the normal where it comes nearest.
  void PushOut(const Points& x, const std::vector<Collider>& colliders, Points* q) const {
    for (int j = 1; j <= n_; ++j) {
      const Eigen::Vector3d a = At(x, j - 1), b = At(x, j);
      for (const Collider& c : colliders) {
        const SurfaceQuery at = QuerySurface(c, b);
        if (at.distance < 0.0) {
          for (int k = 0; k < dim_; ++k) (*q)(j, k) -= at.distance * at.normal[k];
        }
        if (c.shape == ColliderShape::kMesh) continue;
        const internal::SegmentContact near = internal::NearestOnSegment(c, a, b);
        if (near.clearance < -internal::kContactSlack * lengths_[j - 1] && near.s > 0.0 &&
            near.s < 1.0) {
          for (int k = 0; k < dim_; ++k) {
            if (j >= 2) (*q)(j - 1, k) -= near.clearance * near.normal[k];
            (*q)(j, k) -= near.clearance * near.normal[k];
          }
        }
      }
    }
  }

 private:
  // Link j's trailing end by the tractrix rule from `p` (kTractrix: the predicted link first put
  // back to its length about its leading end's prediction; kCarry: `p` already has the lengths),
  // the leading end's correction p_{j-1} -> x_{j-1} carried by the tractrix step.
  void TractrixLink(const Points& p, SweepRule rule, int j, Points* x) const {
    double head_old[3], head_new[3], tail[3];
    const Eigen::RowVectorXd d = p.row(j) - p.row(j - 1);
    const Eigen::RowVectorXd restored =
        rule == SweepRule::kCarry
            ? Eigen::RowVectorXd(p.row(j))
            : Eigen::RowVectorXd(p.row(j - 1) + (lengths_[j - 1] / d.norm()) * d);
    for (int k = 0; k < dim_; ++k) {
      head_old[k] = p(j - 1, k);
      head_new[k] = (*x)(j - 1, k);
      tail[k] = restored[k];
    }
    if (dim_ == 2) {
      internal::TractrixStep<2>(head_old, head_new, tail, lengths_[j - 1], inv_lengths_[j - 1]);
    } else {
      internal::TractrixStep<3>(head_old, head_new, tail, lengths_[j - 1], inv_lengths_[j - 1]);
    }
    for (int k = 0; k < dim_; ++k) (*x)(j, k) = tail[k];
  }

  const Eigen::VectorXd& lengths_;
  const Eigen::VectorXd inv_lengths_;
  const int n_, dim_;
  const Eigen::VectorXd mass_;
  std::vector<double> work_;
  std::vector<double> multipliers_;  // the overall projection's last, where the next starts
  std::vector<char> contact_;
};

// The colliders' names in messages: "colliders[2] (sphere)", with the time of a moving one.
std::string ColliderName(const std::vector<Collider>& colliders, size_t c, double time) {
  std::string name =
      "colliders[" + std::to_string(c) + "] (" + ColliderShapeName(colliders[c].shape) + ")";
  if (colliders[c].motion) name += " at " + FormatNumber(time) + " s of its motion";
  return name;
}

// A chain that starts inside a collider (its colliders at time 0) is refused, by point or link,
// collider and depth; so is a driven end whose path enters one (static colliders: the straight
// path through the rows; moving ones are checked at every sub-step, CheckHead).
void CheckStartOutside(const Chain& chain, const Points& root_path,
                       const std::vector<Collider>& colliders) {
  const double shortest = chain.lengths.minCoeff();
  const Points& x = chain.points;
  for (size_t c = 0; c < colliders.size(); ++c) {
    const Collider collider = ColliderAt(colliders[c], 0.0);
    const std::string name = ColliderName(colliders, c, 0.0);
    for (Eigen::Index i = 0; i < x.rows(); ++i) {
      const double clearance = QuerySurface(collider, At(x, static_cast<int>(i))).distance;
      if (clearance < -internal::kContactSlack * shortest) {
        throw InputError("chain.points[" + std::to_string(i) + "]",
                         "lies inside " + name + " by " + FormatNumber(-clearance) +
                             "; the chain must start outside every collider");
      }
    }
    for (Eigen::Index i = 1; i < x.rows(); ++i) {
      const int j = static_cast<int>(i);
      const double clearance = internal::SegmentClearance(collider, At(x, j - 1), At(x, j));
      if (clearance < -internal::kContactSlack * chain.lengths[i - 1]) {
        throw InputError("chain.points[" + std::to_string(i) + "]",
                         "link " + std::to_string(i) + " (points " + std::to_string(i - 1) +
                             " to " + std::to_string(i) + ") passes through " + name + ", " +
                             FormatNumber(-clearance) +
                             " deep; the chain must start outside every collider");
      }
    }
    if (colliders[c].motion) continue;
    Eigen::Vector3d from = At(x, 0);
    for (Eigen::Index f = 0; f < root_path.rows(); ++f) {
      const Eigen::Vector3d to = At(root_path, static_cast<int>(f));
      const double clearance = internal::SegmentClearance(collider, from, to);
      if (clearance < -internal::kContactSlack * shortest) {
        throw InputError("root_path[" + std::to_string(f) + "]",
                         "the driven end's path to this row enters " + name + ", " +
                             FormatNumber(-clearance) +
                             " deep; the path must stay outside every collider");
      }
      from = to;
    }
  }
}

}  // namespace

DynamicResult SimulateChain(const Chain& chain, const Points& root_path,
                            const DynamicOptions& options) {
  ValidateChain(chain, "chain");
  const int dim = chain.dim();
  const int n = chain.num_links();
  ThrowIfAny(options.ValidateFor(dim));
  if (root_path.cols() != dim || !root_path.allFinite()) {
    throw InputError("root_path", "has " + std::to_string(root_path.cols()) +
                                      " columns or a value that is not finite; expected " +
                                      std::to_string(dim) + " finite coordinates per frame");
  }
  if (options.masses.size() != 0 && options.masses.size() != n) {
    throw InputError("masses", "has " + std::to_string(options.masses.size()) +
                                   " entries; expected none (masses by length or equal) or " +
                                   std::to_string(n) + ", one per free point 1 .. " +
                                   std::to_string(n));
  }
  const std::vector<Collider>& colliders = options.colliders;
  if (!colliders.empty()) CheckStartOutside(chain, root_path, colliders);
  const bool moving = AnyMoves(colliders);
  const Eigen::VectorXd& lengths = chain.lengths;
  // Masses, the free points' total 1: given, by length or equal.
  Eigen::VectorXd mass = Eigen::VectorXd::Zero(n + 1);
  for (int j = 1; j <= n; ++j) {
    mass[j] = options.masses.size() == n ? options.masses[j - 1]
              : options.mass_by_length   ? 0.5 * (lengths[j - 1] + (j < n ? lengths[j] : 0.0))
                                         : 1.0;
  }
  mass /= mass.sum();
  const double h = 1.0 / (options.frame_rate * options.substeps);
  const Eigen::RowVectorXd g = options.gravity.transpose();
  Eigen::RowVectorXd air = options.WindAt(0.0, dim).transpose();
  Projector projector(lengths, dim, mass);
  internal::OverallContactState contact_state;

  Points x = chain.points, x_old, p(n + 1, dim), projected(n + 1, dim), corrected(n + 1, dim),
         pushed;
  Points v = Points::Zero(n + 1, dim);
  DynamicResult result;
  // The velocity is the last sub-step's mean: the energy is taken at that sub-step's middle, the
  // potential at the mean of its two positions (second order, as the velocity).
  const auto energy = [&]() {
    double e = 0.0;
    for (int j = 1; j <= n; ++j) {
      e += mass[j] * (0.5 * v.row(j).squaredNorm() - 0.5 * g.dot(x.row(j) + x_old.row(j)));
    }
    return e;
  };
  const auto measure_lengths = [&]() {
    for (int i = 1; i <= n; ++i) {
      const double length = (x.row(i) - x.row(i - 1)).norm();
      result.max_relative_length_error = std::fmax(
          result.max_relative_length_error, std::fabs(length - lengths[i - 1]) / lengths[i - 1]);
    }
  };
  const bool sequential =
      options.projection == Projection::kDftl || options.projection == Projection::kTractrix;
  const Eigen::Index frames = root_path.rows();
  result.frames.reserve(frames + 1);
  result.frames.push_back(x);
  x_old = x;
  result.energy.resize(frames + 1);
  result.energy[0] = energy();
  std::vector<Collider> placed;
  for (Eigen::Index f = 0; f < frames; ++f) {
    const Eigen::RowVectorXd from = x.row(0);
    for (int s = 1; s <= options.substeps; ++s) {
      // The sub-step's times (seconds from the run's start): the wind at its middle, the
      // colliders at its end (where the projected positions are).
      const double steps = options.frame_rate * options.substeps;
      const double t_mid = (static_cast<double>(f) * options.substeps + (s - 0.5)) / steps;
      const double t_end = (static_cast<double>(f) * options.substeps + s) / steps;
      if (!options.wind_keys.empty()) air = options.WindAt(t_mid, dim).transpose();
      x_old = x;
      for (int k = 0; k < dim; ++k) {
        p(0, k) = internal::SubstepHead(from[k], root_path(f, k), s, options.substeps);
      }
      for (int j = 1; j <= n; ++j) {
        const Eigen::RowVectorXd predicted =
            v.row(j) + h * (g + options.damping * (air - v.row(j)));
        p.row(j) = x.row(j) + h * predicted;
      }
      if (moving) {
        placed = CollidersAt(colliders, t_end);
        for (size_t c = 0; c < placed.size(); ++c) {
          const double clearance = QuerySurface(placed[c], At(p, 0)).distance;
          if (clearance < -internal::kContactSlack * lengths.minCoeff()) {
            throw InputError("root_path[" + std::to_string(f) + "]",
                             "the driven end lies inside " + ColliderName(colliders, c, t_end) +
                                 " by " + FormatNumber(-clearance) +
                                 "; the path must stay outside every collider");
          }
        }
      }
      const std::vector<Collider>& now = moving ? placed : colliders;
      bool contact = false;
      // Whether an overall projection did not converge (its tractrix start kept, which then takes
      // the tractrix projection's velocity correction: without it that projection gains energy).
      bool fell_back = false;
      // The overall and SHAKE projections of a prediction `q`.
      const auto project = [&](const Points& q, Points* out) {
        if (options.projection == Projection::kOverall) {
          if (!projector.Overall(q, out)) {
            ++result.failures;
            fell_back = true;
          }
        } else if (!projector.Shake(x_old, q, out)) {
          // SHAKE's forces are those of the sub-step's start: past its stability limit (a step
          // longer than about 2 / the chain's highest frequency) its lengths have no solution.
          // That sub-step is then projected by the overall projection, which always has one.
          ++result.failures;
          if (!projector.Overall(q, out)) fell_back = true;
        }
      };
      switch (options.projection) {
        case Projection::kOverall:
        case Projection::kShake:
          project(p, &projected);
          if (!now.empty() && !projector.Clear(projected, now)) {
            contact = true;
            // The overall projection with the contacts as constraints of its own solve
            // (overall/contact_step.h): the least mass-weighted motion from the prediction that
            // keeps the lengths and every point and link outside every collider, from the
            // tractrix contact projection (outside every collider), and where that does not
            // converge, from the projection without colliders (where that did not converge, the
            // tractrix projection it kept). Solved, it is the projection: no velocity
            // correction.
            if (options.projection == Projection::kOverall) {
              projector.Sequential(p, SweepRule::kTractrix, now, &corrected);
              bool solved = internal::LeastConstraintContact(lengths, mass, p, now, &contact_state,
                                                             &corrected);
              if (!solved) {
                corrected = projected;
                solved = internal::LeastConstraintContact(lengths, mass, p, now, &contact_state,
                                                          &corrected);
              }
              if (solved) {
                projected = corrected;
                fell_back = false;
                ++result.contact_solves;
                break;
              }
              ++result.contact_solve_failures;
            }
            // SHAKE's projection, and an overall one with contacts that did not converge: where
            // the projection leaves a point or a link inside a collider, the prediction is moved
            // out by that penetration (the contact's inelastic impulse) and projected again, up
            // to 8 times; if that does not clear it, the projection is kept up to the first link
            // not clear, and from there on each trailing end is carried by the tractrix step of
            // its leading end's change and, where its link is not clear, takes the clear
            // direction nearest that (the sequential contact sweep).
            pushed = p;
            bool clear = false;
            for (int round = 0; round < 8 && !clear; ++round) {
              projector.PushOut(projected, now, &pushed);
              project(pushed, &projected);
              clear = projector.Clear(projected, now);
            }
            if (!clear) {
              projector.Sequential(projected, SweepRule::kCarry, now, &corrected);
              projected = corrected;
            }
          }
          break;
        case Projection::kTractrix:
          if (now.empty()) {
            projector.Tractrix(p, &projected);
          } else {
            contact = projector.Sequential(p, SweepRule::kTractrix, now, &projected);
          }
          break;
        case Projection::kDftl:
          if (now.empty()) {
            projector.FollowTheLeader(p, &projected);
          } else {
            contact = projector.Sequential(p, SweepRule::kFollowTheLeader, now, &projected);
          }
          break;
      }
      result.contact_substeps += contact;
      x = projected;
      v = (x - x_old) / h;
      if (sequential || fell_back) {
        // Mueller et al. 2012, eq. (9): v_j += s (-d_{j+1}) / h, d = the correction x - p; not
        // of a point a collider placed (its correction is the contact's, not the link's).
        for (int j = 1; j < n; ++j) {
          if (contact && projector.contact(j + 1)) continue;
          v.row(j) -= options.dftl_damping * (x.row(j + 1) - p.row(j + 1)) / h;
        }
      }
    }
    measure_lengths();
    result.frames.push_back(x);
    result.energy[f + 1] = energy();
  }
  return result;
}

}  // namespace flexkin
