// The overall step with colliders (overall/contact_step.h, docs/colliders.md "The overall
// method").
//
// A sub-problem: minimize the metric f(x) over points 1..n (point 0 the prescribed head) subject
// to c_i(x) = (|x_i - x_{i-1}|^2 - L_i^2) / (2 L_i) = 0 and, for each collider k, the contact
// constraints g >= 0:
//  - point j against collider k: g = the signed distance of x_j (gradient: the outward normal);
//  - link i against collider k, where its interior comes nearer than both its ends: g = the
//    least signed distance along the link, reached at x_{i-1} + s (x_i - x_{i-1}) (gradient, by
//    the envelope theorem: (1 - s) normal in x_{i-1}, s normal in x_i).
// A link is outside a convex collider exactly when both its ends are and, where its interior
// comes nearest, that point is: the two kinds together say "no point and no link inside". A
// mesh, not convex, is measured at the local minimum of the distance along the link that
// NearestOnSegment finds (where the mesh's features are coarser than its samples, the least);
// its faces' normals jump at edges, as a box's do. A sub-problem's solution is kept only where
// the exact clearances (SegmentClearance: a mesh's crossings) find every link outside.
//
// KKT conditions, with the Lagrangian f + lambda'c - mu'g: grad f + J_c' lambda - J_g' mu = 0,
// c = 0, and g >= 0, mu >= 0, mu g = 0. The complementarity is met by a primal-dual active set:
// the contacts with mu - kappa g > 0 are equalities g = 0, the others have mu = 0 (a contact
// the step would enter has g < 0 and joins; one whose multiplier pulls inward leaves). Each
// iteration is a Newton step on those equations, a sparse symmetric indefinite system solved by
// sparse LU; the contacts' curvature enters its Hessian by central differences of their exact
// gradients.

#include "overall/contact_step.h"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "chain/substep.h"
#include "overall/objective.h"
#include "overall/step.h"
#include "world/contact.h"
#include "world/mesh_collider.h"

namespace flexkin::internal {
namespace {

using Eigen::Vector3d;

// One contact constraint of the active set (see the top of this file).
struct Contact {
  bool link = false;
  int index = 0;     // point j (1..n) or link i (1..n)
  int collider = 0;  // k
  double value = 0.0;
  double s = 0.0;  // a link's: where along it the contact is
  Vector3d normal = Vector3d::UnitZ();
  double multiplier = 0.0;
};

class ContactSolver {
 public:
  // `point_weights` (n + 1 entries, [0] unused; their largest about 1), if set: the metric is
  // sum_j w_j |x_j - old_j|^2 (options' squared weight 1, the others 0). `moving` (k, 1..n; -1:
  // n): only points 1..k are unknowns, the points after k held where they are (the L2 metric's
  // still tail, which the caller places at the old points); the constraints are those of links
  // 1..k+1 and of the contacts of points 1..k and links 1..k+1. `smoothing` > 0: the L2 term
  // smoothed (objective.h's Evaluate).
  ContactSolver(const Eigen::VectorXd& lengths, const Points& old_points,
                const OverallOptions& options, const std::vector<Collider>& colliders,
                OverallContactState* state, const Eigen::VectorXd* point_weights = nullptr,
                int moving = -1, double smoothing = 0.0)
      : lengths_(lengths),
        old_(old_points),
        options_(options),
        colliders_(colliders),
        state_(*state),
        n_(static_cast<int>(lengths.size())),
        dim_(static_cast<int>(old_points.cols())),
        m_(static_cast<int>(colliders.size())),
        k_(moving < 0 ? n_ : moving),
        links_(std::min(k_ + 1, n_)),
        unknowns_(k_ * dim_),
        last_(k_ < n_ ? std::min(n_, k_ + 2) : -1),
        shortest_(lengths.minCoeff()),
        weight_sum_(WeightSum(options.weights, lengths)),
        smoothing_(smoothing) {
    sink_.dim = dim_;
    sink_.offset.assign(n_ + 1, -1);
    for (int j = 1; j <= k_; ++j) sink_.offset[j] = (j - 1) * dim_;
    if (point_weights != nullptr) sink_.point_weights = point_weights->data();
  }

  // Solves the sub-problem with the head at row 0 of `*x`, from `*x` (outside every collider,
  // lengths kept). On success `*x` is the solution; else it is left as it was.
  OverallReport Solve(Points* x);
  // After Solve: the force the solution's contacts put on the still point j (k < j): minus the
  // multiplier times s times the normal of an active contact of link j, into `*force` (dim).
  void AddContactForceOnStill(int j, Eigen::VectorXd* force) const;

 private:
  // The state of the iteration at one configuration.
  struct Point {
    Points x;
    double objective = 0.0;
    Eigen::VectorXd gradient;   // of the metric
    Eigen::VectorXd c;          // the length constraints
    std::vector<Contact> near;  // the contact constraints within a step's reach
    double violation = 0.0;     // largest |c_i| / L_i
    double penetration = 0.0;   // sum of max(0, -g) over every contact constraint
    double least = 0.0;         // least clearance of any point or link, relative to its link
  };

  Vector3d At(const Points& x, int j) const {
    return Vector3d(x(j, 0), x(j, 1), dim_ == 3 ? x(j, 2) : 0.0);
  }
  double& Multiplier(const Contact& c) {
    return (c.link ? state_.link_multipliers : state_.point_multipliers)[c.index * m_ + c.collider];
  }

  // The values at `p->x` (the metric's derivatives into gradient and, if `hessian`, triplets_).
  void Evaluate(Point* p, bool hessian);
  // The contact constraints of `x` within reach of a step into `*near` (their multipliers from
  // the state), and the penetration and least clearance over all of them.
  // `keep`: the iterate's (not a trial's): a link whose contact moved to its end passes its
  // multiplier to that end's point.
  void FindContacts(const Points& x, bool keep, std::vector<Contact>* near, double* penetration,
                    double* least);
  // The length constraints' multipliers that best meet stationarity at `p` with the contacts'
  // multipliers (least squares), into state_.lambda.
  void StartingMultipliers(const Point& p);
  Contact Measure(const Contact& contact, const Points& x) const;
  void AddGradient(const Contact& contact, double scale, Eigen::VectorXd* out) const;
  double Linearized(const Contact& contact, const Eigen::VectorXd& step) const;
  // The contact's Hessian times `scale` (central differences of its gradient) into triplets_.
  void AddCurvature(const Contact& contact, const Points& x, double scale);
  double Stationarity(const Point& p, Eigen::VectorXd* residual) const;
  // The step's quadratic model with the contacts of `working` as equalities: the step and the
  // new multipliers (lambda, then one per working contact) into `*solution`.
  bool SolveModel(const Point& p, const std::vector<int>& working, Eigen::VectorXd* solution);
  // The model's solution with its active contacts chosen by a primal active set (a contact whose
  // multiplier pulls inward leaves; the one the step would enter most joins).
  bool SolveQp(const Point& p, std::vector<int>* working, Eigen::VectorXd* solution);
  // The second-order correction of a trial point (Nocedal and Wright, section 18.3): the step
  // p^ that the last model's matrix gives for the constraints' values at the trial (lengths and
  // working contacts), which the constraints' curvature left off them; `trial` + p^ into
  // `*corrected`, evaluated. False where the model gives none or it moves a point by more than
  // half the shortest link.
  bool Correct(const Point& p, const std::vector<int>& working, const Point& trial,
               Point* corrected);
  double Merit(const Point& p, double penalty) const {
    double sum = 0.0;
    for (int i = 0; i < links_; ++i) sum += std::fabs(p.c[i]);
    return p.objective + penalty * (sum + p.penetration);
  }

  const Eigen::VectorXd& lengths_;
  const Points& old_;
  const OverallOptions& options_;
  const std::vector<Collider>& colliders_;
  OverallContactState& state_;
  const int n_, dim_, m_, k_, links_, unknowns_, last_;
  const double shortest_, weight_sum_, smoothing_;
  std::vector<Contact> final_;  // the contacts of Solve's last iterate
  Sink sink_;
  std::vector<Eigen::Triplet<double>> triplets_;  // the Lagrangian's Hessian at the iterate
  Eigen::SparseMatrix<double> kkt_;
  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> lu_;
};

// A link over a convex edge of a sharp box or a mesh: the signed distance between the link's
// line and the edge's is smooth there, and its gradient is their common perpendicular, d x u for
// the link's direction d and the edge's u, turned outward. Where the link crosses the edge that
// is the normal, whatever face the point measures nearest (their normals turn by up to a right
// angle across it). Into `*normal` (world), where the link's nearest point (parameter s) lies on
// such an edge and the perpendicular lies between its two faces' normals (else a face is nearer);
// returns whether it did. The edge: for a box, the point within 1e-9 of its size of two faces'
// planes and not of a third; for a mesh, MeshNearestConvexEdge.
bool EdgeNormal(const Collider& c, const Vector3d& a, const Vector3d& b, double s,
                Vector3d* normal) {
  if (c.margin > 0.0 || !(s > 0.0 && s < 1.0)) return false;  // rounded edges are smooth already
  if (c.shape != ColliderShape::kBox && c.shape != ColliderShape::kMesh) return false;
  const Eigen::Isometry3d to_local = c.pose.inverse(Eigen::Isometry);
  const double scale = c.shape == ColliderShape::kMesh ? c.scale : 1.0;
  const Vector3d la = to_local * a / scale, lb = to_local * b / scale, p = la + s * (lb - la);
  Vector3d u, n1 = Vector3d::Zero(), n2 = Vector3d::Zero();
  if (c.shape == ColliderShape::kBox) {
    const double tol = 1e-9 * c.extents.norm();
    int count = 0, free_axis = -1;
    for (int k = 0; k < 3; ++k) {
      if (std::fabs(std::fabs(p[k]) - c.extents[k]) > tol) {
        free_axis = k;
        continue;
      }
      (count++ == 0 ? n1 : n2)[k] = p[k] > 0.0 ? 1.0 : -1.0;
    }
    if (count != 2) return false;
    u = Vector3d::Unit(free_axis);
  } else {
    Vector3d from, to;
    if (!MeshNearestConvexEdge(*c.mesh, p, &from, &to, &n1, &n2)) return false;
    u = (to - from).normalized();
  }
  Vector3d n = (lb - la).normalized().cross(u);
  if (!(n.norm() > 1e-6)) return false;  // the link along the edge: no single perpendicular
  n.normalize();
  if (n.dot(n1 + n2) < 0.0) n = -n;
  const Vector3d across = n1.cross(n2);
  if (n.cross(n2).dot(across) < 0.0 || n1.cross(n).dot(across) < 0.0) return false;
  *normal = c.pose.linear() * n;
  return true;
}

Contact ContactSolver::Measure(const Contact& contact, const Points& x) const {
  Contact out = contact;
  const Collider& c = colliders_[contact.collider];
  // A box's edges, a cylinder's rims and a mesh's edges and vertices: on or inside the surface
  // there the normal is a face's, not the gradient of the distance to the edge, which turns by up
  // to a right angle across it. Measured again a hair outside (1e-6 of a link along the normal),
  // where it is the direction from the edge: on a face the same normal, at an edge the one across
  // it.
  const bool edged = c.shape == ColliderShape::kBox || c.shape == ColliderShape::kCylinder ||
                     c.shape == ColliderShape::kMesh;
  const double hair = 1e-6 * lengths_[contact.index - 1];
  if (!contact.link) {
    const Vector3d p = At(x, contact.index);
    const SurfaceQuery q = QuerySurface(c, p);
    out.value = q.distance;
    out.normal = q.normal;
    if (edged && q.distance < hair) {
      out.normal = QuerySurface(c, p + (hair - q.distance) * q.normal).normal;
    }
  } else {
    const Vector3d a = At(x, contact.index - 1), b = At(x, contact.index);
    const SegmentContact near = NearestOnSegment(c, a, b);
    out.value = near.clearance;
    out.s = near.s;
    out.normal = near.normal;
    if (edged && near.clearance < hair && !EdgeNormal(c, a, b, near.s, &out.normal)) {
      const Vector3d shift = (hair - near.clearance) * near.normal;
      out.normal = NearestOnSegment(c, a + shift, b + shift).normal;
    }
    if (dim_ == 2 && near.s > 0.0 && near.s < 1.0) {
      // Where the interior is nearest, the normal is across the link (exactly so on a smooth
      // surface, and at a corner of the collider's section the gradient of the signed distance
      // from the corner to the link's line).
      const Vector3d u = (b - a).normalized();
      const Vector3d across = out.normal - out.normal.dot(u) * u;
      if (across.norm() > 0.0) out.normal = across.normalized();
    }
  }
  return out;
}

void ContactSolver::AddGradient(const Contact& contact, double scale, Eigen::VectorXd* out) const {
  if (!contact.link) {
    const int row = sink_.offset[contact.index];
    for (int q = 0; q < dim_; ++q) (*out)[row + q] += scale * contact.normal[q];
    return;
  }
  const int i = contact.index;
  if (i >= 2) {
    const int row = sink_.offset[i - 1];
    for (int q = 0; q < dim_; ++q) (*out)[row + q] += scale * (1.0 - contact.s) * contact.normal[q];
  }
  const int row = sink_.offset[i];
  if (row < 0) return;  // the still point after the last moving one
  for (int q = 0; q < dim_; ++q) (*out)[row + q] += scale * contact.s * contact.normal[q];
}

void ContactSolver::AddContactForceOnStill(int j, Eigen::VectorXd* force) const {
  for (const Contact& c : final_) {
    if (c.link && c.index == j && c.multiplier > 0.0) {
      for (int q = 0; q < dim_; ++q) (*force)[q] -= c.multiplier * c.s * c.normal[q];
    }
  }
}

double ContactSolver::Linearized(const Contact& contact, const Eigen::VectorXd& step) const {
  double value = contact.value;
  const auto add = [&](int j, double w) {
    if (j < 1 || sink_.offset[j] < 0) return;
    for (int q = 0; q < dim_; ++q) value += w * contact.normal[q] * step[sink_.offset[j] + q];
  };
  if (contact.link) {
    add(contact.index - 1, 1.0 - contact.s);
    add(contact.index, contact.s);
  } else {
    add(contact.index, 1.0);
  }
  return value;
}

void ContactSolver::AddCurvature(const Contact& contact, const Points& x, double scale) {
  // The coordinates the contact depends on: its point, or its link's moving ends.
  int first = contact.index;
  const int last = contact.index;
  if (contact.link && contact.index >= 2) first = contact.index - 1;
  const double h = 1e-6 * shortest_;
  Points probe = x;
  Eigen::VectorXd plus = Eigen::VectorXd::Zero(unknowns_), minus = plus;
  for (int j = first; j <= last; ++j) {
    if (sink_.offset[j] < 0) continue;
    for (int q = 0; q < dim_; ++q) {
      const int col = sink_.offset[j] + q;
      plus.setZero();
      minus.setZero();
      probe(j, q) = x(j, q) + h;
      AddGradient(Measure(contact, probe), 1.0, &plus);
      probe(j, q) = x(j, q) - h;
      AddGradient(Measure(contact, probe), 1.0, &minus);
      probe(j, q) = x(j, q);
      for (int r = first; r <= last; ++r) {
        if (sink_.offset[r] < 0) continue;
        for (int p = 0; p < dim_; ++p) {
          const int row = sink_.offset[r] + p;
          const double d = (plus[row] - minus[row]) / (2.0 * h);
          // Symmetrized: half here, half at the mirror.
          triplets_.emplace_back(row, col, 0.5 * scale * d);
          triplets_.emplace_back(col, row, 0.5 * scale * d);
        }
      }
    }
  }
}

void ContactSolver::FindContacts(const Points& x, bool keep, std::vector<Contact>* near,
                                 double* penetration, double* least) {
  near->clear();
  *penetration = 0.0;
  *least = std::numeric_limits<double>::infinity();
  // A step moves no point by more than half the shortest link: constraints farther than the
  // shortest link cannot be reached.
  const double reach = shortest_;
  std::vector<double> depth(n_ + 1);
  for (int k = 0; k < m_; ++k) {
    const Collider& c = colliders_[k];
    depth[0] = QuerySurface(c, At(x, 0)).distance;
    // (The still point after the last moving one is measured for the links beside it; it is no
    // unknown, and no contact of its own.)
    for (int j = 1; j <= links_; ++j) {
      Contact p;
      p.index = j;
      p.collider = k;
      p = Measure(p, x);
      depth[j] = p.value;
      *least = std::fmin(*least, p.value / lengths_[j - 1]);
      *penetration += std::fmax(0.0, -p.value);
      p.multiplier = Multiplier(p);
      if (j <= k_ && (p.value < reach || p.multiplier > 0.0)) near->push_back(p);
    }
    // Links whose interior comes nearer than both ends (a link nearest at an end is covered by
    // that point's constraint).
    for (int i = 1; i <= links_; ++i) {
      Contact l;
      l.link = true;
      l.index = i;
      l.collider = k;
      double& mu = Multiplier(l);
      const Vector3d a = At(x, i - 1), b = At(x, i);
      if (mu == 0.0 && QuerySurface(c, 0.5 * (a + b)).distance - 0.5 * lengths_[i - 1] > reach) {
        continue;
      }
      l = Measure(l, x);
      const bool interior = l.s > 0.0 && l.s < 1.0 &&
                            l.value < std::fmin(depth[i - 1], depth[i]) - 1e-12 * lengths_[i - 1];
      if (!interior) {
        if (keep && mu > 0.0) {  // its end carries it on
          const int j = l.s >= 0.5 ? i : i - 1;
          if (j >= 1) state_.point_multipliers[j * m_ + k] += mu;
        }
        if (keep) mu = 0.0;
        continue;
      }
      *least = std::fmin(*least, l.value / lengths_[i - 1]);
      *penetration += std::fmax(0.0, -l.value);
      l.multiplier = mu;
      near->push_back(l);
    }
  }
  // Multipliers passed on to a point above: read them again.
  for (Contact& c : *near) c.multiplier = Multiplier(c);
}

void ContactSolver::Evaluate(Point* p, bool hessian) {
  p->gradient = Eigen::VectorXd::Zero(unknowns_);
  sink_.gradient = p->gradient.data();
  sink_.hessian = hessian ? &triplets_ : nullptr;
  sink_.band = nullptr;
  sink_.form = nullptr;
  if (hessian) triplets_.clear();
  p->objective =
      internal::Evaluate(options_.weights, lengths_, old_, p->x, sink_, last_, smoothing_);
  p->c.resize(links_);
  p->violation = 0.0;
  for (int i = 1; i <= links_; ++i) {
    const double sq = (p->x.row(i) - p->x.row(i - 1)).squaredNorm();
    const double l = lengths_[i - 1];
    p->c[i - 1] = (sq - l * l) / (2.0 * l);
    p->violation = std::fmax(p->violation, std::fabs(p->c[i - 1]) / l);
  }
  FindContacts(p->x, hessian, &p->near, &p->penetration, &p->least);
}

// The Lagrangian's gradient at `p` with the state's multipliers, into `*residual`; returns the
// optimality measure (as OverallOptions::optimality_tolerance: relative to the metric's
// gradient, 0 at the rounding level of the positions).
double ContactSolver::Stationarity(const Point& p, Eigen::VectorXd* residual) const {
  *residual = p.gradient;
  const Eigen::VectorXd& lambda = state_.lambda;
  for (int i = 1; i <= links_; ++i) {
    const double f = lambda[i - 1] / lengths_[i - 1];
    for (int q = 0; q < dim_; ++q) {
      const double d = f * (p.x(i, q) - p.x(i - 1, q));
      if (i <= k_) (*residual)[sink_.offset[i] + q] += d;
      if (i >= 2) (*residual)[sink_.offset[i - 1] + q] -= d;
    }
  }
  double mu_max = 0.0;
  for (const Contact& c : p.near) {
    if (c.multiplier == 0.0) continue;
    AddGradient(c, -c.multiplier, residual);
    mu_max = std::fmax(mu_max, std::fabs(c.multiplier));
  }
  const double r = residual->cwiseAbs().maxCoeff();
  const double extent = std::fmax(p.x.cwiseAbs().maxCoeff(), lengths_.maxCoeff());
  double kappa = weight_sum_ + (2.0 * lambda.cwiseAbs().maxCoeff() + mu_max) / shortest_;
  if (options_.weights.l2 > 0.0 || options_.weights.l2_weighted > 0.0) {
    // The L2 term's curvature at a point moved by r is its weight over sqrt(r^2 + mu^2).
    for (int j = 1; j <= k_; ++j) {
      const double moved = std::hypot((p.x.row(j) - old_.row(j)).norm(), smoothing_);
      if (moved > 0.0) kappa = std::fmax(kappa, L2Weight(options_.weights, lengths_, j) / moved);
    }
  }
  if (r <= 64.0 * std::numeric_limits<double>::epsilon() * extent * kappa) return 0.0;
  return r / std::fmax(p.gradient.cwiseAbs().maxCoeff(), std::numeric_limits<double>::min());
}

void ContactSolver::StartingMultipliers(const Point& p) {
  // J J' lambda = -J (grad f - J_g' mu), J the length constraints' Jacobian (n by unknowns).
  Eigen::VectorXd force = p.gradient;
  for (const Contact& c : p.near) {
    if (c.multiplier != 0.0) AddGradient(c, -c.multiplier, &force);
  }
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 1; i <= links_; ++i) {
    for (int q = 0; q < dim_; ++q) {
      const double d = (p.x(i, q) - p.x(i - 1, q)) / lengths_[i - 1];
      if (i <= k_) entries.emplace_back(i - 1, sink_.offset[i] + q, d);
      if (i >= 2) entries.emplace_back(i - 1, sink_.offset[i - 1] + q, -d);
    }
  }
  Eigen::SparseMatrix<double> jacobian(links_, unknowns_);
  jacobian.setFromTriplets(entries.begin(), entries.end());
  const Eigen::SparseMatrix<double> normal = jacobian * jacobian.transpose();
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(normal);
  Eigen::VectorXd lambda = ldlt.solve(-(jacobian * force));
  if (ldlt.info() == Eigen::Success && lambda.allFinite()) {
    state_.lambda = lambda;
  } else {
    state_.lambda.setZero(links_);
  }
}

bool ContactSolver::SolveModel(const Point& p, const std::vector<int>& working,
                               Eigen::VectorXd* solution) {
  const int na = static_cast<int>(working.size());
  const int size = unknowns_ + links_ + na;
  std::vector<Eigen::Triplet<double>> entries = triplets_;
  // Jacobian rows of c_i: D_i / L_i on x_i, -D_i / L_i on x_{i-1}.
  for (int i = 1; i <= links_; ++i) {
    const int row = unknowns_ + i - 1;
    for (int q = 0; q < dim_; ++q) {
      const double d = (p.x(i, q) - p.x(i - 1, q)) / lengths_[i - 1];
      if (i <= k_) {
        entries.emplace_back(row, sink_.offset[i] + q, d);
        entries.emplace_back(sink_.offset[i] + q, row, d);
      }
      if (i >= 2) {
        entries.emplace_back(row, sink_.offset[i - 1] + q, -d);
        entries.emplace_back(sink_.offset[i - 1] + q, row, -d);
      }
    }
  }
  // Rows of the working contacts, as -grad g (the system stays symmetric).
  Eigen::VectorXd column(unknowns_);
  for (int a = 0; a < na; ++a) {
    column.setZero();
    AddGradient(p.near[working[a]], -1.0, &column);
    const int row = unknowns_ + links_ + a;
    for (int r = 0; r < unknowns_; ++r) {
      if (column[r] == 0.0) continue;
      entries.emplace_back(row, r, column[r]);
      entries.emplace_back(r, row, column[r]);
    }
  }
  Eigen::VectorXd rhs(size);
  rhs.head(unknowns_) = -p.gradient;
  rhs.segment(unknowns_, links_) = -p.c;
  for (int a = 0; a < na; ++a) rhs[unknowns_ + links_ + a] = p.near[working[a]].value;
  const size_t base = entries.size();
  for (const double regularization : {0.0, 1e-12, 1e-9}) {
    entries.resize(base);
    if (regularization > 0.0) {
      for (int r = unknowns_; r < size; ++r) entries.emplace_back(r, r, -regularization);
    }
    kkt_.resize(size, size);
    kkt_.setFromTriplets(entries.begin(), entries.end());
    lu_.analyzePattern(kkt_);
    lu_.factorize(kkt_);
    if (lu_.info() != Eigen::Success) continue;
    *solution = lu_.solve(rhs);
    if (lu_.info() == Eigen::Success && solution->allFinite()) return true;
  }
  return false;
}

bool ContactSolver::SolveQp(const Point& p, std::vector<int>* working, Eigen::VectorXd* solution) {
  // A contact that has left joins again at most twice (no cycling at a corner, whose normal
  // jumps).
  std::vector<int> left(p.near.size(), 0);
  for (;;) {
    if (!SolveModel(p, *working, solution)) return false;
    const Eigen::VectorXd step = solution->head(unknowns_);
    // A working contact whose multiplier pulls inward leaves (the most negative first).
    int leave = -1;
    double most = 0.0;
    for (size_t a = 0; a < working->size(); ++a) {
      const double mu = (*solution)[unknowns_ + links_ + static_cast<int>(a)];
      if (mu < most) most = mu, leave = static_cast<int>(a);
    }
    if (leave >= 0) {
      ++left[(*working)[leave]];
      working->erase(working->begin() + leave);
      continue;
    }
    // The contact the step would enter most joins.
    int join = -1;
    double deepest = 0.0;
    for (size_t b = 0; b < p.near.size(); ++b) {
      if (left[b] > 2 ||
          std::find(working->begin(), working->end(), static_cast<int>(b)) != working->end()) {
        continue;
      }
      const Contact& c = p.near[b];
      const double g = Linearized(c, step) / lengths_[c.index - 1];
      if (g < -1e-14 && g < deepest) deepest = g, join = static_cast<int>(b);
    }
    if (join < 0) return true;
    working->push_back(join);
  }
}

bool ContactSolver::Correct(const Point& p, const std::vector<int>& working, const Point& trial,
                            Point* corrected) {
  const int na = static_cast<int>(working.size());
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(unknowns_ + links_ + na);
  rhs.segment(unknowns_, links_) = -trial.c;
  for (int a = 0; a < na; ++a) {
    rhs[unknowns_ + links_ + a] = Measure(p.near[working[a]], trial.x).value;
  }
  const Eigen::VectorXd correction = lu_.solve(rhs);
  if (lu_.info() != Eigen::Success || !correction.allFinite()) return false;
  corrected->x = trial.x;
  for (int j = 1; j <= k_; ++j) {
    const auto move = correction.segment(sink_.offset[j], dim_);
    if (move.norm() > 0.5 * shortest_) return false;
    for (int q = 0; q < dim_; ++q) corrected->x(j, q) += move[q];
  }
  Evaluate(corrected, false);
  return true;
}

OverallReport ContactSolver::Solve(Points* x_io) {
  OverallReport report;
  if (state_.lambda.size() != links_) state_.lambda = Eigen::VectorXd::Zero(links_);
  const int max_iterations = std::max(options_.max_iterations, 1);
  Point p, trial, corrected;
  p.x = *x_io;
  Evaluate(&p, true);
  // A contact the start has left (off its surface by more than 1e-6 of its link) starts without
  // the multiplier the last sub-step left it (a link's contact passed to its end point, say):
  // held as an equality it would pull its point back onto the surface, and the links beside it
  // inside (at a box's corner the iteration then stalled there).
  for (Contact& c : p.near) {
    if (c.multiplier > 0.0 && c.value > 1e-6 * lengths_[c.index - 1]) {
      Multiplier(c) = c.multiplier = 0.0;
    }
  }
  StartingMultipliers(p);
  Eigen::VectorXd residual, solution;
  std::vector<int> working;
  bool polished = false;
  int polish_iteration = -1;
  Point converged;
  for (int iteration = 0;; ++iteration) {
    // Converged: the lengths kept, nothing inside, the contacts with a multiplier on their
    // surface, and the Lagrangian stationary.
    double contact_violation = 0.0;
    for (const Contact& c : p.near) {
      if (c.multiplier > 0.0) {
        contact_violation =
            std::fmax(contact_violation, std::fabs(c.value) / lengths_[c.index - 1]);
      }
    }
    report.objective = p.objective;
    report.constraint_violation = p.violation;
    report.optimality = Stationarity(p, &residual);
    report.iterations = iteration;
    if (iteration > 0 && p.violation <= options_.constraint_tolerance &&
        contact_violation <= options_.constraint_tolerance && p.least >= -0.5 * kContactSlack &&
        report.optimality <= options_.optimality_tolerance) {
      // One more Newton step takes the lengths to the rounding (it converges quadratically).
      if (polished || p.violation <= 1e-15) {
        report.status = OverallStatus::kConverged;
        break;
      }
      polished = true;
      converged = p;
    }
    if (polished && iteration > 0 && iteration == polish_iteration + 1) {
      // The polishing step did not keep convergence: the converged iterate stands.
      p = converged;
      report.status = OverallStatus::kConverged;
      break;
    }
    if (polished && polish_iteration < 0) polish_iteration = iteration;
    if (iteration >= max_iterations) {
      report.status = OverallStatus::kMaxIterations;
      return report;
    }
    // The model: the Lagrangian's Hessian with the contacts' curvature.
    for (int i = 1; i <= links_; ++i) {
      const double w = state_.lambda[i - 1] / lengths_[i - 1];
      for (int q = 0; q < dim_; ++q) {
        const int b = i <= k_ ? sink_.offset[i] + q : -1;
        if (b >= 0) triplets_.emplace_back(b, b, w);
        if (i >= 2) {
          const int a = sink_.offset[i - 1] + q;
          triplets_.emplace_back(a, a, w);
          if (b >= 0) {
            triplets_.emplace_back(a, b, -w);
            triplets_.emplace_back(b, a, -w);
          }
        }
      }
    }
    working.clear();
    for (size_t a = 0; a < p.near.size(); ++a) {
      const Contact& c = p.near[a];
      if (c.multiplier > 0.0) {
        AddCurvature(c, p.x, -c.multiplier);
        working.push_back(static_cast<int>(a));
      }
    }
    // Where the model is not convex along the step (the L2 term's radial curvature is 0, and a
    // link's in compression is negative), its step may lead nowhere the merit falls: then the
    // Hessian is damped, d I with d from 1e-4 of the metric's scale up by 100 at a time, and the
    // model solved again (the iteration's fixed points, the KKT conditions, are the same).
    const std::vector<int> start_working = working;
    const size_t hessian_size = triplets_.size();
    double alpha = 1.0, damping = 0.0;
    Eigen::VectorXd step;
    for (;;) {
      working = start_working;
      triplets_.resize(hessian_size);
      for (int r = 0; damping > 0.0 && r < unknowns_; ++r) triplets_.emplace_back(r, r, damping);
      if (!SolveQp(p, &working, &solution)) {
        report.status = OverallStatus::kFailed;
        return report;
      }
      step = solution.head(unknowns_);
      // The step's length: at most half the shortest link for any point; then backtracking on
      // the l1 merit function (penalty above every multiplier), a full step also taken where it
      // halves the infeasibility.
      double longest = 0.0;
      for (int j = 1; j <= k_; ++j)
        longest = std::fmax(longest, step.segment(sink_.offset[j], dim_).norm());
      alpha = std::fmin(1.0, 0.5 * shortest_ / std::fmax(longest, 1e-300));
      double penalty = 0.0;
      for (int i = 0; i < links_; ++i) {
        penalty = std::fmax(penalty, std::fabs(solution[unknowns_ + i]));
      }
      for (size_t a = 0; a < working.size(); ++a) {
        penalty = std::fmax(penalty, std::fabs(solution[unknowns_ + links_ + static_cast<int>(a)]));
      }
      penalty = 2.0 * penalty + 1e-3 * weight_sum_ * shortest_;
      const double merit = Merit(p, penalty);
      double infeasibility = p.penetration;
      for (int i = 0; i < links_; ++i) infeasibility += std::fabs(p.c[i]);
      const double slope = p.gradient.dot(step) - penalty * infeasibility;
      bool found = false;
      for (int tries = 0; tries <= 30; ++tries) {
        trial.x = p.x;
        for (int j = 1; j <= k_; ++j) {
          for (int q = 0; q < dim_; ++q) trial.x(j, q) += alpha * step[sink_.offset[j] + q];
        }
        // (The multipliers the trial's contacts carry are not used: measured again below.)
        Evaluate(&trial, false);
        double trial_infeasibility = trial.penetration;
        for (int i = 0; i < links_; ++i) trial_infeasibility += std::fabs(trial.c[i]);
        // (A full step that changes the merit only at its rounding is taken: near the solution
        // the step's own gain is below it.)
        const double trial_merit = Merit(trial, penalty);
        // A full step of at most 1e-6 of the shortest link is taken where the merit rises by
        // no more than 1e-10 of itself: the constraints' curvature can make the merit rise
        // along the Newton step near the solution, and the multipliers move with it.
        const double sufficient = merit + 1e-4 * alpha * std::fmin(slope, 0.0);
        const bool accepted = trial_merit <= sufficient ||
                              (tries == 0 && trial_merit <= merit + 1e-13 * std::fabs(merit)) ||
                              (tries == 0 && trial_infeasibility <= 0.5 * infeasibility) ||
                              (tries == 0 && longest <= 1e-6 * shortest_ &&
                               trial_merit <= merit + 1e-10 * std::fabs(merit));
        // Where the full step leaves the lengths more than the iterate does, its second-order
        // correction is tried: taken where it meets the sufficient decrease and the step did not,
        // or it leaves the lengths less than the step does (the l1 penalty, small while the
        // multipliers are, can accept a step a fifth of a link off them, from which the
        // iteration does not find its way back).
        if (tries == 0 && trial.violation > std::fmax(p.violation, 1e-12) &&
            Correct(p, working, trial, &corrected) && Merit(corrected, penalty) <= sufficient &&
            (!accepted || corrected.violation < trial.violation)) {
          std::swap(trial, corrected);
          found = true;
          break;
        }
        if (accepted) {
          found = true;
          break;
        }
        if (tries < 30) alpha *= 0.5;
      }
      if (found || damping > 1e6 * weight_sum_) break;
      damping = damping == 0.0 ? 1e-4 * weight_sum_ : 100.0 * damping;
    }
    // The multipliers: lambda and the working contacts' move by alpha toward the model's; every
    // other contact's is 0.
    state_.lambda += alpha * (solution.segment(unknowns_, links_) - state_.lambda);
    for (const Contact& c : p.near) Multiplier(c) = 0.0;
    for (size_t a = 0; a < working.size(); ++a) {
      const Contact& c = p.near[working[a]];
      Multiplier(c) = c.multiplier +
                      alpha * (solution[unknowns_ + links_ + static_cast<int>(a)] - c.multiplier);
    }
    p.x = trial.x;
    Evaluate(&p, true);
  }
  *x_io = p.x;
  final_ = p.near;
  return report;
}

// Every link of `x` outside every collider (to kContactSlack of its length); the least clearance
// relative to its link into `*least`, and the links within 1e-9 of their length of a collider
// (in contact) into `*touching`.
bool Clear(const Points& x, const Eigen::VectorXd& lengths, const std::vector<Collider>& colliders,
           double* least, int* touching) {
  const int dim = static_cast<int>(x.cols());
  const auto at = [&](int j) { return Vector3d(x(j, 0), x(j, 1), dim == 3 ? x(j, 2) : 0.0); };
  *least = std::numeric_limits<double>::infinity();
  *touching = 0;
  for (Eigen::Index i = 1; i <= lengths.size(); ++i) {
    const double clearance = SegmentClearance(colliders, at(i - 1), at(i)) / lengths[i - 1];
    *least = std::fmin(*least, clearance);
    if (clearance <= 1e-9) ++*touching;
  }
  return *least >= -kContactSlack;
}

// The points 1..n of `x` that are not where they were in `old`, up to the last that moved.
int CountMoving(const Points& old, const Points& x) {
  int k = static_cast<int>(old.rows()) - 1;
  while (k > 0 && x.row(k) == old.row(k)) --k;
  return k;
}

// The state's contact multipliers sized for n links and `colliders` (kept where they are).
void SizeMultipliers(int n, size_t colliders, OverallContactState* state) {
  const size_t pairs = static_cast<size_t>(n + 1) * colliders;
  if (state->point_multipliers.size() != pairs) {
    state->point_multipliers.assign(pairs, 0.0);
    state->link_multipliers.assign(pairs, 0.0);
  }
}

void ClearMultipliers(OverallContactState* state) {
  std::fill(state->point_multipliers.begin(), state->point_multipliers.end(), 0.0);
  std::fill(state->link_multipliers.begin(), state->link_multipliers.end(), 0.0);
}

// The outward normal of the collider each old point j = 1..n lies on (within 1e-9 of its link;
// the nearest where several), zero where it touches none, into `*normals` (n + 1 entries).
void RestingNormals(const Points& old, const Eigen::VectorXd& lengths,
                    const std::vector<Collider>& colliders, std::vector<Vector3d>* normals) {
  const int n = static_cast<int>(lengths.size());
  const int dim = static_cast<int>(old.cols());
  normals->assign(n + 1, Vector3d::Zero());
  for (int j = 1; j <= n; ++j) {
    const Vector3d p(old(j, 0), old(j, 1), dim == 3 ? old(j, 2) : 0.0);
    double nearest = 1e-9 * lengths[j - 1];
    for (const Collider& c : colliders) {
      const SurfaceQuery q = QuerySurface(c, p);
      if (q.distance <= nearest) {
        nearest = q.distance;
        (*normals)[j] = q.normal;
        if (dim == 2) (*normals)[j][2] = 0.0;
      }
    }
    if ((*normals)[j].squaredNorm() > 0.0) (*normals)[j].normalize();
  }
}

// One sub-step under a metric with an L2 term (docs/colliders.md, "The L2 metric"), colliders
// static: the active set of overall/active_set.cc, points 1..k moving and the points after k
// still while they hold the pull of the chain (their friction, and the collider a still point
// lies on pushing back), each solve a ContactSolver with the tail held. The start: the solution
// of the problem with the L2 term smoothed (mu = 1e-2, 1e-4, 1e-6 of the shortest link) over
// every point, from `guess` (the sub-problem's solution without colliders), or where that does
// not converge from `*x` (the sub-step's sequential contact step); its tail still from the last
// point that moved by more than 1e-5 of its link. A moving point that comes back to rest (within
// 1e-12 of its link) ends the moving set there; a first still point whose tail cannot hold its
// pull moves (solved smoothed, then exactly), unless it came to rest when it was free to.
// `*x` becomes the solution where it converged.
OverallReport SolveL2Contact(const Eigen::VectorXd& lengths, const Points& old,
                             const OverallOptions& options, const std::vector<Collider>& colliders,
                             const Points& guess, OverallContactState* state, Points* x) {
  const int n = static_cast<int>(lengths.size());
  const int dim = static_cast<int>(old.cols());
  const double shortest = lengths.minCoeff();
  const TailFriction& friction = state->active_set.friction;
  constexpr double kSmoothing[] = {1e-2, 1e-4, 1e-6};
  OverallReport report;
  int iterations = 0;
  Points& current = state->current;
  Points& trial = state->trial;
  current = guess;
  for (const double mu : kSmoothing) {
    ContactSolver smoothed(lengths, old, options, colliders, state, nullptr, n, mu * shortest);
    report = smoothed.Solve(&current);
    iterations += report.iterations;
    if (!report.converged() && mu == kSmoothing[0]) {
      current = *x;
      report = smoothed.Solve(&current);
      iterations += report.iterations;
    }
  }
  int k = n;
  while (k > 1 && (current.row(k) - old.row(k)).norm() <= 1e-5 * lengths[k - 1]) --k;
  std::vector<char> rested(n + 1, 0);
  bool released = false;
  for (int round = 0;; ++round) {
    if (round > 2 * n + 8) {  // the active set cycles
      report.status = OverallStatus::kStalled;
      break;
    }
    trial = current;
    trial.bottomRows(n - k) = old.bottomRows(n - k);
    if (released) {
      for (const double mu : kSmoothing) {
        ContactSolver smoothed(lengths, old, options, colliders, state, nullptr, k, mu * shortest);
        iterations += smoothed.Solve(&trial).iterations;
      }
      released = false;
    }
    ContactSolver exact(lengths, old, options, colliders, state, nullptr, k, 0.0);
    report = exact.Solve(&trial);
    iterations += report.iterations;
    if (!report.converged()) {
      if (k == n) break;
      ++k;
      released = true;
      continue;
    }
    current = trial;
    int rest = 0;
    for (int j = 2; j <= k && rest == 0; ++j) {
      if (!rested[j] && (trial.row(j) - old.row(j)).norm() <= 1e-12 * lengths[j - 1]) rest = j;
    }
    if (rest > 0) {
      rested[rest] = 1;
      k = rest - 1;
      continue;
    }
    if (k == n) break;
    // The pull on the first still point, its link's contacts' push included, against what the
    // tail after it and the collider it lies on hold.
    PullOnFirstStillPoint(lengths, old, options, k, state->lambda[k], trial, &state->active_set);
    Eigen::VectorXd& force = state->active_set.force;
    exact.AddContactForceOnStill(k + 1, &force);
    Vector3d v = Vector3d::Zero(), e = Vector3d::Zero();
    for (int q = 0; q < dim; ++q) v[q] = force[q];
    double a = 0.0, b = 0.0;
    if (k + 1 < n) {
      for (int q = 0; q < dim; ++q) e[q] = friction.e(k + 1, q);  // link k+2
      a = friction.lo[k + 2];
      b = friction.hi[k + 2];
    }
    if (HeldDistance(v, e, state->normals[k + 1], a, b) <= friction.w[k + 1] * (1.0 + 1e-9)) break;
    // A point that came back to rest when it was free to move: the solve itself found it still
    // (the tail's friction counts no support from a collider along a still link's interior).
    if (rested[k + 1]) break;
    ++k;
    released = true;
  }
  report.iterations = iterations;
  report.moving_points = k;
  if (report.converged()) *x = current;
  return report;
}

}  // namespace

void OverallContactStep(const Eigen::VectorXd& lengths, const Eigen::VectorXd& head,
                        const OverallOptions& options, const std::vector<Collider>& colliders,
                        Points* points, OverallWorkspace* workspace, OverallContactState* state,
                        OverallReport* report, ContactStats* stats) {
  const int n = static_cast<int>(lengths.size());
  const int dim = static_cast<int>(points->cols());
  SizeMultipliers(n, colliders.size(), state);
  // The step without colliders, kept where it ends clear.
  state->free = *points;
  OverallStepUnchecked(lengths, head, options, &state->free, workspace, report);
  double least = 0.0;
  int touching = 0;
  if (Clear(state->free, lengths, colliders, &least, &touching)) {
    stats->contact_link_steps += touching;
    *points = state->free;
    stats->least_clearance = std::fmin(stats->least_clearance, least);
    ClearMultipliers(state);
    return;
  }
  // Continuation in head sub-steps of at most half the shortest link, each from the sequential
  // contact step (tractrix) of the last one's solution.
  const Points old = *points;
  const Eigen::VectorXd from = old.row(0).transpose();
  const Eigen::VectorXd inv_lengths = lengths.cwiseInverse();
  const double distance = (head - from).norm();
  const int sub_steps =
      std::max(1, static_cast<int>(std::ceil(distance / (0.5 * lengths.minCoeff()))));
  OverallReport result;
  result.status = OverallStatus::kConverged;
  int iterations = 0, fallbacks = 0;
  const bool has_mesh = std::any_of(colliders.begin(), colliders.end(), [](const Collider& c) {
    return c.shape == ColliderShape::kMesh;
  });
  const bool l2 = options.weights.l2 > 0.0 || options.weights.l2_weighted > 0.0;
  if (l2) {
    RestingNormals(old, lengths, colliders, &state->normals);
    MakeTailFriction(options.weights, lengths, old, &state->active_set, &state->normals);
  }
  Eigen::VectorXd target(dim);
  ContactStats sweep_stats;
  for (int s = 1; s <= sub_steps; ++s) {
    for (int k = 0; k < dim; ++k) target[k] = SubstepHead(from[k], head[k], s, sub_steps);
    state->start = *points;
    ContactSweep(Method::kTractrix, dim, target.data(), lengths.data(), inv_lengths.data(), n,
                 state->start.data(), colliders, &sweep_stats);
    state->previous_solution.swap(*points);  // kept for a retry, without a copy
    *points = state->start;
    OverallReport sub;
    if (l2) {
      // The sub-problem without colliders, from the old configuration: a start near the
      // solution where the contacts change it little.
      state->guess = old;
      OverallReport free_report;
      OverallStepUnchecked(lengths, target, options, &state->guess, workspace, &free_report);
      sub = SolveL2Contact(lengths, old, options, colliders, state->guess, state, points);
    } else {
      ContactSolver solver(lengths, old, options, colliders, state);
      sub = solver.Solve(points);
      if (!sub.converged()) {
        // The sequential contact step can start far from the solution (in 3D a link swung
        // round a box's edge moves the chain behind it; the first model steps of half a link
        // then leave the lengths by a fifth of a link, and the iteration wanders inside): the
        // solve is tried again from the last sub-step's solution with only the head moved.
        // (Solved in place: the next sub-step replaces that buffer.)
        iterations += sub.iterations;
        Points& retry = state->previous_solution;
        retry.row(0) = target.transpose();
        ClearMultipliers(state);
        ContactSolver again(lengths, old, options, colliders, state);
        sub = again.Solve(&retry);
        if (sub.converged()) points->swap(retry);
      }
    }
    iterations += sub.iterations;
    // The solver measures a link against a mesh at its nearest local minimum (NearestOnSegment):
    // a converged solution is kept only where every link is clear by the exact clearances.
    // (With an L2 term the solves do not measure the still tail: checked here too.)
    if (sub.converged() && (has_mesh || l2) &&
        !Clear(*points, lengths, colliders, &least, &touching)) {
      sub.status = OverallStatus::kFailed;
    }
    if (!sub.converged()) {
      ++fallbacks;
      *points = state->start;
      ClearMultipliers(state);
      result.status = sub.status;
    }
    result.objective = sub.objective;
    result.constraint_violation = std::fmax(result.constraint_violation, sub.constraint_violation);
    result.optimality = std::fmax(result.optimality, sub.optimality);
  }
  if (!Clear(*points, lengths, colliders, &least, &touching))
    result.status = OverallStatus::kFailed;
  stats->least_clearance = std::fmin(stats->least_clearance, least);
  stats->contact_link_steps += touching;
  result.iterations = iterations;
  result.moving_points = l2 ? CountMoving(old, *points) : n;
  result.start = "continuation in " + std::to_string(sub_steps) +
                 " head sub-steps with colliders, each from the sequential contact step";
  if (fallbacks > 0) {
    result.start += "; " + std::to_string(fallbacks) +
                    " sub-steps kept the sequential contact step (not converged)";
  }
  *report = std::move(result);
}

bool LeastConstraintContact(const Eigen::VectorXd& lengths, const Eigen::VectorXd& mass,
                            const Points& predicted, const std::vector<Collider>& colliders,
                            OverallContactState* state, Points* x, int* iterations) {
  const int n = static_cast<int>(lengths.size());
  SizeMultipliers(n, colliders.size(), state);
  // The masses scaled to a largest of 1: the squared metric's scale, which the solver's
  // tolerances and merit are measured against (the minimizer is the same).
  Eigen::VectorXd weights = mass / mass.tail(n).maxCoeff();
  weights[0] = 0.0;
  OverallOptions options;
  options.weights = ObjectiveWeights();
  options.weights.squared = 1.0;
  state->start = *x;
  ContactSolver solver(lengths, predicted, options, colliders, state, &weights);
  const OverallReport report = solver.Solve(x);
  if (iterations != nullptr) *iterations = report.iterations;
  double least = 0.0;
  int touching = 0;
  if (report.converged() && Clear(*x, lengths, colliders, &least, &touching)) return true;
  *x = state->start;
  ClearMultipliers(state);
  return false;
}

}  // namespace flexkin::internal
