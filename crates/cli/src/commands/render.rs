//! `cirrus render FILE ...`: one volume, a camera, a sun and a sky, to EXR
//! (and a PNG preview). The flags are the issue-4 contract; see `--help`.

use super::CliResult;
use cirrus_bricks::{convert, read_cbrk, BrickVolume, Precision};
use cirrus_render::image_io::{write_exr, write_png};
use cirrus_render::medium::BrickField;
use cirrus_render::DensityField;
use cirrus_render::{
    render, Budget, Camera, Environment, IntegratorKind, Lights, MajorantMode, Medium,
    RenderSettings, Scene, Sun, TransmittanceEstimator,
};
use cirrus_vdb::VolumeFile;
use glam::{DMat4, DVec3, Vec3};
use std::path::PathBuf;
use std::time::Instant;

/// Three finite numbers "x,y,z" (a leading minus is fine).
fn triple(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|c| c.trim().parse::<f64>().map_err(|e| format!("{s:?}: {e}")))
        .collect::<Result<_, _>>()?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok([x, y, z]),
        _ => Err(format!("expected three finite numbers x,y,z, got {s:?}")),
    }
}

/// A world position, kept in f64 until it is moved into render space.
fn point(s: &str) -> Result<DVec3, String> {
    triple(s).map(DVec3::from_array)
}

/// A direction or colour.
fn vec3(s: &str) -> Result<Vec3, String> {
    triple(s).map(|v| DVec3::from_array(v).as_vec3())
}

fn resolution(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WxH, got {s:?}"))?;
    let w: u32 = w.parse().map_err(|e| format!("{s:?}: {e}"))?;
    let h: u32 = h.parse().map_err(|e| format!("{s:?}: {e}"))?;
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(format!(
            "resolution {w}x{h} must be between 1 and 16384 a side"
        ));
    }
    Ok((w, h))
}

#[derive(clap::Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Output EXR (RGBA f32; alpha = 1 - camera-ray transmittance).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Also write an sRGB PNG preview.
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Exposure of the PNG preview, in stops.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub exposure: f32,
    /// Write render statistics as JSON.
    #[arg(long)]
    pub stats: Option<PathBuf>,
}

/// What to render and how: everything but the outputs, shared with the
/// benchmarks that render the same scene many times.
#[derive(clap::Args, Clone)]
pub struct SceneArgs {
    /// A .vdb, .nvdb or .cbrk file.
    pub file: PathBuf,
    /// The density grid (default: "density", else the first float grid).
    #[arg(long)]
    pub grid: Option<String>,
    #[arg(long, default_value = "512x512", value_parser = resolution)]
    pub res: (u32, u32),
    /// Samples per pixel.
    #[arg(long, conflicts_with = "time")]
    pub spp: Option<u32>,
    /// Render passes until this many seconds are spent.
    #[arg(long)]
    pub time: Option<f64>,
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Camera position (world space); default: framed on the volume.
    #[arg(long, value_parser = point, allow_hyphen_values = true, requires = "camera_to")]
    pub camera_from: Option<DVec3>,
    #[arg(long, value_parser = point, allow_hyphen_values = true, requires = "camera_from")]
    pub camera_to: Option<DVec3>,
    #[arg(long, value_parser = vec3, allow_hyphen_values = true, default_value = "0,1,0")]
    pub camera_up: Vec3,
    /// Vertical field of view in degrees.
    #[arg(long, default_value_t = 40.0)]
    pub fov: f32,
    /// Direction the sunlight travels (from the sun toward the scene).
    #[arg(long, value_parser = vec3, allow_hyphen_values = true, default_value = "0.7,-0.5,0.5")]
    pub sun_dir: Vec3,
    /// Sun irradiance on a surface facing it (W/m^2 per channel, Mitsuba's `directional`).
    #[arg(long, value_parser = vec3, allow_hyphen_values = true, default_value = "2.6,2.5,2.3")]
    pub sun_irradiance: Vec3,
    /// Angular diameter of the sun in degrees (0: a delta light; the real sun is 0.53).
    #[arg(long, default_value_t = 0.53)]
    pub sun_angle: f32,
    #[arg(long)]
    pub no_sun: bool,
    /// Constant sky radiance (0,0,0 for none).
    #[arg(long, value_parser = vec3, allow_hyphen_values = true, default_value = "0.16,0.22,0.34")]
    pub env_radiance: Vec3,
    /// Extinction per unit density, in 1/world units (default: 0.5 / voxel
    /// size, so density 1 is half a mean free path per voxel).
    #[arg(long)]
    pub density_scale: Option<f32>,
    /// Single-scattering albedo.
    #[arg(long, default_value_t = 0.99)]
    pub albedo: f32,
    /// Henyey-Greenstein asymmetry (a cloud's Mie lobe is near 0.85; one
    /// HG lobe that sharp makes sunlit paths noisy, 0.6 keeps the silver
    /// lining at a fraction of the noise).
    #[arg(long, default_value_t = 0.6, allow_hyphen_values = true)]
    pub g: f32,
    /// Real scattering events per path (0: only the sky through the volume, 1: single scattering).
    #[arg(long)]
    pub max_depth: Option<u32>,
    #[arg(long, default_value = "path", value_parser = ["path", "raymarch", "raymarch2pass"])]
    pub integrator: String,
    #[arg(long, default_value = "ratio", value_parser = ["ratio", "residual", "track-length"])]
    pub transmittance: String,
    /// Majorants for tracking: the brick hierarchy, or one global majorant (Mitsuba-like).
    #[arg(long, default_value = "hierarchy", value_parser = ["hierarchy", "global"])]
    pub majorant: String,
    /// Majorant cells are refined while crossing one would cost more than this
    /// many extra null collisions (optical depth; Blender Cycles uses 1.442; 0
    /// refines to the finest 4^3 cells).
    #[arg(long, default_value_t = 1.0)]
    pub refine_optical_depth: f32,
    /// Ray-march step in voxels.
    #[arg(long, default_value_t = 0.5)]
    pub step: f32,
}

/// Loads the volume of a .vdb/.nvdb (converted at f32) or a .cbrk.
pub fn load_volume(
    file: &PathBuf,
    grid: Option<&str>,
) -> Result<BrickVolume, Box<dyn std::error::Error>> {
    if file.extension().is_some_and(|e| e == "cbrk") {
        return Ok(read_cbrk(file)?);
    }
    let f = VolumeFile::open(file)?;
    let index = super::convert::choose_grid(&f, grid)?;
    let g = f.read_grid(index)?;
    Ok(convert(&g, Precision::F32).map_err(|e| format!("{}: {e}", file.display()))?)
}

/// The scene and settings that `args` describe, over a loaded volume.
///
/// Render space is world space minus the volume's centre, computed in f64,
/// so f32 stays precise for volumes far from the origin.
pub fn prepare<'v>(
    args: &SceneArgs,
    volume: &'v BrickVolume,
) -> Result<(Scene<BrickField<'v>>, RenderSettings), Box<dyn std::error::Error>> {
    let world_from_local = volume.local_from_world().inverse();
    let centre = world_from_local.transform_point3(volume.local_extent().as_dvec3() * 0.5);
    let field = BrickField::new(volume, DMat4::IDENTITY, centre);
    let to_render = |p: DVec3| (p - centre).as_vec3();
    let (w, h) = args.res;
    let camera = match (args.camera_from, args.camera_to) {
        (Some(from), Some(to)) => Camera::new(
            to_render(from),
            to_render(to),
            args.camera_up,
            args.fov,
            w,
            h,
        ),
        _ => Camera::framing(field.bounds(), w, h),
    };
    let density_scale = args.density_scale.unwrap_or(0.5 / field.voxel_size());
    let field = field.with_refinement(density_scale, args.refine_optical_depth);
    let lights = Lights {
        sun: (!args.no_sun).then(|| {
            Sun::new(
                args.sun_dir,
                args.sun_irradiance,
                args.sun_angle.to_radians(),
            )
        }),
        environment: Some(Environment::new(args.env_radiance)),
    }
    .pruned();
    let scene = Scene {
        medium: Medium::new(field, density_scale, Vec3::splat(args.albedo), args.g),
        camera,
        lights,
    };
    scene.validate()?;
    let settings = RenderSettings {
        integrator: match args.integrator.as_str() {
            "raymarch" => IntegratorKind::RayMarch,
            "raymarch2pass" => IntegratorKind::RayMarch2Pass,
            _ => IntegratorKind::Path,
        },
        transmittance: match args.transmittance.as_str() {
            "residual" => TransmittanceEstimator::Residual,
            "track-length" => TransmittanceEstimator::TrackLength,
            _ => TransmittanceEstimator::Ratio,
        },
        majorant: if args.majorant == "global" {
            MajorantMode::Global
        } else {
            MajorantMode::Hierarchy
        },
        budget: match (args.spp, args.time) {
            (_, Some(t)) => Budget::Time(t),
            (Some(n), None) => Budget::Spp(n),
            (None, None) => Budget::Spp(64),
        },
        seed: args.seed,
        max_depth: args.max_depth,
        step_voxels: args.step,
        progress: true,
        ..Default::default()
    };
    settings.validate()?;
    Ok((scene, settings))
}

pub fn run(args: &RenderArgs) -> CliResult {
    let start = Instant::now();
    let volume = load_volume(&args.scene.file, args.scene.grid.as_deref())?;
    let load_seconds = start.elapsed().as_secs_f64();
    let (w, h) = args.scene.res;
    let (scene, settings) = prepare(&args.scene, &volume)?;
    let rendered = render(&scene, &settings);
    write_exr(&args.output, &rendered.image)
        .map_err(|e| format!("{}: {e}", args.output.display()))?;
    if let Some(png) = &args.png {
        write_png(png, &rendered.image, args.exposure)
            .map_err(|e| format!("{}: {e}", png.display()))?;
    }
    let s = &rendered.stats;
    eprintln!(
        "{}: {}x{} at {} spp in {:.2} s ({:.0} paths/s; {} real, {} null collisions; load {:.2} s)",
        args.output.display(),
        w,
        h,
        s.spp,
        s.wall_seconds,
        s.rays_per_second,
        s.real_collisions,
        s.null_collisions,
        load_seconds
    );
    if let Some(path) = &args.stats {
        super::write_whole(path, s.to_json().as_bytes())?;
    }
    Ok(())
}
