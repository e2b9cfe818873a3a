//! `cirrus render FILE ...`: one volume, a camera, a sun and a sky, to EXR
//! (and a PNG preview). The flags are the issue-4 contract; see `--help`.

use super::CliResult;
use cirrus_bricks::{convert, read_cbrk, BrickVolume, Precision};
use cirrus_render::exr_layers::{write_exr_layers, Aov};
use cirrus_render::image_io::write_png;
use cirrus_render::medium::BrickField;
use cirrus_render::DensityField;
use cirrus_render::{
    render, Budget, Camera, Crop, EnvMap, Environment, IntegratorKind, Lights, MajorantMode,
    Medium, RenderSettings, Rendered, Scene, Sun, TransmittanceEstimator,
};
use cirrus_vdb::VolumeFile;
use clap::ArgMatches;
use glam::{DMat4, DVec3, Vec3};
use std::path::{Path, PathBuf};
use std::sync::Arc;
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

pub fn resolution(s: &str) -> Result<(u32, u32), String> {
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
    /// Output EXR (RGBA f32; alpha = 1 - camera-ray transmittance); a
    /// scene file may give it instead (`[output] exr`).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Also write an sRGB PNG preview.
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Exposure of the PNG preview, in stops.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub exposure: f32,
    /// Write render statistics as JSON.
    #[arg(long)]
    pub stats: Option<PathBuf>,
    /// AOV layers to add to the EXR: albedo, depth, emission, direct, samples.
    #[arg(long, value_delimiter = ',', value_parser = Aov::parse)]
    pub aov: Vec<Aov>,
    /// Render only the pixels [x0, x1) x [y0, y1) into a full-size EXR with
    /// a data window (merge tiles with `cirrus merge`).
    #[arg(long, value_parser = crop)]
    pub crop: Option<Crop>,
}

/// "x0,y0,x1,y1" in pixels.
pub fn crop(s: &str) -> Result<Crop, String> {
    let v: Vec<u32> = s
        .split(',')
        .map(|c| c.trim().parse::<u32>().map_err(|e| format!("{s:?}: {e}")))
        .collect::<Result<_, _>>()?;
    match v[..] {
        [x0, y0, x1, y1] => Ok(Crop { x0, y0, x1, y1 }),
        _ => Err(format!("expected x0,y0,x1,y1, got {s:?}")),
    }
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
    /// A lat-long HDR sky (EXR) instead of the constant radiance.
    #[arg(long)]
    pub env_map: Option<PathBuf>,
    /// Rotation of the sky map about +Y, in degrees.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub env_rotation: f32,
    /// Multiplier of the sky map's radiance.
    #[arg(long, default_value_t = 1.0)]
    pub env_intensity: f32,
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
    /// Shadow-ray transmittance estimator. Residual ratio tracking (the
    /// segment minorants as control) is the default: in BENCHMARKS.md it is
    /// 1.07x to 1.17x as efficient as plain ratio tracking over the
    /// hierarchy, with less noise per path than track-length.
    #[arg(long, default_value = "residual", value_parser = ["ratio", "residual", "track-length"])]
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
    Ok(load_volume_counted(file, grid)?.0)
}

/// [`load_volume`] and the bytes it read from disk (a .cbrk counts whole).
pub fn load_volume_counted(
    file: &PathBuf,
    grid: Option<&str>,
) -> Result<(BrickVolume, u64), Box<dyn std::error::Error>> {
    if file.extension().is_some_and(|e| e == "cbrk") {
        let bytes = std::fs::metadata(file).map(|m| m.len()).unwrap_or(0);
        return Ok((read_cbrk(file)?, bytes));
    }
    let f = VolumeFile::open(file)?;
    let index = super::convert::choose_grid(&f, grid)?;
    let g = f.read_grid(index)?;
    let volume = convert(&g, Precision::F32).map_err(|e| format!("{}: {e}", file.display()))?;
    Ok((volume, f.bytes_read()))
}

/// The sky: the map if one is given, else the constant radiance.
pub fn environment(args: &SceneArgs) -> Result<Environment, String> {
    match &args.env_map {
        None => Ok(Environment::new(args.env_radiance)),
        Some(path) => {
            let map = EnvMap::read_exr(path, args.env_rotation)?;
            Ok(Environment::from_map(
                Arc::new(map),
                Vec3::splat(args.env_intensity),
            ))
        }
    }
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
    let lights = lights(args)?;
    let scene = Scene {
        medium: Medium::new(field, density_scale, Vec3::splat(args.albedo), args.g),
        camera,
        lights,
    };
    scene.validate()?;
    let settings = settings(args)?;
    Ok((scene, settings))
}

/// The sun and sky that `args` describe (absent or black lights pruned).
pub fn lights(args: &SceneArgs) -> Result<Lights, String> {
    Ok(Lights {
        sun: (!args.no_sun).then(|| {
            Sun::new(
                args.sun_dir,
                args.sun_irradiance,
                args.sun_angle.to_radians(),
            )
        }),
        environment: Some(environment(args)?),
    }
    .pruned())
}

/// The render settings that `args` describe, validated.
pub fn settings(args: &SceneArgs) -> Result<RenderSettings, String> {
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
    Ok(settings)
}

pub fn run(args: &RenderArgs, matches: &ArgMatches) -> CliResult {
    if args.scene.file.extension().is_some_and(|e| e == "toml") {
        return super::scene_render::run(args, matches);
    }
    let output = args
        .output
        .as_ref()
        .ok_or("an output file is required: -o OUT.exr")?;
    let start = Instant::now();
    let (volume, bytes_read) = load_volume_counted(&args.scene.file, args.scene.grid.as_deref())?;
    let load_seconds = start.elapsed().as_secs_f64();
    let (scene, mut settings) = prepare(&args.scene, &volume)?;
    settings.crop = args.crop;
    settings.aovs = !args.aov.is_empty();
    if let Some(c) = &args.crop {
        c.validate(args.scene.res.0, args.scene.res.1)?;
    }
    let mut rendered = render(&scene, &settings);
    rendered.stats.bytes_read = bytes_read;
    rendered.stats.grids_loaded = 1;
    let outputs = Outputs {
        exr: output,
        png: args.png.as_deref(),
        exposure: args.exposure,
        stats: args.stats.as_deref(),
        aovs: &args.aov,
    };
    write_outputs(&rendered, &outputs, load_seconds)
}

/// Where a render goes.
pub struct Outputs<'a> {
    pub exr: &'a Path,
    pub png: Option<&'a Path>,
    pub exposure: f32,
    pub stats: Option<&'a Path>,
    pub aovs: &'a [Aov],
}

/// Writes the EXR (with AOV layers and a crop's data window), the PNG
/// preview and the statistics, and prints a summary line.
pub fn write_outputs(rendered: &Rendered, out: &Outputs, load_seconds: f64) -> CliResult {
    write_exr_layers(out.exr, rendered, out.aovs)
        .map_err(|e| format!("{}: {e}", out.exr.display()))?;
    if let Some(png) = out.png {
        write_png(png, &rendered.image, out.exposure)
            .map_err(|e| format!("{}: {e}", png.display()))?;
    }
    let s = &rendered.stats;
    eprintln!(
        "{}: {}x{} at {} spp in {:.2} s ({:.0} paths/s; {} real, {} null collisions; load {:.2} s)",
        out.exr.display(),
        s.width,
        s.height,
        s.spp,
        s.wall_seconds,
        s.rays_per_second,
        s.counters.real_collisions,
        s.counters.null_collisions,
        load_seconds
    );
    if let Some(path) = out.stats {
        super::write_whole(path, s.to_json().as_bytes())?;
    }
    Ok(())
}
