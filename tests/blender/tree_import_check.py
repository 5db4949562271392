"""Run inside Blender (blender -b --factory-startup --python THIS -- RESULT.npz FILE.glb): imports
the glTF of a 3D tree result with Blender's own importer and checks, frame by frame, that every
bone's head lies on the tree's point it sits on (docs/gltf-export.md, "Trees": point_r on the
root, link_c on the parent of c, tip_c on the leaf c, slide_c on a sliding point c), in Blender's
world coordinates, which for a z-up file are flexkin's; and that the skinned capsules follow the
links: each vertex of the evaluated mesh (Blender's own skinning) keeps, in every frame, the
distance it has in the first frame from the link of its bone (link_c's, or for tip_c and slide_c
the link into c: the far half of a sliding link's capsule), so a sliding link's capsule stretches
with it. Prints the largest errors against the scene's size; exits 1 if a bone head is off its
point by more than 4e-6 of it, a vertex's distance changes by more than 1e-5 of it, or a bone, a
keyframe or the armature is missing."""
import json
import zipfile
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
    with zipfile.ZipFile(result) as z:
        sliding = json.loads(z.read("tree.json")).get("sliding", [])
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
    inner = set(parents.tolist())
    leaves = sum(1 for i in range(len(parents)) if i not in inner)
    slides = sum(1 for c in sliding if c in inner)
    if len(heads) != len(parents) + leaves + slides:
        raise SystemExit(f"{len(heads)} bones; expected {len(parents) + leaves + slides}")
    action = armature.animation_data.action
    times = sorted({round(k.co[0], 6) for c in action.fcurves for k in c.keyframe_points})
    if len(times) != len(frames):
        raise SystemExit(f"{len(times)} keyframes; expected {len(frames)}")
    meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    if len(meshes) != 1:
        raise SystemExit(f"expected one mesh, found {len(meshes)}")
    mesh = meshes[0]
    # Each vertex's link: the point c its bone's name ends in (link_c, tip_c, slide_c: the link
    # from parents[c] to c).
    group_point = {g.index: int(g.name.rpartition("_")[2]) for g in mesh.vertex_groups}
    vertex_point = np.array([group_point[max(v.groups, key=lambda e: e.weight).group]
                             for v in mesh.data.vertices])
    if (parents[vertex_point] < 0).any():
        raise SystemExit("a vertex skinned to the root's bone")

    def link_distances(f, coords):
        a = frames[f][parents[vertex_point]]
        b = frames[f][vertex_point]
        ab = b - a
        length2 = np.einsum("ij,ij->i", ab, ab)
        t = np.clip(np.einsum("ij,ij->i", coords - a, ab) / np.where(length2 > 0, length2, 1),
                    0.0, 1.0)
        return np.linalg.norm(coords - (a + t[:, None] * ab), axis=1)

    scene = bpy.context.scene
    depsgraph = bpy.context.evaluated_depsgraph_get()
    worst, size = 0.0, float(np.abs(frames).max())
    first_distances, worst_vertex = None, 0.0
    for f, t in enumerate(times):
        whole = int(np.floor(t))
        scene.frame_set(whole, subframe=t - whole)
        for name, point in heads.items():
            head = armature.matrix_world @ armature.pose.bones[name].head
            worst = max(worst, float(np.linalg.norm(np.array(head) - frames[f][point])))
        evaluated = mesh.evaluated_get(depsgraph)
        skinned = evaluated.to_mesh()
        coords = np.empty(3 * len(skinned.vertices))
        skinned.vertices.foreach_get("co", coords)
        evaluated.to_mesh_clear()
        matrix = np.array(evaluated.matrix_world)
        coords = coords.reshape(-1, 3) @ matrix[:3, :3].T + matrix[:3, 3]
        distances = link_distances(f, coords)
        if first_distances is None:
            first_distances = distances
        worst_vertex = max(worst_vertex, float(np.abs(distances - first_distances).max()))
    print(f"blender {bpy.app.version_string}: {len(heads)} bones x {len(frames)} frames, "
          f"largest distance of a bone's head from its point {worst:.3g} "
          f"(scene size {size:.3g}, {worst / size:.2g} of it); {len(vertex_point)} vertices, "
          f"largest change of a vertex's distance from its link {worst_vertex:.3g} "
          f"({worst_vertex / size:.2g} of the scene)")
    if not worst_vertex <= 1e-5 * size:
        raise SystemExit("a capsule's vertex left its place about its link")
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
