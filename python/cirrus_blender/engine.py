"""The `RenderEngine` that renders Blender's scene with the `cirrus` module.

A render exports the evaluated scene (`export.py`), reports what it could
not map in Blender's info log (and keeps the list in `REPORTS`), renders
through `cirrus.render` on its own thread with Blender's progress bar fed
from cirrus's progress and Esc (`test_break`) cancelling it, then writes
the image into the render result: Combined (RGBA; alpha is the volume's
coverage), and what the view layer asks for: Depth (cirrus's sampled
distance to the first scattering, 1e10 where none), Emit, and cirrus's
albedo and direct-light layers as the passes "Albedo" and "Direct".

The render runs where `scene.cirrus.device` says (Auto, CPU or GPU
Compute, as `cirrus render --device`): the GPU renders Combined only, so
with a pass on, Auto renders on the CPU and GPU Compute is refused. What
the GPU refuses, or a missing Vulkan driver, is an error report naming it;
where the render ran (and why Auto fell back to the CPU) is reported too.
A GPU render reports no progress and finishes before Esc is seen.
"""

from __future__ import annotations

import bpy
import numpy as np

from . import export
from .properties import DEVICES

# The reports of the last render, for scripts and tests (the info log has them too).
REPORTS: list[tuple[str, str]] = []


class Cancelled(Exception):
    """Esc was pressed: the render stops."""


def compatible_panels():
    """The panels of Blender's own properties that apply to cirrus too."""
    names = ("RENDER_PT_format", "RENDER_PT_frame_range", "RENDER_PT_output", "RENDER_PT_motion_blur",
             "DATA_PT_camera", "DATA_PT_lens", "DATA_PT_camera_display", "DATA_PT_light",
             "DATA_PT_volume_file", "DATA_PT_volume_grids", "EEVEE_LIGHT_PT_light")
    panels = (getattr(bpy.types, n, None) for n in names)
    return [p for p in panels if p is not None and isinstance(getattr(p, "COMPAT_ENGINES", None), set)]


class CirrusRenderEngine(bpy.types.RenderEngine):
    bl_idname = "CIRRUS"
    bl_label = "Cirrus"
    bl_use_preview = False
    bl_use_eevee_viewport = True

    def report_all(self, level: str, messages) -> None:
        for m in messages:
            REPORTS.append((level, m))
            self.report({level}, m)
            print(f"cirrus: {level.lower()}: {m}")

    def render(self, depsgraph) -> None:
        REPORTS.clear()
        scene = depsgraph.scene
        r = scene.render
        scale = r.resolution_percentage / 100.0
        w, h = max(1, int(r.resolution_x * scale)), max(1, int(r.resolution_y * scale))
        try:
            desc, warnings = export.scene_description(depsgraph, (w, h))
        except (OSError, ValueError) as e:
            self.report_all("ERROR", [str(e)])
            return
        self.report_all("WARNING", warnings)
        image, stats = self.run(scene, desc)
        if image is None:
            return
        self.report_all("WARNING", [blender_words(w) for w in stats.get("warnings", [])])
        self.report_all("INFO", [f"cirrus rendered on {device_words(stats.get('device', ''))}"])
        self.write(image, stats, w, h)
        self.update_stats("", f"cirrus: {stats['spp']} spp in {stats['wall_seconds']:.1f} s")

    def run(self, scene, desc):
        import cirrus

        settings = scene.cirrus
        aov = [name for name, wanted in layer_passes(scene).items() if wanted]
        device = DEVICES[settings.device]
        options = {"spp": settings.spp, "seed": settings.seed, "device": device}
        if aov:
            options["aov"] = aov
        if settings.max_depth > 0:
            options["max_depth"] = settings.max_depth

        def progress(done: int, total: int) -> None:
            self.update_progress(done / max(total, 1))
            if self.test_break():
                raise Cancelled()

        try:
            return cirrus.render(desc, progress=progress, threads=settings.threads or None, **options)
        except Cancelled:
            return None, None
        except (OSError, ValueError) as e:
            self.report_all("ERROR", [blender_words(str(e))])
            return None, None

    def write(self, image: np.ndarray, stats: dict, w: int, h: int) -> None:
        aovs = stats.get("aovs", {})
        for name in ("Albedo", "Direct"):
            if name.lower() in aovs:
                self.add_pass(name, 3, "RGB")
        result = self.begin_result(0, 0, w, h)
        layer = result.layers[0]

        def put(name: str, pixels: np.ndarray) -> None:
            # Blender's rows run bottom to top; cirrus's top to bottom.
            flat = np.ascontiguousarray(pixels[::-1]).reshape(w * h, -1)
            layer.passes[name].rect = flat

        put("Combined", image)
        if "depth" in aovs and "Depth" in layer.passes:
            put("Depth", aovs["depth"])
        if "emission" in aovs and "Emit" in layer.passes:
            put("Emit", aovs["emission"])
        for name in ("Albedo", "Direct"):
            if name.lower() in aovs:
                put(name, aovs[name.lower()])
        self.end_result(result)


def layer_passes(scene) -> dict[str, bool]:
    """cirrus's AOV for each pass the view layer may ask for, and whether it does."""
    layer = bpy.context.view_layer if bpy.context.view_layer else scene.view_layers[0]
    return {
        "depth": layer.use_pass_z,
        "emission": layer.use_pass_emit,
        "albedo": layer.cirrus.use_pass_albedo,
        "direct": layer.cirrus.use_pass_direct,
    }


def device_words(device: str) -> str:
    """'the GPU: <adapter>' or 'the CPU', from the stats' "cpu" or "gpu: <adapter>"."""
    return f"the GPU: {device[5:]}" if device.startswith("gpu: ") else "the CPU"


def blender_words(message: str) -> str:
    """cirrus's message with its command-line advice in Blender's terms."""
    return (message.replace("--device gpu", "Device GPU Compute")
            .replace("use --device cpu", "set Device to CPU (Render Properties > Cirrus)")
            .replace("AOVs", "passes other than Combined (View Layer Properties > Cirrus Passes)"))
