//! UsdLux lights: the first `DistantLight` as the sun and the first
//! `DomeLight` as the sky (the `[sun]` and `[environment]` tables), every
//! other distant and dome light, every `SphereLight` (a spot where its
//! `shaping:cone:angle` is authored) and every `RectLight`, `DiskLight`
//! and `CylinderLight` as a `[[light]]`.
//!
//! Emission is `intensity x 2^exposure x color` (UsdLux). A distant light's
//! irradiance (what cirrus's sun is given in) is that value when
//! `normalize` is on or the angle is 0, else that radiance times the
//! solid-angle factor of its disk, `pi sin^2(angle / 2)`. A dome light's
//! `texture:file` is a lat-long EXR in OpenEXR's layout, which is cirrus's
//! (row 0 up +Y, column 0 toward -Z, u toward +X); the dome's rotation
//! about +Y turns it. Unauthored inputs take UsdLux's fallbacks.
//!
//! A sphere light's radiance is `intensity x 2^exposure x color`, over its
//! area `4 pi r^2` where `normalize` is on; its radius is scaled by its
//! world transform (the mean of the axes' scales). With `treatAsPoint` it
//! is a point of the sphere's own intensity, `L pi r^2`. UsdLux has no
//! soft falloff: a sphere light is its ball (`soft_falloff` off). A spot's axis is
//! the light's -Z; `shaping:focus` and IES profiles are named in a warning
//! and not applied.

use glam::{DVec3, Vec3};
use openusd::usd::Prim;

use crate::description::{EnvironmentSpec, LightSpec, SunSpec};
use crate::error::{Error, Result};
use crate::light_keys::LightKey;

use super::values::{
    attr_asset, attr_number, attr_text, attr_triple, sample_times, shown_number, value,
};
use super::xform::{sample_times_of, world_at};
use super::Reader;

/// An input by its UsdLux name, or the pre-`inputs:` name older files use.
fn input_number(p: &Prim, name: &str, t: f64) -> Result<Option<f64>> {
    Ok(match attr_number(p, &format!("inputs:{name}"), t)? {
        Some(x) => Some(x),
        None => attr_number(p, name, t)?,
    })
}

/// Whether the bool attribute `name` is authored true.
fn flag(p: &Prim, name: &str, t: f64) -> Result<bool> {
    Ok(matches!(
        value(p, name, t)?,
        Some(openusd::sdf::Value::Bool(true))
    ))
}

/// `intensity x 2^exposure x color`, with the light's intensity fallback.
fn emission(r: &mut Reader, path: &str, intensity_fallback: f64, t: f64) -> Result<Vec3> {
    let p = r.stage.prim(path);
    let intensity = input_number(&p, "intensity", t)?.unwrap_or(intensity_fallback);
    let exposure = input_number(&p, "exposure", t)?.unwrap_or(0.0);
    let colour = match attr_triple(&p, "inputs:color", t)? {
        Some(c) => c,
        None => attr_triple(&p, "color", t)?.unwrap_or([1.0; 3]),
    };
    if flag(&p, "inputs:enableColorTemperature", t)? {
        r.warn(format!("{path}: colour temperature is not applied"));
    }
    let scale = intensity * exposure.exp2();
    let e = DVec3::from_array(colour) * scale;
    if !e.is_finite() || e.min_element() < 0.0 {
        return Err(r.error(
            path,
            format!("emission {} must be finite and >= 0", shown(e)),
        ));
    }
    Ok(e.as_vec3())
}

/// A vector as a person writes it: `(1e300, 0, 0)`.
fn shown(v: DVec3) -> String {
    format!("({})", v.to_array().map(shown_number).join(", "))
}

/// `spec` checked as a scene file's `[[light]]` is, after its values were
/// converted to f32 (a double of 1e300 is infinite there), the error
/// naming the stage and the prim.
fn checked(r: &Reader, path: &str, spec: LightSpec) -> Result<LightSpec> {
    spec.check().map_err(|e| r.error(path, e))?;
    Ok(spec)
}

/// The times the light at `path` changes at: its attributes' samples and
/// its transform's, sorted, deduplicated.
pub(super) fn change_times(r: &Reader, path: &str) -> Result<Vec<f64>> {
    let attributes = r
        .stage
        .prim(path)
        .attributes()
        .map_err(|e| r.error(path, format!("{e:#}")))?;
    let mut times = sample_times_of(&r.stage, path)?;
    for a in &attributes {
        times.extend(sample_times(a)?);
    }
    times.sort_by(f64::total_cmp);
    times.dedup();
    Ok(times)
}

/// The `[[light]]` `read` makes of the light at `path` at the stage's
/// start, keyed at each time its values or transform are sampled at where
/// there are two or more (its flags, such as `normalize`, read at the
/// start).
pub fn keyed(
    r: &mut Reader,
    path: &str,
    read: impl Fn(&mut Reader, f64) -> Result<LightSpec>,
) -> Result<LightSpec> {
    let times = change_times(r, path)?;
    let mut spec = read(r, r.time.start)?;
    if times.len() < 2 {
        return Ok(spec);
    }
    let mut keys = Vec::with_capacity(times.len());
    for &t in &times {
        let at = read(r, t)?;
        if at.kind != spec.kind {
            return Err(r.error(
                path,
                format!(
                    "the light is a {} at time {t} but a {} at the start: its kind cannot change",
                    at.kind, spec.kind
                ),
            ));
        }
        keys.push(LightKey::of(&at, t));
    }
    spec.keys = Some(keys);
    checked(r, path, spec)
}

/// Below this irradiance (W/m^2, a 250th of the default sun's) a distant
/// light lights nothing a render shows; a stage's light that weak is
/// most often one authored for `normalize` without it.
const DIM_IRRADIANCE: f32 = 0.01;

/// The sun of the `DistantLight` at `path`.
pub fn distant(r: &mut Reader, path: &str, t: f64) -> Result<SunSpec> {
    let p = r.stage.prim(path);
    let angle = input_number(&p, "angle", t)?.unwrap_or(0.53);
    let normalize = flag(&p, "inputs:normalize", t)?;
    let radiance = emission(r, path, 50000.0, t)?;
    let half = (0.5 * angle).to_radians();
    let irradiance = if normalize || angle <= 0.0 {
        radiance
    } else {
        radiance * (std::f64::consts::PI * half.sin().powi(2)) as f32
    };
    if irradiance.max_element() > 0.0 && irradiance.max_element() < DIM_IRRADIANCE {
        let hint = match normalize || angle <= 0.0 {
            true => "",
            false => {
                " (normalize off: intensity is the radiance of its disk, times \
                       pi sin^2(angle / 2); set inputs:normalize = 1 to give irradiance)"
            }
        };
        r.warn(format!(
            "{path}: irradiance {:.3e} W/m^2 lights nothing visibly (the default sun \
             gives 2.5){hint}",
            irradiance.max_element()
        ));
    }
    // The light's -Z axis, left for the sun to normalise (as a scene
    // file's direction is).
    let world = world_at(&r.stage, path, t)?;
    let direction = world.transform_vector3(DVec3::NEG_Z);
    if !direction.is_finite() || direction.length() < 1e-12 {
        return Err(r.error(path, "the light's transform gives it no direction"));
    }
    let sun = SunSpec {
        sun: Some(true),
        sun_dir: Some(direction.as_vec3().to_array()),
        sun_irradiance: Some(irradiance.to_array()),
        sun_angle: Some(angle as f32),
    };
    sun.check().map_err(|e| r.error(path, e))?;
    Ok(sun)
}

/// The sky of the `DomeLight` at `path`.
pub fn dome(r: &mut Reader, path: &str, t: f64) -> Result<EnvironmentSpec> {
    let p = r.stage.prim(path);
    let radiance = emission(r, path, 1.0, t)?;
    let world = world_at(&r.stage, path, t)?;
    // The dome turns about +Y only: where its X axis points.
    let x = world.transform_vector3(DVec3::X).normalize_or_zero();
    let y = world.transform_vector3(DVec3::Y).normalize_or_zero();
    if (y - DVec3::Y).length() > 1e-6 {
        r.warn(format!(
            "{path}: the dome is tilted off +Y: only its turn about +Y is applied"
        ));
    }
    // `+ 0.0` makes an unturned dome's -0 degrees +0.
    let rotation = (-x.z).atan2(x.x).to_degrees() as f32 + 0.0;
    let texture = attr_asset(&p, "inputs:texture:file", t)?;
    let format = attr_text(&p, "inputs:texture:format", t)?.unwrap_or_else(|| "automatic".into());
    let Some((authored, resolved)) = texture.filter(|(a, _)| !a.is_empty()) else {
        let env = EnvironmentSpec {
            env_radiance: Some(radiance.to_array()),
            ..Default::default()
        };
        env.check().map_err(|e| r.error(path, e))?;
        return Ok(env);
    };
    if format != "automatic" && format != "latlong" {
        return Err(r.error(
            path,
            format!("texture:format {format:?}: only latlong maps are read"),
        ));
    }
    let map = resolved.ok_or_else(|| {
        Error::file(format!(
            "{}: {path}: texture:file @{authored}@ names no file that exists",
            r.file
        ))
    })?;
    if (radiance.max_element() - radiance.min_element()).abs() > 1e-6 * radiance.max_element() {
        r.warn(format!(
            "{path}: a coloured dome tints a texture: only its mean is applied"
        ));
    }
    let map = super::package::extracted(&map)
        .map_err(|e| Error::file(format!("{}: {path}: {e}", r.file)))?;
    let env = EnvironmentSpec {
        env_map: Some(map),
        env_intensity: Some((radiance.x + radiance.y + radiance.z) / 3.0),
        env_rotation: Some(rotation),
        ..Default::default()
    };
    env.check().map_err(|e| r.error(path, e))?;
    Ok(env)
}

/// A `[[light]]` named `name` of the distant light at `path` (its sun
/// table's numbers).
pub fn extra_distant(r: &mut Reader, path: &str, name: &str, t: f64) -> Result<LightSpec> {
    let sun = distant(r, path, t)?;
    checked(
        r,
        path,
        LightSpec {
            kind: "distant".into(),
            name: Some(name.into()),
            direction: sun.sun_dir,
            color: sun.sun_irradiance,
            angle: sun.sun_angle,
            ..Default::default()
        },
    )
}

/// A `[[light]]` named `name` of the dome light at `path`.
pub fn extra_dome(r: &mut Reader, path: &str, name: &str, t: f64) -> Result<LightSpec> {
    let env = dome(r, path, t)?;
    checked(
        r,
        path,
        LightSpec {
            kind: "dome".into(),
            name: Some(name.into()),
            color: env.env_radiance,
            intensity: env.env_intensity,
            map: env.env_map,
            rotation: env.env_rotation,
            ..Default::default()
        },
    )
}

/// The `[[light]]` named `name` of the `SphereLight` at `path`: a sphere,
/// a point, or either shaped into a spot.
pub fn sphere(r: &mut Reader, path: &str, name: &str, t: f64) -> Result<LightSpec> {
    let p = r.stage.prim(path);
    let strength = emission(r, path, 1.0, t)?;
    let normalize = flag(&p, "inputs:normalize", t)?;
    let as_point = flag(&p, "treatAsPoint", t)?;
    let radius = input_number(&p, "radius", t)?.unwrap_or(0.5);
    let world = world_at(&r.stage, path, t)?;
    let position = world.transform_point3(DVec3::ZERO);
    let scale = (world.transform_vector3(DVec3::X).length()
        + world.transform_vector3(DVec3::Y).length()
        + world.transform_vector3(DVec3::Z).length())
        / 3.0;
    let radius = radius * scale;
    if !position.is_finite() || !radius.is_finite() || radius < 0.0 {
        return Err(r.error(
            path,
            format!(
                "position {} and radius {} must be finite, the radius >= 0",
                shown(position),
                shown_number(radius)
            ),
        ));
    }
    let mut spec = LightSpec {
        kind: "sphere".into(),
        name: Some(name.into()),
        position: Some(position.as_vec3().to_array()),
        ..Default::default()
    };
    if as_point {
        // A point sending what the sphere sends: its radiance times its
        // projected area.
        let area = std::f64::consts::PI * radius * radius;
        let area_scale = if normalize { 0.25 } else { area };
        spec.kind = "point".into();
        spec.color = Some((strength.as_dvec3() * area_scale).as_vec3().to_array());
    } else {
        spec.radius = Some(radius as f32);
        spec.color = Some(strength.to_array());
        spec.normalize = Some(normalize);
    }
    if let Some(angle) = input_number(&p, "shaping:cone:angle", t)? {
        let softness = input_number(&p, "shaping:cone:softness", t)?.unwrap_or(0.0);
        let axis = world.transform_vector3(DVec3::NEG_Z);
        if !axis.is_finite() || axis.length() < 1e-12 {
            return Err(r.error(path, "the light's transform gives its cone no axis"));
        }
        if !(angle > 0.0 && angle <= 180.0 && (0.0..=1.0).contains(&softness)) {
            return Err(r.error(
                path,
                format!("cone angle {angle} must be in (0, 180] and softness {softness} in [0, 1]"),
            ));
        }
        spec.kind = "spot".into();
        spec.radius = Some(if as_point { 0.0 } else { radius as f32 });
        spec.direction = Some(axis.as_vec3().to_array());
        spec.cone_angle = Some(angle as f32);
        spec.cone_softness = Some(softness as f32);
    }
    if input_number(&p, "shaping:focus", t)?.is_some_and(|f| f != 0.0) {
        r.warn(format!("{path}: shaping:focus is not applied"));
    }
    if attr_asset(&p, "inputs:shaping:ies:file", t)?.is_some() {
        r.warn(format!("{path}: an IES profile is not applied"));
    }
    checked(r, path, spec)
}

/// The `[[light]]` named `name` of the `RectLight` or `DiskLight` at
/// `path` (`kind` `rect` or `disk`): its shape in the light's XY plane
/// scaled by its world transform, emitting along its -Z.
pub fn area(r: &mut Reader, path: &str, name: &str, kind: &str, t: f64) -> Result<LightSpec> {
    let p = r.stage.prim(path);
    let strength = emission(r, path, 1.0, t)?;
    let normalize = flag(&p, "inputs:normalize", t)?;
    let world = world_at(&r.stage, path, t)?;
    let (x, y) = (
        world.transform_vector3(DVec3::X),
        world.transform_vector3(DVec3::Y),
    );
    let normal = world.transform_vector3(DVec3::NEG_Z);
    let (w, h) = if kind == "rect" {
        let w = input_number(&p, "width", t)?.unwrap_or(1.0);
        let h = input_number(&p, "height", t)?.unwrap_or(1.0);
        if attr_asset(&p, "inputs:texture:file", t)?.is_some_and(|(a, _)| !a.is_empty()) {
            r.warn(format!("{path}: a rect light's texture is not applied"));
        }
        (w, h)
    } else {
        let d = 2.0 * input_number(&p, "radius", t)?.unwrap_or(0.5);
        (d, d)
    };
    let (w, h) = (w * x.length(), h * y.length());
    let centre = world.transform_point3(DVec3::ZERO);
    let finite = centre.is_finite() && normal.is_finite() && y.is_finite();
    let sized = w > 0.0 && h > 0.0 && normal.length() >= 1e-12 && y.length() >= 1e-12;
    if !(finite && sized) {
        return Err(r.error(
            path,
            format!(
                "a {kind} light needs a finite transform and a positive size (here {} x {})",
                shown_number(w),
                shown_number(h)
            ),
        ));
    }
    checked(
        r,
        path,
        LightSpec {
            kind: kind.into(),
            name: Some(name.into()),
            position: Some(centre.as_vec3().to_array()),
            direction: Some(normal.as_vec3().to_array()),
            up: Some(y.as_vec3().to_array()),
            width: Some(w as f32),
            height: Some(h as f32),
            color: Some(strength.to_array()),
            normalize: Some(normalize),
            ..Default::default()
        },
    )
}

/// The `[[light]]` named `name` of the `CylinderLight` at `path`: its
/// side along the light's X axis, its length scaled by the transform's X
/// scale and its radius by the mean of the Y and Z scales, emitting
/// outward (its caps dark). `treatAsLine` is named in a warning: the
/// cylinder keeps its radius.
pub fn cylinder(r: &mut Reader, path: &str, name: &str, t: f64) -> Result<LightSpec> {
    let p = r.stage.prim(path);
    let strength = emission(r, path, 1.0, t)?;
    let normalize = flag(&p, "inputs:normalize", t)?;
    if flag(&p, "treatAsLine", t)? {
        r.warn(format!(
            "{path}: treatAsLine is not applied (the cylinder keeps its radius)"
        ));
    }
    let world = world_at(&r.stage, path, t)?;
    let [x, y, z] = [DVec3::X, DVec3::Y, DVec3::Z].map(|v| world.transform_vector3(v));
    let length = input_number(&p, "length", t)?.unwrap_or(1.0) * x.length();
    let radius = input_number(&p, "radius", t)?.unwrap_or(0.5) * 0.5 * (y.length() + z.length());
    let centre = world.transform_point3(DVec3::ZERO);
    let finite = centre.is_finite() && x.is_finite();
    if !(finite && length > 0.0 && radius > 0.0) {
        return Err(r.error(
            path,
            format!(
                "a cylinder light needs a finite transform and a positive size (here length {}, radius {})",
                shown_number(length),
                shown_number(radius)
            ),
        ));
    }
    checked(
        r,
        path,
        LightSpec {
            kind: "cylinder".into(),
            name: Some(name.into()),
            position: Some(centre.as_vec3().to_array()),
            direction: Some(x.as_vec3().to_array()),
            length: Some(length as f32),
            radius: Some(radius as f32),
            color: Some(strength.to_array()),
            normalize: Some(normalize),
            ..Default::default()
        },
    )
}
