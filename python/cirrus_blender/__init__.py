"""Cirrus as a Blender render engine: volumes path-traced by the `cirrus`
Python module, rendered from Blender's own scene (F12 and animations).

`export.py` turns the evaluated scene (its depsgraph) into a cirrus scene
description, reporting what it cannot map; `engine.py` is the
`RenderEngine` that renders it, streams progress and honours Esc.
"""

from __future__ import annotations

import bpy

from . import engine, properties


def register() -> None:
    properties.register()
    bpy.utils.register_class(engine.CirrusRenderEngine)
    for panel in engine.compatible_panels():
        panel.COMPAT_ENGINES.add(engine.CirrusRenderEngine.bl_idname)


def unregister() -> None:
    for panel in engine.compatible_panels():
        panel.COMPAT_ENGINES.discard(engine.CirrusRenderEngine.bl_idname)
    bpy.utils.unregister_class(engine.CirrusRenderEngine)
    properties.unregister()
