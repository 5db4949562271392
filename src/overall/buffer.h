#pragma once
// Views of reused buffers. The overall solver's problem sizes change with its active set (points
// 1..k free, k changing from one solve to the next), and an Eigen::VectorXd reallocates on every
// resize, so its buffers are sized for the largest problem (k = n) and used through views of the
// current size (Eigen::Map: the same arithmetic as on a vector of that size).

#include <Eigen/Core>
#include <new>

namespace flexkin::internal {

using VectorView = Eigen::Map<Eigen::VectorXd>;
using MatrixView = Eigen::Map<Eigen::MatrixXd>;  // column-major, like Eigen::MatrixXd

// Makes `*buffer` at least `size` long (allocates only when it is shorter; its values are then
// lost).
inline void Reserve(Eigen::VectorXd* buffer, Eigen::Index size) {
  if (buffer->size() < size) buffer->resize(size);
}

// The first `size` entries of `*buffer` (grown first if needed).
inline VectorView Leading(Eigen::VectorXd* buffer, Eigen::Index size) {
  Reserve(buffer, size);
  return VectorView(buffer->data(), size);
}

// The first rows * cols entries of `*buffer` as a rows by cols matrix (grown first if needed).
inline MatrixView LeadingMatrix(Eigen::VectorXd* buffer, Eigen::Index rows, Eigen::Index cols) {
  Reserve(buffer, rows * cols);
  return MatrixView(buffer->data(), rows, cols);
}

// Exchanges what two views show (an Eigen::Map cannot be assigned to; Eigen documents placement
// new as the way to point one at other storage). O(1), like Eigen::VectorXd::swap.
inline void SwapViews(VectorView* a, VectorView* b) {
  double* const a_data = a->data();
  const Eigen::Index a_size = a->size();
  new (a) VectorView(b->data(), b->size());
  new (b) VectorView(a_data, a_size);
}

}  // namespace flexkin::internal
