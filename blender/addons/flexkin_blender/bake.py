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
    points' parents (-1 for the first bone's head). A bone connected to its parent starts on the
    parent's tail point; one that is not (or the first) has a head point of its own, hanging from
    the parent's tail point by a link of the offset's length."""

    def __init__(self, bones, heads, tails, up, parents):
        self.bones, self.heads, self.tails, self.up = bones, heads, tails, up
        self.parents = parents

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
    """The selected bones of `armature` as a tree (Body): one of them (the root) whose parent is
    not selected, every other below it; bones parent first, depth first, point 0 the root's
    head. Raises BakeError (`kind` names what the selection should be)."""
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
    heads, tails, parents = [], [], []
    for bone, parent in zip(bones, up):
        _check_bone(bone)
        if parent < 0 or not bone.use_connect:
            if parent >= 0 and not (bone.head_local - bones[parent].tail_local).length > 1e-6 * \
                    max(1.0, bones[parent].length):
                raise BakeError(f"bone '{bone.name}' starts on the tail of "
                                f"'{bones[parent].name}' without being connected to it; connect "
                                "it (Bone Properties > Relations > Connected)")
            parents.append(-1 if parent < 0 else tails[parent])  # a head point of its own
            heads.append(len(parents) - 1)
        else:
            heads.append(tails[parent])
        parents.append(heads[-1])
        tails.append(len(parents) - 1)
    return Body(bones, heads, tails, up, parents)


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
                local = [None] * len(body.parents)
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
    range (the run moves the rope's first point to the second frame's position, and so on)."""
    target = bpy.data.objects.get(target_name)
    if target is None:
        raise BakeError(f"target '{target_name}' is not an object of this file; choose the "
                        "object (an Empty) whose motion drives the rope's first point")
    frames, poses = gather_poses(context, target)
    return {"frames": frames, "path": [pose[:3, 3] for pose in poses]}


CHUNK = 16  # frames a piece of a bake's run, between which a bake from the interface may stop


def chain_steps(flexkin, points, path, method, substeps, what="chain"):
    """flexkin.run of `points` (world space), the first driven along `path` (a point per frame
    after the first), in pieces of CHUNK frames, each from where the last ended: a generator
    that yields (frames done, frames) after each piece and returns every frame's points."""
    frames = [[list(p) for p in points]]
    total = len(path) + 1
    for start in range(0, len(path), CHUNK):
        try:
            piece = flexkin.run(frames[-1], [list(p) for p in path[start:start + CHUNK]],
                                method=method, substeps=substeps).frames
        except flexkin.InputError as error:
            raise BakeError(f"flexkin refused the {what}: {error}") from error
        frames += [list(map(list, frame)) for frame in piece[1:]]
        yield len(frames), total
    return frames


def in_armature(data, frames):
    """Every frame's world points in the armature's space at that frame."""
    return [[data["world"][f].inverted() @ Vector(tuple(x)) for x in frame]
            for f, frame in enumerate(frames)]


def tree_steps(flexkin, data, body, targets, method, fix_root, looks=None):
    """flexkin.reach_tree of the body's points in the armature's space, the tail of each target
    bone driven along its target's path (in the armature's space at each frame), or with
    looks[k] the bone turned to point at it, the root's head fixed or not, in pieces of CHUNK
    frames, each from where the last ended: a generator that yields (frames done, frames) and
    returns the frames' points in the armature's space and the frames after the first that did
    not reach their targets."""
    frames = [list(map(list, data["local_points"]))]
    paths = [[list(data["world"][f].inverted() @ data["paths"][k][f])
              for k in range(len(targets))] for f in range(1, len(data["frames"]))]
    missed = 0
    for start in range(0, len(paths), CHUNK):
        try:
            piece, report = flexkin.reach_tree(
                frames[-1], body.parents, targets, paths[start:start + CHUNK],
                fixed=[0] if fix_root else [],
                method="tractrix" if method == "overall" else method,
                overall={"squared": 1.0} if method == "overall" else None,
                looks=looks if looks is not None else [False] * len(targets))
        except flexkin.InputError as error:
            raise BakeError(f"flexkin refused the tree: {error}") from error
        frames += [list(map(list, frame)) for frame in piece[1:]]
        missed += int((~report["reached"]).sum())
        yield len(frames), len(data["frames"])
    return [[Vector(tuple(x)) for x in frame] for frame in frames], missed


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
        if i == 0 or not bone.use_connect:  # a head that moves relative to its parent
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


def _remove_object(name, datablocks):
    """An earlier bake's object of the name, and its data where nothing else uses it."""
    old = bpy.data.objects.get(name)
    if old is not None:
        data = old.data
        bpy.data.objects.remove(old)
        if data is not None and data.users == 0:
            datablocks.remove(data)


def write_rope(context, curve, frames, frames_points):
    """A poly curve object '<curve>.flexkin' (replacing an earlier one) with a point per rope
    point, each point's coordinates keyed at every frame (world space: the object at the
    origin), with the source curve's bevel and materials. Returns it."""
    name = curve.name + ".flexkin"
    _remove_object(name, bpy.data.curves)
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


# Hair: strands of a hair curves object moved with its object (the head) by flexkin's strand
# engine, written to a cache of every frame's points that a mesh of the strands plays back.

def hair_strands(hair):
    """The strands of a hair curves object at the current frame, in world space: (P, 3) points
    and (S+1,) offsets (strand i is rows offsets[i] to offsets[i+1]-1, its root first)."""
    import numpy as np
    if hair is None or hair.type != 'CURVES':
        what = "none" if hair is None else f"'{hair.name}', of type {hair.type.lower()}"
        raise BakeError(f"select a hair curves object (the active object is {what})")
    data = hair.data
    if len(data.curves) == 0:
        raise BakeError(f"hair '{hair.name}' has no strands")
    local = np.empty(len(data.points) * 3, dtype=np.float32)
    data.position_data.foreach_get("vector", local)
    offsets = np.array([c.first_point_index for c in data.curves] + [len(data.points)],
                       dtype=np.int64)
    short = np.nonzero(np.diff(offsets) < 2)[0]
    if len(short):
        raise BakeError(f"strand {int(short[0])} of '{hair.name}' has fewer than 2 points; "
                        "every strand needs a link")
    world = np.array(hair.matrix_world, dtype=np.float64)
    local = local.reshape(-1, 3).astype(np.float64)
    points = local @ world[:3, :3].T + world[:3, 3]
    return points, offsets


def gather_poses(context, obj):
    """The scene's frame range and the object's world matrix (4 by 4, numpy) at every frame of it.
    Restores the current frame."""
    import numpy as np
    scene = context.scene
    frames = _frames(scene)
    current = scene.frame_current
    poses = []
    try:
        for f in frames:
            scene.frame_set(f)
            poses.append(np.array(obj.matrix_world, dtype=np.float64))
    finally:
        scene.frame_set(current)
    return frames, poses


def rigid_poses(name, frames, poses):
    """The poses as rotations and translations in double precision: Blender's matrices are single
    precision (their rotations orthonormal to about 1e-7), so each is taken to its nearest
    rotation. Raises BakeError for a scaled or sheared pose (the strands move rigidly)."""
    import numpy as np
    out = []
    for f, pose in zip(frames, poses):
        u, singular, vt = np.linalg.svd(pose[:3, :3])
        if np.abs(singular - 1.0).max() > 1e-5 or np.linalg.det(pose[:3, :3]) <= 0.0:
            raise BakeError(f"'{name}' is scaled at frame {f} (scale "
                            + ", ".join(f"{x:.6g}" for x in singular)
                            + "); strands move rigidly with their object: apply its scale "
                            "(and its parents') or keep it 1")
        rigid = np.eye(4)
        rigid[:3, :3] = u @ vt
        rigid[:3, 3] = pose[:3, 3]
        out.append(rigid)
    return out


def hair_steps(flexkin, points, offsets, poses, method, substeps):
    """The strand engine (flexkin.StrandBatch) on the strands given at the first pose, their
    roots pinned to the body, the body at each later pose, as a generator: it yields (frames
    done, frames) after each frame, and returns the (F, P, 3) float32 points (StopIteration's
    value), so that a caller may stop between frames (a cancelled bake) with nothing written."""
    import numpy as np
    strands = [points[offsets[i]:offsets[i + 1]] for i in range(len(offsets) - 1)]
    out = np.empty((len(poses), len(points), 3), dtype=np.float32)
    out[0] = points
    try:
        batch = flexkin.StrandBatch(strands, method=method, substeps=substeps, pinned=1,
                                    rest=poses[0])
        for f in range(1, len(poses)):
            batch.step(poses[f])
            out[f] = np.concatenate(batch.points())
            yield f + 1, len(poses)
    except flexkin.InputError as error:
        raise BakeError(f"flexkin refused the strands: {error}") from error
    return out


def run_steps(steps, window_manager=None):
    """A generator of (done, total) steps run to its end, with the window manager's progress;
    returns its value."""
    started = False
    try:
        while True:
            done, total = next(steps)
            if window_manager is not None:
                if not started:
                    window_manager.progress_begin(0, total)
                    started = True
                window_manager.progress_update(done)
    except StopIteration as end:
        return end.value
    finally:
        if started:
            window_manager.progress_end()


def write_strand_cache(path, points, offsets, frames):
    """The cache: an .npz whose points (F, P, 3), offsets (S+1,) and frames (F,) members are laid
    out as in flexkin's strand files (docs/strands.md), written whole (to a temporary file
    renamed over `path`)."""
    import os
    import numpy as np
    temporary = path + ".part.npz"
    try:
        np.savez(temporary, points=points, offsets=offsets, frames=np.asarray(frames, np.int64))
        os.replace(temporary, path)
    except OSError as error:
        if os.path.exists(temporary):
            os.remove(temporary)
        raise BakeError(f"cannot write the strand cache '{path}': {error.strerror}") from error


_CACHES = {}  # absolute path -> (modification time, points, frames)


def read_strand_cache(path):
    """points (F, P, 3), offsets and frames of a strand cache or a strand file, cached by its
    modification time. Raises BakeError for a file that is not one."""
    import os
    import numpy as np
    try:
        stamp = os.path.getmtime(path)
    except OSError as error:
        raise BakeError(f"cannot read '{path}': {error.strerror}") from error
    cached = _CACHES.get(path)
    if cached is not None and cached[0] == stamp:
        return cached[1:]
    try:
        with np.load(path) as archive:
            points = np.asarray(archive["points"], dtype=np.float32)
            offsets = np.asarray(archive["offsets"], dtype=np.int64)
            frames = np.asarray(archive["frames"], dtype=np.int64)
    except (OSError, KeyError, ValueError) as error:
        raise BakeError(f"'{path}' is not a strand file (points, offsets and frames; "
                        f"docs/strands.md): {error}") from error
    if points.ndim != 3 or points.shape[2] not in (2, 3) or len(frames) != points.shape[0] or \
            len(offsets) < 2 or offsets[0] != 0 or offsets[-1] != points.shape[1] or \
            np.any(np.diff(offsets) < 1):
        raise BakeError(f"'{path}' is not a valid strand file: points {points.shape}, offsets of "
                        f"{len(offsets)}, frames of {len(frames)}")
    if points.shape[2] == 2:
        points = np.concatenate([points, np.zeros(points.shape[:2] + (1,), np.float32)], axis=2)
    _CACHES[path] = (stamp, points, offsets, frames)
    return points, offsets, frames


def strand_mesh(name, points, offsets, cache, first_frame, collection):
    """A mesh of the strands (a vertex per point, an edge per link) at the first frame, playing
    the cache back (its `flexkin_cache` and `flexkin_first_frame` properties; the add-on's frame
    handler sets its vertices). Replaces an earlier object of the name."""
    import numpy as np
    _remove_object(name, bpy.data.meshes)
    mesh = bpy.data.meshes.new(name)
    count = points.shape[1]
    linked = np.ones(count, dtype=bool)  # a point with a next point in its strand
    linked[np.asarray(offsets[1:]) - 1] = False
    starts = np.nonzero(linked)[0].astype(np.int32)
    mesh.vertices.add(count)
    mesh.vertices.foreach_set("co", points[0].ravel())
    mesh.edges.add(len(starts))
    mesh.edges.foreach_set("vertices", np.stack([starts, starts + 1], axis=1).ravel())
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    obj["flexkin_cache"] = cache
    obj["flexkin_first_frame"] = int(first_frame)
    collection.objects.link(obj)
    return obj


def play_strands(scene):
    """Every strand mesh of the scene at the scene's frame: its cache's record of the frame
    (the last recorded at or before it; the first before the cache starts)."""
    import numpy as np
    for obj in scene.objects:
        path = obj.get("flexkin_cache") if obj.type == 'MESH' else None
        if not path:
            continue
        try:
            points, _, frames = read_strand_cache(bpy.path.abspath(path))
        except BakeError:
            continue
        at = scene.frame_current - int(obj.get("flexkin_first_frame", 0))
        k = max(0, int(np.searchsorted(frames, at, side="right")) - 1)
        if len(obj.data.vertices) == points.shape[1]:
            obj.data.vertices.foreach_set("co", points[k].ravel())
            obj.data.update()
