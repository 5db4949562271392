"""The flexkin add-on's bone-chain bake in headless Blender (docs/blender.md; run by
tests/blender/addon.sh):

  blender -b --factory-startup --python tests/blender/bake_chain_check.py -- ADDON_ZIP MODULE_DIR

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
ADDON_ZIP, MODULE_DIR = argv[0], argv[1]
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


def expect_report(case, words, **kwargs):
    action = bpy.context.active_object.animation_data.action \
        if bpy.context.active_object and bpy.context.active_object.animation_data else None
    before = len(action.fcurves) if action else 0
    try:
        bake(**kwargs)
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
    bad_inputs()
    timing()
except SystemExit:
    raise
except BaseException:
    traceback.print_exc()
    fail("an exception")
print("ok", flush=True)
os._exit(0)
