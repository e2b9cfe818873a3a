"""The render settings cirrus adds to a scene (`scene.cirrus`) and to each
view layer (`view_layer.cirrus`: its passes), and their panels.

The device is chosen as Cycles' is, per scene at the top of the render
settings (`scene.cycles.device`: CPU or GPU Compute); cirrus has no list of
GPUs to tick in the Preferences (it takes the best Vulkan adapter it
finds), so the scene's setting is the whole choice.
"""

from __future__ import annotations

import bpy

# Blender's identifiers, and what `cirrus.render(device=)` calls them.
DEVICES = {"AUTO": "auto", "CPU": "cpu", "GPU": "gpu"}


class CirrusSettings(bpy.types.PropertyGroup):
    device: bpy.props.EnumProperty(
        name="Device",
        description="Where cirrus renders",
        items=(
            ("AUTO", "Auto", "A hardware GPU where there is one, else the CPU; a scene or a pass "
             "the GPU does not render goes to the CPU, saying why"),
            ("CPU", "CPU", "Use the CPU for rendering (every feature and pass)"),
            ("GPU", "GPU Compute", "Use a Vulkan GPU (a software one too, such as lavapipe); what "
             "the GPU does not render is an error naming it"),
        ),
        default="AUTO",
    )
    spp: bpy.props.IntProperty(name="Samples", description="Samples per pixel", default=64, min=1)
    seed: bpy.props.IntProperty(name="Seed", default=0, min=0)
    max_depth: bpy.props.IntProperty(
        name="Max Scattering", description="Scattering events per path (0: unlimited, by Russian roulette)",
        default=0, min=0)
    threads: bpy.props.IntProperty(name="Threads", description="0: all cores", default=0, min=0)


class CirrusLayerSettings(bpy.types.PropertyGroup):
    """cirrus's own passes, opt-in as Blender's passes are (the GPU renders
    none: with one on, Auto renders on the CPU)."""

    use_pass_albedo: bpy.props.BoolProperty(
        name="Albedo", description="The first scattering's albedo (guides a denoiser)", default=False)
    use_pass_direct: bpy.props.BoolProperty(
        name="Direct", description="Light scattered once from the lamps and the sky", default=False)


class CIRRUS_PT_sampling(bpy.types.Panel):
    bl_label = "Cirrus"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {"CIRRUS"}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES

    def draw(self, context):
        settings = context.scene.cirrus
        for name in ("device", "spp", "seed", "max_depth", "threads"):
            self.layout.prop(settings, name)


class CIRRUS_PT_passes(bpy.types.Panel):
    bl_label = "Cirrus Passes"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "view_layer"
    COMPAT_ENGINES = {"CIRRUS"}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES

    def draw(self, context):
        layer = context.view_layer
        self.layout.prop(layer, "use_pass_z")
        self.layout.prop(layer, "use_pass_emit")
        for name in ("use_pass_albedo", "use_pass_direct"):
            self.layout.prop(layer.cirrus, name)


CLASSES = (CirrusSettings, CirrusLayerSettings, CIRRUS_PT_sampling, CIRRUS_PT_passes)


def register() -> None:
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.cirrus = bpy.props.PointerProperty(type=CirrusSettings)
    bpy.types.ViewLayer.cirrus = bpy.props.PointerProperty(type=CirrusLayerSettings)


def unregister() -> None:
    del bpy.types.ViewLayer.cirrus
    del bpy.types.Scene.cirrus
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
