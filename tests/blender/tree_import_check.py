"""Run inside Blender (blender -b --factory-startup --python THIS -- RESULT.npz FILE.glb): imports
the glTF of a 3D tree result with Blender's own importer and checks, frame by frame, that every
bone's head lies on the tree's point it sits on (docs/gltf-export.md, "Trees": point_r on the
root, link_c on the parent of c, tip_c on the leaf c), in Blender's world coordinates, which for
a z-up file are flexkin's. Prints the largest distance against the scene's size; exits 1 if it
exceeds 4e-6 of it or if a bone, a keyframe or the armature is missing."""
import sys

import bpy
import numpy as np

# Debian's Blender 3.4 glTF importer builds meshes with np.bool, an alias that NumPy 1.24 (Debian
# 12's) removed: without it the import of any mesh fails. The alias is the builtin bool.
if not hasattr(np, "bool"):
    np.bool = bool


def main():
    result, glb = sys.argv[sys.argv.index("--") + 1:]
    with np.load(result) as data:
        frames = data["frames"]
        parents = data["parents"]
    if frames.shape[2] != 3:
        raise SystemExit("the check takes a 3D tree result")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=glb)
    armatures = [o for o in bpy.context.scene.objects if o.type == "ARMATURE"]
    if len(armatures) != 1:
        raise SystemExit(f"expected one armature, found {len(armatures)}")
    armature = armatures[0]
    # The point each bone's head sits on, from its name.
    heads = {}
    for bone in armature.data.bones:
        kind, _, index = bone.name.rpartition("_")
        point = int(index)
        heads[bone.name] = parents[point] if kind == "link" else point
    leaves = sum(1 for i in range(len(parents)) if i not in set(parents.tolist()))
    if len(heads) != len(parents) + leaves:
        raise SystemExit(f"{len(heads)} bones; expected {len(parents) + leaves}")
    action = armature.animation_data.action
    times = sorted({round(k.co[0], 6) for c in action.fcurves for k in c.keyframe_points})
    if len(times) != len(frames):
        raise SystemExit(f"{len(times)} keyframes; expected {len(frames)}")
    scene = bpy.context.scene
    worst, size = 0.0, float(np.abs(frames).max())
    for f, t in enumerate(times):
        whole = int(np.floor(t))
        scene.frame_set(whole, subframe=t - whole)
        for name, point in heads.items():
            head = armature.matrix_world @ armature.pose.bones[name].head
            worst = max(worst, float(np.linalg.norm(np.array(head) - frames[f][point])))
    print(f"blender {bpy.app.version_string}: {len(heads)} bones x {len(frames)} frames, "
          f"largest distance of a bone's head from its point {worst:.3g} "
          f"(scene size {size:.3g}, {worst / size:.2g} of it)")
    # Blender composes the bones' matrices in float32 down the tree: about 1e-7 of the scene a
    # level (4.5e-7 on the torso, 3 levels of bones; 1.1e-6 on the plant, 10).
    if not worst <= 4e-6 * size:
        raise SystemExit("bone heads off their points by more than 4e-6 of the scene")


try:
    main()
except SystemExit as e:
    if e.code not in (None, 0):
        print(f"FAIL {e.code}")
        sys.stdout.flush()
        import os
        os._exit(1)
except Exception as e:  # Blender would otherwise print the error and exit 0
    print(f"FAIL {type(e).__name__}: {e}")
    sys.stdout.flush()
    import os
    os._exit(1)
