// The sweep of the fixed-base arm's step (src/arm/sweep.h).
#include "arm/sweep.h"

#include <cstdlib>
#include <string>

#include "arm/internal.h"
#include "arm/lanes.h"
#include "chain/simd.h"
#include "chain/substep.h"
#include "sequential/link_rules.h"
#include "world/contact.h"

namespace flexkin::arm_internal {

// Whether the AVX2 sweeps (src/arm/lanes.h) can run here: AllowedSimd() (src/chain/simd.h).
bool HasAvx2Fma() {
#if FLEXKIN_HAVE_WAVEFRONT
  return internal::AllowedSimd().avx2_fma;
#else
  return false;
#endif
}

Sweeper::Sweeper(const ArmModel& model, const Points& start, const Eigen::VectorXd& target,
                 int substeps, const std::vector<Collider>* colliders, const StepWindow& window)
    : model_(model),
      start_(start),
      target_(target),
      substeps_(substeps),
      n_(model.num_links()),
      dim_(model.dim),
      has_limits_(model.has_limits()),
      colliders_(colliders != nullptr && !colliders->empty() ? colliders : nullptr) {
  base_direction_ = model.base_direction.normalized();
  inv_lengths_.resize(n_);
  for (int j = 0; j < n_; ++j) inv_lengths_[j] = 1.0 / model.link_lengths[j];
  lanes_[0].resize(n_ + 1, dim_);
  fast_ = !has_limits_ && colliders_ == nullptr && HasAvx2Fma();
  if (colliders_ != nullptr && AnyMoves(*colliders_)) {
    posed_.reserve(substeps_);
    for (int s = 1; s <= substeps_; ++s) {
      posed_.push_back(CollidersAt(*colliders_, window.Substep(s, substeps_)));
    }
  }
}

SmallVec Sweeper::FastLanes(int lanes, const double* u, double* points0) {
  sweeps_ += lanes;
  ++passes_;
  double bases[kMaxLanes * 3];
#if FLEXKIN_HAVE_WAVEFRONT
  internal::ArmSweepLanesAvx2(dim_, lanes, start_.data(), u, target_.data(), substeps_,
                              model_.link_lengths.data(), inv_lengths_.data(), n_, points0, bases);
#endif
  SmallVec f(dim_);
  for (int l = 0; l < lanes; ++l) {
    for (int k = 0; k < dim_; ++k) fast_bases_[l][k] = bases[l * dim_ + k] - model_.base[k];
  }
  for (int k = 0; k < dim_; ++k) f[k] = fast_bases_[0][k];
  return f;
}

SmallVec Sweeper::Evaluate(const SmallVec& u) {
  Points& p = lanes_[0];
  if (fast_) {
    limited_ = false;
    return FastLanes(1, u.data(), p.data());
  }
  for (int i = 0; i <= n_; ++i) {
    for (int k = 0; k < dim_; ++k) p(i, k) = start_(i, k) + u[k];
  }
  double* lanes[1] = {p.data()};
  RunLanes(1, lanes, &limited_);
  return p.row(0).transpose() - model_.base;
}

void Sweeper::Jacobian(const SmallVec& u, const SmallVec& f, double h, SmallMat* jac) {
  if (fast_) {
    double us[kMaxLanes * 3];
    for (int c = 0; c < dim_; ++c) {
      for (int k = 0; k < dim_; ++k) us[c * dim_ + k] = u[k] + (k == c ? h : 0.0);
    }
    lanes_[1].resize(n_ + 1, dim_);
    FastLanes(dim_, us, lanes_[1].data());
    for (int c = 0; c < dim_; ++c) {
      for (int k = 0; k < dim_; ++k) (*jac)(k, c) = (fast_bases_[c][k] - f[k]) / h;
    }
    return;
  }
  // Lanes 1..dim, so that lane 0 (points()) keeps the last Evaluate.
  double* lanes[kMaxLanes - 1];
  for (int c = 0; c < dim_; ++c) {
    Points& p = lanes_[c + 1];
    p.resize(n_ + 1, dim_);
    for (int i = 0; i <= n_; ++i) {
      for (int k = 0; k < dim_; ++k) p(i, k) = start_(i, k) + (u[k] + (k == c ? h : 0.0));
    }
    lanes[c] = p.data();
  }
  bool limited[kMaxLanes];
  RunLanes(dim_, lanes, limited);
  for (int c = 0; c < dim_; ++c) {
    for (int k = 0; k < dim_; ++k)
      (*jac)(k, c) = ((lanes_[c + 1](0, k) - model_.base[k]) - f[k]) / h;
  }
}

SmallVec Sweeper::EvaluateWithJacobian(const SmallVec& u, double h, SmallMat* jac,
                                       const SmallVec* probe, SmallVec* f_probe) {
  if (fast_) {
    double us[kMaxLanes * 3];
    for (int c = 0; c <= dim_; ++c) {
      for (int k = 0; k < dim_; ++k) us[c * dim_ + k] = u[k] + (k + 1 == c ? h : 0.0);
    }
    const bool probing = probe != nullptr && spare_lane();
    if (probing) {
      for (int k = 0; k < dim_; ++k) us[(dim_ + 1) * dim_ + k] = (*probe)[k];
    }
    limited_ = false;
    const SmallVec f = FastLanes(dim_ + 1 + (probing ? 1 : 0), us, lanes_[0].data());
    for (int c = 0; c < dim_; ++c) {
      for (int k = 0; k < dim_; ++k) (*jac)(k, c) = (fast_bases_[c + 1][k] - f[k]) / h;
    }
    if (probing) {
      f_probe->resize(dim_);
      for (int k = 0; k < dim_; ++k) (*f_probe)[k] = fast_bases_[dim_ + 1][k];
    }
    return f;
  }
  double* lanes[kMaxLanes];
  for (int c = 0; c <= dim_; ++c) {
    Points& p = lanes_[c];
    p.resize(n_ + 1, dim_);
    for (int i = 0; i <= n_; ++i) {
      for (int k = 0; k < dim_; ++k) p(i, k) = start_(i, k) + (u[k] + (k + 1 == c ? h : 0.0));
    }
    lanes[c] = p.data();
  }
  bool limited[kMaxLanes];
  RunLanes(dim_ + 1, lanes, limited);
  limited_ = limited[0];
  const SmallVec f = lanes_[0].row(0).transpose() - model_.base;
  for (int c = 0; c < dim_; ++c) {
    for (int k = 0; k < dim_; ++k)
      (*jac)(k, c) = ((lanes_[c + 1](0, k) - model_.base[k]) - f[k]) / h;
  }
  return f;
}

SmallVec Sweeper::SweepInPlace(Points* points) {
  double* lanes[1] = {points->data()};
  RunLanes(1, lanes, &limited_);
  return points->row(0).transpose() - model_.base;
}

void Sweeper::RunLanes(int lanes, double* const* points, bool* limited) {
  sweeps_ += lanes;
  ++passes_;
  if (dim_ == 2) {
    switch (lanes) {
      case 1:
        Run<2, 1>(points, limited);
        break;
      case 2:
        Run<2, 2>(points, limited);
        break;
      case 3:
        Run<2, 3>(points, limited);
        break;
      default:
        Run<2, 4>(points, limited);
        break;
    }
  } else {
    switch (lanes) {
      case 1:
        Run<3, 1>(points, limited);
        break;
      case 2:
        Run<3, 2>(points, limited);
        break;
      case 3:
        Run<3, 3>(points, limited);
        break;
      default:
        Run<3, 4>(points, limited);
        break;
    }
  }
}

template <int Dim, int K>
void Sweeper::Run(double* const* lanes, bool* limited_out) {
  const int n = n_;
  const double* lengths = model_.link_lengths.data();
  const double* inv_lengths = inv_lengths_.data();
  double from[K][Dim], head_old[K][Dim];
  bool limited[K] = {};
  for (int l = 0; l < K; ++l) {
    for (int k = 0; k < Dim; ++k) from[l][k] = lanes[l][n * Dim + k];
  }
  for (int s = 1; s <= substeps_; ++s) {
    const std::vector<Collider>* colliders = posed_.empty() ? colliders_ : &posed_[s - 1];
    for (int l = 0; l < K; ++l) {
      double* head = lanes[l] + n * Dim;
      for (int k = 0; k < Dim; ++k) {
        head_old[l][k] = head[k];
        head[k] = internal::SubstepHead(from[l][k], target_[k], s, substeps_);
      }
    }
    for (int j = n; j >= 1; --j) {
      // The lanes are independent: their link steps overlap in the processor's pipeline.
      for (int l = 0; l < K; ++l) {
        double* tail = lanes[l] + (j - 1) * Dim;
        double tail_old[Dim];
        for (int k = 0; k < Dim; ++k) tail_old[k] = tail[k];
        internal::TractrixStep<Dim>(head_old[l], tail + Dim, tail, lengths[j - 1],
                                    inv_lengths[j - 1]);
        if (has_limits_) limited[l] |= Limit(lanes[l], j);
        if (colliders != nullptr) Contact<Dim>(*colliders, lanes[l], j, tail_old);
        for (int k = 0; k < Dim; ++k) head_old[l][k] = tail_old[k];
      }
    }
  }
  for (int l = 0; l < K; ++l) limited_out[l] = limited[l];
}

template <int Dim>
void Sweeper::Contact(const std::vector<Collider>& colliders, double* p, int j,
                      const double* tail_old) {
  Eigen::Vector3d head = Eigen::Vector3d::Zero(), tail = head, old = head;
  for (int k = 0; k < Dim; ++k) {
    head[k] = p[j * Dim + k];
    tail[k] = p[(j - 1) * Dim + k];
    old[k] = tail_old[k];
  }
  const double length = model_.link_lengths[j - 1];
  if (internal::SegmentClearance(colliders, head, tail) >= -internal::kContactSlack * length) {
    return;  // the rule's step stands
  }
  Eigen::Vector3d x;
  if (!internal::ContactTail(Dim, head, old, length, colliders, &x)) {
    wedged_ = true;
    return;
  }
  ++contacts_;
  for (int k = 0; k < Dim; ++k) p[(j - 1) * Dim + k] = x[k];
}

bool Sweeper::Limit(double* p, int j) const {
  const int dim = dim_;
  const double length = model_.link_lengths[j - 1];
  double d[3], ref[3];
  for (int k = 0; k < dim; ++k) d[k] = (p[j * dim + k] - p[(j - 1) * dim + k]) / length;
  bool changed = false;
  if (j < n_) {
    const double next_length = model_.link_lengths[j];
    for (int k = 0; k < dim; ++k) ref[k] = (p[(j + 1) * dim + k] - p[j * dim + k]) / next_length;
    // Joint j turns link j into link j+1: seen from link j+1 the angle is reversed.
    changed |= dim == 2 ? ClampDirection(2, ref, -model_.joint_max[j], -model_.joint_min[j], d)
                        : ClampDirection(3, ref, 0.0, model_.max_bend[j], d);
  }
  if (j == 1) {
    changed |= dim == 2 ? ClampDirection(2, base_direction_.data(), model_.joint_min[0],
                                         model_.joint_max[0], d)
                        : ClampDirection(3, base_direction_.data(), 0.0, model_.max_bend[0], d);
  }
  if (!changed) return false;
  for (int k = 0; k < dim; ++k) p[(j - 1) * dim + k] = p[j * dim + k] - length * d[k];
  return true;
}

}  // namespace flexkin::arm_internal
