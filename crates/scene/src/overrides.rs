//! Settings given by the caller over a scene: every `cirrus render` flag as
//! a plain optional field. A field that is set wins over the scene file;
//! one left `None` leaves the file's value (or the default) in place.

use std::path::PathBuf;

use cirrus_render::exr_layers::Aov;
use cirrus_render::{
    Crop, IntegratorKind, MajorantMode, SamplerKind, TransmittanceEstimator, VelocityUnit,
};
use glam::{DVec3, Vec3};
use serde::Deserialize;

use crate::description::{Colour, EnvironmentSpec, SceneDescription, SunSpec};

/// Every flag of `cirrus render`, each `None` unless given.
///
/// The volume fields apply to every volume of a scene file.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Overrides {
    // Volumes.
    pub grid: Option<String>,
    pub density_scale: Option<Colour>,
    pub albedo: Option<Colour>,
    pub g: Option<f32>,
    pub phase: Option<String>,
    pub g2: Option<f32>,
    pub lobe_weight: Option<f32>,
    pub droplet_diameter: Option<f32>,
    pub draine_alpha: Option<f32>,
    pub velocity: Option<String>,
    pub velocity_unit: Option<VelocityUnit>,
    pub velocity_scale: Option<f32>,
    // Render.
    pub spp: Option<u32>,
    pub time: Option<f64>,
    pub seed: Option<u64>,
    pub sampler: Option<SamplerKind>,
    pub noise_threshold: Option<f32>,
    pub min_spp: Option<u32>,
    pub integrator: Option<IntegratorKind>,
    pub transmittance: Option<TransmittanceEstimator>,
    pub majorant: Option<MajorantMode>,
    pub max_depth: Option<u32>,
    pub step: Option<f32>,
    pub shadow_step: Option<f32>,
    pub refine_optical_depth: Option<f32>,
    pub denoise: Option<bool>,
    /// `[open, close]`, frames.
    pub shutter: Option<[f32; 2]>,
    // Camera.
    #[serde(default, deserialize_with = "resolution")]
    pub res: Option<(u32, u32)>,
    /// World position; given together with `camera_to`.
    pub camera_from: Option<DVec3>,
    pub camera_to: Option<DVec3>,
    pub camera_up: Option<Vec3>,
    pub fov: Option<f32>,
    // Lights.
    /// `Some(false)` is `--no-sun`.
    pub sun: Option<bool>,
    pub sun_dir: Option<Vec3>,
    pub sun_irradiance: Option<Vec3>,
    pub sun_angle: Option<f32>,
    pub env_radiance: Option<Vec3>,
    /// Relative to the working directory, unlike a scene file's map.
    pub env_map: Option<PathBuf>,
    pub env_rotation: Option<f32>,
    pub env_intensity: Option<f32>,
    // Outputs.
    pub output: Option<PathBuf>,
    pub png: Option<PathBuf>,
    pub exposure: Option<f32>,
    pub stats: Option<PathBuf>,
    pub aov: Option<Vec<Aov>>,
    #[serde(default, deserialize_with = "crop")]
    pub crop: Option<Crop>,
    // Compositing.
    pub light_groups: Option<bool>,
    pub cryptomatte: Option<bool>,
    pub deep: Option<PathBuf>,
    pub deep_samples: Option<u32>,
    /// `FILE.exr[:CHANNEL]`, relative to the working directory.
    pub holdout_depth: Option<String>,
    pub holdout_far: Option<f32>,
    // End of compositing.
}

fn resolution<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<(u32, u32)>, D::Error> {
    let s = String::deserialize(d)?;
    crate::parse::resolution(&s)
        .map(Some)
        .map_err(serde::de::Error::custom)
}

fn crop<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<Crop>, D::Error> {
    let [x0, y0, x1, y1] = <[u32; 4]>::deserialize(d)?;
    Ok(Some(Crop { x0, y0, x1, y1 }))
}

/// `slot = value` where a value was given.
fn set<T>(slot: &mut Option<T>, value: Option<T>) {
    if value.is_some() {
        *slot = value;
    }
}

impl Overrides {
    /// Writes every given field into `d`.
    pub fn apply(&self, d: &mut SceneDescription) {
        let arr = |v: Option<Vec3>| v.map(|v| v.to_array());
        for v in &mut d.volumes {
            set(&mut v.density, self.grid.clone());
            set(&mut v.density_scale, self.density_scale);
            set(&mut v.albedo, self.albedo);
            set(&mut v.g, self.g);
            set(&mut v.phase, self.phase.clone());
            set(&mut v.g2, self.g2);
            set(&mut v.lobe_weight, self.lobe_weight);
            set(&mut v.droplet_diameter, self.droplet_diameter);
            set(&mut v.draine_alpha, self.draine_alpha);
            set(&mut v.velocity, self.velocity.clone());
            set(&mut v.velocity_unit, self.velocity_unit);
            set(&mut v.velocity_scale, self.velocity_scale);
        }
        let r = &mut d.render;
        if self.spp.is_some() || self.time.is_some() {
            r.spp = self.spp;
            r.time = self.time;
        }
        set(&mut r.seed, self.seed);
        set(&mut r.sampler, self.sampler);
        set(&mut r.noise_threshold, self.noise_threshold);
        set(&mut r.min_spp, self.min_spp);
        set(&mut r.integrator, self.integrator);
        set(&mut r.transmittance, self.transmittance);
        set(&mut r.majorant, self.majorant);
        set(&mut r.max_depth, self.max_depth);
        set(&mut r.step, self.step);
        set(&mut r.shadow_step, self.shadow_step);
        set(&mut r.refine_optical_depth, self.refine_optical_depth);
        set(&mut r.denoise, self.denoise);
        set(&mut r.shutter, self.shutter);
        let c = &mut d.camera;
        set(&mut c.res, self.res);
        if let (Some(from), Some(to)) = (self.camera_from, self.camera_to) {
            c.from = Some(from.to_array());
            c.to = Some(to.to_array());
        }
        set(&mut c.up, arr(self.camera_up));
        set(&mut c.fov, self.fov);
        if self.sun.is_some()
            || self.sun_dir.is_some()
            || self.sun_irradiance.is_some()
            || self.sun_angle.is_some()
        {
            let s = d.sun.get_or_insert_with(SunSpec::default);
            set(&mut s.enabled, self.sun);
            set(&mut s.direction, arr(self.sun_dir));
            set(&mut s.irradiance, arr(self.sun_irradiance));
            set(&mut s.angle, self.sun_angle);
        }
        if self.env_radiance.is_some()
            || self.env_map.is_some()
            || self.env_rotation.is_some()
            || self.env_intensity.is_some()
        {
            let e = d.environment.get_or_insert_with(EnvironmentSpec::default);
            set(&mut e.radiance, arr(self.env_radiance));
            set(&mut e.map, self.env_map.clone());
            set(&mut e.rotation, self.env_rotation);
            set(&mut e.intensity, self.env_intensity);
        }
        let o = &mut d.output;
        set(&mut o.exr, self.output.clone());
        set(&mut o.png, self.png.clone());
        set(&mut o.exposure, self.exposure);
        set(&mut o.stats, self.stats.clone());
        set(&mut o.aov, self.aov.clone());
        set(&mut o.crop, self.crop.map(|c| [c.x0, c.y0, c.x1, c.y1]));
        // Compositing.
        set(&mut o.light_groups, self.light_groups);
        set(&mut o.cryptomatte, self.cryptomatte);
        set(&mut o.deep, self.deep.clone());
        set(&mut o.deep_samples, self.deep_samples);
        set(&mut d.render.holdout_depth, self.holdout_depth.clone());
        set(&mut d.render.holdout_far, self.holdout_far);
        // End of compositing.
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn given_fields_win_and_absent_ones_keep_the_file() {
        let mut d = SceneDescription::parse(
            r#"
            [render]
            spp = 8
            seed = 3
            [camera]
            fov = 30
            [sun]
            irradiance = [1, 1, 1]
            [[volume]]
            file = "a.vdb"
            albedo = [0.5, 0.6, 0.7]
            g = 0.2
            [[volume]]
            file = "b.vdb"
            "#,
        )
        .unwrap();
        let o = Overrides {
            time: Some(2.0),
            g: Some(-0.3),
            sun_dir: Some(Vec3::new(0.0, -1.0, 0.0)),
            camera_from: Some(DVec3::ONE),
            camera_to: Some(DVec3::ZERO),
            ..Default::default()
        };
        o.apply(&mut d);
        assert_eq!((d.render.spp, d.render.time), (None, Some(2.0)));
        assert_eq!(d.render.seed, Some(3));
        assert_eq!(d.camera.fov, Some(30.0));
        assert_eq!(d.camera.from, Some([1.0; 3]));
        let sun = d.sun.as_ref().unwrap();
        assert_eq!(sun.direction, Some([0.0, -1.0, 0.0]));
        assert_eq!(sun.irradiance, Some([1.0; 3]));
        assert_eq!(d.volumes[0].g, Some(-0.3));
        assert_eq!(d.volumes[1].g, Some(-0.3));
        assert_eq!(d.volumes[0].albedo, Some(Colour::Rgb([0.5, 0.6, 0.7])));
        assert!(d.environment.is_none(), "no sky field given, none written");
    }

    #[test]
    fn json_overrides_refuse_unknown_names() {
        let o: Overrides = serde_json::from_str(r#"{"spp": 4, "res": "8x4"}"#).unwrap();
        assert_eq!((o.spp, o.res), (Some(4), Some((8, 4))));
        let e = serde_json::from_str::<Overrides>(r#"{"spp": 4, "sampels": 2}"#).unwrap_err();
        assert!(e.to_string().contains("sampels"), "{e}");
    }
}
