//! The command-line form of [`Overrides`]: `clap` arguments that the
//! `cirrus` binary and the benchmarks share, so their flags cannot drift
//! apart. A flag left out is `None`, so it never hides a scene file's value;
//! the defaults shown in `--help` are the ones in `defaults.rs`.

use std::path::PathBuf;

use cirrus_render::exr_layers::Aov;
use cirrus_render::{
    Crop, IntegratorKind, MajorantMode, SamplerKind, TransmittanceEstimator, VelocityUnit,
};
use glam::{DVec3, Vec3};

use crate::description::Colour;
use crate::overrides::Overrides;
use crate::parse;

fn point(s: &str) -> Result<DVec3, String> {
    parse::triple(s).map(DVec3::from_array)
}

fn vec3(s: &str) -> Result<Vec3, String> {
    parse::triple(s).map(|v| DVec3::from_array(v).as_vec3())
}

/// What to render and how: every flag but the outputs.
#[derive(clap::Args, Clone, Debug)]
pub struct SceneFlags {
    /// A .vdb, .nvdb or .cbrk file, or a scene file (.toml).
    pub file: PathBuf,
    /// The density grid [default: "density", else the first float grid].
    #[arg(long)]
    pub grid: Option<String>,
    /// Image size [default: 512x512].
    #[arg(long, value_parser = parse::resolution)]
    pub res: Option<(u32, u32)>,
    /// Samples per pixel [default: 64].
    #[arg(long, conflicts_with = "time")]
    pub spp: Option<u32>,
    /// Render passes until this many seconds are spent.
    #[arg(long)]
    pub time: Option<f64>,
    /// Same seed, same image, on any thread count [default: 0].
    #[arg(long)]
    pub seed: Option<u64>,
    /// Sample numbers: Owen-scrambled Sobol points for the first path
    /// vertices, or independent random numbers [default: sobol].
    #[arg(long, value_enum)]
    pub sampler: Option<SamplerKind>,
    /// Adaptive sampling: a pixel stops once the relative standard error
    /// of its mean is below this (e.g. 0.02); with --time, passes go to the
    /// pixels of highest error [default: off].
    #[arg(long)]
    pub noise_threshold: Option<f32>,
    /// Samples every pixel takes before adaptive sampling may stop it
    /// [default: 16].
    #[arg(long)]
    pub min_spp: Option<u32>,
    /// Camera position (world space) [default: framed on the volume].
    #[arg(long, value_parser = point, allow_hyphen_values = true, requires = "camera_to")]
    pub camera_from: Option<DVec3>,
    #[arg(long, value_parser = point, allow_hyphen_values = true, requires = "camera_from")]
    pub camera_to: Option<DVec3>,
    /// [default: 0,1,0]
    #[arg(long, value_parser = vec3, allow_hyphen_values = true)]
    pub camera_up: Option<Vec3>,
    /// Vertical field of view in degrees [default: 40].
    #[arg(long)]
    pub fov: Option<f32>,
    /// Direction the sunlight travels, from the sun toward the scene [default: 0.7,-0.5,0.5].
    #[arg(long, value_parser = vec3, allow_hyphen_values = true)]
    pub sun_dir: Option<Vec3>,
    /// Sun irradiance on a surface facing it (W/m^2 per channel, Mitsuba's
    /// `directional`) [default: 2.6,2.5,2.3].
    #[arg(long, value_parser = vec3, allow_hyphen_values = true)]
    pub sun_irradiance: Option<Vec3>,
    /// Angular diameter of the sun in degrees (0: a delta light) [default: 0.53].
    #[arg(long)]
    pub sun_angle: Option<f32>,
    #[arg(long)]
    pub no_sun: bool,
    /// Constant sky radiance (0,0,0 for none) [default: 0.16,0.22,0.34].
    #[arg(long, value_parser = vec3, allow_hyphen_values = true)]
    pub env_radiance: Option<Vec3>,
    /// A lat-long HDR sky (EXR) instead of the constant radiance.
    #[arg(long)]
    pub env_map: Option<PathBuf>,
    /// Rotation of the sky map about +Y, in degrees [default: 0].
    #[arg(long, allow_hyphen_values = true)]
    pub env_rotation: Option<f32>,
    /// Multiplier of the sky map's radiance [default: 1].
    #[arg(long)]
    pub env_intensity: Option<f32>,
    /// Extinction per unit density, in 1/world units: one number, or R,G,B
    /// for a chromatic medium [default: 0.5 / voxel size, so density 1 is
    /// half a mean free path per voxel].
    #[arg(long, value_parser = crate::parse::colour)]
    pub density_scale: Option<Colour>,
    /// Single-scattering albedo: one number or R,G,B [default: 0.99].
    #[arg(long, value_parser = crate::parse::colour)]
    pub albedo: Option<Colour>,
    /// Henyey-Greenstein asymmetry (of the first lobe of hg2; Draine's g)
    /// [default: 0.6].
    #[arg(long, allow_hyphen_values = true)]
    pub g: Option<f32>,
    /// Phase function: hg, hg2 (two HG lobes), draine, mie (Jendersie and
    /// d'Eon 2023's fit by droplet diameter), rayleigh, or table:FILE (two
    /// columns, cos(theta) and value) [default: hg].
    #[arg(long)]
    pub phase: Option<String>,
    /// The second lobe of hg2 [default: -0.3].
    #[arg(long, allow_hyphen_values = true)]
    pub g2: Option<f32>,
    /// Weight of hg2's first lobe, in [0, 1] [default: 0.8].
    #[arg(long)]
    pub lobe_weight: Option<f32>,
    /// Droplet diameter of mie, in micrometres (5 to 50) [default: 20].
    #[arg(long)]
    pub droplet_diameter: Option<f32>,
    /// Draine's alpha [default: 1].
    #[arg(long)]
    pub draine_alpha: Option<f32>,
    /// Real scattering events per path (0: only the sky through the volume,
    /// 1: single scattering) [default: unlimited, ended by Russian roulette].
    #[arg(long)]
    pub max_depth: Option<u32>,
    /// [default: path]
    #[arg(long, value_enum)]
    pub integrator: Option<IntegratorKind>,
    /// Shadow-ray transmittance estimator [default: residual].
    #[arg(long, value_enum)]
    pub transmittance: Option<TransmittanceEstimator>,
    /// Majorants for tracking: the brick hierarchy, one global majorant
    /// (Mitsuba-like), or whichever a probe of the scene finds cheaper
    /// [default: auto].
    #[arg(long, value_enum)]
    pub majorant: Option<MajorantMode>,
    /// Majorant cells are refined while crossing one would cost more than
    /// this many extra null collisions (optical depth; Blender Cycles uses
    /// 1.442; 0 refines to the finest 4^3 cells) [default: 1].
    #[arg(long)]
    pub refine_optical_depth: Option<f32>,
    /// Ray-march step in voxels [default: 0.5].
    #[arg(long)]
    pub step: Option<f32>,
    /// The ray marchers' shadow-ray step in voxels, as vdb_render's
    /// -shadowstep [default: the step].
    #[arg(long)]
    pub shadow_step: Option<f32>,
    /// Motion blur: the shutter's open and close times in frames around
    /// the frame, e.g. -0.25,0.25 (centred) or 0,0.5 [default: 0,0, none].
    #[arg(long, value_parser = parse::shutter, allow_hyphen_values = true)]
    pub shutter: Option<[f32; 2]>,
    /// The vec3 velocity grid moving the volume while the shutter is open
    /// [default: "vel" or "v" if the file has one].
    #[arg(long)]
    pub velocity: Option<String>,
    /// What velocity values measure: world units or velocity-grid voxels,
    /// per frame [default: world].
    #[arg(long, value_enum)]
    pub velocity_unit: Option<VelocityUnit>,
    /// Multiplies velocity values, e.g. 0.041667 (1/24) for per-second
    /// velocities at 24 fps [default: 1].
    #[arg(long)]
    pub velocity_scale: Option<f32>,
    /// Denoise with Intel Open Image Denoise 2.x (guided by the albedo
    /// AOV); the EXR keeps the noisy image as `noisy.R/G/B`.
    #[arg(long)]
    pub denoise: bool,
    // Compositing.
    /// A camera-space depth image (planar depth, as Blender's Z pass) of
    /// the same camera and size, FILE.exr[:CHANNEL]: camera rays end there,
    /// so the cloud renders behind geometry it was never given
    /// [default channel: Z, or the one ending in .Z].
    #[arg(long)]
    pub holdout_depth: Option<String>,
    /// Depths at or beyond this are no depth [default: 1e10, Blender's
    /// background].
    #[arg(long)]
    pub holdout_far: Option<f32>,
    // End of compositing.
}

/// Where the image goes.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct OutputFlags {
    /// Output EXR (RGBA f32; alpha = 1 - camera-ray transmittance); a
    /// scene file may give it instead (`[output] exr`).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Also write an sRGB PNG preview.
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Exposure of the PNG preview, in stops [default: 0].
    #[arg(long, allow_hyphen_values = true)]
    pub exposure: Option<f32>,
    /// Write render statistics as JSON.
    #[arg(long)]
    pub stats: Option<PathBuf>,
    /// AOV layers to add to the EXR.
    #[arg(long, value_delimiter = ',', value_enum)]
    pub aov: Vec<Aov>,
    /// Render only the pixels [x0, x1) x [y0, y1) into a full-size EXR with
    /// a data window (merge tiles with `cirrus merge`).
    #[arg(long, value_parser = parse::crop)]
    pub crop: Option<Crop>,
    // Compositing.
    /// Write a deep scanline EXR (Z, ZBack, R, G, B, A) of the camera rays'
    /// volumetric samples.
    #[arg(long)]
    pub deep: Option<PathBuf>,
    /// Deep samples per pixel at most, merged by optical depth (plus one
    /// for the background) [default: 16].
    #[arg(long)]
    pub deep_samples: Option<u32>,
    // End of compositing.
}

impl SceneFlags {
    /// The flags given, as overrides (outputs left unset).
    pub fn overrides(&self) -> Overrides {
        Overrides {
            grid: self.grid.clone(),
            density_scale: self.density_scale,
            albedo: self.albedo,
            g: self.g,
            phase: self.phase.clone(),
            g2: self.g2,
            lobe_weight: self.lobe_weight,
            droplet_diameter: self.droplet_diameter,
            draine_alpha: self.draine_alpha,
            velocity: self.velocity.clone(),
            velocity_unit: self.velocity_unit,
            velocity_scale: self.velocity_scale,
            shutter: self.shutter,
            spp: self.spp,
            time: self.time,
            seed: self.seed,
            sampler: self.sampler,
            noise_threshold: self.noise_threshold,
            min_spp: self.min_spp,
            integrator: self.integrator,
            transmittance: self.transmittance,
            majorant: self.majorant,
            max_depth: self.max_depth,
            step: self.step,
            shadow_step: self.shadow_step,
            refine_optical_depth: self.refine_optical_depth,
            denoise: self.denoise.then_some(true),
            res: self.res,
            camera_from: self.camera_from,
            camera_to: self.camera_to,
            camera_up: self.camera_up,
            fov: self.fov,
            sun: self.no_sun.then_some(false),
            sun_dir: self.sun_dir,
            sun_irradiance: self.sun_irradiance,
            sun_angle: self.sun_angle,
            env_radiance: self.env_radiance,
            env_map: self.env_map.clone(),
            env_rotation: self.env_rotation,
            env_intensity: self.env_intensity,
            holdout_depth: self.holdout_depth.clone(),
            holdout_far: self.holdout_far,
            ..Default::default()
        }
    }
}

impl OutputFlags {
    /// Writes the output flags given into `o`.
    pub fn write_into(&self, o: &mut Overrides) {
        o.output = self.output.clone();
        o.png = self.png.clone();
        o.exposure = self.exposure;
        o.stats = self.stats.clone();
        o.aov = (!self.aov.is_empty()).then(|| self.aov.clone());
        o.crop = self.crop;
        o.deep = self.deep.clone();
        o.deep_samples = self.deep_samples;
    }
}
