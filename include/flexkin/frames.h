#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <iterator>
#include <vector>

#include "flexkin/chain.h"

namespace flexkin {

namespace internal {
// Memory for dense frames: a block of 4 MiB or more is aligned to 2 MiB and advised as
// transparent huge pages (as numpy does for its arrays), so a run filling it does not fault a
// page every 4 KiB; smaller blocks come from malloc. Either is freed with std::free.
void* AllocateFrameBlock(size_t bytes);
template <typename T>
struct FrameBlockAllocator {
  using value_type = T;
  FrameBlockAllocator() = default;
  template <typename U>
  FrameBlockAllocator(const FrameBlockAllocator<U>&) {}  // NOLINT: allocators convert
  T* allocate(size_t n) { return static_cast<T*>(AllocateFrameBlock(n * sizeof(T))); }
  void deallocate(T* p, size_t) { std::free(p); }
  template <typename U>
  bool operator==(const FrameBlockAllocator<U>&) const {
    return true;
  }
  template <typename U>
  bool operator!=(const FrameBlockAllocator<U>&) const {
    return false;
  }
};
}  // namespace internal

// The arrays of dense frames.
template <typename T>
using FrameArray = std::vector<T, internal::FrameBlockAllocator<T>>;

// A configuration or a vector handed to a sink or a writer, from a Points/VectorXd or a Frame's
// view alike, without a copy. Packed (Stride<0, 0>): the rows are contiguous, so a copy out of it
// is one linear copy (a block of a wider matrix is first copied into a packed temporary).
using PointsRef = Eigen::Ref<const Points, 0, Eigen::Stride<0, 0>>;
using VectorRef = Eigen::Ref<const Eigen::VectorXd>;

// One recorded configuration: a view into the Frames that holds it, valid while those Frames
// live and are not added to or cleared.
struct Frame {
  int64_t step;                     // leader steps done; 0 is the initial configuration
  Eigen::Map<const Points> points;  // (n+1) by dim
  // Angle in radians, in [0, pi], between each link (from its trailing to its leading end) and
  // the leading end's current direction of motion (that of the last leader step that moved it;
  // for frame 0, that of the first). 0 means aligned with the pull. Empty (size 0) if the run
  // kept none or the leader never moves.
  Eigen::Map<const Eigen::VectorXd> link_angles;
};

// The recorded configurations of a run, held densely in the layout of the result file's arrays
// and of Python's: the points of every frame form one (F, n+1, dim) array in C order (frame f's
// points are rows f*(n+1) .. f*(n+1)+n of a row-major matrix of dim columns), the steps one (F)
// array, the link angles, when kept, one (F, n) array. A frame costs no allocation of its own.
// Every frame has the same number of points and dimensions and either every frame has link
// angles or none has; Add enforces it.
class Frames {
 public:
  class Iterator {
   public:
    using iterator_category = std::forward_iterator_tag;
    using value_type = Frame;
    using difference_type = std::ptrdiff_t;
    using pointer = void;
    using reference = Frame;
    Iterator(const Frames* frames, size_t index) : frames_(frames), index_(index) {}
    Frame operator*() const { return (*frames_)[index_]; }
    Iterator& operator++() {
      ++index_;
      return *this;
    }
    bool operator==(const Iterator& other) const { return index_ == other.index_; }
    bool operator!=(const Iterator& other) const { return index_ != other.index_; }

   private:
    const Frames* frames_;
    size_t index_;
  };

  Frames() = default;

  // Appends a frame. The first frame fixes the shape (points' rows and columns, and whether link
  // angles are kept: a nonempty `link_angles` must have points.rows() - 1 values); a later frame
  // of another shape throws std::invalid_argument.
  void Add(int64_t step, const PointsRef& points, const VectorRef& link_angles);
  void Add(int64_t step, const PointsRef& points) { Add(step, points, Eigen::VectorXd()); }
  // Room for `count` frames of `num_points` points in `dim` dimensions without reallocating.
  void Reserve(int64_t count, int64_t num_points, int dim, bool link_angles);
  // Forgets the frames and their shape.
  void Clear();
  // Keeps the first `count` frames (count <= size()).
  void Truncate(size_t count);
  // Drops every frame's link angles (the frames then have none).
  void DropLinkAngles();

  size_t size() const { return steps_.size(); }
  bool empty() const { return steps_.empty(); }
  Frame operator[](size_t f) const;
  Frame front() const { return (*this)[0]; }
  Frame back() const { return (*this)[size() - 1]; }
  Iterator begin() const { return {this, 0}; }
  Iterator end() const { return {this, size()}; }

  // Points per frame (n+1) and their dimension; 0 before the first frame.
  int64_t num_points() const { return num_points_; }
  int dim() const { return dim_; }
  bool has_link_angles() const { return has_angles_; }

  // The dense arrays: size() * num_points() * dim() coordinates, size() steps, and
  // size() * (num_points() - 1) link angles (none without them).
  const FrameArray<double>& points_data() const { return points_; }
  const FrameArray<int64_t>& steps() const { return steps_; }
  const FrameArray<double>& link_angles_data() const { return angles_; }
  // Every frame's points stacked: (size() * num_points()) by dim.
  Eigen::Map<const Points> all_points() const;
  // Makes `count` frames of `num_points` points in `dim` dimensions, with link angles or not,
  // all zero, for a reader that fills the arrays below in place.
  void Resize(int64_t count, int64_t num_points, int dim, bool link_angles);
  double* mutable_points_data() { return points_.data(); }
  // Writable views of frame f, for a caller that changes a frame in place.
  Eigen::Map<Points> mutable_points(size_t f);
  Eigen::Map<Eigen::VectorXd> mutable_link_angles(size_t f);
  void set_step(size_t f, int64_t step) { steps_[f] = step; }
  int64_t* mutable_steps() { return steps_.data(); }
  double* mutable_link_angles_data() { return angles_.data(); }

 private:
  FrameArray<double> points_;
  FrameArray<int64_t> steps_;
  FrameArray<double> angles_;
  int64_t num_points_ = 0;
  int dim_ = 0;
  bool has_angles_ = false;
};

}  // namespace flexkin
