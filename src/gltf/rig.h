#pragma once
// The skeleton's pose per frame, as stored in a glTF file (float32), and the rotation math the
// writer and the reader share so that both turn a stored quaternion into the same matrix.

#include <Eigen/Core>
#include <array>
#include <string>
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

// The skeleton of a tree (docs/gltf-export.md, "Trees"): a bone per link, as a rig has. Joint 0,
// "point_<r>", sits on the root point r; each other point c has the joint "link_<c>" on its
// parent's point, whose +Y points to c (the link's bone, a child of the joint of the link that
// ends at the parent, or of joint 0); each leaf c has a joint "tip_<c>" on c, a child of link_<c>
// with its orientation. Joints are ordered root, links (breadth first from the root, children in
// index order), tips: every parent before its children.
struct TreeSkeleton {
  std::vector<int> parent;  // each joint's parent joint; -1 for joint 0
  std::vector<int> head;    // the point each joint sits on
  std::vector<int> toward;  // the point its +Y points to; -1 for a tip (and a lone root)
  std::vector<std::string> names;
};
// `parents`: a valid tree (ValidateTree). `sliding`: the points whose link into them changes
// length (a robot tree's prismatic joints); each that is not a leaf gets a joint "slide_<c>" on c
// as a leaf gets its tip, a child of link_<c> with its orientation (the end that link's capsule
// stretches to), after the tips in the same order.
TreeSkeleton MakeTreeSkeleton(const std::vector<int>& parents,
                              const std::vector<int>& sliding = {});

// Poses the tree's skeleton for each of `frames` ((n+1) by 3, the tree's points; a link of
// length 0 only where it slides: its bone keeps the direction of the frame before, or of the first
// frame where it has one, or its parent's), as PoseChain poses a chain: joint 0 turned from frame
// to frame by the smallest rotation that turns its bone (toward the root's first child), each other
// joint from its parent by the smallest rotation between their bones, translations from the float32
// values of the ancestors.
RigAnimation PoseTree(const TreeSkeleton& skeleton, const std::vector<Points>& frames);

}  // namespace flexkin::gltf
