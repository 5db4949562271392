#pragma once
// The skeleton's pose per frame, as stored in a glTF file (float32), and the rotation math the
// writer and the reader share so that both turn a stored quaternion into the same matrix.

#include <Eigen/Core>
#include <array>
#include <vector>

#include "flexkin/chain.h"

namespace flexkin::gltf {

// The rotation matrix of the quaternion (x, y, z, w), normalized in double first (glTF stores
// unit quaternions, but only to float precision).
Eigen::Matrix3d QuaternionMatrix(double x, double y, double z, double w);

// The keyframes of every joint: joint j's local translation (in its parent's frame) and local
// rotation at each frame, float32 as they go into the file.
struct RigAnimation {
  int num_joints = 0;
  int num_frames = 0;
  std::vector<std::vector<float>> translation;  // [joint][3 * frame + axis]
  std::vector<std::vector<float>> rotation;     // [joint][4 * frame + k], k: x, y, z, w
};

// Poses the chain for each frame of `frames` (each (n+1) by 3, in the skeleton's space: joint 0's
// parent frame). Joint j's +Y axis points from point j to point j+1 (the last joint keeps its
// parent's orientation). The twist about the bone is the least possible: joint 0's orientation
// is carried from frame to frame by the smallest rotation that turns its bone, each child's
// from its parent by the smallest rotation between their bones. Each joint's translation is
// computed from the float32 rotations of its ancestors as a reader composes them, so that the
// composed position is the input point to float32 rounding of that translation. Quaternion
// signs are kept continuous over time (a LINEAR sampler then takes the short way). Consecutive
// points must not coincide (checked by the caller).
RigAnimation PoseChain(const std::vector<Points>& frames);

}  // namespace flexkin::gltf
