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


class Body:
    """Selected bones as a tree of points: `bones` parent first, bone i from point heads[i] to
    point tails[i], up[i] the index in `bones` of its parent (-1: not among them), `parents` the
    points' parents (-1 for the first bone's head)."""

    def __init__(self, bones, heads, tails, up):
        self.bones, self.heads, self.tails, self.up = bones, heads, tails, up
        self.parents = [-1] * (len(bones) + 1)
        for i in range(len(bones)):
            self.parents[tails[i]] = heads[i]

    def point_of_tail(self, name):
        for bone, tail in zip(self.bones, self.tails):
            if bone.name == name:
                return tail
        return None


def selected_chain(armature):
    """The selected bones as a chain (a tree without branches), root first. Raises BakeError."""
    return selected_tree(armature, "chain")


def _check_bone(bone):
    if not bone.length > 1e-9:
        raise BakeError(f"bone '{bone.name}' has length {bone.length:g}; every bone needs a "
                        "positive length")
    if not bone.use_inherit_rotation or bone.inherit_scale != 'FULL':
        raise BakeError(f"bone '{bone.name}' does not inherit its parent's rotation and "
                        "scale (Bone Properties > Relations); the bake needs both")


def selected_tree(armature, kind="tree"):
    """The selected bones of `armature` as a tree: one of them (the root) whose parent is not
    selected, every other connected to its selected parent (its head on the parent's tail).
    Point 0 is the root's head and point i + 1 the tail of bones[i]; bones parent first, depth
    first. Raises BakeError (`kind` names what the selection should be)."""
    if armature is None or armature.type != 'ARMATURE':
        what = "none" if armature is None else \
            f"'{armature.name}', of type {armature.type.lower()}"
        raise BakeError(f"select an armature (the active object is {what})")
    selected = [b for b in armature.data.bones if b.select]
    if not selected:
        raise BakeError(f"select the bones of a {kind} in '{armature.name}' (none is selected)")
    names = set(b.name for b in selected)
    roots = [b for b in selected if b.parent is None or b.parent.name not in names]
    if len(roots) != 1:
        raise BakeError(f"the selected bones are not one {kind}: "
                        f"{len(roots)} of them have no selected parent ("
                        + ", ".join(sorted(b.name for b in roots)) + ")")
    bones, up, stack = [], [], [(roots[0], -1)]
    while stack:
        bone, parent = stack.pop()
        bones.append(bone)
        up.append(parent)
        here = len(bones) - 1
        for child in sorted(bone.children, key=lambda c: c.name, reverse=True):
            if child.name in names:
                stack.append((child, here))
    if kind == "chain":
        for i, bone in enumerate(bones):
            children = sorted(b.name for b, u in zip(bones, up) if u == i)
            if len(children) > 1:
                raise BakeError(f"the selected bones branch at '{bone.name}' ("
                                + ", ".join(children) + "); select one chain")
    for bone, parent in zip(bones, up):
        _check_bone(bone)
        if parent >= 0 and (bone.head_local - bones[parent].tail_local).length > \
                1e-6 * max(1.0, bones[parent].length):
            raise BakeError(f"bone '{bone.name}' does not start at the tail of "
                            f"'{bones[parent].name}'; the bones must be connected")
    heads = [0 if parent < 0 else parent + 1 for parent in up]
    return Body(bones, heads, [i + 1 for i in range(len(bones))], up)


def _frames(scene):
    if scene.frame_end <= scene.frame_start:
        raise BakeError(f"the frame range {scene.frame_start}..{scene.frame_end} has no frame "
                        "after the first; set the scene's end frame after its start")
    return list(range(scene.frame_start, scene.frame_end + 1))


def gather(context, armature, body, targets):
    """Everything a bake needs from the scene, frame by frame: the armature's world matrix, the
    pose of the first bone's parent (outside the body), and each target's world position (a
    target None: the first bone's head as animated); and at the first frame the body's points
    (world and armature space) and its bones' pose rotations. Restores the current frame."""
    scene = context.scene
    frames = _frames(scene)
    objects = []
    for name in targets:
        if name is None:
            objects.append(None)
            continue
        target = bpy.data.objects.get(name) if name else None
        if target is None:
            raise BakeError(f"target '{name}' is not an object of this file; choose the object "
                            "(an Empty) whose motion drives the bone")
        objects.append(target)
    pose = armature.pose.bones
    first = body.bones[0]
    parent = first.parent
    current = scene.frame_current
    data = {"frames": frames, "world": [], "parent_pose": [], "paths": [[] for _ in targets]}
    try:
        for f in frames:
            scene.frame_set(f)
            world = armature.matrix_world.copy()
            data["world"].append(world)
            data["parent_pose"].append(pose[parent.name].matrix.copy() if parent else None)
            for k, target in enumerate(objects):
                data["paths"][k].append(target.matrix_world.translation.copy() if target
                                        else world @ pose[first.name].head)
            if f == frames[0]:
                local = [None] * (len(body.bones) + 1)
                for i, bone in enumerate(body.bones):
                    local[body.heads[i]] = pose[bone.name].head.copy()
                    local[body.tails[i]] = pose[bone.name].tail.copy()
                data["local_points"] = local
                data["points"] = [world @ p for p in local]
                data["start_rotations"] = [pose[b.name].matrix.to_quaternion()
                                           for b in body.bones]
    finally:
        scene.frame_set(current)
    return data


def gather_path(context, target_name):
    """A rope's driving path: the target object's world position at every frame of the scene's
    range (the run moves the rope's first point to the second frame's position, and so on).
    Restores the current frame."""
    scene = context.scene
    frames = _frames(scene)
    target = bpy.data.objects.get(target_name)
    if target is None:
        raise BakeError(f"target '{target_name}' is not an object of this file; choose the "
                        "object (an Empty) whose motion drives the rope's first point")
    current = scene.frame_current
    path = []
    try:
        for f in frames:
            scene.frame_set(f)
            path.append(target.matrix_world.translation.copy())
    finally:
        scene.frame_set(current)
    return {"frames": frames, "path": path}


def run_chain(flexkin, points, path, method, substeps, window_manager=None, what="chain"):
    """flexkin.run of `points` (world space), the first driven along `path` (a point per frame
    after the first), with the window manager's progress where given. Returns the frames'
    points (world space); BakeError where flexkin refuses them."""
    if window_manager is not None:
        window_manager.progress_begin(0, len(path) + 1)
    try:
        return flexkin.run([list(p) for p in points], [list(p) for p in path], method=method,
                           substeps=substeps,
                           progress=(lambda done, total: window_manager.progress_update(done))
                           if window_manager is not None else None).frames
    except flexkin.InputError as error:
        raise BakeError(f"flexkin refused the {what}: {error}") from error
    finally:
        if window_manager is not None:
            window_manager.progress_end()


def chain_frames(flexkin, data, method, substeps, window_manager=None):
    """The chain's frames (run_chain from its first-frame points along its path), every frame's
    points in the armature's space."""
    frames = run_chain(flexkin, data["points"], data["paths"][0][1:], method, substeps,
                       window_manager)
    return [[data["world"][f].inverted() @ Vector(tuple(x)) for x in frame]
            for f, frame in enumerate(frames)]


def run_flexkin_tree(flexkin, data, body, targets, method, fix_root):
    """flexkin.reach_tree of the body's points in the armature's space, the tail of each target
    bone driven along its target's path (in the armature's space at each frame), the root's head
    fixed or not. Returns the frames' points in the armature's space and the report."""
    points = [list(p) for p in data["local_points"]]
    paths = [[list(data["world"][f].inverted() @ data["paths"][k][f])
              for k in range(len(targets))] for f in range(1, len(data["frames"]))]
    frames, report = flexkin.reach_tree(points, body.parents, targets, paths,
                                        fixed=[0] if fix_root else [],
                                        method="tractrix" if method == "overall" else method,
                                        overall={"squared": 1.0} if method == "overall" else None)
    return [[Vector(tuple(x)) for x in frame] for frame in frames], report


def _aligned(rotation, direction):
    """`rotation` turned by the least rotation that takes its y axis onto `direction`."""
    y = rotation @ Vector((0.0, 1.0, 0.0))
    return (y.rotation_difference(direction.normalized()) @ rotation).normalized()


def pose_keys(armature, body, data, frames_points):
    """The pose of every bone at every frame that puts its head on its point and its tail toward
    its tail's point (`frames_points`: every frame's points in the armature's space), each bone's
    roll carried from frame to frame by the least rotation: per bone, its matrix_basis's rotation
    (quaternions) and location."""
    bones = body.bones
    rest = [b.matrix_local.copy() for b in bones]
    outside = bones[0].parent
    outside_rest = outside.matrix_local.copy() if outside else None
    rotations = list(data["start_rotations"])
    keys = {b.name: {"rotation": [], "location": []} for b in bones}
    for f in range(len(data["frames"])):
        p = frames_points[f]
        matrices = []
        for i, bone in enumerate(bones):
            head, tail = p[body.heads[i]], p[body.tails[i]]
            rotations[i] = _aligned(rotations[i], tail - head)
            matrix = Matrix.Translation(head) @ rotations[i].to_matrix().to_4x4()
            matrices.append(matrix)
            if body.up[i] >= 0:
                above, above_rest = matrices[body.up[i]], rest[body.up[i]]
            else:
                above, above_rest = data["parent_pose"][f], outside_rest
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


def write_keys(armature, body, frames, keys):
    """The keys into the armature's action (made if it has none): each bone's rotation in its
    rotation mode and the first bone's location, one key per frame, replacing the curves of
    those channels."""
    if armature.animation_data is None:
        armature.animation_data_create()
    if armature.animation_data.action is None:
        armature.animation_data.action = bpy.data.actions.new(armature.name + "Action")
    action = armature.animation_data.action
    for i, bone in enumerate(body.bones):
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


def curve_polyline(context, curve):
    """The first spline of a curve object as Blender evaluates it (its resolution, modifiers
    not applied), in world space: the points of a poly spline, or a Bezier or NURBS spline
    sampled by Blender. Raises BakeError for an object that is not a curve with a spline."""
    if curve is None or curve.type != 'CURVE':
        what = "none" if curve is None else f"'{curve.name}', of type {curve.type.lower()}"
        raise BakeError(f"select a curve object (the active object is {what})")
    if len(curve.data.splines) != 1:
        raise BakeError(f"curve '{curve.name}' has {len(curve.data.splines)} splines; a rope is "
                        "one spline")
    spline = curve.data.splines[0]
    world = curve.matrix_world
    if spline.type == 'POLY':
        points = [world @ Vector(p.co[:3]) for p in spline.points]
    else:
        # Blender's own sampling of the spline (its resolution), through a mesh of the curve
        # without its bevel: the vertices in order along it.
        depsgraph = context.evaluated_depsgraph_get()
        saved = (curve.data.bevel_depth, curve.data.extrude, curve.data.bevel_mode)
        curve.data.bevel_depth, curve.data.extrude, curve.data.bevel_mode = 0.0, 0.0, 'ROUND'
        try:
            depsgraph.update()
            evaluated = curve.evaluated_get(depsgraph)
            mesh = evaluated.to_mesh()
            points = [world @ v.co for v in mesh.vertices]
            evaluated.to_mesh_clear()
        finally:
            curve.data.bevel_depth, curve.data.extrude, curve.data.bevel_mode = saved
            depsgraph.update()
    if len(points) < 2:
        raise BakeError(f"curve '{curve.name}' has fewer than 2 points")
    return points


def resample(points, link):
    """Points along the polyline `points` whose consecutive distances are exactly `link` (the
    chain's links: each next point where the sphere of radius `link` about the last one leaves
    the polyline), from its first point; the rest shorter than a link is dropped. Raises
    BakeError where not one link fits."""
    out = [Vector(points[0])]
    segment = 0
    while True:
        center = out[-1]
        found = None
        for s in range(segment, len(points) - 1):
            a, b = Vector(points[s]), Vector(points[s + 1])
            d = b - a
            if d.length == 0.0:
                continue
            # |a + t d - center| = link for the largest t in [0, 1] (farther along the line).
            f = a - center
            qa, qb, qc = d.dot(d), 2.0 * f.dot(d), f.dot(f) - link * link
            disc = qb * qb - 4.0 * qa * qc
            if disc < 0.0:
                continue
            t = (-qb + math.sqrt(disc)) / (2.0 * qa)
            if 0.0 <= t <= 1.0 and (s > segment or t > 0.0):
                found, segment = a + t * d, s
                break
        if found is None:
            break
        # Exactly `link` from the last point (the intersection, rounded, may be off by 1e-16).
        found = center + (found - center).normalized() * link
        out.append(found)
    if len(out) < 2:
        raise BakeError(f"the curve is shorter than one link ({link:g}); choose a shorter link")
    return out


def write_rope(context, curve, frames, frames_points):
    """A poly curve object '<curve>.flexkin' (replacing an earlier one) with a point per rope
    point, each point's coordinates keyed at every frame (world space: the object at the
    origin), with the source curve's bevel and materials. Returns it."""
    name = curve.name + ".flexkin"
    old = bpy.data.objects.get(name)
    if old is not None:
        data = old.data
        bpy.data.objects.remove(old)
        if data is not None and data.users == 0:
            bpy.data.curves.remove(data)
    data = bpy.data.curves.new(name, 'CURVE')
    data.dimensions = '3D'
    for attribute in ("bevel_depth", "bevel_resolution", "resolution_u", "use_fill_caps"):
        setattr(data, attribute, getattr(curve.data, attribute))
    for material in curve.data.materials:
        data.materials.append(material)
    spline = data.splines.new('POLY')
    count = len(frames_points[0])
    spline.points.add(count - 1)
    for i, p in enumerate(frames_points[0]):
        spline.points[i].co = (p[0], p[1], p[2], 1.0)
    obj = bpy.data.objects.new(name, data)
    for collection in curve.users_collection:
        collection.objects.link(obj)
    data.animation_data_create()
    action = bpy.data.actions.new(name + "Action")
    data.animation_data.action = action
    for i in range(count):
        for k in range(3):
            _set_curve(action, f"splines[0].points[{i}].co", k, f"point {i}", frames,
                       [frame[i][k] for frame in frames_points])
    return obj
