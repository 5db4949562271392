// The sequential rules of the paper's other two metrics (Sec. 4.1 and 4.2), applied sub-step by
// sub-step as the leading end moves in a straight line:
//  - minimum rotation: for one link, the tail position that rotates the link least (zero
//    rotation) is the old tail moved by the head's displacement, so the whole chain translates;
//  - minimum joint-angle change: the first link has no joint before it and moves by the tractrix
//    (L2) step; every later link keeps its angle to the link before it, so it turns with that
//    link: the chain behind the first link moves rigidly with it. In 3D the rotations keeping a
//    joint angle are not unique; the rule applies the smallest rotation taking the first link's
//    old direction to its new one (Eigen's Quaternion::FromTwoVectors; for an exact reversal it
//    picks an axis perpendicular to the link).

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "chain/denormals.h"
#include "sequential/joint_rotation.h"
#include "sequential/link_rules.h"
#include "sequential/sweep.h"
#include "sequential/whole_chain.h"

namespace flexkin::internal {

void SweepsMinRotation(int dim, const double* heads, int64_t num_sweeps, int n, double* points) {
  for (int64_t s = 0; s < num_sweeps; ++s) {
    for (int k = 0; k < dim; ++k) {
      const double shift = heads[s * dim + k] - points[k];
      for (int i = 0; i <= n; ++i) points[i * dim + k] += shift;
    }
  }
}

namespace {

// One sweep of the joint-angle rule: the head moves from head_old to head_new, the first link's
// tail from first_old to first_new (the tractrix step), and `rotation` takes the link's old
// direction to its new one (the chain behind turns with it).
template <int Dim>
void JointAngleMotion(const Eigen::Matrix<double, Dim, 1>& head_old,
                      const Eigen::Matrix<double, Dim, 1>& head_new,
                      const Eigen::Matrix<double, Dim, 1>& first_old, double length,
                      double inv_length, Eigen::Matrix<double, Dim, 1>* first_new,
                      Eigen::Matrix<double, Dim, Dim>* rotation) {
  *first_new = first_old;
  TractrixStep<Dim>(head_old.data(), head_new.data(), first_new->data(), length, inv_length);
  const Eigen::Matrix<double, Dim, 1> u = first_old - head_old, v = *first_new - head_new;
  *rotation = RotationBetween<Dim>(u, v);
}

template <int Dim>
void MinJointAngle(const double* heads, int64_t num_sweeps, const double* lengths,
                   const double* inv_lengths, int n, double* points) {
  using Vec = Eigen::Matrix<double, Dim, 1>;
  Eigen::Map<Eigen::Matrix<double, Dim, Eigen::Dynamic>> p(points, Dim, n + 1);
  Eigen::Matrix<double, Dim, Dim> rotation;
  Vec first_new;
  for (int64_t s = 0; s < num_sweeps; ++s) {
    const Vec head_old = p.col(0), first_old = p.col(1);
    const Vec head_new = Eigen::Map<const Vec>(heads + s * Dim);
    JointAngleMotion<Dim>(head_old, head_new, first_old, lengths[0], inv_lengths[0], &first_new,
                          &rotation);
    for (int i = 2; i <= n; ++i) p.col(i) = first_new + rotation * (p.col(i) - first_old);
    p.col(0) = head_new;
    p.col(1) = first_new;
  }
}

}  // namespace

void SweepsMinJointAngle(int dim, const double* heads, int64_t num_sweeps, const double* lengths,
                         const double* inv_lengths, int n, double* points) {
  dim == 2 ? MinJointAngle<2>(heads, num_sweeps, lengths, inv_lengths, n, points)
           : MinJointAngle<3>(heads, num_sweeps, lengths, inv_lengths, n, points);
}

void WholeChainWork::Prepare(Method method, int chain_dim, const double* link_lengths,
                             const double* point_weights, int num_links, int sweeps) {
  dim = chain_dim;
  n = num_links;
  max_sweeps = sweeps;
  rotate = method == Method::kMinJointAngle;
  first = rotate ? 2 : 0;
  const int count = n + 1 - first;
  lanes_padded = (count + kPad - 1) / kPad * kPad;
  stride = lanes_padded + 1 + kPad;
  from.assign(static_cast<size_t>(3) * sweeps, 0.0);
  to.assign(static_cast<size_t>(3) * sweeps, 0.0);
  rotation.assign(rotate ? static_cast<size_t>(9) * sweeps : 0, 0.0);
  placed.assign(static_cast<size_t>(first) * dim * sweeps, 0.0);
  coords.assign(static_cast<size_t>(dim) * stride, 0.0);
  moved.assign(lanes_padded, 0.0);
  weights.assign(lanes_padded, 0.0);
  lengths.assign(lanes_padded, 1.0);
  inv_lengths.assign(lanes_padded, 0.0);
  valid.assign(lanes_padded, 0.0);
  for (int j = 0; j < count; ++j) {
    const int i = first + j;
    weights[j] = point_weights[i];
    valid[j] = 1.0;
    if (i >= 1) {
      lengths[j] = link_lengths[i - 1];
      inv_lengths[j] = 1.0 / link_lengths[i - 1];
    }
  }
}

namespace {

// The motions of a call's sweeps, one after another from the chain's placed points, into `w`;
// the placed points' share of what the trace observes (their distances, their links' lengths).
template <int Dim>
void WholeChainMotions(const double* heads, int64_t num_sweeps, const double* lengths,
                       const double* inv_lengths, const double* points, WholeChainWork* w,
                       SweepTrace* trace) {
  using Vec = Eigen::Matrix<double, Dim, 1>;
  if (!w->rotate) {
    // Point 0 moves as the kernel will move it: p0 + (head - p0).
    double p0[Dim];
    for (int k = 0; k < Dim; ++k) p0[k] = points[k];
    for (int64_t s = 0; s < num_sweeps; ++s) {
      for (int k = 0; k < Dim; ++k) {
        const double shift = heads[s * Dim + k] - p0[k];
        w->to[s * 3 + k] = shift;
        p0[k] += shift;
      }
      trace->sweep_l2[s] = 0.0;
      trace->sweep_l2w[s] = 0.0;
    }
    return;
  }
  Vec head = Eigen::Map<const Vec>(points), first = Eigen::Map<const Vec>(points + Dim);
  Vec first_new;
  Eigen::Matrix<double, Dim, Dim> rotation;
  for (int64_t s = 0; s < num_sweeps; ++s) {
    const Vec head_new = Eigen::Map<const Vec>(heads + s * Dim);
    JointAngleMotion<Dim>(head, head_new, first, lengths[0], inv_lengths[0], &first_new, &rotation);
    for (int r = 0; r < Dim; ++r) {
      w->from[s * 3 + r] = first[r];
      w->to[s * 3 + r] = first_new[r];
      for (int c = 0; c < Dim; ++c) w->rotation[s * 9 + r * 3 + c] = rotation(r, c);
      w->placed[s * 2 * Dim + r] = head_new[r];
      w->placed[s * 2 * Dim + Dim + r] = first_new[r];
    }
    const double d0 = (head_new - head).norm(), d1 = (first_new - first).norm();
    trace->sweep_l2[s] = d0 + d1;
    trace->sweep_l2w[s] = d0 * trace->weights[0] + d1 * trace->weights[1];
    trace->path_length[0] += d0;
    trace->path_length[1] += d1;
    if (trace->flags[s] & SweepTrace::kStepEnd) {
      const double error = std::fabs((first_new - head_new).norm() - lengths[0]) * inv_lengths[0];
      trace->max_length_error = std::fmax(trace->max_length_error, error);
    }
    head = head_new;
    first = first_new;
  }
}

}  // namespace

void TracedWholeChainSweeps(const double* heads, int64_t num_sweeps, const double* lengths,
                            const double* inv_lengths, double* points, WholeChainWork* work,
                            SweepTrace* trace) {
  const SubnormalsAsZero subnormals;
  work->dim == 2
      ? WholeChainMotions<2>(heads, num_sweeps, lengths, inv_lengths, points, work, trace)
      : WholeChainMotions<3>(heads, num_sweeps, lengths, inv_lengths, points, work, trace);
  WholeChainKernel()(num_sweeps, work, points, trace);
}

}  // namespace flexkin::internal
