//! A description's lights (checked in `light_checks.rs`): the `[sun]` and `[environment]` shorthands
//! and the `[[light]]` tables, checked, turned into the renderer's light
//! list, and each tagged with its light-group layer.
//!
//! A light's strength is `intensity * 2^exposure * color`, as UsdLux
//! writes it: a distant light's irradiance (W/m^2 on a surface facing
//! it, as `[sun]`), a sphere's surface radiance (divided by its area
//! `4 pi r^2` where `normalize` is set), a point's radiant intensity
//! (W/sr; a point has no surface), an area light's radiance (a rect's,
//! a disk's or a cylinder's side; over its area where `normalize` is on), a dome's radiance or its map's
//! multiplier. A sphere of radius `r` and radiance `L` lights the far
//! field as a point of intensity `L pi r^2`.
//!
//! Light groups: a light's `group`, else its `name`, else its kind's
//! layer (`sun` for distant lights, `sky` for domes, `lights` for sphere,
//! spot and area lights); the layers are `sun`, `sky` and `emission`, then
//! the others in the order the lights name them.

use std::f32::consts::PI;
use std::path::Path;
use std::sync::Arc;

use cirrus_render::compositing::{DEFAULT_LIGHT_GROUPS, MAX_LIGHT_GROUPS};
use cirrus_render::kernel::light::LightsOverShutter;
use cirrus_render::{
    AreaLight, AreaShape, Environment, IntegratorKind, Light, Lights, SphereLight, Spot, Sun,
};
use glam::Vec3;

use crate::description::{LightSpec, SceneDescription};
use crate::error::{Error, Result};
use crate::light_checks::check_shorthands;

/// The angular diameter of a distant light where none is given: the sun's.
const DEFAULT_ANGLE_DEGREES: f32 = 0.53;
/// A sphere light's radius where none is given (UsdLux's fallback).
const DEFAULT_SPHERE_RADIUS: f32 = 0.5;
/// A disk or cylinder light's radius where none is given (UsdLux's
/// fallback).
const DEFAULT_DISK_RADIUS: f32 = 0.5;
/// A cylinder light's length where none is given (UsdLux's fallback).
const DEFAULT_CYLINDER_LENGTH: f32 = 1.0;
/// The layer of sphere and spot lights with no name or group.
const DEFAULT_LOCAL_GROUP: &str = "lights";

impl LightSpec {
    /// What the light is called in messages: its number (from 1), and
    /// its name where it has one.
    pub(crate) fn label(&self, i: usize) -> String {
        match &self.name {
            Some(name) => format!("light {} ({name:?})", i + 1),
            None => format!("light {}", i + 1),
        }
    }

    /// `intensity * 2^exposure * color`.
    pub(crate) fn strength(&self) -> Vec3 {
        let scale = self.intensity.unwrap_or(1.0) * self.exposure.unwrap_or(0.0).exp2();
        Vec3::from_array(self.color.unwrap_or([1.0; 3])) * scale
    }

    /// The light-group layer its light goes to.
    fn group_name(&self) -> &str {
        if let Some(g) = self.group.as_deref().or(self.name.as_deref()) {
            return g;
        }
        match self.kind.as_str() {
            "distant" => DEFAULT_LIGHT_GROUPS[0],
            "dome" => DEFAULT_LIGHT_GROUPS[1],
            _ => DEFAULT_LOCAL_GROUP,
        }
    }

    /// The renderer's light (checked by [`Self::check`]); a dome's map is
    /// read here.
    pub(crate) fn light(&self) -> Result<Light> {
        let strength = self.strength();
        let v3 = |v: Option<[f32; 3]>| Vec3::from_array(v.unwrap_or_default());
        Ok(match self.kind.as_str() {
            "distant" => Sun::new(
                v3(self.direction),
                strength,
                self.angle.unwrap_or(DEFAULT_ANGLE_DEGREES).to_radians(),
            )
            .into(),
            "rect" | "disk" | "cylinder" => self
                .area_light(strength)
                .seen_by_camera(self.visible_to_camera.unwrap_or(false))
                .into(),
            "dome" => match &self.map {
                None => Environment::new(strength).into(),
                Some(path) => {
                    let map = cirrus_render::read_env_map(path, self.rotation.unwrap_or(0.0))?;
                    Environment::from_map(Arc::new(map), strength).into()
                }
            },
            kind => {
                let default_radius = if kind == "sphere" {
                    DEFAULT_SPHERE_RADIUS
                } else {
                    0.0
                };
                let r = self.radius.unwrap_or(default_radius);
                let light = SphereLight::new(v3(self.position), r, intensity(strength, r, self))
                    .seen_by_camera(self.visible_to_camera.unwrap_or(false))
                    .with_soft_falloff(self.soft_falloff.unwrap_or(false));
                match kind {
                    "spot" => light.with_spot(Spot::new(
                        v3(self.direction),
                        self.cone_angle.unwrap_or(180.0).to_radians(),
                        self.cone_softness.unwrap_or(0.0),
                    )),
                    _ => light,
                }
                .into()
            }
        })
    }
}

impl LightSpec {
    /// A `rect`, `disk` or `cylinder` light of strength `strength`
    /// (checked): its radiance, over its area where normalised.
    fn area_light(&self, strength: Vec3) -> AreaLight {
        let unit = self.area_shape(strength);
        if self.normalize.unwrap_or(false) {
            self.area_shape(strength / unit.area())
        } else {
            unit
        }
    }

    /// The area light's shape, of radiance `radiance`.
    fn area_shape(&self, radiance: Vec3) -> AreaLight {
        let v3 = |v: Option<[f32; 3]>| Vec3::from_array(v.unwrap_or_default());
        let (centre, normal) = (v3(self.position), v3(self.direction).normalize());
        let radius = self.radius.unwrap_or(DEFAULT_DISK_RADIUS);
        let (shape, w, h) = match self.kind.as_str() {
            "cylinder" => {
                let length = self.length.unwrap_or(DEFAULT_CYLINDER_LENGTH);
                return AreaLight::cylinder(centre, normal, length, radius, radiance);
            }
            "rect" => (
                AreaShape::Rect,
                self.width.unwrap_or(1.0),
                self.height.unwrap_or(1.0),
            ),
            _ => (
                AreaShape::Disk,
                self.width.unwrap_or(2.0 * radius),
                self.height.unwrap_or(2.0 * radius),
            ),
        };
        // The height's axis: `up` square to the normal, else +Y, else +Z.
        let up = [self.up.map(Vec3::from_array), Some(Vec3::Y), Some(Vec3::Z)]
            .into_iter()
            .flatten()
            .map(|u| u - u.dot(normal) * normal)
            .find(|u| u.length_squared() > 1e-8)
            .unwrap_or(Vec3::Y)
            .normalize();
        let across = up.cross(normal);
        AreaLight::new(
            shape,
            centre,
            0.5 * w * across,
            0.5 * h * up,
            normal,
            radiance,
        )
    }
}

/// The radiant intensity of a sphere of radius `r` whose strength is
/// `strength`: its radiance times its projected area `pi r^2`; where
/// normalised, its radiance is `strength / (4 pi r^2)`, so its intensity
/// is `strength / 4` whatever the radius (computed so: the product of the
/// two would be `inf x 0` for a tiny radius). A point's strength is its
/// intensity.
fn intensity(strength: Vec3, r: f32, spec: &LightSpec) -> Vec3 {
    if r <= 0.0 {
        strength
    } else if spec.normalize.unwrap_or(false) {
        0.25 * strength
    } else {
        strength * (PI * r * r)
    }
}

/// The light-group layers of `desc`: `sun`, `sky` and `emission`, then
/// each other group its lights name, in order; more than the film keeps
/// is an error (asked for where light groups are written).
pub fn light_group_names(desc: &SceneDescription) -> Result<Vec<String>> {
    group_names(&desc.lights).map_err(Error::input)
}

/// Each light's group name, in the layers' order (`sun`, `sky`,
/// `emission`, then as the lights name them), however many.
fn all_group_names(lights: &[LightSpec]) -> Vec<String> {
    let mut names: Vec<String> = DEFAULT_LIGHT_GROUPS.iter().map(|s| s.to_string()).collect();
    for spec in lights {
        let g = spec.group_name();
        if !names.iter().any(|n| n == g) {
            names.push(g.to_string());
        }
    }
    names
}

/// [`light_group_names`] of `lights`; more than the film keeps is an
/// error, its list cut after a few names.
fn group_names(lights: &[LightSpec]) -> std::result::Result<Vec<String>, String> {
    let names = all_group_names(lights);
    if names.len() > MAX_LIGHT_GROUPS {
        return Err(format!(
            "{} light groups ({}); at most {MAX_LIGHT_GROUPS}: give lights a shared `group`",
            names.len(),
            listed(&names, 10)
        ));
    }
    Ok(names)
}

/// The first `most` names joined, then how many more: "a, b, ... and 9990
/// more".
pub(crate) fn listed(names: &[String], most: usize) -> String {
    if names.len() <= most {
        return names.join(", ");
    }
    format!(
        "{}, ... and {} more",
        names[..most].join(", "),
        names.len() - most
    )
}

/// The lights of `desc`, each tagged with its light group's index in
/// [`light_group_names`]; black lights pruned. Without `[[light]]` the
/// sun and sky are there unless switched off; with any, only where their
/// tables (or flags) are given.
pub fn lights(desc: &SceneDescription) -> Result<Lights> {
    check_shorthands(desc).map_err(Error::input)?;
    // The groups tag each light's contributions; where there are more than
    // the film keeps (which only matters where light groups are written,
    // and is refused there), lights are tagged by their kind's layer.
    let names = match group_names(&desc.lights) {
        Ok(names) => names,
        Err(_) => DEFAULT_LIGHT_GROUPS.iter().map(|s| s.to_string()).collect(),
    };
    // Domes to `sky`; every other kind to `sun`, as the kernel's own
    // default groups put them.
    let kind_layer = |spec: &LightSpec| match spec.kind.as_str() {
        "dome" => DEFAULT_LIGHT_GROUPS[1],
        _ => DEFAULT_LIGHT_GROUPS[0],
    };
    let index = |g: &str| names.iter().position(|n| n == g).unwrap_or(0) as u8;
    let shorthand = desc.lights.is_empty();
    let mut list: Vec<(Light, u8)> = Vec::new();
    let sun = desc
        .sun
        .clone()
        .or_else(|| shorthand.then(Default::default));
    if let Some(sun) = sun.filter(|s| s.sun()) {
        let light = Sun::new(
            Vec3::from_array(sun.sun_dir()),
            Vec3::from_array(sun.sun_irradiance()),
            sun.sun_angle().to_radians(),
        );
        list.push((light.into(), index(DEFAULT_LIGHT_GROUPS[0])));
    }
    let env = desc
        .environment
        .clone()
        .or_else(|| shorthand.then(Default::default));
    if let Some(env) = env {
        let light = match &env.env_map {
            None => Environment::new(Vec3::from_array(env.env_radiance())),
            Some(path) => {
                let map = cirrus_render::read_env_map(path, env.env_rotation())?;
                Environment::from_map(Arc::new(map), Vec3::splat(env.env_intensity()))
            }
        };
        list.push((light.into(), index(DEFAULT_LIGHT_GROUPS[1])));
    }
    let frame = desc.frame();
    let first_table = list.len();
    for spec in &desc.lights {
        let group = if names.iter().any(|n| n == spec.group_name()) {
            spec.group_name()
        } else {
            kind_layer(spec)
        };
        list.push((spec.at(frame).light()?, index(group)));
    }
    let emission = index(DEFAULT_LIGHT_GROUPS[2]);
    let shutter = over_shutter(desc, &list, first_table, emission)?;
    let still = Lights::grouped(list, emission);
    Ok(match shutter {
        Some(s) => still.with_shutter(s),
        None => still,
    }
    .pruned())
}

/// Times a moving light is tabulated at over the shutter: as many as a
/// moving volume's transform (`moving.rs`).
const SHUTTER_TABLES: usize = 65;

/// The lights at [`SHUTTER_TABLES`] times over the shutter where any
/// `[[light]]` changes while it is open: `frame` (the lights made at the
/// frame with their groups, the `[[light]]`s from `first_light` on) with
/// each moving light made again at each time.
fn over_shutter(
    desc: &SceneDescription,
    frame: &[(Light, u8)],
    first_light: usize,
    emission_group: u8,
) -> Result<Option<LightsOverShutter>> {
    let [open, close] = desc.render.shutter();
    let (t0, t1) = (
        desc.frame() + f64::from(open),
        desc.frame() + f64::from(close),
    );
    let moving: Vec<bool> = desc.lights.iter().map(|l| l.moves_within(t0, t1)).collect();
    let Some(first) = moving.iter().position(|&m| m) else {
        return Ok(None);
    };
    if desc.render.integrator() == IntegratorKind::RayMarch2Pass {
        return Err(Error::input(format!(
            "{} changes while the shutter is open: raymarch2pass caches the light at one time; \
             render it with the path tracer or raymarch, or close the shutter",
            desc.lights[first].label(first)
        )));
    }
    let table = |time: f64| -> Result<Lights> {
        let mut list = frame.to_vec();
        for (i, spec) in desc.lights.iter().enumerate().filter(|(i, _)| moving[*i]) {
            list[first_light + i].0 = spec.at(time).light()?;
        }
        Ok(Lights::grouped(list, emission_group))
    };
    let tables = (0..SHUTTER_TABLES)
        .map(|k| table(t0 + (t1 - t0) * k as f64 / (SHUTTER_TABLES - 1) as f64))
        .collect::<Result<Vec<_>>>()?;
    Ok(LightsOverShutter::new(open, close, tables))
}

impl LightSpec {
    /// Checks every `[[light]]` of a description, naming the light. (Their
    /// light groups are checked where they are written.)
    pub fn check_all(lights: &[LightSpec]) -> std::result::Result<(), String> {
        for (i, spec) in lights.iter().enumerate() {
            spec.check()
                .map_err(|e| format!("{}: {e}", spec.label(i)))?;
        }
        Ok(())
    }

    /// Each dome map's path relative to `dir`, as a scene file's are.
    pub fn rebase_all(lights: &mut [LightSpec], dir: &Path) {
        for map in lights.iter_mut().filter_map(|l| l.map.as_mut()) {
            *map = dir.join(&*map);
        }
    }
}
