#pragma once
// One formula for the leading end's positions along a leader step split into equal sub-steps,
// shared by every engine (sequential sweeps, runs, the overall continuation, the arms), so that
// they move the head through the very same points.

namespace flexkin::internal {

// A coordinate of the head after sub-step j of n (1 <= j <= n) from `from` to `to`: the straight
// line at fraction j / n, and exactly `to` at j == n.
inline double SubstepHead(double from, double to, int j, int n) {
  return j == n ? to : from + (to - from) * (static_cast<double>(j) / n);
}

}  // namespace flexkin::internal
