"""The bake of a bone chain (docs/blender.md): what the operator reads from the scene, the run of
flexkin, and the keyframes it writes. Every check is made and every number computed before
anything in the scene changes, so that a refused or failed bake leaves the scene as it was."""
import math

import bpy
from mathutils import Matrix, Vector


class BakeError(Exception):
    """A problem of the scene or the selection, said as the user should read it."""


METHODS = [
    ("tractrix", "Tractrix", "The least-velocity motion, link by link from the driven end"),
    ("ftl", "Follow the leader", "Each link's trailing end to the nearest point at its length"),
    ("overall", "Overall", "All points at once: the least squared motion under the lengths"),
]


def selected_chain(armature):
    """The selected bones of `armature` as a chain, root first: each the child of the one before
    and starting at its tail (connected). Raises BakeError naming what is wrong."""
    if armature is None or armature.type != 'ARMATURE':
        what = "none" if armature is None else \
            f"'{armature.name}', of type {armature.type.lower()}"
        raise BakeError(f"select an armature (the active object is {what})")
    bones = [b for b in armature.data.bones if b.select]
    if not bones:
        raise BakeError(f"select the bones of a chain in '{armature.name}' (none is selected)")
    selected = set(b.name for b in bones)
    roots = [b for b in bones if b.parent is None or b.parent.name not in selected]
    if len(roots) != 1:
        raise BakeError("the selected bones are not one chain: "
                        f"{len(roots)} of them have no selected parent ("
                        + ", ".join(sorted(b.name for b in roots)) + ")")
    chain = [roots[0]]
    while True:
        children = [c for c in chain[-1].children if c.name in selected]
        if len(children) > 1:
            raise BakeError(f"the selected bones branch at '{chain[-1].name}' ("
                            + ", ".join(sorted(c.name for c in children))
                            + "); select one chain")
        if not children:
            break
        chain.append(children[0])
    if len(chain) != len(bones):
        raise BakeError("the selected bones are not one chain")
    for bone in chain:
        if not bone.length > 1e-9:
            raise BakeError(f"bone '{bone.name}' has length {bone.length:g}; every bone of the "
                            "chain needs a positive length")
        if not bone.use_inherit_rotation or bone.inherit_scale != 'FULL':
            raise BakeError(f"bone '{bone.name}' does not inherit its parent's rotation and "
                            "scale (Bone Properties > Relations); the bake needs both")
    for parent, child in zip(chain, chain[1:]):
        if (child.head_local - parent.tail_local).length > 1e-6 * max(1.0, parent.length):
            raise BakeError(f"bone '{child.name}' does not start at the tail of '{parent.name}'; "
                            "the chain's bones must be connected")
    return chain


def _frames(scene):
    if scene.frame_end <= scene.frame_start:
        raise BakeError(f"the frame range {scene.frame_start}..{scene.frame_end} has no frame "
                        "after the first; set the scene's end frame after its start")
    return list(range(scene.frame_start, scene.frame_end + 1))


def gather(context, armature, chain, target_name):
    """Everything the bake needs from the scene, frame by frame: the chain's points at the first
    frame (world), the driven end's path, the armature's world matrix and the pose of the chain's
    parent bone (outside the chain) at every frame. Restores the current frame."""
    scene = context.scene
    frames = _frames(scene)
    target = None
    if target_name:
        target = bpy.data.objects.get(target_name)
        if target is None:
            raise BakeError(f"target '{target_name}' is not an object of this file; choose the "
                            "object (an Empty) whose motion drives the chain, or none to follow "
                            "the first bone's own animation")
    pose = armature.pose.bones
    parent = chain[0].parent
    current = scene.frame_current
    data = {"frames": frames, "world": [], "parent_pose": [], "path": []}
    try:
        for f in frames:
            scene.frame_set(f)
            world = armature.matrix_world.copy()
            data["world"].append(world)
            data["parent_pose"].append(pose[parent.name].matrix.copy() if parent else None)
            head = world @ pose[chain[0].name].head
            data["path"].append(target.matrix_world.translation.copy() if target else head)
            if f == frames[0]:
                points = [world @ pose[b.name].head for b in chain]
                points.append(world @ pose[chain[-1].name].tail)
                data["points"] = points
                data["start_rotations"] = [pose[b.name].matrix.to_quaternion() for b in chain]
    finally:
        scene.frame_set(current)
    return data


def run_flexkin(flexkin, data, method, substeps, progress=None):
    """flexkin.run of the chain's first-frame points, its first point driven along the path (the
    frames after the first). Returns the frames' points, (F, n+1, 3) in world space."""
    points = [list(p) for p in data["points"]]
    path = [list(p) for p in data["path"][1:]]
    result = flexkin.run(points, path, method=method, substeps=substeps, progress=progress)
    return result.frames


def _aligned(rotation, direction):
    """`rotation` turned by the least rotation that takes its y axis onto `direction`."""
    y = rotation @ Vector((0.0, 1.0, 0.0))
    return (y.rotation_difference(direction.normalized()) @ rotation).normalized()


def pose_keys(armature, chain, data, frames_points):
    """The pose of every bone at every frame that puts its head on its point and its tail toward
    the next, each bone's roll carried from frame to frame by the least rotation: per bone, its
    matrix_basis's rotation (quaternions) and, for the chain's first bone, its location."""
    rest = [b.matrix_local.copy() for b in chain]
    parent = chain[0].parent
    parent_rest = parent.matrix_local.copy() if parent else None
    rotations = list(data["start_rotations"])
    keys = {b.name: {"rotation": [], "location": []} for b in chain}
    for f in range(len(data["frames"])):
        to_armature = data["world"][f].inverted()
        p = [to_armature @ Vector(tuple(x)) for x in frames_points[f]]
        above = data["parent_pose"][f]
        above_rest = parent_rest
        for i, bone in enumerate(chain):
            rotations[i] = _aligned(rotations[i], p[i + 1] - p[i])
            matrix = Matrix.Translation(p[i]) @ rotations[i].to_matrix().to_4x4()
            if above is None:
                basis = rest[i].inverted() @ matrix
            else:
                basis = rest[i].inverted() @ above_rest @ above.inverted() @ matrix
            location, rotation, _ = basis.decompose()
            previous = keys[bone.name]["rotation"]
            if previous and previous[-1].dot(rotation) < 0.0:
                rotation.negate()  # the same rotation, on the side of the last key
            previous.append(rotation)
            keys[bone.name]["location"].append(location)
            above, above_rest = matrix, rest[i]
    return keys


def _set_curve(action, data_path, index, group, frames, values):
    curve = action.fcurves.find(data_path, index=index)
    if curve is not None:
        action.fcurves.remove(curve)
    curve = action.fcurves.new(data_path, index=index, action_group=group)
    curve.keyframe_points.add(len(frames))
    co = []
    for f, v in zip(frames, values):
        co += [float(f), float(v)]
    curve.keyframe_points.foreach_set("co", co)
    for point in curve.keyframe_points:
        point.interpolation = 'LINEAR'
    curve.update()


def _axis_angle(q):
    """[angle, x, y, z] of a unit quaternion, in double precision (mathutils' to_axis_angle
    computes in single precision and returns a zero angle for rotations below about 1e-4)."""
    sine = math.sqrt(q.x * q.x + q.y * q.y + q.z * q.z)
    if sine == 0.0:
        return [0.0, 0.0, 1.0, 0.0]
    return [2.0 * math.atan2(sine, q.w), q.x / sine, q.y / sine, q.z / sine]


def write_keys(armature, chain, frames, keys):
    """The keys into the armature's action (made if it has none): each bone's rotation in its
    rotation mode and the first bone's location, one key per frame, replacing the curves of
    those channels."""
    if armature.animation_data is None:
        armature.animation_data_create()
    if armature.animation_data.action is None:
        armature.animation_data.action = bpy.data.actions.new(armature.name + "Action")
    action = armature.animation_data.action
    for i, bone in enumerate(chain):
        pb = armature.pose.bones[bone.name]
        base = f'pose.bones["{bpy.utils.escape_identifier(bone.name)}"]'
        rotations = keys[bone.name]["rotation"]
        if pb.rotation_mode == 'QUATERNION':
            for k in range(4):
                _set_curve(action, base + ".rotation_quaternion", k, bone.name, frames,
                           [q[k] for q in rotations])
        elif pb.rotation_mode == 'AXIS_ANGLE':
            values = [_axis_angle(q) for q in rotations]
            for k in range(4):
                _set_curve(action, base + ".rotation_axis_angle", k, bone.name, frames,
                           [v[k] for v in values])
        else:
            eulers, last = [], None
            for q in rotations:
                e = q.to_euler(pb.rotation_mode, last) if last else q.to_euler(pb.rotation_mode)
                eulers.append(e)
                last = e
            for k in range(3):
                _set_curve(action, base + ".rotation_euler", k, bone.name, frames,
                           [e[k] for e in eulers])
        if i == 0:
            for k in range(3):
                _set_curve(action, base + ".location", k, bone.name, frames,
                           [v[k] for v in keys[bone.name]["location"]])
