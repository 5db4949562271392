"""The walkthrough of docs/blender.md, rendered headless by Blender itself:

    blender -b --factory-startup --python blender/examples/walkthrough.py -- MODULE_DIR OUT_DIR

builds two scenes as an artist would (a tail of 24 bones whose root an animated Empty carries,
beads on its bones to be seen; a rope hanging from an animated hand), bakes them with the
add-on's operators (from blender/, as its own folder), and renders three frames of each with
Cycles into OUT_DIR/blender_tail.png and OUT_DIR/blender_rope.png (the frames side by side).
`make demo` runs it; docs/images holds the pictures it made."""
import math
import os
import sys

import bpy
from mathutils import Vector

argv = sys.argv[sys.argv.index("--") + 1:]
MODULE_DIR, OUT_DIR = argv[0], argv[1]
sys.path.insert(0, MODULE_DIR)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "addons"))
import flexkin_blender  # noqa: E402

flexkin_blender.register()
FRAMES = (1, 45, 90)


def fresh_scene(end):
    for collection in (bpy.data.objects, bpy.data.armatures, bpy.data.actions, bpy.data.meshes,
                       bpy.data.curves):
        for item in list(collection):
            collection.remove(item)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, end
    scene.frame_set(1)
    scene.render.engine = 'CYCLES'
    scene.cycles.device = 'CPU'
    scene.cycles.samples = 16
    scene.cycles.use_denoising = False
    scene.render.resolution_x, scene.render.resolution_y = 420, 320
    scene.render.film_transparent = False
    world = bpy.data.worlds.get("World") or bpy.data.worlds.new("World")
    scene.world = world
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.8, 0.8, 0.82, 1.0)
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    scene.camera = camera
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", 'SUN'))
    sun.data.energy = 3.0
    sun.rotation_euler = (0.6, 0.2, 0.8)
    scene.collection.objects.link(sun)
    return scene, camera


def material(name, color):
    m = bpy.data.materials.get(name) or bpy.data.materials.new(name)
    m.diffuse_color = color + (1.0,)
    m.use_nodes = True
    m.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = color + (1.0,)
    return m


def look(camera, location, target):
    camera.location = location
    camera.rotation_euler = (Vector(target) - Vector(location)).to_track_quat('-Z', 'Y').to_euler()


def render_row(scene, name):
    """The scene at FRAMES, rendered and put side by side into OUT_DIR/name."""
    import numpy as np
    tiles = []
    for f in FRAMES:
        scene.frame_set(f)
        path = os.path.join(OUT_DIR, f"{name}_{f}.png")
        scene.render.filepath = path
        bpy.ops.render.render(write_still=True)
        image = bpy.data.images.load(path)
        pixels = np.empty(image.size[0] * image.size[1] * 4, dtype=np.float32)
        image.pixels.foreach_get(pixels)
        tiles.append(pixels.reshape(image.size[1], image.size[0], 4))
        bpy.data.images.remove(image)
        os.remove(path)
    row = np.concatenate(tiles, axis=1)
    out = bpy.data.images.new(name, row.shape[1], row.shape[0])
    out.pixels.foreach_set(row.ravel())
    out.filepath_raw = os.path.join(OUT_DIR, name + ".png")
    out.file_format = 'PNG'
    out.save()
    print(f"wrote {out.filepath_raw}", flush=True)


def tail():
    scene, camera = fresh_scene(90)
    data = bpy.data.armatures.new("Tail")
    arm = bpy.data.objects.new("Tail", data)
    scene.collection.objects.link(arm)
    bpy.context.view_layer.objects.active = arm
    bpy.ops.object.mode_set(mode='EDIT')
    previous = None
    for i in range(24):
        b = data.edit_bones.new(f"tail{i:02d}")
        b.head, b.tail = (0.0, -0.08 * i, 1.0), (0.0, -0.08 * (i + 1), 1.0)
        if previous is not None:
            b.parent, b.use_connect = previous, True
        previous = b
    bpy.ops.object.mode_set(mode='OBJECT')
    red = material("bead", (0.8, 0.25, 0.1))
    for i in range(24):  # a bead on each bone's tail, for the render
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.045 * (1.0 - 0.025 * i), segments=16,
                                             ring_count=8)
        bead = bpy.context.active_object
        bead.data.materials.append(red)
        bead.parent, bead.parent_type, bead.parent_bone = arm, 'BONE', f"tail{i:02d}"
        bead.location = (0.0, 0.0, 0.0)  # at the bone's tail
    root = bpy.data.objects.new("Root", None)
    scene.collection.objects.link(root)
    for f in range(1, 91):  # the root goes round a loop
        a = 2 * math.pi * (f - 1) / 90
        root.location = (0.6 * math.sin(a), 0.5 * (1 - math.cos(a)), 1.0 + 0.3 * math.sin(2 * a))
        root.keyframe_insert("location", frame=f)
    for b in data.bones:
        b.select = True
    bpy.context.view_layer.objects.active = arm
    bpy.ops.flexkin.bake_chain(method="tractrix", target="Root")
    look(camera, (3.2, -2.6, 2.6), (0.0, -0.6, 0.9))
    render_row(scene, "blender_tail")


def rope():
    scene, camera = fresh_scene(90)
    data = bpy.data.curves.new("Rope", 'CURVE')
    data.dimensions, data.bevel_depth, data.bevel_resolution = '3D', 0.02, 4
    data.materials.append(material("rope", (0.75, 0.6, 0.3)))
    spline = data.splines.new('POLY')
    spline.points.add(1)
    spline.points[0].co, spline.points[1].co = (0.0, 0.0, 1.6, 1.0), (0.0, 0.0, 0.1, 1.0)
    curve = bpy.data.objects.new("Rope", data)
    scene.collection.objects.link(curve)
    hand = bpy.data.objects.new("Hand", None)
    scene.collection.objects.link(hand)
    for f in range(1, 91):  # the hand sweeps sideways and back, up and down
        a = 2 * math.pi * (f - 1) / 90
        hand.location = (1.0 * math.sin(a), 0.3 * math.sin(2 * a), 1.6 + 0.2 * (1 - math.cos(a)))
        hand.keyframe_insert("location", frame=f)
    bpy.context.view_layer.objects.active = curve
    bpy.ops.flexkin.bake_rope(method="tractrix", target="Hand", link_length=0.05)
    curve.hide_render = True
    look(camera, (0.0, -4.5, 1.4), (0.0, 0.0, 1.0))
    render_row(scene, "blender_rope")


os.makedirs(OUT_DIR, exist_ok=True)
tail()
rope()
os._exit(0)
