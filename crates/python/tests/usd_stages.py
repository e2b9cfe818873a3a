"""Stages authored with Pixar's usd-core (the independent writer) for the
USD reader's tests, each beside the TOML scene that says the same things.

Every builder writes into a directory and returns the stage's path; the
TOML twins are dicts in the scene-file format (`cirrus.render` takes them).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdShade, UsdVol

REPO = Path(__file__).resolve().parents[3]
CLOUD = REPO / "data" / "cloud.vdb"
SKY = REPO / "data" / "sky.exr"

# The medium every stage binds, and its TOML form.
DENSITY, ALBEDO, G = 0.8, (0.9, 0.85, 0.8), 0.5
MEDIUM = {"density_scale": DENSITY, "albedo": list(ALBEDO), "g": G}
SUN_DIR_ROT = (-50.0, 30.0, 0.0)  # rotateXYZ degrees of the distant light


def material(stage: Usd.Stage, path: str = "/Materials/Smoke") -> UsdShade.Material:
    mat = UsdShade.Material.Define(stage, path)
    shader = UsdShade.Shader.Define(stage, path + "/Volume")
    shader.CreateIdAttr("cirrus:volume")
    shader.CreateInput("density", Sdf.ValueTypeNames.Float).Set(DENSITY)
    shader.CreateInput("albedo", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(*ALBEDO))
    shader.CreateInput("anisotropy", Sdf.ValueTypeNames.Float).Set(G)
    out = shader.CreateOutput("volume", Sdf.ValueTypeNames.Token)
    mat.CreateVolumeOutput().ConnectToSource(out)
    return mat


def cloud_volume(stage: Usd.Stage, path: str, vdb: str, mat: UsdShade.Material | None) -> UsdVol.Volume:
    vol = UsdVol.Volume.Define(stage, path)
    field = UsdVol.OpenVDBAsset.Define(stage, path + "/density")
    field.CreateFilePathAttr(Sdf.AssetPath(vdb))
    field.CreateFieldNameAttr("density")
    vol.CreateFieldRelationship("density", field.GetPath())
    if mat is not None:
        UsdShade.MaterialBindingAPI.Apply(vol.GetPrim()).Bind(mat)
    return vol


def distant_light(stage: Usd.Stage, intensity=3.0, colour=(1.0, 0.95, 0.9)) -> None:
    sun = UsdLux.DistantLight.Define(stage, "/Lights/Sun")
    sun.CreateIntensityAttr(intensity)
    sun.CreateColorAttr(Gf.Vec3f(*colour))
    sun.CreateAngleAttr(0.53)
    sun.CreateNormalizeAttr(True)
    UsdGeom.XformCommonAPI(sun.GetPrim()).SetRotate(Gf.Vec3f(*SUN_DIR_ROT))


def sun_toml(intensity=3.0, colour=(1.0, 0.95, 0.9)) -> dict:
    """The same sun: a light's -Z axis after rotateXYZ (X, then Y, then Z)."""
    rx, ry, rz = (math.radians(a) for a in SUN_DIR_ROT)
    d = (0.0, 0.0, -1.0)
    d = (d[0], d[1] * math.cos(rx) - d[2] * math.sin(rx), d[1] * math.sin(rx) + d[2] * math.cos(rx))
    d = (d[0] * math.cos(ry) + d[2] * math.sin(ry), d[1], -d[0] * math.sin(ry) + d[2] * math.cos(ry))
    d = (d[0] * math.cos(rz) - d[1] * math.sin(rz), d[0] * math.sin(rz) + d[1] * math.cos(rz), d[2])
    return {"direction": list(d), "irradiance": [intensity * c for c in colour], "angle": 0.53}


def dome_light(stage: Usd.Stage, sky: str, intensity=0.5) -> None:
    dome = UsdLux.DomeLight.Define(stage, "/Lights/Sky")
    dome.CreateIntensityAttr(intensity)
    dome.CreateTextureFileAttr(Sdf.AssetPath(sky))
    dome.CreateTextureFormatAttr("latlong")


def camera(stage: Usd.Stage, path="/Cam", eye=(150.0, 120.0, -260.0), target=(117.0, 58.0, 68.0)):
    cam = UsdGeom.Camera.Define(stage, path)
    cam.CreateFocalLengthAttr(35.0)
    cam.CreateHorizontalApertureAttr(24.0)
    cam.CreateVerticalApertureAttr(24.0)
    cam.CreateClippingRangeAttr(Gf.Vec2f(1.0, 100000.0))
    m = look_at(eye, target)
    cam.AddTransformOp().Set(m)
    return cam, m


def look_at(eye, target, up=(0.0, 1.0, 0.0)) -> Gf.Matrix4d:
    """Camera-to-world (USD row vectors): the camera looks along -Z."""
    eye, target, up = Gf.Vec3d(*eye), Gf.Vec3d(*target), Gf.Vec3d(*up)
    f = (target - eye).GetNormalized()
    r = Gf.Cross(f, up).GetNormalized()
    u = Gf.Cross(r, f)
    return Gf.Matrix4d(r[0], r[1], r[2], 0, u[0], u[1], u[2], 0, -f[0], -f[1], -f[2], 0, eye[0], eye[1], eye[2], 1)


def rows(m: Gf.Matrix4d) -> list[list[float]]:
    """A USD (row-vector) matrix as the scene file's rows (column vectors)."""
    return [[m[c][r] for c in range(4)] for r in range(4)]


def fov_of(focal=35.0, aperture=24.0) -> float:
    return math.degrees(2 * math.atan(0.5 * aperture / focal))


def render_settings(stage: Usd.Stage, res=(64, 64), cam="/Cam") -> None:
    from pxr import UsdRender

    rs = UsdRender.Settings.Define(stage, "/Render/Settings")
    rs.CreateResolutionAttr(Gf.Vec2i(*res))
    rs.CreateCameraRel().SetTargets([cam])


def new_stage(path: Path, start=None, end=None) -> Usd.Stage:
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    if start is not None:
        stage.SetStartTimeCode(start)
        stage.SetEndTimeCode(end)
        stage.SetTimeCodesPerSecond(24)
    return stage
