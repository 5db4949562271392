#pragma once
// The root placement of GrowStrands on its own, so that a groom file can be checked without
// holding its strands (ValidateGroomText).

#include <Eigen/Core>
#include <functional>

#include "flexkin/groom.h"

namespace flexkin::groom_internal {

// Places the roots of a valid `spec` exactly as GrowStrands does, calling visit(root, normal,
// link_length) for each strand in order (normal: the outward unit normal at the root). Throws
// InputError "region" as GrowStrands does.
void PlaceRoots(const GrowSpec& spec,
                const std::function<void(const Eigen::Vector3d& root, const Eigen::Vector3d& normal,
                                         double link_length)>& visit);

}  // namespace flexkin::groom_internal
