//! The scene description: exactly the TOML format of a scene file (and the
//! JSON form the Python bindings pass for a dict).
//!
//! Every table and field maps to a `cirrus render` flag (the README's
//! "Scene files" section has the table); [`Overrides`](crate::Overrides)
//! written over it win. Every field is optional here; the defaults are
//! applied when the description is resolved (`defaults.rs`). Unknown keys
//! and wrong types are errors that name the file, the key, and its line
//! and column (serde's `deny_unknown_fields`; toml's errors carry the span).

use std::path::{Path, PathBuf};

use cirrus_render::exr_layers::Aov;
use cirrus_render::{
    IntegratorKind, MajorantMode, SamplerKind, TransmittanceEstimator, VelocityUnit,
};
use serde::Deserialize;

use crate::error::{Error, Result};

/// A whole scene file.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDescription {
    #[serde(default)]
    pub output: OutputSpec,
    #[serde(default)]
    pub render: RenderSpec,
    #[serde(default)]
    pub camera: CameraSpec,
    /// Absent: the `--sun-*` defaults; `enabled = false`: no sun.
    pub sun: Option<SunSpec>,
    /// Absent: the `--env-radiance` default.
    pub environment: Option<EnvironmentSpec>,
    #[serde(default, rename = "volume")]
    pub volumes: Vec<VolumeSpec>,
}

/// `-o`, `--png`, `--exposure`, `--stats`, `--aov`, `--crop`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    pub exr: Option<PathBuf>,
    pub png: Option<PathBuf>,
    pub exposure: Option<f32>,
    pub stats: Option<PathBuf>,
    pub aov: Option<Vec<Aov>>,
    /// `[x0, y0, x1, y1]`, pixels, half-open.
    pub crop: Option<[u32; 4]>,
    // Compositing (`--aov lights`, `--aov cryptomatte`, `--deep`, `--deep-samples`).
    /// Light-group layers `sun`, `sky`, `emission`.
    pub light_groups: Option<bool>,
    /// `CryptoObject` and `CryptoAsset` layers.
    pub cryptomatte: Option<bool>,
    /// A deep scanline EXR of the camera rays' volumetric samples.
    pub deep: Option<PathBuf>,
    /// At most this many deep samples per pixel (plus the background).
    pub deep_samples: Option<u32>,
    // End of compositing.
}

/// `--spp`, `--time`, `--seed`, `--integrator`, `--transmittance`,
/// `--majorant`, `--max-depth`, `--step`, `--refine-optical-depth`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderSpec {
    pub spp: Option<u32>,
    pub time: Option<f64>,
    pub seed: Option<u64>,
    /// `"sobol"` or `"random"` (`--sampler`).
    pub sampler: Option<SamplerKind>,
    /// Relative error at which a pixel stops (`--noise-threshold`).
    pub noise_threshold: Option<f32>,
    /// Samples before a pixel may stop (`--min-spp`).
    pub min_spp: Option<u32>,
    pub integrator: Option<IntegratorKind>,
    pub transmittance: Option<TransmittanceEstimator>,
    pub majorant: Option<MajorantMode>,
    pub max_depth: Option<u32>,
    pub step: Option<f32>,
    /// The ray marchers' shadow-ray step in voxels (`--shadow-step`).
    pub shadow_step: Option<f32>,
    /// Majorant cells are refined while crossing one costs more than this
    /// optical depth in null collisions (lone volumes).
    pub refine_optical_depth: Option<f32>,
    /// Denoise the image with Open Image Denoise, guided by the albedo AOV.
    pub denoise: Option<bool>,
    /// A frame range, `"A-B"` or `"A-B:STEP"`, for paths holding a frame
    /// pattern (`####`, `%04d`).
    pub frames: Option<String>,
    /// `[open, close]` in frames around the frame (`--shutter`): motion
    /// blur from the volumes' velocity grids.
    pub shutter: Option<[f32; 2]>,
    // Compositing (`--holdout-depth`, `--holdout-far`).
    /// `"FILE.exr[:CHANNEL]"`: a camera-space (planar) depth image where
    /// camera rays end, relative to the scene file.
    pub holdout_depth: Option<String>,
    /// Depths at or beyond this are no depth (default 1e10).
    pub holdout_far: Option<f32>,
    // End of compositing.
}

/// `--res`, `--camera-from`, `--camera-to`, `--camera-up`, `--fov`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// `"WxH"`, as the flag.
    #[serde(default, deserialize_with = "resolution")]
    pub res: Option<(u32, u32)>,
    pub from: Option<[f64; 3]>,
    pub to: Option<[f64; 3]>,
    pub up: Option<[f32; 3]>,
    pub fov: Option<f32>,
}

/// `--sun-dir`, `--sun-irradiance`, `--sun-angle`, `--no-sun`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SunSpec {
    pub enabled: Option<bool>,
    /// The direction sunlight travels (from the sun toward the scene).
    pub direction: Option<[f32; 3]>,
    pub irradiance: Option<[f32; 3]>,
    /// Angular diameter in degrees.
    pub angle: Option<f32>,
}

/// `--env-radiance`, `--env-map`, `--env-rotation`, `--env-intensity`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentSpec {
    /// Constant radiance (ignored when a map is given).
    pub radiance: Option<[f32; 3]>,
    /// Lat-long EXR, relative to the scene file.
    pub map: Option<PathBuf>,
    /// Degrees about +Y.
    pub rotation: Option<f32>,
    pub intensity: Option<f32>,
}

/// A number or an RGB triple.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum Colour {
    Grey(f32),
    Rgb([f32; 3]),
}

impl Colour {
    pub fn rgb(self) -> [f32; 3] {
        match self {
            Colour::Grey(v) => [v; 3],
            Colour::Rgb(c) => c,
        }
    }

    pub fn vec3(self) -> glam::Vec3 {
        glam::Vec3::from_array(self.rgb())
    }
}

/// The command-line form: `x` or `r,g,b`.
impl std::fmt::Display for Colour {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Colour::Grey(v) => write!(f, "{v}"),
            Colour::Rgb([r, g, b]) => write!(f, "{r},{g},{b}"),
        }
    }
}

/// One volume instance. `--grid`, `--density-scale`, `--albedo` and `--g`
/// given on the command line apply to every volume.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VolumeSpec {
    /// A .vdb, .nvdb or .cbrk file, relative to the scene file.
    pub file: PathBuf,
    // Compositing.
    /// The instance's name in the Cryptomatte manifest (default: the
    /// file's stem, made unique with `_2`, `_3`, ...).
    pub name: Option<String>,
    /// A matte: lights and shadows the other volumes, never seen.
    pub holdout: Option<bool>,
    // End of compositing.
    /// Density grid name (default "density", else the first float grid).
    pub density: Option<String>,
    /// Temperature grid name: blackbody emission (see `blackbody`).
    pub temperature: Option<String>,
    /// Emission grid name: `value * emission_color * emission_scale`.
    pub emission: Option<String>,
    /// Velocity grid name (vec3), for motion blur when the shutter is
    /// open (default: `vel` or `v` if the file has one).
    pub velocity: Option<String>,
    /// `"world"` (world units per frame, the default) or `"voxels"`
    /// (velocity-grid voxels per frame).
    pub velocity_unit: Option<VelocityUnit>,
    /// Multiplies the velocity (1/24: per-second values at 24 fps).
    pub velocity_scale: Option<f32>,
    /// Extinction per unit density in 1/world units: one number, or one
    /// per RGB channel (a chromatic medium).
    pub density_scale: Option<Colour>,
    pub albedo: Option<Colour>,
    /// Mean cosine of the (first) Henyey-Greenstein lobe, or Draine's g.
    pub g: Option<f32>,
    /// `hg`, `hg2`, `draine`, `mie`, `rayleigh` or `table:FILE` (a
    /// two-column text file of cos(theta) and value).
    pub phase: Option<String>,
    /// The second lobe of `hg2`.
    pub g2: Option<f32>,
    /// Weight of the first lobe of `hg2`, in [0, 1].
    pub lobe_weight: Option<f32>,
    /// Droplet diameter of `mie`, micrometres (5 to 50).
    pub droplet_diameter: Option<f32>,
    /// Draine's alpha.
    pub draine_alpha: Option<f32>,
    #[serde(default)]
    pub transform: TransformSpec,
    #[serde(default)]
    pub blackbody: BlackbodySpec,
    pub emission_color: Option<[f32; 3]>,
    pub emission_scale: Option<f32>,
}

/// Object to world: scale, then rotate, then translate.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransformSpec {
    pub translate: Option<[f64; 3]>,
    /// Axis-angle rotation.
    pub rotate: Option<AxisAngle>,
    /// Euler angles in degrees, applied about X, then Y, then Z
    /// (exclusive with `rotate`).
    pub euler: Option<[f64; 3]>,
    /// Uniform (a number) or per axis.
    pub scale: Option<ScaleSpec>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisAngle {
    pub axis: [f64; 3],
    pub degrees: f64,
}

#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(untagged)]
pub enum ScaleSpec {
    Uniform(f64),
    Axes([f64; 3]),
}

/// pbrt-v4's blackbody parameters: `Le = scale * Blackbody((T - offset) * temperature_scale)`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlackbodySpec {
    pub scale: Option<f32>,
    pub offset: Option<f32>,
    pub temperature_scale: Option<f32>,
}

fn resolution<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> std::result::Result<Option<(u32, u32)>, D::Error> {
    let s = String::deserialize(d)?;
    crate::parse::resolution(&s)
        .map(Some)
        .map_err(serde::de::Error::custom)
}

impl SceneDescription {
    /// Reads and parses `path`; errors name the file (toml's messages give
    /// the line, column and key).
    pub fn read(path: &Path) -> Result<SceneDescription> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| Error::file(format!("{}: {e}", path.display())))?;
        Self::parse(&text).map_err(|e| Error::input(format!("{}: {e}", path.display())))
    }

    /// Parses the TOML form.
    pub fn parse(text: &str) -> std::result::Result<SceneDescription, String> {
        let file: SceneDescription = toml::from_str(text).map_err(|e| e.to_string())?;
        file.check()?;
        Ok(file)
    }

    /// Parses the JSON form (the same fields and nesting as the TOML).
    pub fn from_json(text: &str) -> std::result::Result<SceneDescription, String> {
        let file: SceneDescription = serde_json::from_str(text).map_err(|e| e.to_string())?;
        file.check()?;
        Ok(file)
    }

    /// Input paths (volumes, sky map) relative to `dir`, as a scene file's
    /// are relative to the file.
    pub fn rebase(&mut self, dir: &Path) {
        for v in &mut self.volumes {
            v.file = dir.join(&v.file);
            if let Some(table) = v.phase.as_deref().and_then(|p| p.strip_prefix("table:")) {
                v.phase = Some(format!("table:{}", dir.join(table).display()));
            }
        }
        if let Some(map) = self.environment.as_mut().and_then(|e| e.map.as_mut()) {
            *map = dir.join(&*map);
        }
        if let Some(spec) = self.render.holdout_depth.as_mut() {
            let (file, channel) = crate::compositing::split_depth_spec(spec);
            let file = dir.join(file).display().to_string();
            *spec = channel.map_or(file.clone(), |c| format!("{file}:{c}"));
        }
    }

    /// Every input and output path with its frame pattern replaced by `frame`.
    pub fn substitute_frame(&mut self, frame: i64) {
        use crate::frames::substitute;
        for v in &mut self.volumes {
            v.file = substitute(&v.file, frame);
        }
        if let Some(map) = self.environment.as_mut().and_then(|e| e.map.as_mut()) {
            *map = substitute(map, frame);
        }
        let o = &mut self.output;
        for path in [&mut o.exr, &mut o.png, &mut o.stats, &mut o.deep]
            .into_iter()
            .flatten()
        {
            *path = substitute(path, frame);
        }
        if let Some(spec) = self.render.holdout_depth.as_mut() {
            *spec = substitute(Path::new(spec.as_str()), frame)
                .display()
                .to_string();
        }
    }

    /// What serde cannot say: exclusive fields.
    fn check(&self) -> std::result::Result<(), String> {
        for (i, v) in self.volumes.iter().enumerate() {
            if v.transform.rotate.is_some() && v.transform.euler.is_some() {
                return Err(format!(
                    "volume {} ({}): give `rotate` or `euler`, not both",
                    i + 1,
                    v.file.display()
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_keys_and_wrong_types_name_the_key_and_line() {
        let e = SceneDescription::parse("[camera]\nfov = 30\nfocal = 2\n").unwrap_err();
        assert!(e.contains("line 3") && e.contains("focal"), "{e}");
        let e = SceneDescription::parse("[render]\nspp = \"many\"\n").unwrap_err();
        assert!(e.contains("line 2") && e.contains("spp"), "{e}");
        let e =
            SceneDescription::parse("[[volume]]\nfile = \"a.vdb\"\nalbedo = [1, 2]\n").unwrap_err();
        assert!(e.contains("line 3") && e.contains("albedo"), "{e}");
        let e = SceneDescription::parse("[camera]\nres = \"12by4\"\n").unwrap_err();
        assert!(e.contains("line 2") && e.contains("WxH"), "{e}");
    }

    #[test]
    fn a_full_scene_parses() {
        let s = SceneDescription::parse(
            r#"
            [output]
            exr = "a.exr"
            aov = ["albedo", "depth"]
            crop = [0, 0, 8, 8]
            [render]
            spp = 4
            integrator = "path"
            transmittance = "track-length"
            [camera]
            res = "32x16"
            from = [1, 2, 3]
            to = [0, 0, 0]
            [sun]
            enabled = false
            [environment]
            map = "sky.exr"
            rotation = 90
            [[volume]]
            file = "a.vdb"
            albedo = [0.9, 0.8, 0.7]
            density_scale = [30, 20, 10]
            transform = { translate = [1, 0, 0], rotate = { axis = [0, 1, 0], degrees = 45 }, scale = 2 }
            [[volume]]
            file = "b.vdb"
            temperature = "temperature"
            blackbody = { scale = 4, offset = 0, temperature_scale = 1000 }
            "#,
        )
        .unwrap();
        assert_eq!(s.volumes.len(), 2);
        assert_eq!(s.camera.res, Some((32, 16)));
        assert_eq!(
            s.render.transmittance,
            Some(TransmittanceEstimator::TrackLength)
        );
        assert_eq!(s.volumes[0].albedo.unwrap().rgb(), [0.9, 0.8, 0.7]);
        assert_eq!(
            s.volumes[0].density_scale,
            Some(Colour::Rgb([30.0, 20.0, 10.0]))
        );
        assert_eq!(s.volumes[1].density_scale, None);
        assert_eq!(s.volumes[1].blackbody.temperature_scale, Some(1000.0));
    }
}
