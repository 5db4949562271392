#pragma once

#include <Eigen/Core>

namespace flexkin {

// #P by dim list of points, one point per row (row-major so that a point is contiguous).
// dim is 2 or 3. Row 0 is the leading end.
using Points = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// A chain of rigid links: point 0 is the leading end, link i (1-based) joins points i-1 and i.
// The link lengths are fixed when the chain is made and never recomputed from the points, so
// rounding in the points cannot make them drift.
struct Chain {
  Points points;            // (n+1) by dim
  Eigen::VectorXd lengths;  // n link lengths, lengths[i-1] is link i
  int dim() const { return static_cast<int>(points.cols()); }
  int num_links() const { return static_cast<int>(lengths.size()); }
};

// Makes a chain whose link lengths are the distances between consecutive points.
// Throws InputError if the shape is not (n+1) by 2 or 3 with n >= 1, a value is not finite, or a
// link has zero length.
Chain MakeChain(const Points& points);

// Checks that a chain is usable (shape, finite values, positive finite lengths matching the
// point count). Throws InputError naming `field` otherwise.
void ValidateChain(const Chain& chain, const char* field = "chain");

// Largest |(|p_i - p_{i-1}| - L_i)| / L_i over the links of `chain`.
double MaxRelativeLengthError(const Chain& chain);

}  // namespace flexkin
