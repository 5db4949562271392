#pragma once

#include <string>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/result_io.h"
#include "flexkin/robot_scenario.h"
#include "flexkin/tree_scenario.h"
#include "flexkin/vocabulary.h"

namespace flexkin {

// Export of a result's motion to glTF 2.0 (docs/gltf-export.md): the chain as a skeleton with one
// joint per point, the motion as keyframed joint animation (one keyframe per recorded frame,
// LINEAR), and optionally a tube mesh skinned to the joints so that the file shows something in
// a viewer. Plays in Blender, three.js and game engines; can drive a rope, tail or tentacle rig.
//
// Skeleton: joint 0 (point 0, the leading end) is the root; joint i is the child of joint i-1.
// Each joint's local +Y axis points along its outgoing link (from point i to point i+1; the last
// joint copies its parent's orientation), so the bones run from the leading to the trailing end,
// as in a tail rig whose root is where the tail is attached. In the rest pose the chain is
// straight along +Y. Every joint has a rotation and a translation channel: the translations are
// the link vectors in the parent's frame, (0, L_i, 0) up to float rounding; they absorb the
// rounding of the rotations to float32, so the joints' positions are the input's to float32
// precision, without error piling up along the chain.
//
// Axes: the joints live in flexkin's coordinates (2D results at z = 0) under a parent node
// "flexkin" whose rotation and scale map them to glTF's right-handed, y-up metres (see
// GltfUpAxis and GltfOptions::scale).

// Which axis of flexkin's coordinates points up (glTF +Y) in the exported scene.
enum class GltfUpAxis {
  kAuto,  // kY for 2D results (the x-y plane faces a default camera), kZ for 3D results
  kY,     // flexkin (x, y, z) -> glTF (x, y, z): no rotation
  kZ,     // flexkin (x, y, z) -> glTF (x, z, -y): z-up data, as Blender shows it after import
};

// The names used by the command line and in the file's extras.
template <>
struct Vocabulary<GltfUpAxis> {
  static constexpr const char* kKind = "up axis";
  static constexpr NamedValue<GltfUpAxis> kEntries[] = {
      {GltfUpAxis::kAuto, "auto", "y for 2D results, z for 3D results"},
      {GltfUpAxis::kY, "y", "flexkin's y points up: no rotation"},
      {GltfUpAxis::kZ, "z", "flexkin's z points up, as Blender shows z-up data"},
  };
};
inline const char* GltfUpAxisName(GltfUpAxis axis) { return NameOf(axis); }
// Throws InputError naming `field` and listing the names.
inline GltfUpAxis ParseGltfUpAxis(const std::string& name, const std::string& field = "up_axis") {
  return ParseName<GltfUpAxis>(name, field);
}

struct GltfOptions {
  // Playback speed: one leader step lasts 1 / steps_per_second seconds, so frame f's keyframe is
  // at time step_f / steps_per_second. With a result recorded at every step the keyframes are
  // at this rate per second. > 0. Typical: 24 to 60.
  double steps_per_second = 30.0;
  // Include a tube mesh skinned to the joints (the visible rope). Without it the file holds the
  // skeleton and its animation only (Blender still makes an armature from the skin).
  bool include_mesh = true;
  // Radius of the tube, in the chain's length unit (before `scale`). 0 picks the links' capsules
  // where the result carries link radii (docs/gltf-export.md), else
  // min(0.25 * mean link length, 0.02 * total length). >= 0.
  double tube_radius = 0.0;
  // Vertices around the tube. 3 to 64. Typical: 8 to 16.
  int tube_sides = 12;
  // Metres (glTF's unit) per length unit of the chain, applied by the "flexkin" node. > 0.
  double scale = 1.0;
  // Which flexkin axis points up in glTF; see GltfUpAxis.
  GltfUpAxis up_axis = GltfUpAxis::kAuto;

  // Every problem (empty if valid), each naming its member ("tube_sides").
  Problems Validate() const;
};

// Writes `result`'s frames to `path` as glTF 2.0: binary (.glb) or JSON with the buffer embedded
// as base64 (.gltf), chosen by the extension (case-insensitive). Written atomically (as
// WriteFileAtomically: a temporary file renamed over `path`; on any error nothing is written and
// an existing file is left untouched). Throws InputError naming the field for invalid options,
// a path without one of those extensions ("path"), or a result the file cannot represent
// ("frames" empty; "frames[f].points" of the wrong shape, non-finite or with coinciding
// consecutive points; "frames[f].step" not increasing; more than 65535 points), before anything
// is written; std::system_error if the file cannot be written.
void WriteGltf(const ResultFile& result, const GltfOptions& options, const std::string& path);

// Writes a tree result (flexkin/tree_scenario.h) to `path` as WriteGltf writes a chain's, with a
// skeleton of a bone per link (docs/gltf-export.md, "Trees"): joint "point_<r>" on the root point,
// "link_<c>" on the parent of each other point c with its +Y toward c, "tip_<c>" on each leaf c.
// Frame f's keyframe is at f / steps_per_second seconds. The mesh (include_mesh) is a capsule per
// link, each moving rigidly with its link's bone, of radius tube_radius, or by default
// min(0.25 * mean link length, 0.02 * total length, 0.25 * its own length). The file's extras
// name the tree's parents and the point of each joint (ReadGltfJointPositions's joint_points).
// Written atomically. Throws InputError as WriteGltf: invalid options; a path without .gltf or
// .glb ("path"); a result glTF cannot hold ("frames[f].points[i]" beyond float32 or on its parent
// point, too many joints).
void WriteTreeGltf(const TreeResultFile& tree, const GltfOptions& options, const std::string& path);

namespace internal {
// The same for a drawing and options Draw (flexkin/draw.h) has checked: only glTF's own limits
// (joints, float32, link directions) are checked here.
void WriteGltf(const CheckedDrawing& drawing, const GltfOptions& options, const std::string& path);
// The same for a tree and options Draw has checked (ValidateTreeResult, Validate): only glTF's own
// limits and the path are checked here.
void WriteTreeGltf(const TreeResultFile& tree, const GltfOptions& options, const std::string& path);
}  // namespace internal

// Joint positions read back from a glTF file.
struct GltfJointMotion {
  // The keyframe times, seconds: every input time of the first animation's samplers, sorted,
  // duplicates removed. One time, 0, if the file has no animation.
  std::vector<double> times;
  // positions[k]: one row per joint of the first skin (in the skin's order), the joints' world
  // positions at times[k]. If the file was written by WriteGltf, in flexkin's coordinates and
  // length unit ((n+1) by dim, the axis mapping and scale undone); otherwise glTF world
  // coordinates, metres (joints by 3).
  std::vector<Points> positions;
  int dim = 3;  // columns of each entry of `positions`
  // For a tree written by WriteTreeGltf: the point of the tree each joint sits on (its head).
  // Empty for other files.
  std::vector<int> joint_points;
};

// Reads a .gltf or .glb file (told apart by content) and evaluates its first animation at each
// keyframe time: node transforms composed from the scene roots down (translation, rotation,
// scale or matrix), LINEAR (slerp for rotations) and STEP samplers. Throws std::system_error if
// the file cannot be read, InputError if it is not valid glTF, has no skin, or uses what this
// reader does not support (CUBICSPLINE, sparse or non-float animation accessors).
GltfJointMotion ReadGltfJointPositions(const std::string& path);

}  // namespace flexkin
