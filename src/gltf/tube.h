#pragma once
// The tube mesh of the exported chain in its rest pose, skinned to the joints.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace flexkin::gltf {

// Vertex and index arrays as they go into the file.
struct TubeMesh {
  std::vector<float> positions;   // 3 per vertex, glTF scene coordinates (metres)
  std::vector<float> normals;     // 3 per vertex, unit length
  std::vector<uint16_t> joints;   // 4 per vertex (JOINTS_0)
  std::vector<float> weights;     // 4 per vertex (WEIGHTS_0), summing to 1
  std::vector<uint32_t> indices;  // 3 per triangle, counter-clockwise seen from outside
  int num_vertices() const { return static_cast<int>(positions.size() / 3); }
};

// A closed tube along the straight rest pose of the skeleton: joint j at (0, arc[j], 0) in the
// skeleton's space (arc[0] = 0, arc[j] = length of links 1..j), mapped to the scene by
// `to_scene` (the "flexkin" node's rotation times its scale). One ring of `sides` vertices per
// joint; an inner ring is skinned half to each of the two bones that meet there (it follows
// their mean direction), the end rings and the two end caps fully to the end joints.
TubeMesh MakeTube(const Eigen::VectorXd& arc, double radius, int sides,
                  const Eigen::Matrix3d& to_scene);

// The chain of capsules of links with radii (a result's "link_radii"): the same straight rest pose
// and axes as MakeTube, link i (from joint i to joint i + 1) a cylinder of radius radii[i] > 0
// about its bone, rings of `sides` vertices at its two joints. At an inner joint where the two
// links' radii differ there are two rings, one of each radius, joined by a flat annulus (with its
// own vertices, facing along the axis): every vertex of a link's side is at its radius from the
// link's axis. All of a joint's rings are skinned half to each bone that meets there (MakeTube's
// inner ring). The ends are hemispheres of the end links' radii: the end ring, `cap_rings` rings
// of latitude (at 90 / (cap_rings + 1) degree steps) and a pole, skinned fully to the end joint,
// every vertex at the radius from the end joint with that point's normal.
TubeMesh MakeCapsuleTube(const Eigen::VectorXd& arc, const Eigen::VectorXd& radii, int sides,
                         int cap_rings, const Eigen::Matrix3d& to_scene);

}  // namespace flexkin::gltf
