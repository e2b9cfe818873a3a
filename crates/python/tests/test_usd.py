"""USD stages authored by Pixar's usd-core render as the TOML scenes that
say the same things: bit for bit where both give the same numbers, within
noise where the camera is given another way (and a moved volume fails
that same check); a stage's frames render their own files and camera; a
moving transform blurs as the average of its instants; what cirrus does
not render is named in a warning.
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pxr = pytest.importorskip("pxr")
from pxr import Gf, Sdf, Usd, UsdGeom  # noqa: E402

import cirrus  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))
import usd_stages as us  # noqa: E402

RES = 48
F32 = np.float32


def f32(x) -> float:
    return float(F32(x))


def sun_matrix() -> Gf.Matrix4d:
    rot = Gf.Rotation(Gf.Vec3d(1, 0, 0), -50) * Gf.Rotation(Gf.Vec3d(0, 1, 0), 30)
    return Gf.Matrix4d().SetRotate(rot)


def author_shot(d: Path, instances=(("A", 0.0), ("B", 300.0)), mesh=False) -> Path:
    """A shot: a cloud asset in its own layer, referenced twice as
    instances under a scaled parent; a distant light, a dome light with an
    HDR map, a camera named by the render settings."""
    d.mkdir(parents=True, exist_ok=True)
    shutil.copy(us.CLOUD, d / "cloud.vdb")
    shutil.copy(us.SKY, d / "sky.exr")
    asset = us.new_stage(d / "cloud_asset.usda")
    root = UsdGeom.Xform.Define(asset, "/Cloud")
    asset.SetDefaultPrim(root.GetPrim())
    mat = us.material(asset, "/Cloud/Materials/Smoke")
    vol = us.cloud_volume(asset, "/Cloud/Volume", "./cloud.vdb", mat)
    UsdGeom.XformCommonAPI(vol.GetPrim()).SetTranslate(Gf.Vec3d(-100, 0, 30))
    asset.GetRootLayer().Save()
    shot = us.new_stage(d / "shot.usda")
    world = UsdGeom.Xform.Define(shot, "/World")
    UsdGeom.XformCommonAPI(world.GetPrim()).SetTranslate(Gf.Vec3d(10, 0, 0))
    UsdGeom.XformCommonAPI(world.GetPrim()).SetScale(Gf.Vec3f(0.5, 0.5, 0.5))
    for name, x in instances:
        p = shot.DefinePrim(f"/World/Cloud{name}")
        p.GetReferences().AddReference("./cloud_asset.usda")
        p.SetInstanceable(True)
        UsdGeom.XformCommonAPI(p).SetTranslate(Gf.Vec3d(x, 0, 0))
    sun = pxr.UsdLux.DistantLight.Define(shot, "/Lights/Sun")
    sun.CreateIntensityAttr(3.0)
    sun.CreateColorAttr(Gf.Vec3f(1.0, 0.95, 0.9))
    sun.CreateAngleAttr(0.53)
    sun.CreateNormalizeAttr(True)
    sun.AddTransformOp().Set(sun_matrix())
    us.dome_light(shot, "./sky.exr")
    us.camera(shot, eye=(120.0, 60.0, -180.0), target=(80.0, 30.0, 30.0))
    us.render_settings(shot, res=(RES, RES))
    if mesh:
        UsdGeom.Mesh.Define(shot, "/World/Ground")
    shot.GetRootLayer().Save()
    return d / "shot.usda"


def camera_twin(cam: Gf.Matrix4d) -> dict:
    """The `[camera]` of `us.camera` with the world matrix `cam`."""
    return {
        "res": f"{RES}x{RES}",
        "matrix": us.rows(cam),
        "focal_length": 35.0,
        "horizontal_aperture": 24.0,
        "vertical_aperture": 24.0,
        "clipping": [1.0, 100000.0],
    }


def shot_twin(d: Path, camera: dict | None = None, moved: float = 0.0) -> dict:
    """The TOML scene of `author_shot`, with numbers from usd-core."""
    stage = Usd.Stage.Open(str(d / "shot.usda"))
    cam = UsdGeom.Xformable(stage.GetPrimAtPath("/Cam")).ComputeLocalToWorldTransform(0)
    sun = sun_matrix()
    medium = {"density_scale": f32(us.DENSITY), "albedo": [f32(c) for c in us.ALBEDO], "g": us.G}
    vol = lambda x: {  # noqa: E731
        "file": str(d / "cloud.vdb"),
        "density": "density",
        **medium,
        "transform": {"translate": [10 + 0.5 * (x - 100) + moved, 0.0, 15.0], "scale": 0.5},
    }
    return {
        "camera": camera or camera_twin(cam),
        "sun": {
            "direction": [-sun[2][0], -sun[2][1], -sun[2][2]],
            "irradiance": [float(F32(c)) * 3.0 for c in (1.0, 0.95, 0.9)],
            "angle": 0.53,
        },
        "environment": {"map": str(d / "sky.exr"), "intensity": 0.5, "rotation": 0.0},
        "volume": [vol(0.0), vol(300.0)],
    }


def render(scene, **kw) -> np.ndarray:
    kw.setdefault("spp", 8)
    kw.setdefault("seed", 1)
    image, _ = cirrus.render(scene, **kw)
    return image


def test_a_composed_shot_renders_as_its_toml_twin_bit_for_bit(tmp_path):
    shot = author_shot(tmp_path)
    usd = render(shot)
    twin = render(shot_twin(tmp_path))
    assert usd[..., 3].mean() > 0.05, "the clouds are in view"
    assert np.array_equal(usd, twin)
    # The same stage as a binary crate, and packaged with its layers, VDB
    # and sky by usd-core into a .usdz, reads the same.
    layer = Sdf.Layer.FindOrOpen(str(shot))
    layer.Export(str(tmp_path / "shot.usdc"))
    assert np.array_equal(render(tmp_path / "shot.usdc"), usd)
    from pxr import UsdUtils

    assert UsdUtils.CreateNewUsdzPackage(Sdf.AssetPath(str(shot)), str(tmp_path / "shot.usdz"))
    (tmp_path / "cloud.vdb").unlink()  # the package's own copy is read
    assert np.array_equal(render(tmp_path / "shot.usdz"), usd)


def block_z(a1, a2, b1, b2, blocks=4) -> np.ndarray:
    """Per block, (mean a - mean b) over its standard error, each error from
    the per-pixel spread between a render's two seeds."""
    lum = [x[..., :3].mean(axis=-1).astype(np.float64) for x in (a1, a2, b1, b2)]
    n = RES // blocks
    z = np.zeros((blocks, blocks))
    for i in range(blocks):
        for j in range(blocks):
            s = [x[i * n:(i + 1) * n, j * n:(j + 1) * n] for x in lum]
            var = lambda p, q: 0.5 * np.mean((p - q) ** 2) / (2 * p.size)  # noqa: E731
            diff = 0.5 * (s[0].mean() + s[1].mean()) - 0.5 * (s[2].mean() + s[3].mean())
            z[i, j] = diff / math.sqrt(var(s[0], s[1]) + var(s[2], s[3]) + 1e-14)
    return z


def test_a_look_at_camera_agrees_within_noise_and_a_moved_volume_does_not(tmp_path):
    shot = author_shot(tmp_path)
    eye, target = (120.0, 60.0, -180.0), (80.0, 30.0, 30.0)
    look = {"res": f"{RES}x{RES}", "from": list(eye), "to": list(target), "up": [0, 1, 0],
            "fov": us.fov_of(35.0, 24.0)}
    usd = [render(shot, spp=32, seed=s) for s in (1, 2)]
    same = [render(shot_twin(tmp_path, camera=look), spp=32, seed=s) for s in (3, 4)]
    moved = [render(shot_twin(tmp_path, camera=look, moved=10.0), spp=32, seed=s) for s in (3, 4)]
    z_same = block_z(*usd, *same)
    z_moved = block_z(*usd, *moved)
    print("look-at twin z:", np.round(z_same, 2), "moved z:", np.round(z_moved, 2), sep="\n")
    assert np.abs(z_same).max() < 5.0
    assert np.abs(z_moved).max() > 8.0


def test_a_stage_with_a_mesh_renders_with_a_warning_naming_it(tmp_path):
    shot = author_shot(tmp_path, mesh=True)
    with pytest.warns(cirrus.SceneWarning, match=r"/World/Ground \(Mesh\)"):
        image, stats = cirrus.render(shot, spp=1)
    assert any("/World/Ground (Mesh)" in w for w in stats["warnings"])
    assert image[..., 3].mean() > 0.05


def author_frames(d: Path) -> Path:
    """Three frames: the camera moves along x (time-sampled), the volume
    file is the cloud on frames 1 and 3 and a fog sphere on frame 2. A
    binary crate: openusd 0.6 reads time-sampled asset paths only there."""
    d.mkdir(parents=True, exist_ok=True)
    shutil.copy(us.CLOUD, d / "cloud.vdb")
    shutil.copy(us.REPO / "data" / "sphere_fog.vdb", d / "sphere.vdb")
    stage = us.new_stage(d / "frames.usdc", start=1, end=3)
    vol = us.cloud_volume(stage, "/Cloud", "./cloud.vdb", us.material(stage))
    path = vol.GetPrim().GetPrimAtPath("density").GetAttribute("filePath")
    for t, f in ((1, "./cloud.vdb"), (2, "./sphere.vdb"), (3, "./cloud.vdb")):
        path.Set(Sdf.AssetPath(f), t)
    cam = UsdGeom.Camera.Define(stage, "/Cam")
    cam.CreateFocalLengthAttr(35.0)
    op = cam.AddTranslateOp()
    for t in (1, 2, 3):
        op.Set(Gf.Vec3d(110.0 + 10.0 * t, 60.0, 400.0), t)
    dome = pxr.UsdLux.DomeLight.Define(stage, "/Sky")
    dome.CreateIntensityAttr(1.0)
    us.render_settings(stage, res=(24, 24))
    stage.GetRootLayer().Save()
    return d / "frames.usdc"


def frame_twin(d: Path, t: int) -> dict:
    file = d / ("sphere.vdb" if t == 2 else "cloud.vdb")
    m = [[1.0, 0, 0, 110.0 + 10.0 * t], [0, 1.0, 0, 60.0], [0, 0, 1.0, 400.0], [0, 0, 0, 1.0]]
    return {
        "render": {"frame": float(t)},
        "camera": {"res": "24x24", "matrix": m, "focal_length": 35.0, "clipping": [1.0, 1e6]},
        "sun": {"enabled": False},
        "environment": {"radiance": [1.0, 1.0, 1.0]},
        "volume": [{"file": str(file), "density": "density", "density_scale": f32(us.DENSITY),
                    "albedo": [f32(c) for c in us.ALBEDO], "g": us.G,
                    "transform": {"matrix": [[1.0, 0, 0, 0], [0, 1.0, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1.0]]}}],
    }


def read_exr(path: Path) -> np.ndarray:
    import OpenEXR

    with OpenEXR.File(str(path), separate_channels=True) as f:
        ch = {name: np.asarray(c.pixels) for name, c in f.channels().items()}
    return np.stack([ch[c] for c in "RGBA"], axis=-1)


def test_a_three_frame_stage_renders_its_own_range_with_its_files_and_camera(tmp_path):
    stage = author_frames(tmp_path)
    cli = os.environ.get("CIRRUS_BIN", "cirrus")
    out = tmp_path / "out.####.exr"
    run = subprocess.run([cli, "render", str(stage), "-o", str(out), "--spp", "4", "--seed", "2"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "3 frames: 3 rendered" in run.stderr, run.stderr
    images = [read_exr(tmp_path / f"out.{t:04d}.exr") for t in (1, 2, 3)]
    for t, image in zip((1, 2, 3), images):
        twin = render(frame_twin(tmp_path, t), spp=4, seed=2)
        assert np.array_equal(image, twin), f"frame {t}"
    # The camera moved and the file changed: no two frames are alike.
    assert not np.array_equal(images[0], images[2])
    assert abs(images[1][..., 3].mean() - images[0][..., 3].mean()) > 0.01


def moving_scene(shutter=None, time=None, camera_moves=False) -> dict:
    """The cloud moving 40 units (voxels; 8 pixels) along x over frames
    0..1 (a volume with transform samples), or the camera moving the other
    way."""
    samples = lambda a, b: [  # noqa: E731
        {"time": 0.0, "matrix": [[1.0, 0, 0, a], [0, 1.0, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1.0]]},
        {"time": 1.0, "matrix": [[1.0, 0, 0, b], [0, 1.0, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1.0]]},
    ]
    cam = {"res": f"{RES}x{RES}", "fov": 40.0}
    eye = [[1.0, 0, 0, 117.0], [0, 1.0, 0, 60.0], [0, 0, 1.0, 420.0], [0, 0, 0, 1.0]]
    vol = {"file": str(us.CLOUD), "density_scale": 0.8, "albedo": 0.8, "g": 0.4}
    if camera_moves:
        cam["samples"] = [{"time": s["time"], "matrix": [row[:3] + [row[3] + e[3]] for row, e in
                                                           zip(s["matrix"], eye)]} for s in samples(0.0, -40.0)]
        vol["transform"] = {"matrix": samples(0.0, 0.0)[0]["matrix"]}
    else:
        cam["matrix"] = eye
        vol["transform"] = {"samples": samples(0.0, 40.0)}
    render_spec = {"frame": 0.0 if time is None else time}
    if shutter:
        render_spec["shutter"] = shutter
    return {"render": render_spec, "camera": cam, "sun": {"direction": [0.3, -1, -0.4]},
            "environment": {"radiance": [0.2, 0.25, 0.35]}, "volume": [vol]}


@pytest.mark.parametrize("camera_moves", [False, True], ids=["volume", "camera"])
def test_a_moving_transform_blurs_as_the_average_of_its_instants(camera_moves):
    k = 16
    blurred = [render(moving_scene(shutter=[0.0, 1.0], camera_moves=camera_moves), spp=64, seed=s)
               for s in (1, 2)]
    instants = [np.mean([render(moving_scene(time=(i + 0.5) / k, camera_moves=camera_moves),
                                spp=4, seed=100 * s + i) for i in range(k)], axis=0) for s in (1, 2)]
    # The control: the frame's own instant, unblurred.
    still = [render(moving_scene(time=0.0, camera_moves=camera_moves), spp=64, seed=s) for s in (1, 2)]
    z_avg = block_z(*blurred, *instants, blocks=8)
    z_still = block_z(*blurred, *still, blocks=8)
    print("blur vs instants:", np.round(z_avg, 2), "blur vs still:", np.round(z_still, 2), sep="\n")
    assert np.abs(z_avg).max() < 5.0
    assert np.abs(z_still).max() > 8.0


def down_matrix(at) -> Gf.Matrix4d:
    """A light at `at` turned so its -Z points down (-Y), exactly."""
    return Gf.Matrix4d(1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, at[0], at[1], at[2], 1)


def author_lights(d: Path) -> Path:
    """The cloud lit by every light kind the reader takes: a sun, a moon (a
    second distant light), a sphere light moved and scaled, a point spot
    shaped by UsdLux's ShapingAPI turned to point down, a rect light
    facing down and a cylinder light turned off the X axis."""
    from pxr import UsdLux

    d.mkdir(parents=True, exist_ok=True)
    shutil.copy(us.CLOUD, d / "cloud.vdb")
    stage = us.new_stage(d / "lights.usda")
    mat = us.material(stage)
    us.cloud_volume(stage, "/Cloud", "./cloud.vdb", mat)
    sun = UsdLux.DistantLight.Define(stage, "/Lights/Sun")
    sun.CreateIntensityAttr(3.0)
    sun.CreateNormalizeAttr(True)
    sun.AddTransformOp().Set(sun_matrix())
    moon = UsdLux.DistantLight.Define(stage, "/Lights/Moon")
    moon.CreateIntensityAttr(0.4)
    moon.CreateNormalizeAttr(True)
    moon.CreateAngleAttr(0.5)
    moon.AddTransformOp().Set(down_matrix((0.0, 0.0, 0.0)))
    bulb = UsdLux.SphereLight.Define(stage, "/Lights/Bulb")
    bulb.CreateRadiusAttr(4.0)
    bulb.CreateIntensityAttr(3.0)
    bulb.CreateExposureAttr(1.0)
    bulb.CreateColorAttr(Gf.Vec3f(1.0, 0.6, 0.3))
    UsdGeom.XformCommonAPI(bulb.GetPrim()).SetTranslate(Gf.Vec3d(140.0, 90.0, 20.0))
    UsdGeom.XformCommonAPI(bulb.GetPrim()).SetScale(Gf.Vec3f(2.0, 2.0, 2.0))
    lamp = UsdLux.SphereLight.Define(stage, "/Lights/Lamp")
    lamp.CreateRadiusAttr(0.5)
    lamp.CreateTreatAsPointAttr(True)
    lamp.CreateIntensityAttr(60000.0)
    shaping = UsdLux.ShapingAPI.Apply(lamp.GetPrim())
    shaping.CreateShapingConeAngleAttr(25.0)
    shaping.CreateShapingConeSoftnessAttr(0.3)
    lamp.AddTransformOp().Set(down_matrix((110.0, 200.0, 60.0)))
    panel = UsdLux.RectLight.Define(stage, "/Lights/Panel")
    panel.CreateWidthAttr(40.0)
    panel.CreateHeightAttr(25.0)
    panel.CreateIntensityAttr(2.5)
    panel.CreateNormalizeAttr(True)
    panel.AddTransformOp().Set(down_matrix((170.0, 190.0, 90.0)))
    tube = UsdLux.CylinderLight.Define(stage, "/Lights/Tube")
    tube.CreateLengthAttr(30.0)
    tube.CreateRadiusAttr(2.0)
    tube.CreateIntensityAttr(3.0)
    UsdGeom.XformCommonAPI(tube.GetPrim()).SetTranslate(Gf.Vec3d(120.0, 150.0, 40.0))
    UsdGeom.XformCommonAPI(tube.GetPrim()).SetRotate(Gf.Vec3f(0.0, 0.0, 30.0))
    us.camera(stage)
    us.render_settings(stage, res=(RES, RES))
    stage.GetRootLayer().Save()
    return d / "lights.usda"


def lights_twin(d: Path) -> dict:
    """The TOML scene of `author_lights`, its lights' numbers from usd-core."""
    stage = Usd.Stage.Open(str(d / "lights.usda"))
    world = lambda p: UsdGeom.Xformable(stage.GetPrimAtPath(p)).ComputeLocalToWorldTransform(0)  # noqa: E731
    cam = world("/Cam")
    sun = sun_matrix()
    moon = world("/Lights/Moon").TransformDir(Gf.Vec3d(0, 0, -1))
    bulb = world("/Lights/Bulb")
    lamp = world("/Lights/Lamp")
    panel = world("/Lights/Panel")
    tube = world("/Lights/Tube")
    axis = lamp.TransformDir(Gf.Vec3d(0, 0, -1))
    scale = sum(bulb.TransformDir(Gf.Vec3d(*e)).GetLength() for e in ((1, 0, 0), (0, 1, 0), (0, 0, 1))) / 3
    return {
        "camera": camera_twin(cam),
        "sun": {"direction": [-sun[2][0], -sun[2][1], -sun[2][2]], "irradiance": [3.0] * 3, "angle": 0.53},
        "environment": {"radiance": [0.0, 0.0, 0.0]},
        "light": [
            {"type": "distant", "name": "Moon", "direction": list(moon), "color": [0.4] * 3, "angle": 0.5},
            {
                "type": "sphere",
                "name": "Bulb",
                "position": list(bulb.Transform(Gf.Vec3d(0, 0, 0))),
                "radius": float(F32(4.0 * scale)),
                "color": [float(F32(6.0 * c)) for c in (1.0, F32(0.6), F32(0.3))],
                "normalize": False,
            },
            {
                "type": "spot",
                "name": "Lamp",
                "position": list(lamp.Transform(Gf.Vec3d(0, 0, 0))),
                "radius": 0.0,
                # A point of the sphere's own intensity: 60000 pi 0.5^2.
                "color": [float(F32(60000.0 * math.pi * 0.25))] * 3,
                "direction": list(axis),
                "cone_angle": 25.0,
                "cone_softness": float(F32(0.3)),
            },
            {
                "type": "rect",
                "name": "Panel",
                "position": list(panel.Transform(Gf.Vec3d(0, 0, 0))),
                "direction": list(panel.TransformDir(Gf.Vec3d(0, 0, -1))),
                "up": list(panel.TransformDir(Gf.Vec3d(0, 1, 0))),
                "width": 40.0,
                "height": 25.0,
                "color": [2.5] * 3,
                "normalize": True,
            },
            {
                "type": "cylinder",
                "name": "Tube",
                "position": list(tube.Transform(Gf.Vec3d(0, 0, 0))),
                "direction": list(tube.TransformDir(Gf.Vec3d(1, 0, 0))),
                "length": 30.0,
                "radius": 2.0,
                "color": [3.0] * 3,
                "normalize": False,
            },
        ],
        "volume": [
            {
                "file": str(d / "cloud.vdb"),
                "density": "density",
                "density_scale": f32(us.DENSITY),
                "albedo": [f32(c) for c in us.ALBEDO],
                "g": us.G,
            }
        ],
    }


def test_every_light_kind_renders_as_its_toml_twin_bit_for_bit(tmp_path):
    stage = author_lights(tmp_path)
    usd = render(stage)
    twin = render(lights_twin(tmp_path))
    assert usd[..., :3].mean() > 0.0
    assert np.array_equal(usd, twin)
    # And each light matters: without the lamp (its intensity zeroed in a
    # copy) the image changes.
    stage_ = Usd.Stage.Open(str(stage))
    stage_.GetPrimAtPath("/Lights/Lamp").GetAttribute("inputs:intensity").Set(0.0)
    stage_.GetRootLayer().Export(str(tmp_path / "no_lamp.usda"))
    assert not np.array_equal(render(tmp_path / "no_lamp.usda"), usd)
