//! What the page controls: the [`View`] (camera, sun, sky, medium,
//! exposure, integrator, device), the partial updates the page sends
//! ([`ViewPatch`]), and the [`Overrides`] a view renders with.
//!
//! The page never names a file: a patch has numbers, flags and one
//! integrator name, and unknown fields are refused, so nothing the browser
//! sends can reach the file system.

use cirrus_render::IntegratorKind;
use cirrus_scene::description::Colour;
use cirrus_scene::{Device, Overrides};
use glam::{DVec3, Vec3};
use serde::{Deserialize, Serialize};

/// Ray-march step (voxels) while the user drags in `auto` mode: at the
/// default 0.5 a marched frame of `data/cloud.vdb` costs about 15 times a
/// 1-spp path-traced one (every step marches a shadow ray); at 4 voxels
/// it costs about half, and has no path-tracing noise.
const DRAG_STEP: f32 = 4.0;

/// The world-space camera: eye, target, up, vertical field of view.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraView {
    pub from: [f64; 3],
    pub to: [f64; 3],
    pub up: [f32; 3],
    /// Vertical, degrees.
    pub fov: f32,
}

/// The sun as the page shows it: where it is in the sky and a multiple of
/// the scene's irradiance.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SunView {
    pub enabled: bool,
    /// Degrees about +Y from +Z toward +X, of the direction toward the sun.
    pub azimuth: f32,
    /// Degrees above the XZ plane.
    pub elevation: f32,
    /// Multiple of the scene's sun irradiance.
    pub intensity: f32,
}

/// Which integrator renders.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// Ray marching (coarse steps) while the user drags, the path tracer
    /// when the view is still.
    #[default]
    Auto,
    Path,
    Raymarch,
    Raymarch2pass,
}

/// Everything the page can change.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct View {
    pub camera: CameraView,
    pub sun: SunView,
    /// Multiple of the scene's sky radiance (or sky map intensity).
    pub sky: f32,
    /// `None` keeps each volume's own value (scene files).
    pub density_scale: Option<f32>,
    pub albedo: Option<f32>,
    pub g: Option<f32>,
    /// Stops, applied when frames are tone-mapped (no re-render).
    pub exposure: f32,
    pub integrator: Mode,
    /// Where passes render (`cirrus render --device`).
    pub device: Device,
    /// The user is dragging (a slider or the camera).
    pub interactive: bool,
    /// Denoise displayed frames (when the library loads).
    pub denoise: bool,
    /// The page's image area in device pixels; frames never exceed it.
    pub viewport: Option<[u32; 2]>,
}

/// A partial update of a [`View`]: each given field replaces the view's.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViewPatch {
    pub camera: Option<CameraView>,
    pub sun: Option<SunPatch>,
    pub sky: Option<f32>,
    pub density_scale: Option<f32>,
    pub albedo: Option<f32>,
    pub g: Option<f32>,
    pub exposure: Option<f32>,
    pub integrator: Option<Mode>,
    pub device: Option<Device>,
    pub interactive: Option<bool>,
    pub denoise: Option<bool>,
    pub viewport: Option<[u32; 2]>,
}

#[derive(Clone, Copy, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SunPatch {
    pub enabled: Option<bool>,
    pub azimuth: Option<f32>,
    pub elevation: Option<f32>,
    pub intensity: Option<f32>,
}

/// The scene's own lights, which the sun and sky sliders scale.
#[derive(Clone, Debug, PartialEq)]
pub struct Lighting {
    pub sun_irradiance: Vec3,
    /// Constant sky radiance, or `None` for a sky map.
    pub sky_radiance: Option<Vec3>,
    /// The sky map's intensity (used when `sky_radiance` is `None`).
    pub sky_map_intensity: f32,
}

/// Checks `x` is finite and within `[lo, hi]`.
fn within(name: &str, x: f32, lo: f32, hi: f32) -> Result<f32, String> {
    if x.is_finite() && (lo..=hi).contains(&x) {
        Ok(x)
    } else {
        Err(format!("{name} must lie in [{lo}, {hi}], got {x}"))
    }
}

impl View {
    /// This view with `patch` written over it, or why the patch is wrong
    /// (the view is unchanged then).
    pub fn patched(&self, patch: &ViewPatch) -> Result<View, String> {
        let mut v = self.clone();
        if let Some(c) = patch.camera {
            v.camera = check_camera(c)?;
        }
        if let Some(s) = patch.sun {
            if let Some(e) = s.enabled {
                v.sun.enabled = e;
            }
            if let Some(a) = s.azimuth {
                v.sun.azimuth = within("sun azimuth", a, -3600.0, 3600.0)?.rem_euclid(360.0);
            }
            if let Some(e) = s.elevation {
                v.sun.elevation = within("sun elevation", e, -90.0, 90.0)?;
            }
            if let Some(i) = s.intensity {
                v.sun.intensity = within("sun intensity", i, 0.0, 1000.0)?;
            }
        }
        if let Some(k) = patch.sky {
            v.sky = within("sky intensity", k, 0.0, 1000.0)?;
        }
        if let Some(d) = patch.density_scale {
            v.density_scale = Some(within("density scale", d, 0.0, 1e9)?);
        }
        if let Some(a) = patch.albedo {
            v.albedo = Some(within("albedo", a, 0.0, 1.0)?);
        }
        if let Some(g) = patch.g {
            v.g = Some(within("g", g, -0.99, 0.99)?);
        }
        if let Some(e) = patch.exposure {
            v.exposure = within("exposure", e, -30.0, 30.0)?;
        }
        if let Some(m) = patch.integrator {
            v.integrator = m;
        }
        if let Some(d) = patch.device {
            v.device = d;
        }
        if let Some(i) = patch.interactive {
            v.interactive = i;
        }
        if let Some(d) = patch.denoise {
            v.denoise = d;
        }
        if let Some([w, h]) = patch.viewport {
            if !(1..=16384).contains(&w) || !(1..=16384).contains(&h) {
                return Err(format!("viewport {w}x{h} must be 1 to 16384 a side"));
            }
            v.viewport = Some([w, h]);
        }
        Ok(v)
    }

    /// The integrator that renders now, and its ray-march step if it is
    /// not the scene's. Drags march only on the CPU: the GPU has no ray
    /// marcher, and path-traces the quick low-resolution passes instead
    /// (under `auto` too, which may land on a GPU).
    pub fn integrator_now(&self) -> (IntegratorKind, Option<f32>) {
        match self.integrator {
            Mode::Auto if self.interactive && self.device == Device::Cpu => {
                (IntegratorKind::RayMarch, Some(DRAG_STEP))
            }
            Mode::Auto | Mode::Path => (IntegratorKind::Path, None),
            Mode::Raymarch => (IntegratorKind::RayMarch, None),
            Mode::Raymarch2pass => (IntegratorKind::RayMarch2Pass, None),
        }
    }

    /// The resolution to render: `base`, shrunk (aspect kept) to fit the
    /// page's viewport, so no frame is bigger than the view.
    pub fn resolution(&self, base: (u32, u32)) -> (u32, u32) {
        let Some([vw, vh]) = self.viewport else {
            return base;
        };
        let (bw, bh) = base;
        if bw <= vw && bh <= vh {
            return base;
        }
        let scale = (f64::from(vw) / f64::from(bw)).min(f64::from(vh) / f64::from(bh));
        let side = |b: u32, v: u32| ((f64::from(b) * scale).floor() as u32).clamp(1, v);
        (side(bw, vw), side(bh, vh))
    }

    /// The overrides of everything that changes the rendered pixels (not
    /// the sample count, seed, exposure or denoising): equal overrides
    /// mean the same image, so they key the accumulation.
    pub fn render_overrides(&self, lighting: &Lighting, res: (u32, u32)) -> Overrides {
        let c = &self.camera;
        let (integrator, step) = self.integrator_now();
        let mut o = Overrides {
            res: Some(res),
            camera_from: Some(c.from),
            camera_to: Some(c.to),
            camera_up: Some(c.up),
            fov: Some(c.fov),
            density_scale: self.density_scale.map(Colour::Grey),
            albedo: self.albedo.map(Colour::Grey),
            g: self.g,
            integrator: Some(integrator),
            step,
            device: Some(self.device),
            // Frames are denoised after accumulation, never per pass.
            denoise: Some(false),
            ..Default::default()
        };
        if self.sun.enabled {
            o.sun_dir = Some(sun_direction(self.sun.azimuth, self.sun.elevation).to_array());
            o.sun_irradiance = Some((lighting.sun_irradiance * self.sun.intensity).to_array());
        } else {
            o.sun = Some(false);
        }
        match lighting.sky_radiance {
            Some(radiance) => o.env_radiance = Some((radiance * self.sky).to_array()),
            None => o.env_intensity = Some(lighting.sky_map_intensity * self.sky),
        }
        o
    }
}

fn check_camera(c: CameraView) -> Result<CameraView, String> {
    let from = DVec3::from_array(c.from);
    let to = DVec3::from_array(c.to);
    let up = Vec3::from_array(c.up);
    if !from.is_finite() || !to.is_finite() || from.abs().max_element() > 1e12 {
        return Err("camera from and to must be finite".into());
    }
    if from.distance(to) <= 1e-9 * from.length().max(1.0) {
        return Err("camera from and to must differ".into());
    }
    if !up.is_finite() || up.length_squared() < 1e-12 {
        return Err("camera up must be a finite non-zero vector".into());
    }
    within("fov", c.fov, 0.1, 179.0)?;
    Ok(c)
}

/// The direction sunlight travels (the renderer's convention) for a sun
/// seen at `azimuth`, `elevation` degrees.
pub fn sun_direction(azimuth: f32, elevation: f32) -> Vec3 {
    let (az, el) = (azimuth.to_radians(), elevation.to_radians());
    -Vec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos())
}

/// Azimuth and elevation (degrees) of the sun whose light travels along
/// `direction`; the inverse of [`sun_direction`].
pub fn sun_angles(direction: Vec3) -> (f32, f32) {
    let to_sun = -direction.normalize_or(Vec3::NEG_Y);
    let elevation = to_sun.y.clamp(-1.0, 1.0).asin().to_degrees();
    let azimuth = to_sun.x.atan2(to_sun.z).to_degrees().rem_euclid(360.0);
    (azimuth, elevation)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view() -> View {
        View {
            camera: CameraView {
                from: [0.0, 0.0, 10.0],
                to: [0.0; 3],
                up: [0.0, 1.0, 0.0],
                fov: 40.0,
            },
            sun: SunView {
                enabled: true,
                azimuth: 30.0,
                elevation: 40.0,
                intensity: 1.0,
            },
            sky: 1.0,
            density_scale: Some(1.0),
            albedo: Some(0.9),
            g: Some(0.5),
            exposure: 0.0,
            integrator: Mode::Auto,
            device: Device::Cpu,
            interactive: false,
            denoise: false,
            viewport: None,
        }
    }

    #[test]
    fn sun_angles_invert_sun_direction() {
        let d = Vec3::new(0.7, -0.5, 0.5).normalize();
        let (az, el) = sun_angles(d);
        assert!((sun_direction(az, el) - d).length() < 1e-5);
    }

    #[test]
    fn bad_values_are_refused_and_leave_the_view() {
        let v = view();
        for json in [
            r#"{"albedo": 1.5}"#,
            r#"{"g": 1.0}"#,
            r#"{"camera": {"from": [0,0,0], "to": [0,0,0], "up": [0,1,0], "fov": 40}}"#,
            r#"{"viewport": [0, 10]}"#,
            r#"{"sun": {"elevation": 91}}"#,
        ] {
            let p: ViewPatch = serde_json::from_str(json).unwrap();
            assert!(v.patched(&p).is_err(), "{json}");
        }
        assert!(serde_json::from_str::<ViewPatch>(r#"{"file": "/etc/passwd"}"#).is_err());
        assert!(serde_json::from_str::<ViewPatch>(r#"{"albedo": NaN}"#).is_err());
        assert!(serde_json::from_str::<ViewPatch>(r#"{"device": "tpu"}"#).is_err());
        assert!(serde_json::from_str::<ViewPatch>(r#"{"device": "GPU"}"#).is_err());
    }

    #[test]
    fn dragging_in_auto_mode_marches_and_exposure_keeps_the_key() {
        let lighting = Lighting {
            sun_irradiance: Vec3::ONE,
            sky_radiance: Some(Vec3::splat(0.2)),
            sky_map_intensity: 1.0,
        };
        let v = view();
        let key = v.render_overrides(&lighting, (64, 64));
        let p: ViewPatch = serde_json::from_str(r#"{"exposure": 1.5}"#).unwrap();
        assert_eq!(
            v.patched(&p).unwrap().render_overrides(&lighting, (64, 64)),
            key
        );
        let p: ViewPatch = serde_json::from_str(r#"{"interactive": true}"#).unwrap();
        let drag = v.patched(&p).unwrap().render_overrides(&lighting, (64, 64));
        assert_eq!(drag.integrator, Some(IntegratorKind::RayMarch));
        assert_eq!(key.integrator, Some(IntegratorKind::Path));
        // The GPU has no marcher: its drags path-trace, and the device
        // keys the accumulation (its estimators differ from the CPU's).
        let p: ViewPatch =
            serde_json::from_str(r#"{"device": "gpu", "interactive": true}"#).unwrap();
        let gpu = v.patched(&p).unwrap().render_overrides(&lighting, (64, 64));
        assert_eq!(gpu.integrator, Some(IntegratorKind::Path));
        assert_eq!(gpu.device, Some(Device::Gpu));
        assert_ne!(gpu, key);
    }

    #[test]
    fn resolution_fits_the_viewport_keeping_aspect() {
        let mut v = view();
        assert_eq!(v.resolution((512, 256)), (512, 256));
        v.viewport = Some([256, 400]);
        assert_eq!(v.resolution((512, 256)), (256, 128));
        v.viewport = Some([1000, 1000]);
        assert_eq!(v.resolution((512, 256)), (512, 256));
    }
}
