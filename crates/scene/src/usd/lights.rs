//! `UsdLuxDistantLight` as the sun and `UsdLuxDomeLight` as the sky.
//!
//! Emission is `intensity x 2^exposure x color` (UsdLux). A distant light's
//! irradiance (what cirrus's sun is given in) is that value when
//! `normalize` is on or the angle is 0, else that radiance times the
//! solid-angle factor of its disk, `pi sin^2(angle / 2)`. A dome light's
//! `texture:file` is a lat-long EXR in OpenEXR's layout, which is cirrus's
//! (row 0 up +Y, column 0 toward -Z, u toward +X); the dome's rotation
//! about +Y turns it. Unauthored inputs take UsdLux's fallbacks.

use glam::{DVec3, Vec3};
use openusd::usd::Prim;

use crate::description::{EnvironmentSpec, SunSpec};
use crate::error::{Error, Result};

use super::values::{attr_asset, attr_number, attr_text, attr_triple, value};
use super::xform::world_at;
use super::Reader;

/// An input by its UsdLux name, or the pre-`inputs:` name older files use.
fn input_number(p: &Prim, name: &str, t: f64) -> Result<Option<f64>> {
    Ok(match attr_number(p, &format!("inputs:{name}"), t)? {
        Some(x) => Some(x),
        None => attr_number(p, name, t)?,
    })
}

/// `intensity x 2^exposure x color`, with the light's intensity fallback.
fn emission(r: &mut Reader, path: &str, intensity_fallback: f64) -> Result<Vec3> {
    let p = r.stage.prim(path);
    let t = r.time.start;
    let intensity = input_number(&p, "intensity", t)?.unwrap_or(intensity_fallback);
    let exposure = input_number(&p, "exposure", t)?.unwrap_or(0.0);
    let colour = match attr_triple(&p, "inputs:color", t)? {
        Some(c) => c,
        None => attr_triple(&p, "color", t)?.unwrap_or([1.0; 3]),
    };
    if value(&p, "inputs:enableColorTemperature", t)?
        .is_some_and(|v| matches!(v, openusd::sdf::Value::Bool(true)))
    {
        r.warn(format!("{path}: colour temperature is not applied"));
    }
    let scale = intensity * exposure.exp2();
    let e = DVec3::from_array(colour) * scale;
    if !e.is_finite() || e.min_element() < 0.0 {
        return Err(r.error(path, format!("emission {e} must be finite and >= 0")));
    }
    Ok(e.as_vec3())
}

/// The sun of the `DistantLight` at `path`.
pub fn distant(r: &mut Reader, path: &str) -> Result<SunSpec> {
    let p = r.stage.prim(path);
    let t = r.time.start;
    let angle = input_number(&p, "angle", t)?.unwrap_or(0.53);
    let normalize = matches!(
        value(&p, "inputs:normalize", t)?,
        Some(openusd::sdf::Value::Bool(true))
    );
    let radiance = emission(r, path, 50000.0)?;
    let half = (0.5 * angle).to_radians();
    let irradiance = if normalize || angle <= 0.0 {
        radiance
    } else {
        radiance * (std::f64::consts::PI * half.sin().powi(2)) as f32
    };
    // The light's -Z axis, left for the sun to normalise (as a scene
    // file's direction is).
    let world = world_at(&r.stage, path, t)?;
    let direction = world.transform_vector3(DVec3::NEG_Z);
    if !direction.is_finite() || direction.length() < 1e-12 {
        return Err(r.error(path, "the light's transform gives it no direction"));
    }
    Ok(SunSpec {
        sun: Some(true),
        sun_dir: Some(direction.as_vec3().to_array()),
        sun_irradiance: Some(irradiance.to_array()),
        sun_angle: Some(angle as f32),
    })
}

/// The sky of the `DomeLight` at `path`.
pub fn dome(r: &mut Reader, path: &str) -> Result<EnvironmentSpec> {
    let p = r.stage.prim(path);
    let t = r.time.start;
    let radiance = emission(r, path, 1.0)?;
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
        return Ok(EnvironmentSpec {
            env_radiance: Some(radiance.to_array()),
            ..Default::default()
        });
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
    Ok(EnvironmentSpec {
        env_map: Some(map),
        env_intensity: Some((radiance.x + radiance.y + radiance.z) / 3.0),
        env_rotation: Some(rotation),
        ..Default::default()
    })
}
