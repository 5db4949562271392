#include "flexkin/frames.h"

#include <sys/mman.h>

#include <cstring>
#include <new>
#include <stdexcept>
#include <string>

namespace flexkin {

void* internal::AllocateFrameBlock(size_t bytes) {
  constexpr size_t kHuge = size_t{2} << 20;
  void* p = nullptr;
  if (bytes >= 2 * kHuge) {
    const size_t rounded = (bytes + kHuge - 1) / kHuge * kHuge;
    p = std::aligned_alloc(kHuge, rounded);
    if (p != nullptr) ::madvise(p, rounded, MADV_HUGEPAGE);  // advice only: errors are harmless
  } else {
    p = std::malloc(bytes == 0 ? 1 : bytes);
  }
  if (p == nullptr) throw std::bad_alloc();
  return p;
}

void Frames::Add(int64_t step, const PointsRef& points, const VectorRef& link_angles) {
  if (empty()) {
    num_points_ = points.rows();
    dim_ = static_cast<int>(points.cols());
    has_angles_ = link_angles.size() > 0;
  }
  if (points.rows() != num_points_ || points.cols() != dim_) {
    throw std::invalid_argument("flexkin: a frame of " + std::to_string(points.rows()) + " by " +
                                std::to_string(points.cols()) + " points added to frames of " +
                                std::to_string(num_points_) + " by " + std::to_string(dim_));
  }
  if (link_angles.size() != (has_angles_ ? num_points_ - 1 : 0)) {
    throw std::invalid_argument("flexkin: a frame with " + std::to_string(link_angles.size()) +
                                " link angles added to frames with " +
                                std::to_string(has_angles_ ? num_points_ - 1 : 0));
  }
  // A PointsRef is packed: its coordinates are contiguous, appended in one copy (no zero fill).
  points_.insert(points_.end(), points.data(), points.data() + points.size());
  angles_.insert(angles_.end(), link_angles.data(), link_angles.data() + link_angles.size());
  steps_.push_back(step);
}

void Frames::Reserve(int64_t count, int64_t num_points, int dim, bool link_angles) {
  points_.reserve(static_cast<size_t>(count * num_points * dim));
  steps_.reserve(static_cast<size_t>(count));
  if (link_angles) angles_.reserve(static_cast<size_t>(count * (num_points - 1)));
}

void Frames::Clear() {
  points_.clear();
  steps_.clear();
  angles_.clear();
  num_points_ = 0;
  dim_ = 0;
  has_angles_ = false;
}

void Frames::Truncate(size_t count) {
  const size_t links = has_angles_ ? static_cast<size_t>(num_points_ - 1) : 0;
  points_.resize(count * static_cast<size_t>(num_points_ * dim_));
  angles_.resize(count * links);
  steps_.resize(count);
}

void Frames::DropLinkAngles() {
  angles_.clear();
  has_angles_ = false;
}

Frame Frames::operator[](size_t f) const {
  const int64_t links = has_angles_ ? num_points_ - 1 : 0;
  return {
      steps_[f],
      Eigen::Map<const Points>(points_.data() + f * static_cast<size_t>(num_points_ * dim_),
                               num_points_, dim_),
      Eigen::Map<const Eigen::VectorXd>(angles_.data() + f * static_cast<size_t>(links), links)};
}

Eigen::Map<const Points> Frames::all_points() const {
  return {points_.data(), static_cast<Eigen::Index>(size()) * num_points_, dim_};
}

Eigen::Map<Points> Frames::mutable_points(size_t f) {
  return {points_.data() + f * static_cast<size_t>(num_points_ * dim_), num_points_, dim_};
}

Eigen::Map<Eigen::VectorXd> Frames::mutable_link_angles(size_t f) {
  const int64_t links = has_angles_ ? num_points_ - 1 : 0;
  return {angles_.data() + f * static_cast<size_t>(links), links};
}

void Frames::Resize(int64_t count, int64_t num_points, int dim, bool link_angles) {
  num_points_ = num_points;
  dim_ = dim;
  has_angles_ = link_angles;
  points_.assign(static_cast<size_t>(count * num_points * dim), 0.0);
  steps_.assign(static_cast<size_t>(count), 0);
  angles_.assign(link_angles ? static_cast<size_t>(count * (num_points - 1)) : 0, 0.0);
}

}  // namespace flexkin
