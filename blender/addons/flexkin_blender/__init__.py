"""flexkin inside Blender (docs/blender.md): natural, length-preserving motion of bone chains and
trees, computed by flexkin's Python module and baked into keyframes.

Install: Edit > Preferences > Add-ons > Install... and choose the zip that `make blender-addon`
writes (build/flexkin_blender.zip), or by path: set Edit > Preferences > File Paths > Scripts to
the repository's blender/ folder (it holds addons/flexkin_blender) and restart Blender; then
enable "Animation: flexkin". The add-on imports flexkin's Python module (built for
the Python that Debian's Blender runs, /usr/bin/python3): from Python's path, or from the folder
set in the add-on's preferences.
"""
import sys
import time

import bpy

from . import bake

bl_info = {
    "name": "flexkin",
    "author": "flexkin",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > flexkin",
    "description": "Natural, length-preserving motion of bone chains, baked into keyframes",
    "category": "Animation",
}


class FlexkinPreferences(bpy.types.AddonPreferences):
    bl_idname = __name__

    module_path: bpy.props.StringProperty(
        name="flexkin module folder",
        description="The folder that holds flexkin's Python module (the folder above flexkin/), "
                    "if Python does not find it",
        subtype='DIR_PATH')

    def draw(self, context):
        self.layout.prop(self, "module_path")


def import_flexkin(context):
    """flexkin's Python module, from Python's path or the preferences' folder; BakeError (with
    how to install it) where neither has it."""
    try:
        import flexkin
        return flexkin
    except ImportError:
        pass
    addon = context.preferences.addons.get(__name__)
    folder = bpy.path.abspath(addon.preferences.module_path) if addon else ""
    if folder and folder not in sys.path:
        sys.path.insert(0, folder)
        try:
            import flexkin
            return flexkin
        except ImportError:
            sys.path.remove(folder)
    raise bake.BakeError(
        "flexkin's Python module was not found"
        + (f" in '{folder}'" if folder else "")
        + ". Build it (make, in the flexkin repository) and either install it (make install) or "
        "set its folder (build/python) in Edit > Preferences > Add-ons > flexkin")


class _Bake:
    """What every bake does with its work: `_work(context)` is a generator that reads and checks
    the scene, yields (frames done, frames) as flexkin runs, and returns the function that writes
    the result. From a script (execute) the work runs to its end; from the interface (invoke) it
    runs between the interface's events, its progress in the status bar, and Esc cancels it with
    nothing written (the result is written only when the work is done). One undo step."""

    def execute(self, context):
        self._started = time.perf_counter()
        try:
            finish = bake.run_steps(self._work(context), context.window_manager)
            finish()
        except bake.BakeError as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        return {'FINISHED'}

    def invoke(self, context, event):
        if context.window is None:
            return self.execute(context)
        self._started = time.perf_counter()
        self._steps = self._work(context)
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.01, window=context.window)
        self._progress = False
        wm.modal_handler_add(self)
        return {'RUNNING_MODAL'}

    def _stop(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        if self._progress:
            wm.progress_end()
        context.workspace.status_text_set(None)

    def modal(self, context, event):
        if event.type == 'ESC':
            self._stop(context)
            self.report({'WARNING'}, f"flexkin: {self.bl_label.lower()} cancelled; nothing was "
                                     "written")
            return {'CANCELLED'}
        if event.type != 'TIMER':
            return {'PASS_THROUGH'}
        deadline = time.perf_counter() + 0.1  # work for a tenth of a second, then the interface
        done = total = 0
        try:
            while time.perf_counter() < deadline:
                done, total = next(self._steps)
        except StopIteration as end:
            self._stop(context)
            try:
                end.value()
            except bake.BakeError as error:
                self.report({'ERROR'}, str(error))
                return {'CANCELLED'}
            return {'FINISHED'}
        except bake.BakeError as error:
            self._stop(context)
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        wm = context.window_manager
        if not self._progress:
            wm.progress_begin(0, total)
            self._progress = True
        wm.progress_update(done)
        context.workspace.status_text_set(
            f"flexkin: {self.bl_label.lower()}, frame {done} of {total} (Esc cancels)")
        return {'RUNNING_MODAL'}

    def _took(self):
        return f"in {time.perf_counter() - self._started:.2f} s"


class FLEXKIN_OT_bake_chain(_Bake, bpy.types.Operator):
    """Bake the natural motion of the selected bone chain, its first bone driven by a target
    object or by its own animation (or, with a fixed base, its tip driven), over the scene's
    frame range"""
    bl_idname = "flexkin.bake_chain"
    bl_label = "Bake bone chain"
    bl_options = {'REGISTER', 'UNDO'}

    method: bpy.props.EnumProperty(name="Method", items=bake.METHODS, default="tractrix")
    target: bpy.props.StringProperty(
        name="Target",
        description="The object whose motion drives the chain's first bone; empty: the first "
                    "bone's own animation")
    substeps: bpy.props.IntProperty(
        name="Sub-steps", description="Steps of the driven end between two frames",
        default=1, min=1, max=1024)
    fixed_base: bpy.props.BoolProperty(
        name="Fixed base", default=False,
        description="Hold the chain's first bone's head where it is in the armature and drive "
                    "the last bone's tail to the target instead (a hyper-redundant arm)")

    def _work(self, context):
        armature = context.active_object
        flexkin = import_flexkin(context)
        chain = bake.selected_chain(armature)
        if self.fixed_base and not self.target:
            raise bake.BakeError("the fixed-base mode drives the chain's tip: choose the target "
                                 "object it follows")
        data = bake.gather(context, armature, chain, [self.target or None])
        missed = 0
        if self.fixed_base:
            # The chain as a tree: its root's head fixed, its last tail the one target.
            points, missed = yield from bake.tree_steps(flexkin, data, chain, [chain.tails[-1]],
                                                        self.method, True)
        else:
            world = yield from bake.chain_steps(flexkin, data["points"], data["paths"][0][1:],
                                                self.method, self.substeps)
            points = bake.in_armature(data, world)
        keys = bake.pose_keys(armature, chain, data, points)

        def finish():
            bake.write_keys(armature, chain, data["frames"], keys)
            self.report({'WARNING'} if missed else {'INFO'},
                        f"flexkin: baked {len(chain.bones)} bones over {len(data['frames'])} "
                        f"frames ({self.method}{', fixed base' if self.fixed_base else ''}) "
                        + self._took()
                        + (f"; {missed} frames did not reach the target" if missed else ""))
        return finish


class FLEXKIN_OT_bake_rope(_Bake, bpy.types.Operator):
    """Bake the natural motion of the active curve object as a rope of links of one length, its
    first point following a target object, over the scene's frame range, into a new poly curve
    whose points are keyed at every frame"""
    bl_idname = "flexkin.bake_rope"
    bl_label = "Bake rope"
    bl_options = {'REGISTER', 'UNDO'}

    method: bpy.props.EnumProperty(name="Method", items=bake.METHODS, default="tractrix")
    target: bpy.props.StringProperty(
        name="Target", description="The object whose motion drives the rope's first point")
    link_length: bpy.props.FloatProperty(
        name="Link length", default=0.0, min=0.0, subtype='DISTANCE',
        description="The length of the rope's links (0: the curve's length over 32)")
    substeps: bpy.props.IntProperty(
        name="Sub-steps", description="Steps of the driven end between two frames",
        default=1, min=1, max=1024)

    def _work(self, context):
        curve = context.active_object
        flexkin = import_flexkin(context)
        polyline = bake.curve_polyline(context, curve)
        if not self.target:
            raise bake.BakeError("the rope has no target: choose the object whose motion "
                                 "drives its first point")
        total = sum((b - a).length for a, b in zip(polyline, polyline[1:]))
        link = self.link_length if self.link_length > 0.0 else total / 32.0
        points = bake.resample(polyline, link)
        data = bake.gather_path(context, self.target)
        frames = yield from bake.chain_steps(flexkin, points, data["path"][1:], self.method,
                                             self.substeps, "rope")

        def finish():
            rope = bake.write_rope(context, curve, data["frames"], frames)
            self.report({'INFO'}, f"flexkin: baked '{rope.name}', {len(points) - 1} links of "
                                  f"{link:.4g} over {len(data['frames'])} frames ({self.method}) "
                                  + self._took())
        return finish


class FLEXKIN_OT_bake_hair(_Bake, bpy.types.Operator):
    """Bake the natural motion of the active hair curves object's strands as its object (the
    head it is parented to) moves over the scene's frame range: flexkin's strand engine, the
    roots held on the head; the strands play back as a mesh from a cache file"""
    bl_idname = "flexkin.bake_hair"
    bl_label = "Bake hair"
    bl_options = {'REGISTER', 'UNDO'}

    method: bpy.props.EnumProperty(name="Method", items=bake.METHODS[:2], default="tractrix")
    substeps: bpy.props.IntProperty(
        name="Sub-steps", description="Steps of the head between two frames",
        default=1, min=1, max=1024)
    cache: bpy.props.StringProperty(
        name="Cache", subtype='FILE_PATH',
        description="The .npz the strands' frames go to (empty: '<hair>.flexkin.npz' beside the "
                    ".blend file, or in the temporary folder for a file not saved)")

    def _work(self, context):
        import os
        hair = context.active_object
        flexkin = import_flexkin(context)
        points, offsets = bake.hair_strands(hair)
        frames, poses = bake.gather_poses(context, hair)
        poses = bake.rigid_poses(hair.name, frames, poses)
        path = self.cache or (f"//{hair.name}.flexkin.npz" if bpy.data.filepath
                              else os.path.join(bpy.app.tempdir, f"{hair.name}.flexkin.npz"))
        points_at = yield from bake.hair_steps(flexkin, points, offsets, poses, self.method,
                                               self.substeps)

        def finish():
            bake.write_strand_cache(bpy.path.abspath(path), points_at, offsets,
                                    [f - frames[0] for f in frames])
            collection = hair.users_collection[0] if hair.users_collection else \
                context.scene.collection
            mesh = bake.strand_mesh(hair.name + ".flexkin", points_at, offsets, path, frames[0],
                                    collection)
            bake.play_strands(context.scene)
            self.report({'INFO'}, f"flexkin: baked {len(offsets) - 1} strands ({len(points)} "
                                  f"points) over {len(frames)} frames into '{mesh.name}' (cache "
                                  f"{path}) " + self._took())
        return finish


class FLEXKIN_OT_import_strands(bpy.types.Operator):
    """Import a strand file written by `flexkin run` (or a hair bake's cache) as a mesh of the
    strands that plays its frames back from the scene's current frame on"""
    bl_idname = "flexkin.import_strands"
    bl_label = "Import flexkin strands (.npz)"
    bl_options = {'REGISTER', 'UNDO'}

    filepath: bpy.props.StringProperty(subtype='FILE_PATH')
    filter_glob: bpy.props.StringProperty(default="*.npz", options={'HIDDEN'})

    def invoke(self, context, event):
        context.window_manager.fileselect_add(self)
        return {'RUNNING_MODAL'}

    def execute(self, context):
        import os
        try:
            points, offsets, frames = bake.read_strand_cache(bpy.path.abspath(self.filepath))
        except bake.BakeError as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        name = os.path.splitext(os.path.basename(self.filepath))[0]
        mesh = bake.strand_mesh(name, points, offsets, self.filepath, context.scene.frame_current,
                                context.scene.collection)
        bake.play_strands(context.scene)
        self.report({'INFO'}, f"flexkin: '{mesh.name}': {len(offsets) - 1} strands, "
                              f"{len(frames)} frames")
        return {'FINISHED'}


class FLEXKIN_OT_run_groom(bpy.types.Operator):
    """Run a flexkin groom file (docs/groom-format.md: strands grown on a scalp and the body's
    keyframed motion) with flexkin's strand engine, and import its strands as a mesh that plays
    the run back from the scene's current frame on"""
    bl_idname = "flexkin.run_groom"
    bl_label = "Run flexkin groom (.json)"
    bl_options = {'REGISTER', 'UNDO'}

    filepath: bpy.props.StringProperty(subtype='FILE_PATH')
    filter_glob: bpy.props.StringProperty(default="*.json", options={'HIDDEN'})
    cache: bpy.props.StringProperty(
        name="Cache", subtype='FILE_PATH',
        description="The strand file the run writes (empty: '<groom>.flexkin.npz' beside the "
                    ".blend file, or in the temporary folder for a file not saved)")

    def invoke(self, context, event):
        context.window_manager.fileselect_add(self)
        return {'RUNNING_MODAL'}

    def execute(self, context):
        import os
        started = time.perf_counter()
        name = os.path.splitext(os.path.basename(self.filepath))[0]
        cache = self.cache or (f"//{name}.flexkin.npz" if bpy.data.filepath
                               else os.path.join(bpy.app.tempdir, f"{name}.flexkin.npz"))
        wm = context.window_manager
        try:
            flexkin = import_flexkin(context)
            wm.progress_begin(0, 1)
            try:
                report = flexkin.run_groom(bpy.path.abspath(self.filepath),
                                           bpy.path.abspath(cache),
                                           progress=lambda done, total:
                                           wm.progress_update(done / max(total, 1)))
            except flexkin.InputError as error:
                raise bake.BakeError(f"flexkin refused the groom: {error}") from error
            except OSError as error:
                raise bake.BakeError(f"cannot run the groom: {error}") from error
            finally:
                wm.progress_end()
            points, offsets, frames = bake.read_strand_cache(bpy.path.abspath(cache))
        except bake.BakeError as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        mesh = bake.strand_mesh(name, points, offsets, cache, context.scene.frame_current,
                                context.scene.collection)
        bake.play_strands(context.scene)
        self.report({'INFO'}, f"flexkin: '{mesh.name}': {len(offsets) - 1} strands, "
                              f"{len(frames)} frames ({report.engine}) in "
                              f"{time.perf_counter() - started:.2f} s")
        return {'FINISHED'}


def menu_import(self, context):
    self.layout.operator(FLEXKIN_OT_import_strands.bl_idname, text="flexkin strands (.npz)")
    self.layout.operator(FLEXKIN_OT_run_groom.bl_idname, text="flexkin groom (.json, run)")


@bpy.app.handlers.persistent
def on_frame_change(scene, depsgraph=None):
    bake.play_strands(scene)


class FlexkinTarget(bpy.types.PropertyGroup):
    """A target of a tree bake: a bone whose tail follows an object."""
    bone: bpy.props.StringProperty(name="Bone", description="The bone whose tail is driven")
    target: bpy.props.PointerProperty(name="Target", type=bpy.types.Object,
                                      description="The object whose motion drives the bone's tail")
    look: bpy.props.BoolProperty(
        name="Look", default=False,
        description="Turn the bone to point at the object (a head looking) rather than move its "
                    "tail onto it")


class FLEXKIN_OT_target_add(bpy.types.Operator):
    """Add a target of the tree bake: a bone and the object its tail follows"""
    bl_idname = "flexkin.target_add"
    bl_label = "Add target"
    bl_options = {'REGISTER', 'UNDO'}

    def execute(self, context):
        item = context.scene.flexkin_targets.add()
        bone = context.active_pose_bone or context.active_bone
        if bone is not None:
            item.bone = bone.name
        return {'FINISHED'}


class FLEXKIN_OT_target_remove(bpy.types.Operator):
    """Remove a target of the tree bake"""
    bl_idname = "flexkin.target_remove"
    bl_label = "Remove target"
    bl_options = {'REGISTER', 'UNDO'}
    index: bpy.props.IntProperty(default=-1)

    def execute(self, context):
        targets = context.scene.flexkin_targets
        if 0 <= self.index < len(targets):
            targets.remove(self.index)
        return {'FINISHED'}


class FLEXKIN_OT_bake_tree(_Bake, bpy.types.Operator):
    """Bake the natural motion of the selected bones (a tree: a spine with arms, a plant), the
    tails of the scene's target bones (flexkin targets) following their objects, the root's
    head fixed or free, over the scene's frame range"""
    bl_idname = "flexkin.bake_tree"
    bl_label = "Bake bone tree"
    bl_options = {'REGISTER', 'UNDO'}

    method: bpy.props.EnumProperty(name="Method", items=bake.METHODS, default="tractrix")
    fix_root: bpy.props.BoolProperty(
        name="Fix the root", default=True,
        description="Hold the root bone's head where it is in the armature (a base)")

    def _work(self, context):
        armature = context.active_object
        flexkin = import_flexkin(context)
        body = bake.selected_tree(armature)
        targets, names, looks = [], [], []
        for k, item in enumerate(context.scene.flexkin_targets):
            point = body.point_of_tail(item.bone)
            if point is None:
                raise bake.BakeError(f"target {k + 1}: bone '{item.bone}' is not among the "
                                     "selected bones; select it or remove the target")
            if item.target is None:
                raise bake.BakeError(f"target {k + 1} (bone '{item.bone}') has no object; "
                                     "choose the object its tail follows")
            targets.append(point)
            names.append(item.target.name)
            looks.append(bool(item.look))
        if not targets:
            raise bake.BakeError("the tree has no target: add one (a bone and the object its "
                                 "tail follows) in the flexkin panel")
        data = bake.gather(context, armature, body, names)
        points, missed = yield from bake.tree_steps(flexkin, data, body, targets, self.method,
                                                    self.fix_root, looks)
        keys = bake.pose_keys(armature, body, data, points)

        def finish():
            bake.write_keys(armature, body, data["frames"], keys)
            self.report({'WARNING'} if missed else {'INFO'},
                        f"flexkin: baked {len(body.bones)} bones over {len(data['frames'])} "
                        f"frames ({self.method}) " + self._took()
                        + (f"; {missed} frames did not reach their targets" if missed else ""))
        return finish


class FLEXKIN_PT_panel(bpy.types.Panel):
    bl_label = "flexkin"
    bl_idname = "FLEXKIN_PT_panel"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "flexkin"

    def draw(self, context):
        scene = context.scene
        layout = self.layout
        layout.label(text="Bone chain")
        layout.prop(scene, "flexkin_method")
        layout.prop(scene, "flexkin_target")
        layout.prop(scene, "flexkin_substeps")
        layout.prop(scene, "flexkin_fixed_base")
        op = layout.operator(FLEXKIN_OT_bake_chain.bl_idname)
        op.method = scene.flexkin_method
        op.target = scene.flexkin_target.name if scene.flexkin_target else ""
        op.substeps = scene.flexkin_substeps
        op.fixed_base = scene.flexkin_fixed_base
        layout.separator()
        layout.label(text="Bone tree")
        armature = context.active_object
        for k, item in enumerate(scene.flexkin_targets):
            row = layout.row(align=True)
            if armature is not None and armature.type == 'ARMATURE':
                row.prop_search(item, "bone", armature.data, "bones", text="")
            else:
                row.prop(item, "bone", text="")
            row.prop(item, "target", text="")
            row.prop(item, "look", text="", icon='HIDE_OFF')
            row.operator(FLEXKIN_OT_target_remove.bl_idname, text="", icon='X').index = k
        layout.operator(FLEXKIN_OT_target_add.bl_idname, icon='ADD')
        layout.prop(scene, "flexkin_fix_root")
        op = layout.operator(FLEXKIN_OT_bake_tree.bl_idname)
        op.method = scene.flexkin_method
        op.fix_root = scene.flexkin_fix_root
        layout.separator()
        layout.label(text="Rope (the active curve)")
        layout.prop(scene, "flexkin_link_length")
        op = layout.operator(FLEXKIN_OT_bake_rope.bl_idname)
        op.method = scene.flexkin_method
        op.target = scene.flexkin_target.name if scene.flexkin_target else ""
        op.link_length = scene.flexkin_link_length
        op.substeps = scene.flexkin_substeps
        layout.separator()
        layout.label(text="Hair (the active hair curves)")
        op = layout.operator(FLEXKIN_OT_bake_hair.bl_idname)
        op.method = scene.flexkin_method if scene.flexkin_method != "overall" else "tractrix"
        op.substeps = scene.flexkin_substeps
        layout.operator(FLEXKIN_OT_import_strands.bl_idname)
        layout.operator(FLEXKIN_OT_run_groom.bl_idname)


CLASSES = (FlexkinPreferences, FLEXKIN_OT_bake_chain, FLEXKIN_OT_bake_rope, FLEXKIN_OT_bake_hair,
           FLEXKIN_OT_import_strands, FLEXKIN_OT_run_groom, FlexkinTarget,
           FLEXKIN_OT_target_add,
           FLEXKIN_OT_target_remove, FLEXKIN_OT_bake_tree, FLEXKIN_PT_panel)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.TOPBAR_MT_file_import.append(menu_import)
    bpy.app.handlers.frame_change_post.append(on_frame_change)
    bpy.types.Scene.flexkin_method = bpy.props.EnumProperty(
        name="Method", items=bake.METHODS, default="tractrix")
    bpy.types.Scene.flexkin_target = bpy.props.PointerProperty(
        name="Target", type=bpy.types.Object,
        description="The object whose motion drives the chain's first bone (none: its own "
                    "animation)")
    bpy.types.Scene.flexkin_substeps = bpy.props.IntProperty(
        name="Sub-steps", default=1, min=1, max=1024)
    bpy.types.Scene.flexkin_targets = bpy.props.CollectionProperty(type=FlexkinTarget)
    bpy.types.Scene.flexkin_link_length = bpy.props.FloatProperty(
        name="Link length", default=0.0, min=0.0, subtype='DISTANCE',
        description="The rope's link length (0: the curve's length over 32)")
    bpy.types.Scene.flexkin_fixed_base = bpy.props.BoolProperty(
        name="Fixed base", default=False,
        description="Hold the chain's root and drive its tip to the target")
    bpy.types.Scene.flexkin_fix_root = bpy.props.BoolProperty(
        name="Fix the root", default=True,
        description="Hold the root bone's head where it is in the armature (a base)")


def unregister():
    if on_frame_change in bpy.app.handlers.frame_change_post:
        bpy.app.handlers.frame_change_post.remove(on_frame_change)
    bpy.types.TOPBAR_MT_file_import.remove(menu_import)
    for name in ("flexkin_method", "flexkin_target", "flexkin_substeps", "flexkin_targets",
                 "flexkin_fix_root", "flexkin_link_length", "flexkin_fixed_base"):
        delattr(bpy.types.Scene, name)
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
