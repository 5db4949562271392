// GltfOptions::Validate and the names of GltfUpAxis.
#include <cmath>
#include <string>

#include "flexkin/error.h"
#include "flexkin/gltf.h"

namespace flexkin {

const char* GltfUpAxisName(GltfUpAxis axis) {
  switch (axis) {
    case GltfUpAxis::kAuto:
      return "auto";
    case GltfUpAxis::kY:
      return "y";
    case GltfUpAxis::kZ:
      return "z";
  }
  return "?";
}

GltfUpAxis ParseGltfUpAxis(const std::string& name, const std::string& field) {
  for (const GltfUpAxis axis : {GltfUpAxis::kAuto, GltfUpAxis::kY, GltfUpAxis::kZ}) {
    if (name == GltfUpAxisName(axis)) return axis;
  }
  throw InputError(field, "\"" + name + "\" is not valid; expected \"auto\", \"y\" or \"z\"");
}

std::string GltfOptions::Validate() const {
  if (!(steps_per_second > 0.0) || !std::isfinite(steps_per_second)) {
    return "steps_per_second: " + FormatNumber(steps_per_second) +
           " is not valid; must be a finite number > 0";
  }
  if (!(tube_radius >= 0.0) || !std::isfinite(tube_radius)) {
    return "tube_radius: " + FormatNumber(tube_radius) +
           " is not valid; must be a finite number >= 0 (0 picks one from the link lengths)";
  }
  if (tube_sides < 3 || tube_sides > 64) {
    return "tube_sides: " + std::to_string(tube_sides) + " is not valid; must be 3 to 64";
  }
  if (!(scale > 0.0) || !std::isfinite(scale)) {
    return "scale: " + FormatNumber(scale) + " is not valid; must be a finite number > 0";
  }
  if (up_axis != GltfUpAxis::kAuto && up_axis != GltfUpAxis::kY && up_axis != GltfUpAxis::kZ) {
    return "up_axis: " + std::to_string(static_cast<int>(up_axis)) +
           " is not valid; must be auto, y or z";
  }
  return "";
}

}  // namespace flexkin
