"""flexkin inside Blender (docs/blender.md): natural, length-preserving motion of bone chains,
computed by flexkin's Python module and baked into keyframes.

Install: Edit > Preferences > Add-ons > Install... and choose the zip that `make blender-addon`
writes (build/flexkin_blender.zip), or add the repository's blender/ folder to Blender's script
paths; then enable "Animation: flexkin". The add-on imports flexkin's Python module (built for
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


class FLEXKIN_OT_bake_chain(bpy.types.Operator):
    """Bake the natural motion of the selected bone chain, its first bone driven by a target
    object or by its own animation, over the scene's frame range"""
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

    def execute(self, context):
        started = time.perf_counter()
        wm = context.window_manager
        armature = context.active_object
        try:
            flexkin = import_flexkin(context)
            chain = bake.selected_chain(armature)
            data = bake.gather(context, armature, chain, self.target)
            count = len(data["frames"])
            wm.progress_begin(0, count)
            try:
                points = bake.run_flexkin(flexkin, data, self.method, self.substeps,
                                          progress=lambda done, total: wm.progress_update(done))
            except flexkin.InputError as error:
                raise bake.BakeError(f"flexkin refused the chain: {error}") from error
            finally:
                wm.progress_end()
            keys = bake.pose_keys(armature, chain, data, points)
        except bake.BakeError as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        bake.write_keys(armature, chain, data["frames"], keys)
        self.report({'INFO'}, f"flexkin: baked {len(chain)} bones over {count} frames "
                              f"({self.method}) in {time.perf_counter() - started:.2f} s")
        return {'FINISHED'}


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
        op = layout.operator(FLEXKIN_OT_bake_chain.bl_idname)
        op.method = scene.flexkin_method
        op.target = scene.flexkin_target.name if scene.flexkin_target else ""
        op.substeps = scene.flexkin_substeps


CLASSES = (FlexkinPreferences, FLEXKIN_OT_bake_chain, FLEXKIN_PT_panel)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.flexkin_method = bpy.props.EnumProperty(
        name="Method", items=bake.METHODS, default="tractrix")
    bpy.types.Scene.flexkin_target = bpy.props.PointerProperty(
        name="Target", type=bpy.types.Object,
        description="The object whose motion drives the chain's first bone (none: its own "
                    "animation)")
    bpy.types.Scene.flexkin_substeps = bpy.props.IntProperty(
        name="Sub-steps", default=1, min=1, max=1024)


def unregister():
    for name in ("flexkin_method", "flexkin_target", "flexkin_substeps"):
        delattr(bpy.types.Scene, name)
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
