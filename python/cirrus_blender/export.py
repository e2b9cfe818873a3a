"""Blender's evaluated scene as a cirrus scene description (the TOML
format, as a dict), with a list of what could not be mapped.

Blender is Z-up and cirrus's sky maps are Y-up, so every position and
direction is turned by the same rotation, (x, y, z) -> (x, z, -y): a
rigid change of frame that changes no image.

What is mapped:

- volume objects: the OpenVDB file of the current frame, the object's
  transform (the file's world space is the object's space, as in Blender),
  and the Principled Volume of its material. Cycles' Principled Volume
  scatters `density x color` and absorbs `density x (1 - color) x
  (1 - sqrt(absorption color))` per unit of the density attribute; cirrus
  takes their sum per channel as the extinction (`density_scale`) and
  scattering over it as the albedo. A Volume Scatter + Volume Absorption
  pair (each density a constant times a grid attribute) maps the same way.
  Blackbody maps the temperature attribute to cirrus's blackbody emission
  (approximately: cirrus emits sigma_a x Le); Emission Strength, which
  Cycles emits evenly through the object's box, is reported, not mapped;
- lamps: every sun lamp (strength is irradiance in both; the first as
  `[sun]`, the others as `[[light]]`), point lamps (Cycles sends a lamp
  of power P and colour c the radiant intensity `P c / (4 pi)` in every
  direction; its radius makes it a ball of that intensity) and spot lamps
  (the same, in a cone of half the spot size, its edge blended over
  `spot_blend` of the cone's `1 - cos`, as Cycles' smoothstep does), each
  named by its object (its light-group layer; camera rays see a lamp's
  surface where its object is visible to the camera), and area lamps (square,
  rectangle, disk, ellipse; Cycles' radiance `P c / (pi A)`, the size
  scaled by the object, emitting along -Z); a point or spot lamp's Soft
  Falloff (`use_soft_falloff`, on by default) maps to `soft_falloff`:
  Cycles then lights each point from the disc of the lamp's radius
  through its centre facing the point, which cirrus does alike; the
  world's Background
  colour or an equirectangular Environment Texture, and the scene camera
  (its matrix, field of view and clip range; a clip start in front of
  every volume clips nothing and is written as 0, which the GPU renders);
- motion blur: the shutter, and the volume's velocity grid.

Everything else (other objects and lamps, nodes cirrus cannot map, linked
inputs) is reported, never silently ignored.
"""

from __future__ import annotations

import math
import os

import bpy
import mathutils

# Blender's Z-up world to cirrus's Y-up: (x, y, z) -> (x, z, -y).
Y_UP = mathutils.Matrix(((1, 0, 0, 0), (0, 0, 1, 0), (0, -1, 0, 0), (0, 0, 0, 1)))


def rows(m: mathutils.Matrix) -> list[list[float]]:
    return [[float(m[r][c]) for c in range(4)] for r in range(4)]


class Export:
    """One scene's description and its reports."""

    def __init__(self, depsgraph, res: tuple[int, int]):
        self.depsgraph = depsgraph
        self.scene = depsgraph.scene
        self.res = res
        self.warnings: list[str] = []
        self.desc: dict = {"render": {}, "camera": {"res": f"{res[0]}x{res[1]}"}, "volume": []}
        # Every volume's world-space box corners (for the near clip).
        self.corners: list[mathutils.Vector] = []

    def warn(self, message: str) -> None:
        if message not in self.warnings:
            self.warnings.append(message)

    def run(self) -> dict:
        suns = []
        for inst in self.depsgraph.object_instances:
            obj = inst.object
            if obj.type == "VOLUME":
                self.volume(obj, inst.matrix_world.copy())
            elif obj.type == "LIGHT" and obj.data.type == "SUN":
                suns.append((obj, inst.matrix_world.copy()))
            elif obj.type == "LIGHT" and obj.data.type in ("POINT", "SPOT"):
                self.lamp(obj, inst.matrix_world.copy())
            elif obj.type == "LIGHT" and obj.data.type == "AREA":
                self.area_lamp(obj, inst.matrix_world.copy())
            elif obj.type == "LIGHT":
                self.warn(f"{obj.name}: {obj.data.type.lower()} lamps are not rendered "
                          "(sun, point, spot and area lamps are)")
            elif obj.type == "CAMERA":
                continue
            elif obj.type in ("EMPTY",):
                continue
            else:
                self.warn(f"{obj.name} ({obj.type.lower()}): not rendered (cirrus renders volume objects)")
        self.sun(suns)
        self.world()
        self.camera()
        self.motion()
        self.drop_idle_near_clip()
        if not self.desc["volume"]:
            raise ValueError("the scene has no volume object with an OpenVDB file to render")
        return self.desc

    # --- volumes ---

    def volume(self, obj, matrix_world) -> None:
        data = obj.data
        path = data.grids.frame_filepath or data.filepath
        path = bpy.path.abspath(path)
        if not path:
            self.warn(f"{obj.name}: the volume has no file: not rendered")
            return
        if not os.path.exists(path):
            raise OSError(f"{obj.name}: {path}: no such OpenVDB file")
        spec = {"file": os.path.abspath(path), "transform": {"matrix": rows(Y_UP @ matrix_world)}}
        grids = self.grid_names(data)
        spec.update(self.medium(obj, grids))
        if data.velocity_grid:
            if data.velocity_grid in grids:
                spec["velocity"] = data.velocity_grid
                fps = self.scene.render.fps / self.scene.render.fps_base
                per_second = data.velocity_unit == "SECOND"
                spec["velocity_scale"] = float(data.velocity_scale) / (fps if per_second else 1.0)
            else:
                self.warn(f"{obj.name}: velocity grid {data.velocity_grid!r} is not in the file")
        self.desc["volume"].append(spec)
        # The grid's box, padded by 5% of its size a side (far more than the
        # filter's voxel): what the volume can fill.
        box = [mathutils.Vector(c) for c in obj.bound_box]
        lo = mathutils.Vector([min(c[i] for c in box) for i in range(3)])
        hi = mathutils.Vector([max(c[i] for c in box) for i in range(3)])
        pad = 0.05 * max(hi - lo)
        lo, hi = lo - mathutils.Vector((pad,) * 3), hi + mathutils.Vector((pad,) * 3)
        self.corners.extend(matrix_world @ mathutils.Vector((x, y, z))
                            for x in (lo.x, hi.x) for y in (lo.y, hi.y) for z in (lo.z, hi.z))

    def grid_names(self, data) -> list[str]:
        try:
            data.grids.load()
        except Exception:  # noqa: BLE001 - a file Blender cannot read is cirrus's to report
            return []
        return [g.name for g in data.grids]

    def medium(self, obj, grids: list[str]) -> dict:
        mat = obj.active_material
        node = volume_node(mat)
        if mat is None or node is None:
            self.warn(f"{obj.name}: no volume shader connected to the material output: scene defaults")
            return {}
        if node.bl_idname == "ShaderNodeVolumePrincipled":
            return self.principled(obj, mat, node, grids)
        if node.bl_idname == "ShaderNodeAddShader":
            mapped = self.scatter_absorption(obj, mat, node, grids)
            if mapped is not None:
                return mapped
        self.warn(f"{mat.name}: node {node.name!r} ({node.bl_idname}) cannot be mapped to cirrus: scene defaults")
        return {}

    def constant(self, mat, node, name: str):
        """An input's own value; a linked input is reported and its value used."""
        socket = node.inputs[name]
        if socket.is_linked:
            src = socket.links[0].from_node
            self.warn(f"{mat.name}: {node.name}.{name} is driven by {src.name!r} ({src.bl_idname}), "
                      "which cirrus cannot evaluate: its unlinked value is used")
        value = socket.default_value
        try:
            return [float(v) for v in value][:3]
        except TypeError:
            return float(value)

    def principled(self, obj, mat, node, grids: list[str]) -> dict:
        c = self.constant(mat, node, "Color")
        d = max(self.constant(mat, node, "Density"), 0.0)
        a = [math.sqrt(max(x, 0.0)) for x in self.constant(mat, node, "Absorption Color")]
        scatter = [d * x for x in c]
        absorb = [d * max(1.0 - x, 0.0) * max(1.0 - y, 0.0) for x, y in zip(c, a)]
        spec = coefficients(scatter, absorb)
        spec["g"] = self.constant(mat, node, "Anisotropy")
        spec["density"] = self.grid(obj, node, "Density Attribute", grids, "density")
        if self.constant(mat, node, "Emission Strength") > 1e-5:
            self.warn(f"{mat.name}: Emission Strength is emitted evenly through the object's box in Cycles; "
                      "cirrus emits from grids: not mapped")
        if self.constant(mat, node, "Blackbody Intensity") > 1e-3:
            temperature = self.grid(obj, node, "Temperature Attribute", grids, "temperature")
            spec["temperature"] = temperature
            spec["blackbody"] = {
                "scale": self.constant(mat, node, "Blackbody Intensity"),
                "offset": 0.0,
                "temperature_scale": self.constant(mat, node, "Temperature"),
            }
            self.warn(f"{mat.name}: blackbody emission is mapped approximately (cirrus emits sigma_a x Le)")
        return spec

    def grid(self, obj, node, socket: str, grids: list[str], fallback: str) -> str:
        name = node.inputs[socket].default_value if socket in node.inputs else fallback
        name = (name or fallback).removeprefix("geom:")
        if grids and name not in grids:
            raise ValueError(f"{obj.name}: the material reads grid {name!r}, the file has {grids}")
        return name

    def scatter_absorption(self, obj, mat, add, grids: list[str]) -> dict | None:
        nodes = [link.from_node for s in add.inputs for link in s.links]
        kinds = {n.bl_idname: n for n in nodes}
        scat = kinds.get("ShaderNodeVolumeScatter")
        absn = kinds.get("ShaderNodeVolumeAbsorption")
        if scat is None or absn is None or len(nodes) != 2:
            return None
        if getattr(scat, "phase", "HENYEY_GREENSTEIN") != "HENYEY_GREENSTEIN":
            self.warn(f"{mat.name}: Volume Scatter phase {scat.phase} is rendered as Henyey-Greenstein")
        ds, gs = self.density_input(mat, scat)
        da, ga = self.density_input(mat, absn)
        if gs != ga:
            self.warn(f"{mat.name}: scatter and absorption read different grids ({gs}, {ga}): using {gs}")
        scatter = [ds * x for x in self.constant(mat, scat, "Color")]
        absorb = [da * (1.0 - x) for x in self.constant(mat, absn, "Color")]
        spec = coefficients(scatter, absorb)
        spec["g"] = self.constant(mat, scat, "Anisotropy")
        spec["density"] = gs
        if grids and gs not in grids:
            raise ValueError(f"{obj.name}: the material reads grid {gs!r}, the file has {grids}")
        return spec

    def density_input(self, mat, node) -> tuple[float, str]:
        """A Density input as `constant x attribute` (a Math multiply of an
        Attribute node), or a constant over the default density grid."""
        socket = node.inputs["Density"]
        if not socket.is_linked:
            return float(socket.default_value), "density"
        math_node = socket.links[0].from_node
        if math_node.bl_idname == "ShaderNodeMath" and math_node.operation == "MULTIPLY":
            attr = [l.from_node for s in math_node.inputs for l in s.links]
            free = [float(s.default_value) for s in math_node.inputs[:2] if not s.is_linked]
            if len(attr) == 1 and attr[0].bl_idname == "ShaderNodeAttribute" and len(free) == 1:
                return free[0], attr[0].attribute_name
        self.warn(f"{mat.name}: {node.name}.Density is driven by {math_node.name!r}, which cirrus cannot "
                  "evaluate: density 1 is used")
        return 1.0, "density"

    # --- lights, world, camera ---

    def sun(self, suns) -> None:
        """The first sun lamp as `[sun]`, the others as distant `[[light]]`s."""
        if not suns:
            self.desc["sun"] = {"enabled": False}
            return
        for i, (obj, m) in enumerate(suns):
            light = obj.data
            direction = (Y_UP @ m).to_3x3() @ mathutils.Vector((0.0, 0.0, -1.0))
            strength = float(light.energy)
            if not getattr(light, "normalize", True) and light.angle > 0:
                # Unnormalised, strength is the disk's radiance.
                strength *= math.pi * math.sin(0.5 * light.angle) ** 2
            colour = [float(c) * strength for c in light.color]
            if i == 0:
                self.desc["sun"] = {
                    "direction": list(direction),
                    "irradiance": colour,
                    "angle": math.degrees(light.angle),
                }
            else:
                self.desc.setdefault("light", []).append({
                    "type": "distant",
                    "name": obj.name,
                    "direction": list(direction),
                    "color": colour,
                    "angle": math.degrees(light.angle),
                })

    def lamp(self, obj, m) -> None:
        """A point or spot lamp as a `[[light]]` of Cycles' intensity."""
        light = obj.data
        world = Y_UP @ m
        position = world.to_translation()
        # Cycles takes the radius as it is, unscaled by the object.
        radius = float(light.shadow_soft_size)
        intensity = [float(c) * float(light.energy) / (4.0 * math.pi) for c in light.color]
        entry: dict = {"name": obj.name, "position": list(position)}
        if radius > 0.0:
            # A ball (or, with Soft Falloff, a facing disc) of radiance
            # I / (pi r^2) sends I; camera rays see it where the lamp's
            # object is visible to the camera, as in Cycles.
            entry.update({"type": "sphere", "radius": radius,
                          "color": [i / (math.pi * radius * radius) for i in intensity],
                          "visible_to_camera": bool(obj.visible_camera),
                          "soft_falloff": bool(getattr(light, "use_soft_falloff", True))})
        else:
            entry.update({"type": "point", "color": intensity})
        if light.type == "SPOT":
            axis = world.to_3x3() @ mathutils.Vector((0.0, 0.0, -1.0))
            entry.update({
                "type": "spot",
                "radius": radius,
                "color": entry["color"],
                "direction": list(axis.normalized()),
                "cone_angle": math.degrees(0.5 * float(light.spot_size)),
                "cone_softness": float(light.spot_blend),
            })
        self.desc.setdefault("light", []).append(entry)

    def area_lamp(self, obj, m) -> None:
        """An area lamp as a `rect` or `disk` `[[light]]`: Cycles' radiance
        `P c / (pi A)` (normalised; `P c / pi` if not), its size scaled by
        the object, emitting along its -Z."""
        light = obj.data
        world = Y_UP @ m
        axes = world.to_3x3()
        x, y, z = axes.col[0], axes.col[1], axes.col[2]
        two_sizes = light.shape in ("RECTANGLE", "ELLIPSE")
        width = float(light.size) * x.length
        height = float(light.size_y if two_sizes else light.size) * y.length
        rect = light.shape in ("SQUARE", "RECTANGLE")
        area = width * height if rect else 0.25 * math.pi * width * height
        if getattr(light, "normalize", True):
            scale = float(light.energy) / (math.pi * area)
        else:
            scale = float(light.energy) / math.pi
        if getattr(light, "spread", math.pi) < math.pi - 1e-6:
            self.warn(f"{obj.name}: the area lamp's spread is not applied (it emits over the hemisphere)")
        self.desc.setdefault("light", []).append({
            "type": "rect" if rect else "disk",
            "name": obj.name,
            "position": list(world.to_translation()),
            "direction": list((-z).normalized()),
            "up": list(y.normalized()),
            "width": width,
            "height": height,
            "color": [float(c) * scale for c in light.color],
            "visible_to_camera": bool(obj.visible_camera),
        })

    def world(self) -> None:
        world = self.scene.world
        env: dict = {"radiance": [0.0, 0.0, 0.0]}
        self.desc["environment"] = env
        if world is None:
            return
        if world.node_tree is None:
            env["radiance"] = [float(c) for c in world.color]
            return
        out = next((n for n in world.node_tree.nodes
                    if n.bl_idname == "ShaderNodeOutputWorld" and n.is_active_output), None)
        links = out.inputs["Surface"].links if out else []
        if not links:
            return
        bg = links[0].from_node
        if bg.bl_idname != "ShaderNodeBackground":
            self.warn(f"world: node {bg.name!r} ({bg.bl_idname}) cannot be mapped: a black sky")
            return
        strength = float(bg.inputs["Strength"].default_value)
        colour = bg.inputs["Color"]
        if not colour.is_linked:
            env["radiance"] = [float(c) * strength for c in colour.default_value[:3]]
            return
        tex = colour.links[0].from_node
        if tex.bl_idname != "ShaderNodeTexEnvironment" or tex.image is None:
            self.warn(f"world: node {tex.name!r} ({tex.bl_idname}) cannot be mapped: a black sky")
            return
        if tex.projection != "EQUIRECTANGULAR" or tex.inputs["Vector"].is_linked:
            self.warn(f"world: {tex.name}: only an unmapped equirectangular texture is read")
        # Blender's equirectangular u starts at -X; cirrus's at -Z (after Y_UP).
        env.update({"map": bpy.path.abspath(tex.image.filepath), "intensity": strength, "rotation": -90.0})
        env.pop("radiance")

    def camera(self) -> None:
        cam = self.scene.camera
        if cam is None:
            self.warn("the scene has no camera: the volumes are framed")
            return
        data = cam.data
        if data.type != "PERSP":
            self.warn(f"{cam.name}: {data.type.lower()} cameras are rendered as perspective")
        if data.shift_x or data.shift_y:
            self.warn(f"{cam.name}: lens shift is not applied")
        if data.dof.use_dof:
            self.warn(f"{cam.name}: depth of field is not rendered")
        # The frame Blender itself computes (sensor fit, aspect) at depth 1.
        corners = data.view_frame(scene=self.scene)
        top = max(v.y for v in corners) / abs(corners[0].z)
        c = self.desc["camera"]
        c["matrix"] = rows(Y_UP @ cam.matrix_world.normalized())
        c["fov"] = math.degrees(2.0 * math.atan(top))
        c["clipping"] = [float(data.clip_start), float(data.clip_end)]

    def drop_idle_near_clip(self) -> None:
        """A clip start that clips no volume, written as 0: the same image,
        and one the GPU renders (it refuses near clipping). Clipping hides
        what lies nearer than the plane at the clip start along the view,
        so it clips nothing when every volume's box lies past that plane
        (the box is convex: its nearest point is a corner). Kept whenever
        anything moves over the shutter."""
        c = self.desc["camera"]
        cam = self.scene.camera
        if "clipping" not in c or "shutter" in self.desc["render"] or not self.corners:
            return
        m = cam.matrix_world.normalized()
        eye = m.translation
        forward = -(m.to_3x3() @ mathutils.Vector((0.0, 0.0, 1.0))).normalized()
        nearest = min((p - eye).dot(forward) for p in self.corners)
        if nearest >= c["clipping"][0]:
            c["clipping"][0] = 0.0

    def motion(self) -> None:
        r = self.scene.render
        if not r.use_motion_blur:
            return
        length = float(r.motion_blur_shutter)
        start = {"START": 0.0, "CENTER": -0.5 * length, "END": -length}[r.motion_blur_position]
        self.desc["render"]["shutter"] = [start, start + length]


def coefficients(scatter: list[float], absorb: list[float]) -> dict:
    """Extinction per unit density and albedo from scattering and absorption."""
    sigma_t = [s + a for s, a in zip(scatter, absorb)]
    albedo = [s / t if t > 0 else 0.0 for s, t in zip(scatter, sigma_t)]
    grey = max(sigma_t) - min(sigma_t) <= 1e-7 * max(max(sigma_t), 1e-30)
    return {"density_scale": sigma_t[0] if grey else sigma_t, "albedo": albedo}


def volume_node(mat):
    """The node feeding the active material output's Volume input."""
    if mat is None or mat.node_tree is None:
        return None
    outs = [n for n in mat.node_tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial"]
    out = next((n for n in outs if n.is_active_output and n.target in ("ALL", "CYCLES")), None)
    out = out or next(iter(outs), None)
    if out is None or not out.inputs["Volume"].links:
        return None
    return out.inputs["Volume"].links[0].from_node


def scene_description(depsgraph, res: tuple[int, int]) -> tuple[dict, list[str]]:
    """The cirrus description of the evaluated scene, and what was not mapped."""
    export = Export(depsgraph, res)
    return export.run(), export.warnings
