#pragma once
// Colours and sizes shared by the figures, plots and animations: one look for all of them.

#include <algorithm>
#include <cmath>

namespace flexkin::render {

struct Rgb {
  double r = 0.0, g = 0.0, b = 0.0;  // 0 to 1
};

inline Rgb Mix(const Rgb& a, const Rgb& b, double t) {
  return {a.r + (b.r - a.r) * t, a.g + (b.g - a.g) * t, a.b + (b.b - a.b) * t};
}

inline constexpr Rgb kWhite{1.0, 1.0, 1.0};
inline constexpr Rgb kInk{0.13, 0.13, 0.13};         // text, axes
inline constexpr Rgb kMuted{0.42, 0.42, 0.42};       // subtitle, tick labels
inline constexpr Rgb kGrid{0.90, 0.90, 0.90};        // grid lines
inline constexpr Rgb kInitial{0.25, 0.25, 0.25};     // the first configuration (dashed)
inline constexpr Rgb kFinal{0.70, 0.09, 0.17};       // the last configuration
inline constexpr Rgb kLeaderPath{0.90, 0.45, 0.05};  // the leading end's path
inline constexpr Rgb kMarker{0.13, 0.40, 0.67};      // plot markers and lines
inline constexpr Rgb kLookedAt{0.45, 0.22, 0.62};    // a tree's points looked at, and the gaze

// Colliders: filled in a neutral stone grey under the chains, outlined a little darker.
inline constexpr Rgb kColliderFill{0.80, 0.80, 0.78};
inline constexpr Rgb kColliderEdge{0.50, 0.50, 0.48};

// The fade of the snapshots from old (t = 0, light) to new (t = 1, dark): a blue ramp.
Rgb FadeColor(double t);
// A perceptually uniform colour map (viridis) for t in [0, 1], for the link index.
Rgb Viridis(double t);

}  // namespace flexkin::render
