// Dynamic chains (flexkin/dynamics.h, docs/dynamics.md): inertial prediction, then one of three
// projections onto the length constraints.
#include "flexkin/dynamics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "chain/substep.h"
#include "overall/newton.h"
#include "sequential/link_rules.h"

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
      problems.emplace_back(at + ".velocity",
                            "has " + std::to_string(key.velocity.size()) +
                                " entries or one that is not finite; expected " +
                                std::to_string(dim) + " finite numbers (a velocity)");
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
  return (1.0 - u) * a.velocity + u * b.velocity;
}

namespace {

// The three projections of the prediction `p` (row 0 the driven end's new place) onto the
// lengths, into `x`; `correction` gets DFTL's d_j = x_j - p_j.
class Projector {
 public:
  Projector(const Eigen::VectorXd& lengths, int dim, const DynamicOptions& options)
      : lengths_(lengths),
        inv_lengths_(lengths.cwiseInverse()),
        n_(static_cast<int>(lengths.size())),
        dim_(dim) {
    if (options.mass_by_length) {
      overall_.weights.squared = 0.0;
      overall_.weights.squared_weighted = 1.0;
    } else {
      overall_.weights.squared = 1.0;
    }
    buffers_.Reserve(n_, dim_, overall_.weights);
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
    double head_old[3], head_new[3], tail[3];
    for (int j = 1; j <= n_; ++j) {
      // The predicted link put back to its length about its leading end's prediction, then the
      // leading end's correction carried by the tractrix step.
      const Eigen::RowVectorXd d = p.row(j) - p.row(j - 1);
      const Eigen::RowVectorXd restored = p.row(j - 1) + (lengths_[j - 1] / d.norm()) * d;
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
  }

  // SHAKE: x_j = p_j + w_j (lambda_j D_j - lambda_{j+1} D_{j+1}), D the links of `old` and w the
  // inverse masses (the driven end's 0), with the multipliers that give every link its length:
  // Newton's method on f_i = |x_i - x_{i-1}|^2 - L_i^2, whose Jacobian is tridiagonal. False if it
  // did not converge in 30 iterations.
  bool Shake(const Points& old, const Points& p, const Eigen::VectorXd& inverse_mass, Points* x) {
    const int n = n_;
    Eigen::VectorXd lambda = Eigen::VectorXd::Zero(n + 2), f(n + 1), lower(n + 1), diag(n + 1),
                    upper(n + 1);
    Points d_old(n + 2, dim_);
    d_old.setZero();
    for (int i = 1; i <= n; ++i) d_old.row(i) = old.row(i) - old.row(i - 1);
    const auto w = [&](int j) { return j >= 1 && j <= n ? inverse_mass[j] : 0.0; };
    const auto place = [&]() {
      x->row(0) = p.row(0);
      for (int j = 1; j <= n; ++j) {
        x->row(j) = p.row(j) + w(j) * (lambda[j] * d_old.row(j) - lambda[j + 1] * d_old.row(j + 1));
      }
    };
    for (int iteration = 0; iteration < 30; ++iteration) {
      place();
      double worst = 0.0;
      for (int i = 1; i <= n; ++i) {
        const Eigen::RowVectorXd d = x->row(i) - x->row(i - 1);
        f[i] = d.squaredNorm() - lengths_[i - 1] * lengths_[i - 1];
        // |D|^2 - L^2 at the rounding of the positions: 2 |D| (eps |x|) each way.
        const double level = 8.0 * std::numeric_limits<double>::epsilon() * lengths_[i - 1] *
                             (x->row(i).cwiseAbs().maxCoeff() +
                              x->row(i - 1).cwiseAbs().maxCoeff() + lengths_[i - 1]);
        worst = std::fmax(worst, std::fabs(f[i]) / level);
        // d D_i / d lambda_{i-1}, lambda_i, lambda_{i+1}.
        lower[i] = i >= 2 ? 2.0 * d.dot(-w(i - 1) * d_old.row(i - 1)) : 0.0;
        diag[i] = 2.0 * d.dot((w(i) + w(i - 1)) * d_old.row(i));
        upper[i] = i < n ? 2.0 * d.dot(-w(i) * d_old.row(i + 1)) : 0.0;
      }
      if (worst <= 1.0) return true;  // every length at the rounding of the positions
      // The tridiagonal solve (Thomas), J delta = -f.
      for (int i = 2; i <= n; ++i) {
        const double m = lower[i] / diag[i - 1];
        diag[i] -= m * upper[i - 1];
        f[i] -= m * f[i - 1];
      }
      for (int i = n; i >= 1; --i) {
        f[i] = (f[i] - (i < n ? upper[i] * f[i + 1] : 0.0)) / diag[i];
      }
      for (int i = 1; i <= n; ++i) lambda[i] -= f[i];
      if (!lambda.allFinite()) return false;
    }
    place();
    return false;
  }

  // The least mass-weighted correction: Newton on the overall problem measured from `p`, from the
  // tractrix projection. False if it did not converge (`x` then holds that projection).
  bool Overall(const Points& p, Points* x) {
    Tractrix(p, x);
    start_ = *x;
    internal::NewtonSolver solver(lengths_, p, overall_, n_, 0.0, &buffers_);
    const OverallReport report = solver.Solve(x);
    if (report.converged()) return true;
    *x = start_;
    return false;
  }

 private:
  const Eigen::VectorXd& lengths_;
  const Eigen::VectorXd inv_lengths_;
  const int n_, dim_;
  OverallOptions overall_;
  internal::NewtonBuffers buffers_;
  Points start_;
};

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
  const Eigen::VectorXd& lengths = chain.lengths;
  // Masses, the free points' total 1.
  Eigen::VectorXd mass = Eigen::VectorXd::Zero(n + 1);
  for (int j = 1; j <= n; ++j) {
    mass[j] = options.mass_by_length ? 0.5 * (lengths[j - 1] + (j < n ? lengths[j] : 0.0)) : 1.0;
  }
  mass /= mass.sum();
  Eigen::VectorXd inverse_mass = Eigen::VectorXd::Zero(n + 1);
  inverse_mass.tail(n) = mass.tail(n).cwiseInverse();
  const double h = 1.0 / (options.frame_rate * options.substeps);
  const Eigen::RowVectorXd g = options.gravity.transpose();
  const Eigen::RowVectorXd air = options.wind.size() == dim
                                     ? Eigen::RowVectorXd(options.wind.transpose())
                                     : Eigen::RowVectorXd::Zero(dim);
  Projector projector(lengths, dim, options);

  Points x = chain.points, x_old, p(n + 1, dim), projected(n + 1, dim);
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
  const Eigen::Index frames = root_path.rows();
  result.frames.reserve(frames + 1);
  result.frames.push_back(x);
  x_old = x;
  result.energy.resize(frames + 1);
  result.energy[0] = energy();
  for (Eigen::Index f = 0; f < frames; ++f) {
    const Eigen::RowVectorXd from = x.row(0);
    for (int s = 1; s <= options.substeps; ++s) {
      x_old = x;
      for (int k = 0; k < dim; ++k) {
        p(0, k) = internal::SubstepHead(from[k], root_path(f, k), s, options.substeps);
      }
      for (int j = 1; j <= n; ++j) {
        const Eigen::RowVectorXd predicted =
            v.row(j) + h * (g + options.damping * (air - v.row(j)));
        p.row(j) = x.row(j) + h * predicted;
      }
      switch (options.projection) {
        case Projection::kOverall:
          if (!projector.Overall(p, &projected)) ++result.failures;
          break;
        case Projection::kTractrix:
          projector.Tractrix(p, &projected);
          break;
        case Projection::kDftl:
          projector.FollowTheLeader(p, &projected);
          break;
        case Projection::kShake:
          // SHAKE's forces are those of the sub-step's start: past its stability limit (a step
          // longer than about 2 / the chain's highest frequency) its lengths have no solution.
          // That sub-step is then projected by the overall projection, which always has one.
          if (!projector.Shake(x_old, p, inverse_mass, &projected)) {
            ++result.failures;
            projector.Overall(p, &projected);
          }
          break;
      }
      x = projected;
      v = (x - x_old) / h;
      if (options.projection == Projection::kDftl || options.projection == Projection::kTractrix) {
        // Mueller et al. 2012, eq. (9): v_j += s (-d_{j+1}) / h, d = the correction x - p.
        for (int j = 1; j < n; ++j) {
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
