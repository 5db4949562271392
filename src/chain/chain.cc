#include "flexkin/chain.h"

#include <cmath>
#include <string>

#include "flexkin/error.h"

namespace flexkin {
namespace {

void ValidatePoints(const Points& points, const std::string& field) {
  if (points.cols() != 2 && points.cols() != 3) {
    throw InputError(field, "points have " + std::to_string(points.cols()) +
                                " coordinates; expected 2 (planar) or 3 (spatial)");
  }
  if (points.rows() < 2) {
    throw InputError(
        field, "a chain needs at least 2 points (1 link); got " + std::to_string(points.rows()));
  }
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    for (Eigen::Index k = 0; k < points.cols(); ++k) {
      if (!std::isfinite(points(i, k))) {
        throw InputError(field + "[" + std::to_string(i) + "][" + std::to_string(k) + "]",
                         "value " + FormatNumber(points(i, k)) + " is not a finite number");
      }
    }
  }
}

}  // namespace

Chain MakeChain(const Points& points) {
  ValidatePoints(points, "points");
  Chain chain;
  chain.points = points;
  const Eigen::Index n = points.rows() - 1;
  chain.lengths.resize(n);
  for (Eigen::Index i = 1; i <= n; ++i) {
    const double length = (points.row(i) - points.row(i - 1)).norm();
    if (!(length > 0.0) || !std::isfinite(length)) {
      throw InputError("points[" + std::to_string(i) + "]",
                       "link " + std::to_string(i) + " has length " + FormatNumber(length) +
                           " (points " + std::to_string(i - 1) + " and " + std::to_string(i) +
                           "); every link needs a positive, finite length");
    }
    chain.lengths[i - 1] = length;
  }
  return chain;
}

void ValidateChain(const Chain& chain, const char* field) {
  const std::string f = field;
  ValidatePoints(chain.points, f + ".points");
  if (chain.lengths.size() != chain.points.rows() - 1) {
    throw InputError(f + ".lengths",
                     "has " + std::to_string(chain.lengths.size()) + " link lengths for " +
                         std::to_string(chain.points.rows()) + " points; expected one per link (" +
                         std::to_string(chain.points.rows() - 1) + ")");
  }
  for (Eigen::Index i = 0; i < chain.lengths.size(); ++i) {
    const double length = chain.lengths[i];
    if (!(length > 0.0) || !std::isfinite(length)) {
      throw InputError(f + ".lengths[" + std::to_string(i) + "]",
                       "link length " + FormatNumber(length) + " is not a positive finite number");
    }
  }
}

double MaxRelativeLengthError(const Chain& chain) {
  double worst = 0.0;
  for (Eigen::Index i = 1; i < chain.points.rows(); ++i) {
    const double length = (chain.points.row(i) - chain.points.row(i - 1)).norm();
    worst = std::fmax(worst, std::fabs(length - chain.lengths[i - 1]) / chain.lengths[i - 1]);
  }
  return worst;
}

}  // namespace flexkin
