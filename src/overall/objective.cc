#include "overall/objective.h"

#include <cmath>
#include <cstdio>
#include <string>

#include "flexkin/error.h"

namespace flexkin {
namespace internal {
namespace {

// Signed angle from link vector u to link vector v (2D), in (-pi, pi].
double TurnAngle(const double* u, const double* v) {
  return std::atan2(u[0] * v[1] - u[1] * v[0], u[0] * v[0] + u[1] * v[1]);
}

// Wraps an angle difference into (-pi, pi].
double Wrap(double a) { return std::remainder(a, 2.0 * M_PI); }

}  // namespace

// The metric of one step and its derivatives, term by term. x(j) and a(j): new and old point j.
double L2Weight(const ObjectiveWeights& w, const Eigen::VectorXd& lengths, int j) {
  const int n = static_cast<int>(lengths.size());
  return w.l2 + w.l2_weighted * 0.5 * (lengths[j - 1] + (j < n ? lengths[j] : 0.0));
}

double WeightSum(const ObjectiveWeights& w, const Eigen::VectorXd& lengths) {
  return w.squared + w.squared_weighted * lengths.maxCoeff() +
         (w.rotation + w.l2 + w.l2_weighted * lengths.maxCoeff()) / lengths.minCoeff() +
         w.joint_angle;
}

double Evaluate(const ObjectiveWeights& w, const Eigen::VectorXd& lengths, const Points& old_points,
                const Points& x, const Sink& sink, int last, double smoothing) {
  const int n = last < 0 ? static_cast<int>(lengths.size()) : last;
  const int dim = static_cast<int>(x.cols());
  assert(old_points.rows() == x.rows() && old_points.cols() == x.cols() && x.rows() > n &&
         lengths.size() >= n);
  double value = 0.0;

  // The paper's L2 metric, sum of w_j |x_j - a_j|: gradient w u, Hessian w (I - u u^T) / r with
  // r = |x_j - a_j| and u = (x_j - a_j) / r; at r = 0 the subgradient 0 and no Hessian (the
  // solver keeps such points out of its unknowns).
  if (w.l2 > 0.0 || w.l2_weighted > 0.0) {
    double d[3], block[9];
    for (int j = 1; j <= n; ++j) {
      const double s = L2Weight(w, lengths, j);
      double sq = 0.0;
      for (int k = 0; k < dim; ++k) {
        d[k] = x(j, k) - old_points(j, k);
        sq += d[k] * d[k];
      }
      const double r = std::sqrt(sq + smoothing * smoothing);
      value += s * r;
      if (r == 0.0) continue;
      for (int k = 0; k < dim; ++k) d[k] /= r;
      sink.Gradient(j, d, s);
      if (!sink.WantsHessian()) continue;
      for (int a = 0; a < dim; ++a) {
        for (int b = 0; b < dim; ++b) block[a * dim + b] = ((a == b ? 1.0 : 0.0) - d[a] * d[b]) / r;
      }
      sink.Block(j, j, block, s);
    }
  }

  // Squared displacement, plain and arc-length weighted. (Plain loops on the row-major storage:
  // no temporaries or index checks per point.)
  const double* const xs = x.data();
  const double* const olds = old_points.data();
  const double* const length = lengths.data();
  double d[3], grad[3];
  if (w.squared > 0.0 || w.squared_weighted > 0.0) {
    for (int j = 1; j <= n; ++j) {
      const double arc = 0.5 * (length[j - 1] + (j < n ? length[j] : 0.0));
      const double s = sink.point_weights != nullptr ? sink.point_weights[j]
                                                     : w.squared + w.squared_weighted * arc;
      double sq = 0.0;
      for (int k = 0; k < dim; ++k) {
        d[k] = xs[j * dim + k] - olds[j * dim + k];
        sq += d[k] * d[k];
        grad[k] = 2.0 * s * d[k];
      }
      value += s * sq;
      sink.Gradient(j, grad, 1.0);
      sink.Identity(j, j, 2.0 * s);
    }
  }

  // Body rotation: sum of |D_i - D_i_old|^2 / L_i over the links.
  if (w.rotation > 0.0) {
    for (int i = 1; i <= n; ++i) {
      const double s = w.rotation / length[i - 1];
      double sq = 0.0;
      for (int k = 0; k < dim; ++k) {
        const int at = i * dim + k;
        d[k] = (xs[at] - xs[at - dim]) - (olds[at] - olds[at - dim]);
        sq += d[k] * d[k];
        grad[k] = 2.0 * s * d[k];
      }
      value += s * sq;
      sink.Gradient(i, grad, 1.0);
      sink.Gradient(i - 1, grad, -1.0);
      sink.Identity(i, i, 2.0 * s);
      sink.Identity(i - 1, i - 1, 2.0 * s);
      sink.Identity(i, i - 1, -2.0 * s);
      sink.Identity(i - 1, i, -2.0 * s);
    }
  }

  // Joint-angle change (2D): sum over inner joints of L_mean (psi_i - psi_i_old)^2, psi_i the
  // turn from link i to link i+1. With theta(u) = atan2(u_y, u_x): grad theta = perp(u)/|u|^2,
  // hess theta = [[2 u_x u_y, u_y^2 - u_x^2], [u_y^2 - u_x^2, -2 u_x u_y]] / |u|^4, and
  // psi_i = theta(D_{i+1}) - theta(D_i), D_i = x_i - x_{i-1}.
  if (w.joint_angle > 0.0 && dim == 2) {
    for (int i = 1; i < n; ++i) {
      auto link = [](const Points& p, int k) {
        return Eigen::Vector2d(p(k, 0) - p(k - 1, 0), p(k, 1) - p(k - 1, 1));
      };
      const Eigen::Vector2d u = link(x, i), v = link(x, i + 1);
      const Eigen::Vector2d u0 = link(old_points, i), v0 = link(old_points, i + 1);
      const double c = w.joint_angle * 0.5 * (lengths[i - 1] + lengths[i]);
      const double delta = Wrap(TurnAngle(u.data(), v.data()) - TurnAngle(u0.data(), v0.data()));
      value += c * delta * delta;
      if (sink.gradient == nullptr && !sink.WantsHessian()) continue;
      // Explicit return types: an Eigen expression returned by `auto` would dangle.
      auto grad_theta = [](const Eigen::Vector2d& q) -> Eigen::Vector2d {
        return Eigen::Vector2d(-q.y(), q.x()) / q.squaredNorm();
      };
      auto hess_theta = [](const Eigen::Vector2d& q) -> Eigen::Matrix2d {
        const double r4 = q.squaredNorm() * q.squaredNorm();
        Eigen::Matrix2d h;
        h << 2.0 * q.x() * q.y(), q.y() * q.y() - q.x() * q.x(), q.y() * q.y() - q.x() * q.x(),
            -2.0 * q.x() * q.y();
        return Eigen::Matrix2d(h / r4);
      };
      // Derivatives with respect to (D_i, D_{i+1}) = (u, v): dpsi = (-grad theta(u), grad
      // theta(v)).
      Eigen::Matrix<double, 4, 1> dpsi;
      dpsi << -grad_theta(u), grad_theta(v);
      Eigen::Matrix4d h = 2.0 * c * dpsi * dpsi.transpose();
      h.topLeftCorner<2, 2>() += 2.0 * c * delta * -hess_theta(u);
      h.bottomRightCorner<2, 2>() += 2.0 * c * delta * hess_theta(v);
      const Eigen::Matrix<double, 4, 1> gd = 2.0 * c * delta * dpsi;
      // Back to points: D_i = x_i - x_{i-1}, D_{i+1} = x_{i+1} - x_i, so
      // d/dx_{i-1} = -d/dD_i, d/dx_i = d/dD_i - d/dD_{i+1}, d/dx_{i+1} = d/dD_{i+1}.
      const int points[3] = {i - 1, i, i + 1};
      Eigen::Matrix<double, 6, 4> m = Eigen::Matrix<double, 6, 4>::Zero();
      m.block<2, 2>(0, 0) = -Eigen::Matrix2d::Identity();
      m.block<2, 2>(2, 0) = Eigen::Matrix2d::Identity();
      m.block<2, 2>(2, 2) = -Eigen::Matrix2d::Identity();
      m.block<2, 2>(4, 2) = Eigen::Matrix2d::Identity();
      const Eigen::Matrix<double, 6, 1> gx = m * gd;
      const Eigen::Matrix<double, 6, 6> hx = m * h * m.transpose();
      for (int a = 0; a < 3; ++a) {
        sink.Gradient(points[a], gx.data() + 2 * a, 1.0);
        for (int b = 0; b < 3; ++b) {
          const Eigen::Matrix<double, 2, 2, Eigen::RowMajor> block = hx.block<2, 2>(2 * a, 2 * b);
          sink.Block(points[a], points[b], block.data(), 1.0);
        }
      }
    }
  }
  return value;
}

}  // namespace internal

double& ObjectiveWeights::operator[](ObjectiveTerm term) {
  switch (term) {
    case ObjectiveTerm::kL2:
      return l2;
    case ObjectiveTerm::kL2Weighted:
      return l2_weighted;
    case ObjectiveTerm::kSquared:
      return squared;
    case ObjectiveTerm::kSquaredWeighted:
      return squared_weighted;
    case ObjectiveTerm::kRotation:
      return rotation;
    case ObjectiveTerm::kJointAngle:
      break;
  }
  return joint_angle;
}

double ObjectiveWeights::operator[](ObjectiveTerm term) const {
  return (*const_cast<ObjectiveWeights*>(this))[term];
}

Problems ObjectiveWeights::Validate() const {
  Problems problems;
  double total = 0.0;
  for (const auto& entry : Vocabulary<ObjectiveTerm>::kEntries) {
    const double value = (*this)[entry.value];
    if (!(value >= 0.0) || !std::isfinite(value)) {
      problems.emplace_back(
          entry.name,
          FormatNumber(value) + " is not valid; each weight must be a finite number >= 0",
          FormatNumber(value), "a finite number >= 0");
    }
    total += value;
  }
  if (!problems.empty()) return problems;
  if ((l2 > 0.0 || l2_weighted > 0.0) && joint_angle > 0.0) {
    problems.emplace_back("joint_angle",
                          FormatNumber(joint_angle) +
                              " cannot be combined with the L2 metric (l2, l2_weighted): that "
                              "combination is not supported; set joint_angle or both L2 weights "
                              "to 0",
                          FormatNumber(joint_angle), "0 with an L2 term");
  }
  if (!(total > 0.0)) {
    std::string names;
    for (const std::string& name : NamesOf<ObjectiveTerm>()) {
      names += (names.empty() ? "" : ", ") + name;
    }
    problems.emplace_back(
        "", "all weights are 0; give at least one term (" + names + ") a positive weight");
  }
  return problems;
}

double OverallObjective(const ObjectiveWeights& weights, const Eigen::VectorXd& lengths,
                        const Points& old_points, const Points& new_points,
                        Eigen::VectorXd* gradient, Eigen::MatrixXd* hessian) {
  const int n = static_cast<int>(lengths.size());
  const int dim = static_cast<int>(new_points.cols());
  internal::Sink sink;
  sink.dim = dim;
  sink.offset.resize(n + 1);
  sink.offset[0] = -1;
  for (int j = 1; j <= n; ++j) sink.offset[j] = (j - 1) * dim;
  if (gradient != nullptr) {
    gradient->setZero(n * dim);
    sink.gradient = gradient->data();
  }
  internal::Triplets triplets;
  if (hessian != nullptr) sink.hessian = &triplets;
  const double value = internal::Evaluate(weights, lengths, old_points, new_points, sink);
  if (hessian != nullptr) {
    Eigen::SparseMatrix<double> h(n * dim, n * dim);
    h.setFromTriplets(triplets.begin(), triplets.end());
    *hessian = Eigen::MatrixXd(h);
  }
  return value;
}

}  // namespace flexkin
