#include "render/style.h"

#include <iterator>

namespace flexkin::render {
namespace {

// Piecewise-linear interpolation in a table of equally spaced colours.
template <size_t N>
Rgb Interpolate(const Rgb (&table)[N], double t) {
  t = std::clamp(t, 0.0, 1.0) * (N - 1);
  const size_t i = std::min(static_cast<size_t>(t), N - 2);
  return Mix(table[i], table[i + 1], t - i);
}

}  // namespace

Rgb FadeColor(double t) {
  // From a light grey-blue to a deep navy, light enough at the start that the old frames recede.
  static constexpr Rgb kRamp[] = {{0.70, 0.80, 0.91},
                                  {0.47, 0.65, 0.84},
                                  {0.25, 0.50, 0.75},
                                  {0.09, 0.31, 0.60},
                                  {0.03, 0.17, 0.40}};
  return Interpolate(kRamp, t);
}

Rgb Viridis(double t) {
  // viridis sampled at 0, 0.1, ..., 1.
  static constexpr Rgb kViridis[] = {
      {0.267, 0.004, 0.329}, {0.282, 0.141, 0.459}, {0.255, 0.267, 0.529}, {0.208, 0.373, 0.553},
      {0.165, 0.471, 0.557}, {0.129, 0.569, 0.549}, {0.133, 0.659, 0.518}, {0.267, 0.749, 0.439},
      {0.478, 0.820, 0.318}, {0.741, 0.875, 0.149}, {0.992, 0.906, 0.145}};
  return Interpolate(kViridis, t);
}

}  // namespace flexkin::render
