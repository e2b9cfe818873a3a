"""The render settings cirrus adds to a scene (`scene.cirrus`) and their panel."""

from __future__ import annotations

import bpy


class CirrusSettings(bpy.types.PropertyGroup):
    spp: bpy.props.IntProperty(name="Samples", description="Samples per pixel", default=64, min=1)
    seed: bpy.props.IntProperty(name="Seed", default=0, min=0)
    max_depth: bpy.props.IntProperty(
        name="Max Scattering", description="Scattering events per path (0: unlimited, by Russian roulette)",
        default=0, min=0)
    threads: bpy.props.IntProperty(name="Threads", description="0: all cores", default=0, min=0)


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
        for name in ("spp", "seed", "max_depth", "threads"):
            self.layout.prop(settings, name)


def register() -> None:
    bpy.utils.register_class(CirrusSettings)
    bpy.utils.register_class(CIRRUS_PT_sampling)
    bpy.types.Scene.cirrus = bpy.props.PointerProperty(type=CirrusSettings)


def unregister() -> None:
    del bpy.types.Scene.cirrus
    bpy.utils.unregister_class(CIRRUS_PT_sampling)
    bpy.utils.unregister_class(CirrusSettings)
