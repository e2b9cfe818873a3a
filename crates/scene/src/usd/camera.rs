//! `UsdGeomCamera` as the scene's camera (its world transform, samples
//! included, focal length, apertures, clipping range and shutter) and
//! `UsdRenderSettings` for the resolution and the camera to use.

use crate::description::CameraSpec;
use crate::error::Result;

use super::values::{attr_number, value};
use super::xform::transform_spec;
use super::Reader;

/// The camera at `path`, and its shutter (`shutter:open`, `shutter:close`,
/// in time codes around the frame) when it has one.
pub fn camera(r: &mut Reader, path: &str) -> Result<(CameraSpec, Option<[f32; 2]>)> {
    let p = r.stage.prim(path);
    let t = r.time.start;
    let transform = transform_spec(&r.stage, path, t)?;
    let number = |name: &str| attr_number(&p, name, t);
    let projection = super::values::attr_text(&p, "projection", t)?;
    if projection.as_deref().is_some_and(|x| x != "perspective") {
        r.warn(format!(
            "{path}: projection {projection:?} is rendered as perspective"
        ));
    }
    for offset in ["horizontalApertureOffset", "verticalApertureOffset"] {
        if number(offset)?.is_some_and(|x| x != 0.0) {
            r.warn(format!("{path}: {offset} is not applied"));
        }
    }
    if number("fStop")?.is_some_and(|x| x > 0.0) {
        r.warn(format!("{path}: depth of field (fStop) is not rendered"));
    }
    let clipping = match value(&p, "clippingRange", t)? {
        Some(openusd::sdf::Value::Vec2f(v)) => [v.x, v.y],
        Some(openusd::sdf::Value::Vec2d(v)) => [v.x as f32, v.y as f32],
        _ => [1.0, 1_000_000.0],
    };
    let spec = CameraSpec {
        matrix: transform.matrix,
        samples: transform.samples,
        focal_length: Some(number("focalLength")?.unwrap_or(50.0) as f32),
        horizontal_aperture: Some(number("horizontalAperture")?.unwrap_or(20.955) as f32),
        vertical_aperture: Some(number("verticalAperture")?.unwrap_or(15.2908) as f32),
        clipping: Some(clipping),
        ..Default::default()
    };
    spec.check().map_err(|e| r.error(path, e))?;
    let open = number("shutter:open")?.unwrap_or(0.0) as f32;
    let close = number("shutter:close")?.unwrap_or(0.0) as f32;
    let shutter = (close > open).then_some([open, close]);
    Ok((spec, shutter))
}

/// What a `RenderSettings` prim says: resolution and camera.
pub struct RenderSettings {
    pub res: Option<(u32, u32)>,
    pub camera: Option<String>,
}

pub fn render_settings(r: &mut Reader, path: &str) -> Result<RenderSettings> {
    let p = r.stage.prim(path);
    let res = match value(&p, "resolution", r.time.start)? {
        Some(openusd::sdf::Value::Vec2i(v)) => {
            let ok = (1..=16384).contains(&v.x) && (1..=16384).contains(&v.y);
            if !ok {
                return Err(r.error(
                    path,
                    format!("resolution {}x{}: each side must be 1 to 16384", v.x, v.y),
                ));
            }
            Some((v.x as u32, v.y as u32))
        }
        _ => None,
    };
    if attr_number(&p, "pixelAspectRatio", r.time.start)?.is_some_and(|a| a != 1.0) {
        r.warn(format!(
            "{path}: pixelAspectRatio is not applied (square pixels)"
        ));
    }
    let camera = p
        .relationship("camera")
        .targets()
        .ok()
        .and_then(|t| t.first().map(|c| c.as_str().to_string()));
    Ok(RenderSettings { res, camera })
}
