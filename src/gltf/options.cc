// GltfOptions::Validate.
#include <cmath>
#include <string>

#include "flexkin/error.h"
#include "flexkin/gltf.h"

namespace flexkin {

Problems GltfOptions::Validate() const {
  Problems problems;
  if (!(steps_per_second > 0.0) || !std::isfinite(steps_per_second)) {
    problems.emplace_back(
        "steps_per_second",
        FormatNumber(steps_per_second) + " is not valid; must be a finite number > 0",
        FormatNumber(steps_per_second), "a finite number > 0");
  }
  if (!(tube_radius >= 0.0) || !std::isfinite(tube_radius)) {
    problems.emplace_back("tube_radius",
                          FormatNumber(tube_radius) +
                              " is not valid; must be a finite number >= 0 (0 picks one from the "
                              "link lengths)",
                          FormatNumber(tube_radius), "a finite number >= 0");
  }
  if (tube_sides < 3 || tube_sides > 64) {
    problems.emplace_back("tube_sides",
                          std::to_string(tube_sides) + " is not valid; must be 3 to 64",
                          std::to_string(tube_sides), "3 to 64");
  }
  if (!(scale > 0.0) || !std::isfinite(scale)) {
    problems.emplace_back("scale",
                          FormatNumber(scale) + " is not valid; must be a finite number > 0",
                          FormatNumber(scale), "a finite number > 0");
  }
  if (FindName<GltfUpAxis>(NameOf(up_axis)) == nullptr) {
    problems.emplace_back("up_axis",
                          std::to_string(static_cast<int>(up_axis)) + " is not valid; must be " +
                              QuotedNames<GltfUpAxis>(),
                          std::to_string(static_cast<int>(up_axis)), QuotedNames<GltfUpAxis>());
  }
  return problems;
}

}  // namespace flexkin
