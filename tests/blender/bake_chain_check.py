"""The flexkin add-on's bakes of bone chains and trees in headless Blender (docs/blender.md; run by
tests/blender/addon.sh):

  blender -b --factory-startup --python tests/blender/bake_chain_check.py -- ADDON_ZIP MODULE_DIR \
      SOURCE_DIR OUT_DIR

installs the add-on from its zip and enables it, builds scenes of armatures and driving objects,
runs the bake operator, and checks frame by frame that every baked bone's head and tail (read back
from Blender's evaluated pose) lie on flexkin's own points for the same chain and path, computed
here by flexkin.run from the scene's numbers written below (not read back from the add-on), to
1e-6 of the scene's size. Then the bad selections and inputs get their reports and leave the
scene unchanged. Prints one line per case; exits 1 on the first failure."""
import math
import os
import sys
import time
import traceback

import bpy
from mathutils import Matrix, Vector

argv = sys.argv[sys.argv.index("--") + 1:]
ADDON_ZIP, MODULE_DIR, SOURCE_DIR, OUT_DIR = argv[0], argv[1], argv[2], argv[3]
sys.path.insert(0, MODULE_DIR)
import flexkin  # noqa: E402  (the module the add-on finds on the same path)

TOLERANCE = 1e-6  # of the scene's size


def fail(message):
    print("FAIL: " + message, flush=True)
    os._exit(1)


def new_scene(frames):
    """The scene emptied (the add-on stays enabled) with the frame range 1..frames."""
    if bpy.context.object and bpy.context.object.mode != 'OBJECT':
        bpy.ops.object.mode_set(mode='OBJECT')
    for collection in (bpy.data.objects, bpy.data.armatures, bpy.data.actions):
        for item in list(collection):
            collection.remove(item)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, frames
    scene.frame_set(1)
    return scene


def make_chain(name, bones, length, location, rotation_z, parent_bone=False):
    """An armature of `bones` connected bones along +z, each `length` long; with parent_bone, a
    'hips' bone below them (along -x) that is the first chain bone's parent."""
    data = bpy.data.armatures.new(name)
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    obj.location = location
    obj.rotation_euler = (0.0, 0.0, rotation_z)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode='EDIT')
    previous = None
    if parent_bone:
        hips = data.edit_bones.new("hips")
        hips.head, hips.tail = (0.3, 0.0, 0.0), (0.0, 0.0, 0.0)
        previous = hips
    for i in range(bones):
        b = data.edit_bones.new(f"b{i:02d}")
        b.head, b.tail = (0.0, 0.0, i * length), (0.0, 0.0, (i + 1) * length)
        if previous is not None:
            b.parent = previous
            b.use_connect = previous.name != "hips"
        previous = b
    bpy.ops.object.mode_set(mode='OBJECT')
    for b in data.bones:
        b.select = b.name.startswith("b")
    return obj


def empty_on_path(name, path):
    """An Empty keyed at every frame on `path` (a point per frame, from frame 1)."""
    obj = bpy.data.objects.new(name, None)
    bpy.context.scene.collection.objects.link(obj)
    for f, p in enumerate(path, start=1):
        obj.location = p
        obj.keyframe_insert("location", frame=f)
    return obj


def baked_points(armature, names, frame):
    bpy.context.scene.frame_set(frame)
    world = armature.matrix_world
    pose = armature.pose.bones
    points = [world @ pose[n].head for n in names]
    points.append(world @ pose[names[-1]].tail)
    return points


def within(case, what, part, worst, size):
    """Fails unless `worst` (the largest difference from flexkin's) is within TOLERANCE of the
    scene's `size`; prints the case's line."""
    if not worst <= TOLERANCE * size:
        fail(f"{case}: {part} is {worst:.3g} from flexkin's ({worst / size:.3g} of the scene, "
             f"more than {TOLERANCE:g})")
    print(f"blender {bpy.app.version_string}: {case}: {what}, largest difference of {part} from "
          f"flexkin's {worst:.3g} (scene size {size:.3g}, {worst / size:.2g} of it)", flush=True)


def compare(case, armature, names, expected, size):
    worst = 0.0
    for f in range(1, len(expected) + 1):
        got = baked_points(armature, names, f)
        for g, e in zip(got, expected[f - 1]):
            worst = max(worst, (g - Vector(tuple(e))).length)
    if not worst <= TOLERANCE * size:
        fail(f"{case}: a baked point is {worst:.3g} from flexkin's ({worst / size:.3g} of the "
             f"scene, more than {TOLERANCE:g})")
    print(f"blender {bpy.app.version_string}: {case}: {len(names)} bones x {len(expected)} frames, "
          f"largest distance of a baked head or tail from flexkin's point {worst:.3g} (scene "
          f"size {size:.3g}, {worst / size:.2g} of it)", flush=True)


def bake(**kwargs):
    return bpy.ops.flexkin.bake_chain(**kwargs)


def case_target(method):
    """A chain of 8 bones on a moved and turned armature, its first bone driven by an Empty."""
    frames, n, length = 60, 8, 0.25
    new_scene(frames)
    location, turn = Vector((1.0, 2.0, 0.5)), math.radians(30)
    arm = make_chain("Tail", n, length, location, turn)
    start = location  # the first bone's head (at the armature's origin)
    path = [start + Vector((0.6 * math.sin(0.05 * f), 0.4 * (1 - math.cos(0.05 * f)), 0.01 * f))
            for f in range(frames)]
    empty_on_path("Driver", path)
    rotation = Matrix.Rotation(turn, 3, 'Z')
    points = [location + rotation @ Vector((0, 0, i * length)) for i in range(n + 1)]
    if bake(method=method, target="Driver") != {'FINISHED'}:
        fail(f"target/{method}: the bake did not finish")
    expected = flexkin.run([list(p) for p in points], [list(p) for p in path[1:]],
                           method=method).frames
    compare(f"target, {method}", arm, [f"b{i:02d}" for i in range(n)], expected,
            n * length + 1.0)
    return arm


def case_fixed_base():
    """The fixed-base mode: the chain's root held, its tip on an Empty (flexkin.reach_tree of
    the chain with point 0 fixed and its last point the target), in the armature's space."""
    frames, n, length = 50, 8, 0.25
    new_scene(frames)
    location, turn = Vector((0.3, 0.0, 0.2)), math.radians(-25)
    arm = make_chain("Arm", n, length, location, turn)
    to_world = Matrix.Translation(location) @ Matrix.Rotation(turn, 4, 'Z')
    tip = Vector((0.0, 0.0, n * length))
    local = [tip + Vector((0.5 * math.sin(0.05 * f), 0.3 * (1 - math.cos(0.05 * f)),
                           -0.4 * math.sin(0.03 * f))) for f in range(frames)]
    empty_on_path("Goal", [to_world @ p for p in local])
    bpy.context.view_layer.objects.active = arm
    if bpy.ops.flexkin.bake_chain(method="tractrix", target="Goal", fixed_base=True) \
            != {'FINISHED'}:
        fail("fixed base: the bake did not finish")
    points = [(0.0, 0.0, i * length) for i in range(n + 1)]
    expected, report = flexkin.reach_tree(points, [-1] + list(range(n)), [n],
                                          [[list(p)] for p in local[1:]], fixed=[0])
    if not report["reached"].all():
        fail("fixed base: flexkin did not reach the test's targets")
    world = [[to_world @ Vector(tuple(p)) for p in frame] for frame in expected]
    compare("fixed base, tractrix", arm, [f"b{i:02d}" for i in range(n)], world, n * length + 1.0)
    expect_report("fixed base without target", "the fixed-base mode drives the chain's tip",
                  fixed_base=True)


def case_parent_animation():
    """A chain hanging from an animated 'hips' bone, its first bone driven by its own head (the
    hips turning), some bones in Euler modes: the keys are in each bone's rotation mode."""
    frames, n, length = 40, 6, 0.2
    new_scene(frames)
    arm = make_chain("Creature", n, length, Vector((0, 0, 0)), 0.0, parent_bone=True)
    pose = arm.pose.bones
    pose["b01"].rotation_mode = 'XYZ'
    pose["b03"].rotation_mode = 'ZXY'
    pose["b04"].rotation_mode = 'AXIS_ANGLE'
    hips = pose["hips"]
    hips.rotation_mode = 'XYZ'
    for f in range(1, frames + 1):
        hips.rotation_euler = (0.0, 0.3 * math.sin(0.15 * f), 0.4 * math.sin(0.1 * f))
        hips.keyframe_insert("rotation_euler", frame=f)
    # The path of the first bone's head, from the hips' motion: the head sits on the hips' tail.
    bpy.context.view_layer.objects.active = arm
    path, points = [], None
    for f in range(1, frames + 1):
        bpy.context.scene.frame_set(f)
        path.append(arm.matrix_world @ pose["b00"].head)
        if f == 1:
            points = [arm.matrix_world @ pose[f"b{i:02d}"].head for i in range(n)]
            points.append(arm.matrix_world @ pose[f"b{n - 1:02d}"].tail)
    bpy.context.scene.frame_set(1)
    if bake(method="ftl") != {'FINISHED'}:
        fail("parent: the bake did not finish")
    expected = flexkin.run([list(p) for p in points], [list(p) for p in path[1:]],
                           method="ftl").frames
    compare("own animation under an animated parent, ftl, Euler and axis-angle bones", arm,
            [f"b{i:02d}" for i in range(n)], expected, n * length + 0.3)


# A body: a spine of 3 bones from the base, two arms of 3 from its top, a head. The arms start
# away from the spine's tail (shoulders offset: not connected); the other bones are connected.
BODY = [  # name, parent, head (None: the parent's tail, connected), tail
    ("spine0", None, (0.0, 0.0, 0.0), (0.0, 0.0, 0.3)),
    ("spine1", "spine0", None, (0.0, 0.0, 0.6)), ("spine2", "spine1", None, (0.0, 0.0, 0.9)),
    ("arm.L0", "spine2", (0.08, 0.0, 0.93), (0.25, 0.0, 0.95)),
    ("arm.L1", "arm.L0", None, (0.5, 0.0, 0.9)), ("arm.L2", "arm.L1", None, (0.7, 0.0, 0.95)),
    ("arm.R0", "spine2", (-0.08, 0.0, 0.93), (-0.25, 0.0, 0.95)),
    ("arm.R1", "arm.R0", None, (-0.5, 0.0, 0.9)), ("arm.R2", "arm.R1", None, (-0.7, 0.0, 0.95)),
    ("head", "spine2", None, (0.0, 0.05, 1.15)),
]


def body_points():
    """The test's own points of BODY: each bone's own head where it has one (hanging from its
    parent's tail), then its tail; with the parents, and each bone's head and tail point."""
    points, parents, head_of, tail_of = [], [], {}, {}
    for name, parent, head, tail in BODY:
        if head is not None:
            points.append(head)
            parents.append(tail_of[parent] if parent else -1)
            head_of[name] = len(points) - 1
        else:
            head_of[name] = tail_of[parent]
        points.append(tail)
        parents.append(head_of[name])
        tail_of[name] = len(points) - 1
    return points, parents, head_of, tail_of


def make_body(location, rotation_z):
    data = bpy.data.armatures.new("Body")
    obj = bpy.data.objects.new("Body", data)
    bpy.context.scene.collection.objects.link(obj)
    obj.location = location
    obj.rotation_euler = (0.0, 0.0, rotation_z)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode='EDIT')
    for name, parent, head, tail in BODY:
        b = data.edit_bones.new(name)
        b.head = data.edit_bones[parent].tail if head is None else head
        b.tail = tail
        if parent:
            b.parent = data.edit_bones[parent]
            b.use_connect = head is None
    bpy.ops.object.mode_set(mode='OBJECT')
    for b in data.bones:
        b.select = True
    return obj


def case_tree(method, look=False):
    """Two hands of a body driven by two Empties, the base fixed (flexkin.reach_tree); with
    `look`, the head bone turned to point at a third (a pointing goal)."""
    frames = 50
    new_scene(frames)
    location, turn = Vector((0.5, -0.2, 0.0)), math.radians(20)
    arm = make_body(location, turn)
    to_world = Matrix.Translation(location) @ Matrix.Rotation(turn, 4, 'Z')
    points, parents, head_of, index = body_points()
    local_paths = []
    for f in range(frames):
        t = 0.08 * f
        # From where the hands are, inward and round (within their reach).
        local_paths.append([
            (0.7 - 0.2 * (1 - math.cos(t)), 0.2 * math.sin(t), 0.95 + 0.08 * math.sin(2 * t)),
            (-0.7 + 0.15 * (1 - math.cos(t)), 0.15 * math.sin(t), 0.95 - 0.08 * math.sin(t)),
            (0.6 * math.sin(t), 0.8, 1.3 - 0.3 * math.sin(0.5 * t))])  # the ball the head watches
    names = ("Hand.L", "Hand.R", "Ball")
    for k, name in enumerate(names):
        empty_on_path(name, [to_world @ Vector(p[k]) for p in local_paths])
    scene = bpy.context.scene
    scene.flexkin_targets.clear()
    bones = ["arm.L2", "arm.R2"] + (["head"] if look else [])
    for k, bone in enumerate(bones):
        item = scene.flexkin_targets.add()
        item.bone, item.target, item.look = bone, bpy.data.objects[names[k]], bone == "head"
    bpy.context.view_layer.objects.active = arm
    if bpy.ops.flexkin.bake_tree(method=method, fix_root=True) != {'FINISHED'}:
        fail(f"tree/{method}: the bake did not finish")
    kwargs = {"overall": {"squared": 1.0}} if method == "overall" else {"method": method}
    expected, report = flexkin.reach_tree(points, parents, [index[b] for b in bones],
                                          [p[:len(bones)] for p in local_paths[1:]], fixed=[0],
                                          looks=[b == "head" for b in bones], **kwargs)
    if not report["reached"].all():
        fail(f"tree/{method}: flexkin did not reach the test's targets")
    # Compare in the world: the test's points through the armature's world matrix.
    worst, pose = 0.0, arm.pose.bones
    for f in range(1, frames + 1):
        scene.frame_set(f)
        for name, _, _, _ in BODY:
            for got, i in ((pose[name].head, head_of[name]), (pose[name].tail, index[name])):
                want = to_world @ Vector(tuple(expected[f - 1][i]))
                worst = max(worst, (arm.matrix_world @ got - want).length)
    size = 2.0
    if not worst <= TOLERANCE * size:
        fail(f"tree/{method}: a baked point is {worst:.3g} from flexkin's")
    if look:  # the baked head points at the ball (to Blender's single precision)
        gaze = 0.0
        for f in range(2, frames + 1):
            scene.frame_set(f)
            head = pose["head"]
            ball = arm.matrix_world.inverted() @ bpy.data.objects["Ball"].matrix_world.translation
            gaze = max(gaze, (head.tail - head.head).angle(ball - head.head))
        if not gaze <= 1e-5:
            fail(f"tree/{method}: the head is {gaze:.3g} rad off the ball")
        print(f"blender {bpy.app.version_string}: tree, {method}: the head's largest angle from "
              f"the ball {gaze:.2g} rad", flush=True)
    print(f"blender {bpy.app.version_string}: tree, {method}: {len(BODY)} bones x {frames} frames, "
          f"shoulders offset, two hands driven{', the head watching a ball' if look else ''}, the base fixed, "
          f"largest distance of a baked head or tail from "
          f"flexkin's point {worst:.3g} (scene size {size:.3g}, {worst / size:.2g} of it)",
          flush=True)
    return arm


def tree_reports():
    arm = case_tree("tractrix")
    scene = bpy.context.scene
    # The panel's target list: add (the active bone) and remove.
    arm.data.bones.active = arm.data.bones["arm.L1"]
    before = len(scene.flexkin_targets)
    bpy.ops.flexkin.target_add()
    if len(scene.flexkin_targets) != before + 1 or scene.flexkin_targets[-1].bone != "arm.L1":
        fail("target_add did not add the active bone")
    bpy.ops.flexkin.target_remove(index=len(scene.flexkin_targets) - 1)
    if len(scene.flexkin_targets) != before:
        fail("target_remove did not remove the target")
    print("operators: target_add and target_remove keep the panel's list", flush=True)
    scene.flexkin_targets[0].bone = "nope"
    expect_report("tree target not selected", "bone 'nope' is not among the selected bones",
                  operator=bpy.ops.flexkin.bake_tree)
    scene.flexkin_targets.clear()
    expect_report("tree without targets", "the tree has no target", operator=bpy.ops.flexkin.bake_tree)
    bpy.context.view_layer.objects.active = arm
    for b in arm.data.bones:
        b.select = b.name in ("spine0", "arm.L1")
    expect_report("tree in pieces", "not one tree", operator=bpy.ops.flexkin.bake_tree)


def rope_points(rope, frame):
    """The baked rope's points at `frame`, from Blender's evaluated curve (world space)."""
    bpy.context.scene.frame_set(frame)
    evaluated = rope.evaluated_get(bpy.context.evaluated_depsgraph_get())
    return [rope.matrix_world @ Vector(p.co[:3]) for p in evaluated.data.splines[0].points]


def make_curve(name, kind, points, location):
    data = bpy.data.curves.new(name, 'CURVE')
    data.dimensions = '3D'
    data.bevel_depth = 0.01
    spline = data.splines.new(kind)
    if kind == 'POLY':
        spline.points.add(len(points) - 1)
        for p, co in zip(spline.points, points):
            p.co = (co[0], co[1], co[2], 1.0)
    else:  # a Bezier arc: its two ends and their handles
        spline.bezier_points.add(1)
        (a, ha), (b, hb) = points
        spline.bezier_points[0].co, spline.bezier_points[0].handle_right = a, ha
        spline.bezier_points[0].handle_left = 2 * Vector(a) - Vector(ha)
        spline.bezier_points[1].co, spline.bezier_points[1].handle_left = b, hb
        spline.bezier_points[1].handle_right = 2 * Vector(b) - Vector(hb)
        spline.resolution_u = 64
    obj = bpy.data.objects.new(name, data)
    obj.location = location
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    return obj


def case_rope_poly():
    """A straight poly rope of 10 links of 0.1 on a moved object, its first point on an Empty:
    the baked points against flexkin.run of the test's own points."""
    frames, n, link = 60, 10, 0.1
    new_scene(frames)
    location = Vector((0.0, 1.0, 0.5))
    make_curve("Rope", 'POLY', [(i * link, 0.0, 0.0) for i in range(n + 1)], location)
    path = [location + Vector((-0.3 * math.sin(0.06 * f), 0.4 * (1 - math.cos(0.06 * f)), 0.0))
            for f in range(frames)]
    empty_on_path("Anchor", path)
    bpy.context.view_layer.objects.active = bpy.data.objects["Rope"]
    if bpy.ops.flexkin.bake_rope(method="tractrix", target="Anchor", link_length=link) \
            != {'FINISHED'}:
        fail("rope: the bake did not finish")
    points = [location + Vector((i * link, 0.0, 0.0)) for i in range(n + 1)]
    expected = flexkin.run([list(p) for p in points], [list(p) for p in path[1:]]).frames
    rope = bpy.data.objects["Rope.flexkin"]
    worst = 0.0
    for f in range(1, frames + 1):
        for got, want in zip(rope_points(rope, f), expected[f - 1]):
            worst = max(worst, (got - Vector(tuple(want))).length)
    within("rope, poly", f"{n} links x {frames} frames", "a baked point", worst, 2.0)


def case_rope_bezier():
    """A Bezier arc resampled to links of 0.05: at the first frame every point on the curve as
    Blender samples it, at every frame every link 0.05 long and the first point on the Empty,
    and the frames those of flexkin.run from the rope's first frame."""
    frames, link = 40, 0.05
    new_scene(frames)
    curve = make_curve("Arc", 'BEZIER', [((0, 0, 0), (0.3, 0.0, 0.3)), ((1, 0, 0), (0.7, 0.0, 0.3))],
                       Vector((0, 0, 0)))
    path = [Vector((0.2 * math.sin(0.1 * f), 0.0, -0.3 * math.sin(0.05 * f))) for f in range(frames)]
    empty_on_path("Hand", path)
    bpy.context.view_layer.objects.active = curve
    if bpy.ops.flexkin.bake_rope(method="ftl", target="Hand", link_length=link) != {'FINISHED'}:
        fail("bezier rope: the bake did not finish")
    rope = bpy.data.objects["Arc.flexkin"]
    first = rope_points(rope, 1)
    # On the arc: within 2e-4 of the cubic Bezier (dense sampling): the rope follows the
    # polyline Blender samples the arc with (resolution 64: its chords are 0.019 long and sag
    # up to 1e-4 from the arc).
    a, b, c, d = (Vector((0, 0, 0)), Vector((0.3, 0, 0.3)), Vector((0.7, 0, 0.3)),
                  Vector((1, 0, 0)))
    dense = [(1 - t) ** 3 * a + 3 * (1 - t) ** 2 * t * b + 3 * (1 - t) * t * t * c + t ** 3 * d
             for t in (k / 20000 for k in range(20001))]
    off = max(min((p - q).length for q in dense) for p in first)
    if not off <= 2e-4:
        fail(f"bezier rope: a first-frame point is {off:.3g} off the arc")
    expected = flexkin.run([list(p) for p in first], [list(p) for p in path[1:]],
                           method="ftl").frames
    worst = worst_link = 0.0
    for f in range(1, frames + 1):
        got = rope_points(rope, f)
        worst_link = max(worst_link, max(abs((q - p).length - link) for p, q in zip(got, got[1:])))
        for g, want in zip(got, expected[f - 1]):
            worst = max(worst, (g - Vector(tuple(want))).length)
    if not (worst <= TOLERANCE and worst_link <= TOLERANCE):
        fail(f"bezier rope: {worst:.3g} from flexkin's, links off by {worst_link:.3g}")
    print(f"blender {bpy.app.version_string}: rope, Bezier arc: {len(first) - 1} links of {link} "
          f"x {frames} frames, first frame within {off:.2g} of the arc, links within "
          f"{worst_link:.2g} of their length, largest distance from flexkin's {worst:.3g}",
          flush=True)


def rope_reports():
    case_rope_poly()
    expect_report("rope without target", "the rope has no target",
                  operator=bpy.ops.flexkin.bake_rope)
    expect_report("rope link too long", "shorter than one link",
                  operator=bpy.ops.flexkin.bake_rope, target="Anchor", link_length=5.0)
    bpy.context.view_layer.objects.active = bpy.data.objects["Anchor"]
    expect_report("rope not a curve", "select a curve object", operator=bpy.ops.flexkin.bake_rope,
                  target="Anchor")


def make_hair(name, strands):
    """A hair curves object of `strands` (lists of points), made as Blender users make one from
    a curve (Object > Convert > Curves)."""
    data = bpy.data.curves.new(name, 'CURVE')
    data.dimensions = '3D'
    for strand in strands:
        spline = data.splines.new('POLY')
        spline.points.add(len(strand) - 1)
        for p, co in zip(spline.points, strand):
            p.co = (co[0], co[1], co[2], 1.0)
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    bpy.ops.object.convert(target='CURVES')
    return bpy.context.active_object


def scalp(count, points, link, radius=0.1):
    """Strands straight out of a sphere's upper half (a Fibonacci spiral of roots)."""
    out = []
    for i in range(count):
        z = 1.0 - (i + 0.5) / count  # upper half
        r, a = math.sqrt(max(0.0, 1.0 - z * z)), i * math.pi * (3.0 - math.sqrt(5.0))
        n = Vector((r * math.cos(a), r * math.sin(a), z))
        out.append([tuple(radius * n + k * link * n) for k in range(points)])
    return out


def head_motion(f):
    """The head's location and XYZ Euler angles at frame f (1-based): turning, nodding and
    moving sideways."""
    return (0.1 * math.sin(0.05 * f), 0.0, 0.0), (0.3 * math.sin(0.07 * f), 0.0,
                                                  0.5 * math.sin(0.1 * f))


def head_pose(f):
    """The head's pose at frame f as a 4 by 4 numpy matrix in double precision (an XYZ Euler
    rotation is Rz Ry Rx)."""
    import numpy as np
    (tx, ty, tz), (x, y, z) = head_motion(f)
    rx = np.array([[1, 0, 0], [0, math.cos(x), -math.sin(x)], [0, math.sin(x), math.cos(x)]])
    ry = np.array([[math.cos(y), 0, math.sin(y)], [0, 1, 0], [-math.sin(y), 0, math.cos(y)]])
    rz = np.array([[math.cos(z), -math.sin(z), 0], [math.sin(z), math.cos(z), 0], [0, 0, 1]])
    pose = np.eye(4)
    pose[:3, :3] = rz @ ry @ rx
    pose[:3, 3] = (tx, ty, tz)
    return pose


def case_hair(out_dir):
    """Strands on a head that turns, nods and moves (their object parented to an animated
    Empty): the strand mesh at every frame against flexkin.run_strands of the test's own strands
    and head poses."""
    frames, count, points, link = 40, 60, 6, 0.02
    new_scene(frames)
    head = bpy.data.objects.new("Head", None)
    bpy.context.scene.collection.objects.link(head)
    head.rotation_mode = 'XYZ'
    for f in range(1, frames + 1):
        head.location, head.rotation_euler = head_motion(f)
        head.keyframe_insert("location", frame=f)
        head.keyframe_insert("rotation_euler", frame=f)
    strands = scalp(count, points, link)
    hair = make_hair("Hair", strands)
    hair.parent = head
    bpy.context.scene.frame_set(1)
    bpy.context.view_layer.objects.active = hair
    cache = os.path.join(out_dir, "hair.flexkin.npz")
    if bpy.ops.flexkin.bake_hair(method="tractrix", cache=cache) != {'FINISHED'}:
        fail("hair: the bake did not finish")
    import numpy as np
    rest = head_pose(1)
    at_rest = np.array([[rest[:3, :3] @ np.array(p) + rest[:3, 3] for p in strand]
                        for strand in strands])
    poses = np.array([head_pose(f) for f in range(2, frames + 1)])
    expected = flexkin.run_strands(at_rest, poses, rest=rest)
    mesh = bpy.data.objects["Hair.flexkin"]
    worst = 0.0
    for f in range(1, frames + 1):
        bpy.context.scene.frame_set(f)
        got = np.array([tuple(v.co) for v in mesh.data.vertices])
        worst = max(worst, float(np.abs(got - expected[f - 1].reshape(-1, 3)).max()))
    within("hair", f"{count} strands of {points - 1} links x {frames} frames on a moving head",
           "a strand point's coordinate", worst, 0.4)


def case_import(source_dir, out_dir):
    """A strand file written by flexkin (run_groom of examples/groom_grass_2d.json): imported, its
    mesh at every frame on the file's points."""
    new_scene(200)
    path = os.path.join(out_dir, "grass.npz")
    flexkin.run_groom(os.path.join(source_dir, "examples", "groom_grass_2d.json"), path)
    if bpy.ops.flexkin.import_strands(filepath=path) != {'FINISHED'}:
        fail("import: did not finish")
    worst, frames, strands = plays_strand_file(bpy.data.objects["grass"], path)
    if not worst <= 1e-6:
        fail(f"import: a vertex is {worst:.3g} from the file's point")
    print(f"blender {bpy.app.version_string}: import: {strands} strands x {frames} frames of a "
          f"strand file from flexkin.run_groom, largest difference {worst:.3g}", flush=True)


def plays_strand_file(mesh, path):
    """The largest difference of the strand mesh's vertices, at the scene frame of each record
    of the 2D strand file at `path` (from frame 1), from its points (z from 0); the records and
    strands."""
    import numpy as np
    with np.load(path) as archive:
        points, frames, offsets = archive["points"], archive["frames"], archive["offsets"]
    worst = 0.0
    for k, step in enumerate(frames):
        bpy.context.scene.frame_set(1 + int(step))
        got = np.array([tuple(v.co) for v in mesh.data.vertices])
        worst = max(worst, float(np.abs(got[:, :2] - points[k]).max()),
                    float(np.abs(got[:, 2]).max()))
    return worst, len(frames), len(offsets) - 1


def case_groom(source_dir, out_dir):
    """A groom file run inside Blender (bpy.ops.flexkin.run_groom): its mesh at every frame on
    the points of the strand file that flexkin.run_groom writes for the same groom here."""
    new_scene(200)
    groom = os.path.join(source_dir, "examples", "groom_grass_2d.json")
    cache = os.path.join(out_dir, "grass_blender.npz")
    if bpy.ops.flexkin.run_groom(filepath=groom, cache=cache) != {'FINISHED'}:
        fail("groom: did not finish")
    reference = os.path.join(out_dir, "grass_reference.npz")
    flexkin.run_groom(groom, reference)
    worst, frames, _ = plays_strand_file(bpy.data.objects["groom_grass_2d"], reference)
    if not worst <= 1e-6:
        fail(f"groom: a vertex is {worst:.3g} from flexkin's point")
    print(f"blender {bpy.app.version_string}: groom file run in Blender: {frames} frames, "
          f"largest difference from flexkin.run_groom's {worst:.3g}", flush=True)
    expect_report("groom not found", "cannot run the groom", operator=bpy.ops.flexkin.run_groom,
                  filepath=os.path.join(out_dir, "missing.json"), cache=cache)


def hair_timing(out_dir):
    """The bake time of 5,000 strands of 24 links over 120 frames (the issue's figure)."""
    frames = 120
    new_scene(frames)
    head = bpy.data.objects.new("Head", None)
    bpy.context.scene.collection.objects.link(head)
    for f in range(1, frames + 1):
        head.rotation_euler = (0.3 * math.sin(0.07 * f), 0.0, 0.5 * math.sin(0.1 * f))
        head.keyframe_insert("rotation_euler", frame=f)
    hair = make_hair("Hair", scalp(5000, 25, 0.006))
    hair.parent = head
    bpy.context.view_layer.objects.active = hair
    started = time.perf_counter()
    if bpy.ops.flexkin.bake_hair(cache=os.path.join(out_dir, "hair5000.npz")) != {'FINISHED'}:
        fail("hair timing: the bake did not finish")
    seconds = time.perf_counter() - started
    size = os.path.getsize(os.path.join(out_dir, "hair5000.npz"))
    os.remove(os.path.join(out_dir, "hair5000.npz"))  # 180 MB
    print(f"timing: 5000 strands x 24 links x 120 frames baked in {seconds:.2f} s (cache "
          f"{size / 1e6:.0f} MB)", flush=True)


def expect_report(case, words, operator=None, **kwargs):
    action = bpy.context.active_object.animation_data.action \
        if bpy.context.active_object and bpy.context.active_object.animation_data else None
    before = len(action.fcurves) if action else 0
    try:
        (operator or bpy.ops.flexkin.bake_chain)(**kwargs)
    except RuntimeError as error:
        if words not in str(error):
            fail(f"{case}: the report is '{error}', without '{words}'")
        after = len(action.fcurves) if action else 0
        if after != before:
            fail(f"{case}: the refused bake changed the keys ({before} curves, now {after})")
        print(f"report: {case}: {str(error).strip()}", flush=True)
        return
    fail(f"{case}: the bake was not refused")


def bad_inputs():
    arm = case_target("tractrix")
    expect_report("missing target", "target 'Nope' is not an object", target="Nope")
    # A branch: a second child of b03 selected too.
    bpy.context.view_layer.objects.active = arm
    bpy.ops.object.mode_set(mode='EDIT')
    side = arm.data.edit_bones.new("side")
    side.head, side.tail = arm.data.edit_bones["b03"].tail, (0.3, 0.0, 1.0)
    side.parent = arm.data.edit_bones["b03"]
    side.use_connect = True
    bpy.ops.object.mode_set(mode='OBJECT')
    arm.data.bones["side"].select = True
    expect_report("a branch", "branch at 'b03'")
    arm.data.bones["side"].select = False
    for b in arm.data.bones:
        b.select = False
    expect_report("nothing selected", "none is selected")
    for b in arm.data.bones:
        b.select = b.name in ("b01", "b04")
    expect_report("two pieces", "not one chain")
    for b in arm.data.bones:
        b.select = b.name.startswith("b")
    # The module missing: the report says how to install it.
    saved = sys.modules.pop("flexkin")
    sys.modules["flexkin"] = None  # import flexkin raises ImportError
    expect_report("module not found", "flexkin's Python module was not found")
    sys.modules["flexkin"] = saved
    # Not on Python's path, but in the add-on's preferences: found there.
    sys.modules.pop("flexkin")
    for name in [m for m in sys.modules if m.startswith("flexkin.")]:
        sys.modules.pop(name)
    sys.path.remove(MODULE_DIR)
    bpy.context.preferences.addons["flexkin_blender"].preferences.module_path = MODULE_DIR
    if bake(method="tractrix", target="Driver") != {'FINISHED'}:
        fail("the module in the preferences' folder: the bake did not finish")
    if MODULE_DIR not in sys.path:
        fail("the preferences' folder was not put on Python's path")
    print("report: module found in the preferences' folder", flush=True)
    empty = bpy.data.objects["Driver"]
    bpy.context.view_layer.objects.active = empty
    expect_report("not an armature", "select an armature")


def timing():
    """The bake time of a 64-bone tail over 250 frames (the issue's figure)."""
    frames, n, length = 250, 64, 0.05
    new_scene(frames)
    arm = make_chain("LongTail", n, length, Vector((0, 0, 0)), 0.0)
    path = [Vector((0.5 * math.sin(0.04 * f), 0.3 * math.sin(0.07 * f), 0.0))
            for f in range(frames)]
    empty_on_path("Driver", path)
    bpy.context.view_layer.objects.active = arm
    started = time.perf_counter()
    if bake(method="tractrix", target="Driver") != {'FINISHED'}:
        fail("timing: the bake did not finish")
    seconds = time.perf_counter() - started
    points = [Vector((0, 0, i * length)) for i in range(n + 1)]
    expected = flexkin.run([list(p) for p in points], [list(p) for p in path[1:]]).frames
    compare("64-bone tail, 250 frames", arm, [f"b{i:02d}" for i in range(n)], expected,
            n * length + 1.0)
    print(f"timing: 64 bones x 250 frames baked in {seconds:.3f} s", flush=True)


try:
    bpy.ops.preferences.addon_install(filepath=ADDON_ZIP, overwrite=True)
    bpy.ops.preferences.addon_enable(module="flexkin_blender")
    if not hasattr(bpy.ops.flexkin, "bake_chain"):
        fail("the add-on's operator is not registered")
    for method in ("tractrix", "ftl", "overall"):
        case_target(method)
    case_parent_animation()
    case_fixed_base()
    case_tree("tractrix", look=True)
    case_tree("overall")
    bad_inputs()
    tree_reports()
    case_rope_bezier()
    rope_reports()
    case_hair(OUT_DIR)
    bpy.context.view_layer.objects.active = bpy.data.objects["Head"]
    expect_report("hair not a curves object", "select a hair curves object",
                  operator=bpy.ops.flexkin.bake_hair)
    case_import(SOURCE_DIR, OUT_DIR)
    case_groom(SOURCE_DIR, OUT_DIR)
    hair_timing(OUT_DIR)
    timing()
except SystemExit:
    raise
except BaseException:
    traceback.print_exc()
    fail("an exception")
print("ok", flush=True)
os._exit(0)
