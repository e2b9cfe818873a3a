"""The cirrus add-on inside Blender (PyPI's bpy, headless): installed from
its extension zip, it renders a scene built in Blender as Cycles renders
it (within noise, per block), renders animations, and reports what it
cannot map. Run by tools/test_blender.sh under CPython 3.13.
"""

from __future__ import annotations

import math
import os
import sys
import tempfile
import zipfile
from pathlib import Path

# Blender's user folders (where extensions install) in a scratch place.
os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="cirrus-blender-"))

import bpy  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

REPO = Path(__file__).resolve().parents[3]
ADDON = REPO / "python" / "cirrus_blender"
MODULE = "bl_ext.user_default.cirrus"
CLOUD = REPO / "data" / "cloud.vdb"
RES = 64
ALBEDO, DENSITY_PER_VOXEL, G = 0.8, 0.5, 0.4
SUN = dict(energy=3.0, color=(1.0, 0.95, 0.9), angle=math.radians(0.53))
SKY = (0.10, 0.15, 0.25)


def build_zip(out: Path) -> Path:
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
        for p in sorted(ADDON.glob("*.py")) + [ADDON / "blender_manifest.toml"]:
            z.write(p, p.name)
    return out


@pytest.fixture(scope="module")
def addon(tmp_path_factory):
    """The add-on installed from its zip, as Blender's Install from Disk does."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    zip_path = build_zip(tmp_path_factory.mktemp("addon") / "cirrus.zip")
    result = bpy.ops.extensions.package_install_files(
        filepath=str(zip_path), repo="user_default", enable_on_install=True)
    assert result == {"FINISHED"}
    return sys.modules[MODULE]


def voxel_size(vol) -> float:
    m = vol.grids["density"].matrix_object
    return math.sqrt(sum(m[r][0] ** 2 for r in range(3)))


def cloud_box(obj):
    """The centre (a Vector) and largest side of `obj`'s evaluated world
    bounding box."""
    import mathutils

    bpy.context.view_layer.update()
    evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    corners = [obj.matrix_world @ mathutils.Vector(c) for c in evaluated.bound_box]
    lo = mathutils.Vector([min(c[i] for c in corners) for i in range(3)])
    hi = mathutils.Vector([max(c[i] for c in corners) for i in range(3)])
    return 0.5 * (lo + hi), max(hi - lo)


def lights_off(scene) -> None:
    """The scene's sun hidden and its sky black."""
    scene.objects["Sun"].hide_render = True
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0


def look_at(eye, target):
    import mathutils

    eye, target = mathutils.Vector(eye), mathutils.Vector(target)
    return mathutils.Matrix.Translation(eye) @ (target - eye).to_track_quat("-Z", "Y").to_matrix().to_4x4()


def build_scene(extra_mesh: bool = False, vdb: Path = CLOUD, density_per_voxel: float = DENSITY_PER_VOXEL):
    """The corpus cloud (or `vdb`) as a volume object under a sun, a world
    colour and a camera; its Principled Volume is grey, albedo ALBEDO."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    # Factory settings disable add-ons; the installed extension stays.
    bpy.ops.preferences.addon_enable(module=MODULE)
    scene = bpy.context.scene
    vol = bpy.data.volumes.new("cloud")
    vol.filepath = str(vdb)
    vol.render.precision = "FULL"
    vol.render.clipping = 0.0
    vol.grids.load()
    obj = bpy.data.objects.new("Cloud", vol)
    scene.collection.objects.link(obj)
    mat = bpy.data.materials.new("Smoke")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    pv = nt.nodes.new("ShaderNodeVolumePrincipled")
    pv.inputs["Color"].default_value = (ALBEDO, ALBEDO, ALBEDO, 1.0)
    pv.inputs["Density"].default_value = density_per_voxel / voxel_size(vol)
    pv.inputs["Anisotropy"].default_value = G
    pv.inputs["Absorption Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(pv.outputs["Volume"], out.inputs["Volume"])
    vol.materials.append(mat)
    # Camera and sun around the cloud's box (Blender is Z-up).
    centre, size = cloud_box(obj)
    cam_data = bpy.data.cameras.new("Cam")
    cam_data.sensor_fit = "VERTICAL"
    cam_data.angle_y = math.radians(40.0)
    cam_data.clip_start = 1e-3
    cam_data.clip_end = 1e7
    cam = bpy.data.objects.new("Cam", cam_data)
    eye = (centre[0] + 0.2 * size, centre[1] - 1.05 * size, centre[2] + 0.3 * size)
    cam.matrix_world = look_at(eye, centre)
    scene.collection.objects.link(cam)
    scene.camera = cam
    sun_data = bpy.data.lights.new("Sun", "SUN")
    sun_data.energy, sun_data.color, sun_data.angle = SUN["energy"], SUN["color"], SUN["angle"]
    sun_data.normalize = True  # strength is the irradiance (cirrus's unit)
    sun = bpy.data.objects.new("Sun", sun_data)
    sun.rotation_euler = (math.radians(40.0), 0.0, math.radians(30.0))
    scene.collection.objects.link(sun)
    world = bpy.data.worlds.new("Sky")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (*SKY, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    scene.world = world
    if extra_mesh:
        bpy.ops.mesh.primitive_cube_add(size=1.0, location=(1e4, 0, 0))
    r = scene.render
    r.resolution_x = r.resolution_y = RES
    r.resolution_percentage = 100
    r.film_transparent = False
    r.use_compositing = False
    r.use_sequencer = False
    r.threads_mode = "FIXED"
    r.threads = 2
    r.image_settings.file_format = "OPEN_EXR"
    r.image_settings.color_depth = "32"
    r.image_settings.color_mode = "RGBA"
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    return scene, mat


def cycles_settings(scene, spp: int, seed: int) -> None:
    """A fair Cycles: unbiased null-scattering volumes, no clamping, no
    adaptive sampling, box filter of one pixel, independent pixels."""
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = spp
    cy.seed = seed
    cy.use_adaptive_sampling = False
    cy.sample_clamp_direct = cy.sample_clamp_indirect = 0.0
    cy.light_sampling_threshold = 0.0
    cy.sampling_pattern = "TABULATED_SOBOL"
    cy.volume_biased = False
    cy.pixel_filter_type = "BOX"
    cy.filter_width = 1.0
    cy.use_guiding = False
    cy.max_bounces = cy.volume_bounces = cy.transparent_max_bounces = 1024
    cy.diffuse_bounces = cy.glossy_bounces = cy.transmission_bounces = 0
    cy.min_light_bounces = cy.min_transparent_bounces = 0
    cy.use_denoising = False
    cy.film_exposure = 1.0
    for lamp in bpy.data.lights:
        lamp.cycles.max_bounces = 1024


def render_to_array(scene, path: Path) -> np.ndarray:
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(str(path), check_existing=False)
    w, h = img.size
    px = np.array(img.pixels[:], dtype=np.float64).reshape(h, w, 4)[::-1]
    bpy.data.images.remove(img)
    return px


def block_stats(a: np.ndarray, b: np.ndarray, blocks: int):
    """Per block: the mean of two renders and its variance, from the
    per-pixel spread between them (pixels are independent)."""
    h, w = a.shape
    n = h // blocks
    means, variances = np.zeros((blocks, blocks)), np.zeros((blocks, blocks))
    for i in range(blocks):
        for j in range(blocks):
            sa = a[i * n:(i + 1) * n, j * n:(j + 1) * n]
            sb = b[i * n:(i + 1) * n, j * n:(j + 1) * n]
            means[i, j] = 0.5 * (sa.mean() + sb.mean())
            var_pixel = 0.5 * np.mean((sa - sb) ** 2)
            variances[i, j] = var_pixel / (2 * sa.size)
    return means, variances


def test_cirrus_renders_the_blender_scene_as_cycles_does(addon, tmp_path):
    scene, _ = build_scene()
    assert_renders_as_cycles(addon, scene, tmp_path)


def add_lamps(scene) -> None:
    """The sun and sky off; a point lamp with a radius beside the cloud and
    a spot lamp above it, its cone on part of it, soft falloff off (the
    exact ball Cycles then renders)."""
    import mathutils

    lights_off(scene)
    centre, size = cloud_box(scene.objects["Cloud"])
    for name, kind, offset, energy in (
        ("Bulb", "POINT", (0.6, -0.3, 0.1), 6.0),
        ("Beam", "SPOT", (0.0, 0.0, 0.9), 12.0),
    ):
        data = bpy.data.lights.new(name, kind)
        data.energy = energy * 4.0 * math.pi * size * size
        data.color = (1.0, 0.9, 0.7) if kind == "POINT" else (0.7, 0.85, 1.0)
        data.shadow_soft_size = 0.04 * size if kind == "POINT" else 0.0
        if hasattr(data, "use_soft_falloff"):
            data.use_soft_falloff = False
        if kind == "SPOT":
            data.spot_size = math.radians(40.0)
            data.spot_blend = 0.3
        lamp = bpy.data.objects.new(name, data)
        lamp.location = centre + size * mathutils.Vector(offset)
        lamp.rotation_euler = (0.0, math.radians(10.0), 0.0)  # -Z nearly down
        lamp.visible_camera = False  # cirrus's lamps light, camera rays miss them
        scene.collection.objects.link(lamp)


def test_point_and_spot_lamps_render_as_cycles_does(addon, tmp_path):
    scene, _ = build_scene()
    add_lamps(scene)
    assert_renders_as_cycles(addon, scene, tmp_path)
    warnings = [m for _, m in addon.engine.REPORTS]
    assert not any("lamps are not rendered" in m for m in warnings), warnings


def add_area_lamps(scene) -> None:
    """A rectangle beside the cloud facing it (its light along local -Z,
    turned to -X) and an ellipse above it facing down."""
    import mathutils

    centre, size = cloud_box(scene.objects["Cloud"])
    for name, shape, offset, rotation in (
        ("Panel", "RECTANGLE", (0.7, -0.2, 0.0), (0.0, math.radians(90.0), 0.0)),
        ("Ceiling", "ELLIPSE", (0.0, 0.0, 0.7), (0.0, 0.0, math.radians(30.0))),
    ):
        data = bpy.data.lights.new(name, "AREA")
        data.shape = shape
        data.size, data.size_y = 0.3 * size, 0.15 * size
        data.energy = 40.0 * size * size
        lamp = bpy.data.objects.new(name, data)
        lamp.location = centre + size * mathutils.Vector(offset)
        lamp.rotation_euler = rotation
        lamp.visible_camera = False  # cirrus's lamps light, camera rays miss them
        scene.collection.objects.link(lamp)


def test_area_lamps_render_as_cycles_does(addon, tmp_path):
    """The area lamps alone, the sun and sky off."""
    scene, _ = build_scene()
    add_lamps(scene)
    for name in ("Bulb", "Beam"):
        scene.objects[name].hide_render = True
    add_area_lamps(scene)
    assert_renders_as_cycles(addon, scene, tmp_path)
    warnings = [m for _, m in addon.engine.REPORTS]
    assert not any("lamps are not rendered" in m for m in warnings), warnings


def test_every_lamp_kind_together_renders_as_cycles_does(addon, tmp_path):
    """The sun, the sky, a point, a spot, a rectangle and an ellipse
    lighting the cloud at once."""
    scene, _ = build_scene()
    background = scene.world.node_tree.nodes["Background"].inputs["Strength"]
    sky = background.default_value
    add_lamps(scene)
    add_area_lamps(scene)
    scene.objects["Sun"].hide_render = False
    background.default_value = sky
    assert sky > 0.0
    assert_renders_as_cycles(addon, scene, tmp_path)
    warnings = [m for _, m in addon.engine.REPORTS]
    assert not any("lamps are not rendered" in m for m in warnings), warnings


FOG = REPO / "data" / "tile_box.vdb"


def fog_scene():
    """A box of homogeneous fog (`tile_box.vdb`) with the sun and sky off,
    its centre and largest side."""
    scene, _ = build_scene(vdb=FOG, density_per_voxel=0.01)
    lights_off(scene)
    centre, size = cloud_box(scene.objects["Cloud"])
    return scene, centre, size


@pytest.mark.parametrize("kind", ["POINT", "SPOT", "AREA", "SUN"])
def test_each_lamp_alone_lights_a_box_of_fog_as_cycles_does(addon, tmp_path, kind):
    """A box of homogeneous fog (`tile_box.vdb`, 0.64 mean free paths
    across: equi-angular sampling on under `auto`) lit by one lamp of each
    kind, the sun and sky off. Points and spots sit above the fog; lamps
    inside fog (where the fog within a spot's ball is lit unshaped, as in
    Cycles) are tested by
    `test_lamps_inside_and_outside_fog_with_and_without_soft_falloff`."""
    import mathutils

    scene, centre, size = fog_scene()
    data = bpy.data.lights.new(kind.title(), kind)
    data.color = (1.0, 0.85, 0.7)
    if kind == "SUN":
        data.energy, data.angle = 2.0, math.radians(3.0)
    else:
        data.energy = 3.0 * 4.0 * math.pi * (0.3 * size) ** 2
    if kind in ("POINT", "SPOT"):
        data.shadow_soft_size = 0.03 * size
        data.use_soft_falloff = False
    if kind == "SPOT":
        data.spot_size, data.spot_blend = math.radians(50.0), 0.25
    if kind == "AREA":
        data.shape, data.size, data.size_y = "RECTANGLE", 0.25 * size, 0.15 * size
    lamp = bpy.data.objects.new(kind.title(), data)
    # Points and spots above the fog, out of view (see the docstring).
    up = 0.3 if kind in ("AREA", "SUN") else 0.9
    lamp.location = centre + size * mathutils.Vector((0.1, 0.05, up))
    lamp.rotation_euler = (math.radians(20.0), 0.0, math.radians(10.0))
    lamp.visible_camera = False  # cirrus's lamps light, camera rays miss them
    scene.collection.objects.link(lamp)
    assert_renders_as_cycles(addon, scene, tmp_path)


def test_a_lamp_visible_to_the_camera_shows_its_ball_as_cycles_does(addon, tmp_path):
    """A point lamp with a radius between the camera and a box of fog,
    visible to the camera: the add-on passes the visibility, and both show
    the ball at the lamp's radiance (and light the fog behind it)."""
    import mathutils

    scene, centre, size = fog_scene()
    camera = scene.camera.matrix_world.to_translation()
    data = bpy.data.lights.new("Bulb", "POINT")
    data.energy = 3.0 * 4.0 * math.pi * (0.3 * size) ** 2
    data.shadow_soft_size = 0.05 * size
    data.use_soft_falloff = False
    lamp = bpy.data.objects.new("Bulb", data)
    lamp.location = camera + 0.5 * (centre - camera) + size * mathutils.Vector((0.1, 0.05, 0.0))
    lamp.visible_camera = True
    scene.collection.objects.link(lamp)
    assert_renders_as_cycles(addon, scene, tmp_path)


@pytest.mark.parametrize("kind", ["POINT", "SPOT"])
@pytest.mark.parametrize("soft", [True, False], ids=["soft", "ball"])
@pytest.mark.parametrize("where", ["inside", "outside"])
def test_lamps_inside_and_outside_fog_with_and_without_soft_falloff(addon, tmp_path, kind, soft, where):
    """A point or spot lamp of a large radius (a fifth of the box), Soft
    Falloff on (a disc facing each point, Blender's default) or off (the
    ball), inside a box of thicker fog (about 6 mean free paths across)
    or above it, hidden from the camera: as Cycles renders it. Inside,
    the fog within the ball glows (a point there sees the ball all round;
    a spot's cone does not apply there) and rays cross the lamp's surface
    without stopping.

    Inside the fog Cycles' image depends on the lamp's Multiple
    Importance switch: with it on (the default) Cycles 5.2 renders these
    lamps 4% (point, disc) to 59% (spot, ball) darker than with it off,
    which an unbiased estimate cannot do (the switch only reweighs light
    samples against scattered rays that meet the lamp); with it off,
    light samples alone, Cycles and cirrus agree. The lamp inside is
    compared with its switch off (README, Lamps inside media)."""
    import mathutils

    scene, _ = build_scene(vdb=FOG, density_per_voxel=0.1)
    lights_off(scene)
    centre, size = cloud_box(scene.objects["Cloud"])
    data = bpy.data.lights.new(kind.title(), kind)
    data.color = (1.0, 0.85, 0.7)
    data.energy = 2.0 * 4.0 * math.pi * (0.3 * size) ** 2
    data.shadow_soft_size = 0.2 * size
    data.use_soft_falloff = soft
    if kind == "SPOT":
        data.spot_size, data.spot_blend = math.radians(70.0), 0.25
    lamp = bpy.data.objects.new(kind.title(), data)
    up = 0.1 if where == "inside" else 0.8
    lamp.location = centre + size * mathutils.Vector((0.05, 0.05, up))
    lamp.rotation_euler = (math.radians(20.0), 0.0, math.radians(10.0))
    lamp.visible_camera = False
    data.cycles.use_multiple_importance_sampling = where == "outside"
    scene.collection.objects.link(lamp)
    assert_renders_as_cycles(addon, scene, tmp_path, res=32, spp=32)


def assert_renders_as_cycles(addon, scene, tmp_path, res: int = RES, spp: int = 64) -> None:
    """Two Cycles and two cirrus renders of `scene` at `res` x `res` pixels
    and `spp` samples agree within noise on the cloud's mean and per block
    of 16x16 pixels."""
    scene.render.resolution_x = scene.render.resolution_y = res
    cyc = []
    for seed in (1, 2):
        cycles_settings(scene, spp, seed)
        cyc.append(render_to_array(scene, tmp_path / f"cycles{seed}.exr"))
    scene.render.engine = "CIRRUS"
    scene.cirrus.spp = spp
    cir = []
    for seed in (1, 2):
        scene.cirrus.seed = seed
        cir.append(render_to_array(scene, tmp_path / f"cirrus{seed}.exr"))
    reports = [m for level, m in addon.engine.REPORTS]
    assert not any(level == "ERROR" for level, _ in addon.engine.REPORTS), reports
    # The cloud: where cirrus's alpha says a volume is.
    alpha = 0.5 * (cir[0][..., 3] + cir[1][..., 3])
    cloud = alpha > 0.05
    assert cloud.sum() > 0.1 * res * res, "the camera sees the cloud"
    lum = lambda px: px[..., :3].mean(axis=-1)  # noqa: E731
    ca, cb = lum(cir[0]), lum(cir[1])
    ya, yb = lum(cyc[0]), lum(cyc[1])
    # The cloud's mean: both renders of each, against the spread of pixels.
    def masked(a, b):
        d = (a - b)[cloud]
        return 0.5 * (a[cloud].mean() + b[cloud].mean()), 0.5 * np.mean(d ** 2) / (2 * d.size)
    mc, vc = masked(ca, cb)
    my, vy = masked(ya, yb)
    z = (mc - my) / math.sqrt(vc + vy)
    print(f"cloud mean: cirrus {mc:.5f} +- {math.sqrt(vc):.5f}, cycles {my:.5f} +- {math.sqrt(vy):.5f}, "
          f"ratio {mc / my:.4f}, z {z:+.2f}")
    assert abs(z) < 5.0
    # Per block of 16x16 pixels.
    bc, vbc = block_stats(ca, cb, res // 16)
    by, vby = block_stats(ya, yb, res // 16)
    zb = (bc - by) / np.sqrt(vbc + vby + 1e-12)
    print("block means cirrus:\n", np.round(bc, 4), "\ncycles:\n", np.round(by, 4), "\nz:\n", np.round(zb, 2))
    assert np.all(np.abs(zb) < 5.0), zb


def test_unmapped_nodes_and_objects_are_reported(addon, tmp_path):
    scene, mat = build_scene(extra_mesh=True)
    nt = mat.node_tree
    noise = nt.nodes.new("ShaderNodeTexNoise")
    noise.name = "Noise Texture"
    pv = next(n for n in nt.nodes if n.bl_idname == "ShaderNodeVolumePrincipled")
    nt.links.new(noise.outputs["Color"], pv.inputs["Color"])
    scene.render.engine = "CIRRUS"
    scene.render.resolution_x = scene.render.resolution_y = 8
    scene.cirrus.spp = 1
    render_to_array(scene, tmp_path / "reported.exr")
    warnings = [m for level, m in addon.engine.REPORTS if level == "WARNING"]
    assert any("Noise Texture" in m and "Color" in m for m in warnings), warnings
    assert any(m.startswith("Cube (mesh)") for m in warnings), warnings


def test_an_animation_renders_every_frame_with_depth(addon, tmp_path):
    scene, _ = build_scene()
    scene.render.engine = "CIRRUS"
    scene.render.resolution_x = scene.render.resolution_y = 16
    scene.cirrus.spp = 2
    scene.view_layers[0].use_pass_z = True
    scene.frame_start, scene.frame_end = 1, 2
    scene.render.filepath = str(tmp_path / "anim_####")
    scene.render.image_settings.exr_codec = "ZIP"
    scene.render.image_settings.use_preview = False
    bpy.ops.render.render(animation=True)
    frames = sorted(p.name for p in tmp_path.glob("anim_*.exr"))
    assert frames == ["anim_0001.exr", "anim_0002.exr"], frames
    img = bpy.data.images.load(str(tmp_path / "anim_0001.exr"))
    px = np.array(img.pixels[:]).reshape(16, 16, 4)
    assert px[..., 3].max() > 0.0, "the cloud covers some pixels"


def test_a_keyframed_lamp_is_exported_as_blender_evaluates_it_at_each_frame(addon):
    """Keyframes on a lamp's location and power reach each frame's
    description as Blender evaluates them there; the lamp holds still over
    the shutter (Cycles' lamps take no motion blur), so no keys are written."""
    scene, _ = build_scene()
    lights_off(scene)
    data = bpy.data.lights.new("Ember", "POINT")
    data.shadow_soft_size = 0.0
    lamp = bpy.data.objects.new("Ember", data)
    scene.collection.objects.link(lamp)
    for frame, x, energy in ((1, 0.0, 100.0), (3, 2.0, 300.0)):
        lamp.location = (x, 5.0, 1.0)
        data.energy = energy
        lamp.keyframe_insert("location", frame=frame)
        data.keyframe_insert("energy", frame=frame)
    for action in (lamp.animation_data.action, data.animation_data.action):
        for fcurve in fcurves(action):
            for k in fcurve.keyframe_points:
                k.interpolation = "LINEAR"
    scene.render.use_motion_blur = True
    for frame, x, energy in ((1, 0.0, 100.0), (2, 1.0, 200.0), (3, 2.0, 300.0)):
        scene.frame_set(frame)
        desc, _ = addon.export.scene_description(bpy.context.evaluated_depsgraph_get(), (8, 8))
        ember = next(l for l in desc["light"] if l["name"] == "Ember")
        # Blender's (x, y, z) is cirrus's (x, z, -y).
        assert ember["position"] == pytest.approx([x, 1.0, -5.0], abs=1e-5)
        assert ember["color"] == pytest.approx([energy / (4.0 * math.pi)] * 3, rel=1e-5)
        assert "keys" not in ember
        assert desc["render"]["shutter"][1] > desc["render"]["shutter"][0]


def fcurves(action):
    """An action's F-curves: on its layered channelbags (Blender 4.4 on) or
    its own list."""
    if hasattr(action, "layers") and action.layers:
        return [fc for layer in action.layers for strip in layer.strips
                for bag in strip.channelbags for fc in bag.fcurves]
    return list(action.fcurves)


def reports(addon, level: str) -> list[str]:
    return [m for lv, m in addon.engine.REPORTS if lv == level]


def no_adapter(messages: list[str]) -> bool:
    """Whether cirrus said there is no Vulkan adapter; then CI (which
    installs lavapipe) fails, and elsewhere the install hint is named."""
    none = any("no Vulkan adapter" in m for m in messages)
    if none:
        assert "CI" not in os.environ, messages
        assert any("mesa-vulkan-drivers" in m for m in messages), messages
    return none


def failed_render(scene) -> None:
    """A render whose engine reported an error: Blender's operator says so
    (in the interface, a message in the status bar), and writes nothing."""
    scene.render.filepath = ""
    with pytest.raises(RuntimeError, match="Error: "):
        bpy.ops.render.render(write_still=False)


def test_the_device_setting_chooses_where_cirrus_renders(addon, tmp_path):
    """Auto by default; GPU Compute renders the image `cirrus.render(...,
    device="gpu")` renders, bit for bit; what the GPU does not render (a
    pass) is an error report naming it, and no image; a pass sends Auto to
    the CPU, which says so; point and spot lamps render on the GPU."""
    import cirrus

    scene, _ = build_scene()
    scene.render.engine = "CIRRUS"
    scene.render.resolution_x = scene.render.resolution_y = 12
    assert scene.cirrus.device == "AUTO"
    scene.cirrus.spp, scene.cirrus.seed = 2, 3
    scene.cirrus.device = "GPU"
    try:
        image = render_to_array(scene, tmp_path / "gpu.exr")
    except RuntimeError:
        if no_adapter(reports(addon, "ERROR")):
            pytest.skip(str(reports(addon, "ERROR")))
        raise
    assert any(m.startswith("cirrus rendered on the GPU: ") for m in reports(addon, "INFO"))
    desc, _ = addon.export.scene_description(bpy.context.evaluated_depsgraph_get(), (12, 12))
    expected, stats = cirrus.render(desc, device="gpu", spp=2, seed=3)
    assert stats["device"].startswith("gpu: ")
    np.testing.assert_array_equal(image.astype(np.float32), expected)
    assert expected[..., 3].max() > 0.0, "the cloud is in view"

    # A pass the GPU does not render: refused by name, in Blender's words.
    scene.view_layers[0].cirrus.use_pass_albedo = True
    failed_render(scene)
    [error] = reports(addon, "ERROR")
    assert "Device GPU Compute does not render passes other than Combined" in error, error
    assert "set Device to CPU" in error, error
    # Auto takes the CPU for it (a hardware GPU would say why).
    scene.cirrus.device = "AUTO"
    render_to_array(scene, tmp_path / "auto.exr")
    assert reports(addon, "ERROR") == []
    assert "cirrus rendered on the CPU" in reports(addon, "INFO")
    scene.view_layers[0].cirrus.use_pass_albedo = False

    # Point and spot lamps render there too: the add-on's image is the
    # module's GPU image of what it exports.
    add_lamps(scene)
    scene.cirrus.device = "GPU"
    image = render_to_array(scene, tmp_path / "lamps.exr")
    assert reports(addon, "ERROR") == []
    bpy.context.view_layer.update()  # the lamps and the dark world, evaluated
    desc, _ = addon.export.scene_description(bpy.context.evaluated_depsgraph_get(), (12, 12))
    # The viewport's depsgraph still holds the sun `lights_off` hides from
    # renders only.
    desc.pop("sun")
    assert any(light.get("type") in ("sphere", "point", "spot") for light in desc.get("light", []))
    expected, _ = cirrus.render(desc, device="gpu", spp=2, seed=3)
    np.testing.assert_array_equal(image.astype(np.float32), expected)
