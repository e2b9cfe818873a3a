//! `cirrus bench error SCENE-FLAGS --out DIR`: run time against error for
//! every estimator and majorant structure on one scene.
//!
//! A converged reference (the best unbiased configuration, long, with its
//! own seed; or `--reference FILE.exr`) is rendered first; then each
//! configuration renders with each time budget and its RMSE and relative
//! MSE against the reference are recorded. An unbiased estimator that is
//! twice as fast but four times noisier is slower: efficiency is
//! 1 / (MSE x time), reported relative to the Mitsuba-like baseline (delta
//! tracking + ratio tracking over one global majorant) at the same budget.
//!
//! Beside the estimators and structures (all with the default Sobol
//! sampler), configurations of the default one show what the sampler,
//! adaptive sampling, light selection and denoising each give:
//! independent random numbers instead of Sobol points, adaptive sampling
//! at `--noise-threshold`, a shadow ray to every light at each vertex
//! (`--light-sampling all`) instead of to one, sunward scattering
//! (`--sunward on`; every other row renders with it off, so that the
//! estimators compare as Mitsuba and Cycles trace),
//! and Open Image Denoise on the finished image (its time counted; left
//! out, with a note, where the library does not load).

mod ceiling;

use crate::fixed_grid::FixedGridField;
use crate::BenchResult;
use ceiling::CollisionCost;
use cirrus_render::{
    render, Adaptive, Budget, IntegratorKind, LightSampling, MajorantMode, Medium, RenderSettings,
    SamplerKind, Scene, Sunward, TransmittanceEstimator, Volumes,
};
use cirrus_scene::{Scene as SceneFile, SceneFlags, VolumeCache};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct ErrorArgs {
    #[command(flatten)]
    pub scene: SceneFlags,
    /// Output folder: results.csv, error_vs_time.png, report.md, reference.exr.
    #[arg(long)]
    pub out: PathBuf,
    /// Time budgets in seconds.
    #[arg(long, value_delimiter = ',', default_value = "0.25,0.5,1,2,4,8")]
    pub budgets: Vec<f64>,
    /// A converged reference image instead of rendering one.
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// Seconds for the reference render (delta + residual ratio tracking over the hierarchy).
    #[arg(long, default_value_t = 120.0)]
    pub reference_time: f64,
    /// Ray-march steps (in voxels) to measure.
    #[arg(long, value_delimiter = ',', default_value = "2,1,0.5")]
    pub steps: Vec<f32>,
    /// Cells per axis of the fixed majorant grid (pbrt-v4's NanoVDB medium uses 64).
    #[arg(long, default_value_t = 64)]
    pub fixed_res: i32,
    /// Relative error at which the adaptive configuration stops a pixel.
    #[arg(long, default_value_t = 0.02)]
    pub adaptive_threshold: f32,
    /// Measure only the configurations whose names contain this (names
    /// hold commas, so repeat the flag for several); the baseline is always
    /// measured.
    #[arg(long)]
    pub only: Vec<String>,
}

#[derive(Clone, Copy, PartialEq)]
enum Structure {
    Hierarchy,
    Fixed,
    Global,
    /// The hierarchy or the global bound, as `MajorantMode::Auto` chooses.
    Auto,
}

impl Structure {
    fn name(self) -> &'static str {
        match self {
            Structure::Hierarchy => "hierarchy",
            Structure::Fixed => "fixed grid",
            Structure::Global => "global",
            Structure::Auto => "automatic",
        }
    }
}

struct Config {
    name: String,
    integrator: IntegratorKind,
    transmittance: TransmittanceEstimator,
    structure: Structure,
    step: f32,
    sampler: SamplerKind,
    adaptive: Option<Adaptive>,
    denoise: bool,
    light_sampling: LightSampling,
    sunward: Sunward,
}

impl Config {
    /// An unbiased configuration with the default sampler.
    fn path(name: String, transmittance: TransmittanceEstimator, structure: Structure) -> Self {
        Config {
            name,
            integrator: IntegratorKind::Path,
            transmittance,
            structure,
            step: 1.0,
            sampler: SamplerKind::Sobol,
            adaptive: None,
            denoise: false,
            light_sampling: LightSampling::default(),
            sunward: Sunward::Off,
        }
    }
}

/// The baseline every efficiency is relative to: Mitsuba 3's scheme.
const BASELINE: &str = "delta + ratio, global";

/// One measured render.
struct Row {
    config: String,
    budget: f64,
    wall: f64,
    spp: u32,
    mse: f64,
    rel_mse: f64,
    paths_per_s: f64,
    lookups_per_path: f64,
    null_per_real: f64,
    real_per_path: f64,
}

fn configs(args: &ErrorArgs) -> Vec<Config> {
    let mut v = Vec::new();
    for structure in [Structure::Hierarchy, Structure::Fixed, Structure::Global] {
        for (t, tn) in [
            (TransmittanceEstimator::Ratio, "ratio"),
            (TransmittanceEstimator::Residual, "residual"),
            (TransmittanceEstimator::TrackLength, "track-length"),
        ] {
            v.push(Config::path(
                format!("delta + {tn}, {}", structure.name()),
                t,
                structure,
            ));
        }
    }
    // The default configuration with each of the image-level techniques.
    // Their names do not start with "delta": the ceiling compares
    // majorant structures at equal sampling.
    let default = |name: &str| {
        Config::path(
            format!("{name}: delta + residual, hierarchy"),
            TransmittanceEstimator::Residual,
            Structure::Hierarchy,
        )
    };
    v.push(Config {
        name: "automatic structure: delta + residual".into(),
        structure: Structure::Auto,
        ..default("")
    });
    v.push(Config {
        sampler: SamplerKind::Random,
        ..default("random numbers")
    });
    v.push(Config {
        adaptive: Some(Adaptive {
            threshold: args.adaptive_threshold,
            min_spp: cirrus_scene::description::RenderSpec::default().min_spp(),
        }),
        ..default(&format!("adaptive {}%", 100.0 * args.adaptive_threshold))
    });
    v.push(Config {
        sunward: Sunward::On,
        ..default("sunward scattering")
    });
    v.push(Config {
        light_sampling: LightSampling::All,
        ..default("every light per vertex")
    });
    match cirrus_scene::denoise_available() {
        Ok(()) => v.push(Config {
            denoise: true,
            ..default("OIDN")
        }),
        Err(e) => eprintln!("not measuring denoising: {e}"),
    }
    for &step in &args.steps {
        for (k, kn) in [
            (IntegratorKind::RayMarch, "raymarch"),
            (IntegratorKind::RayMarch2Pass, "raymarch2pass"),
        ] {
            v.push(Config {
                integrator: k,
                step,
                ..Config::path(
                    format!("{kn}, step {step}"),
                    TransmittanceEstimator::Ratio,
                    Structure::Hierarchy,
                )
            });
        }
    }
    if !args.only.is_empty() {
        v.retain(|c| c.name == BASELINE || args.only.iter().any(|o| c.name.contains(o.as_str())));
    }
    v
}

fn errors(image: &[[f32; 4]], reference: &[[f32; 4]]) -> (f64, f64) {
    let (mut mse, mut rel) = (0f64, 0f64);
    for (a, r) in image.iter().zip(reference) {
        for c in 0..3 {
            let d = (a[c] - r[c]) as f64;
            mse += d * d;
            // Relative MSE as in the rendering literature: (x - r)^2 / (r^2 + eps).
            rel += d * d / ((r[c] as f64).powi(2) + 1e-2);
        }
    }
    let n = (3 * reference.len()).max(1) as f64;
    (mse / n, rel / n)
}

/// Width, height and RGBA pixels (row-major) of an image file.
type RgbaImage = (usize, usize, Vec<[f32; 4]>);

fn read_exr_rgba(path: &Path) -> Result<RgbaImage, Box<dyn std::error::Error>> {
    use exr::prelude::*;
    let image = read_first_rgba_layer_from_file(
        path,
        |res, _| (res.width(), vec![[0f32; 4]; res.width() * res.height()]),
        |(w, px), pos, (r, g, b, a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = [r, g, b, a]
        },
    )
    .map_err(|e| format!("{}: {e}", path.display()))?;
    let size = image.layer_data.size;
    Ok((
        size.width(),
        size.height(),
        image.layer_data.channel_data.pixels.1,
    ))
}

/// The scene again, loaded through `cache`, its fields walked through a
/// fixed grid of `res` cells a side (the uniform-grid baseline).
fn fixed_grid_scene<'c>(
    file: &SceneFile,
    res: i32,
    cache: &'c mut VolumeCache,
) -> Result<Scene<Volumes<FixedGridField<'c>>>, Box<dyn std::error::Error>> {
    let p = file.prepare(cache, None)?;
    let fixed: Vec<Medium<FixedGridField>> = p
        .scene
        .media
        .into_instances()
        .into_iter()
        .map(|m| Medium {
            field: FixedGridField::new(m.field.into_still(), res),
            density_scale: m.density_scale,
            extinction_tint: m.extinction_tint,
            albedo: m.albedo,
            phase: m.phase,
            emission: None,
            holdout: m.holdout,
        })
        .collect();
    Ok(Scene {
        media: Volumes::new(fixed),
        camera: p.scene.camera,
        lights: p.scene.lights,
    })
}

impl Row {
    /// The row of `config` at `budget` seconds: render `r`'s error against
    /// `reference` and its work.
    fn of(config: &str, budget: f64, r: &cirrus_render::Rendered, reference: &[[f32; 4]]) -> Self {
        let (mse, rel_mse) = errors(&r.image.rgba, reference);
        let s = &r.stats;
        let per_path = |n: u64| n as f64 / s.counters.paths.max(1) as f64;
        Row {
            config: config.to_string(),
            budget,
            // The denoiser's time is part of the image's cost.
            wall: s.wall_seconds + s.denoise_seconds,
            spp: s.spp,
            mse,
            rel_mse,
            paths_per_s: s.rays_per_second,
            lookups_per_path: per_path(s.counters.density_lookups),
            null_per_real: s.counters.null_collisions as f64
                / s.counters.real_collisions.max(1) as f64,
            real_per_path: per_path(s.counters.real_collisions),
        }
    }
}

/// A reference image from `path`, which must be `w` x `h`.
fn read_reference(
    path: &Path,
    w: u32,
    h: u32,
) -> Result<Vec<[f32; 4]>, Box<dyn std::error::Error>> {
    let (rw, rh, px) = read_exr_rgba(path)?;
    if (rw, rh) != (w as usize, h as usize) {
        return Err(format!(
            "{}: reference is {rw}x{rh}, the scene is {w}x{h}",
            path.display()
        )
        .into());
    }
    Ok(px)
}

impl Config {
    /// The render settings of this configuration over `base`.
    fn settings(&self, budget: Budget, seed: u64, base: &RenderSettings) -> RenderSettings {
        RenderSettings {
            integrator: self.integrator,
            transmittance: self.transmittance,
            majorant: match self.structure {
                Structure::Global => MajorantMode::Global,
                Structure::Auto => MajorantMode::Auto,
                Structure::Hierarchy | Structure::Fixed => MajorantMode::Hierarchy,
            },
            budget,
            seed,
            step_voxels: self.step,
            sampler: self.sampler,
            adaptive: self.adaptive,
            aovs: self.denoise,
            light_sampling: self.light_sampling,
            sunward: self.sunward,
            progress: false,
            ..base.clone()
        }
    }
}

pub fn run(args: &ErrorArgs) -> BenchResult {
    std::fs::create_dir_all(&args.out)?;
    let mut file = SceneFile::load(&args.scene.file)?;
    file.apply(&args.scene.overrides());
    let mut cache = VolumeCache::default();
    let prepared = file.prepare(&mut cache, None)?;
    let (scene, base) = (&prepared.scene, &prepared.settings);
    let (w, h) = (scene.camera.width(), scene.camera.height());
    let mut fixed_cache = VolumeCache::default();
    let fixed_scene = fixed_grid_scene(&file, args.fixed_res, &mut fixed_cache)?;
    let settings_for = |c: &Config, budget: Budget, seed: u64| c.settings(budget, seed, base);
    let render_with = |c: &Config, s: &RenderSettings| {
        if c.structure == Structure::Fixed {
            render(&fixed_scene, s)
        } else {
            render(scene, s)
        }
    };

    let reference = match &args.reference {
        Some(path) => read_reference(path, w, h)?,
        None => {
            let c = Config::path(
                "reference".into(),
                TransmittanceEstimator::Residual,
                Structure::Hierarchy,
            );
            eprintln!(
                "rendering the reference ({} s, delta + residual, hierarchy) ...",
                args.reference_time
            );
            let r = render_with(
                &c,
                &settings_for(
                    &c,
                    Budget::Time(args.reference_time),
                    base.seed ^ 0x5EED_F2EF,
                ),
            );
            cirrus_render::image_io::write_exr(&args.out.join("reference.exr"), &r.image)?;
            eprintln!("reference: {} spp", r.stats.spp);
            r.image.rgba
        }
    };

    let mut rows = Vec::new();
    for c in configs(args) {
        for &b in &args.budgets {
            let mut r = render_with(&c, &settings_for(&c, Budget::Time(b), base.seed));
            if c.denoise {
                cirrus_scene::denoise(&mut r)?;
            }
            let row = Row::of(&c.name, b, &r, &reference);
            eprintln!(
                "{:<34} {:>5.2} s: {:>5} spp, RMSE {:.5}, relMSE {:.5}",
                row.config,
                row.wall,
                row.spp,
                row.mse.sqrt(),
                row.rel_mse
            );
            rows.push(row);
        }
    }
    write_csv(&args.out.join("results.csv"), &rows)?;
    crate::plot::error_vs_time(&args.out.join("error_vs_time.png"), &rows_for_plot(&rows))?;
    let collision = ceiling::collision_cost(&scene.media);
    let report = report(args, &rows, w, h, collision);
    crate::write_whole(&args.out.join("report.md"), report.as_bytes())?;
    println!("{report}");
    Ok(())
}

fn rows_for_plot(rows: &[Row]) -> Vec<(String, Vec<(f64, f64)>)> {
    let mut series: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for r in rows {
        match series.iter_mut().find(|(n, _)| *n == r.config) {
            Some((_, pts)) => pts.push((r.wall, r.mse.sqrt())),
            None => series.push((r.config.clone(), vec![(r.wall, r.mse.sqrt())])),
        }
    }
    series
}

fn write_csv(path: &Path, rows: &[Row]) -> std::io::Result<()> {
    let mut s = String::from(
        "config,budget_s,wall_s,spp,rmse,mse,rel_mse,paths_per_s,lookups_per_path,null_per_real\n",
    );
    for r in rows {
        let _ = writeln!(
            s,
            "\"{}\",{},{:.4},{},{:.6e},{:.6e},{:.6e},{:.0},{:.2},{:.3}",
            r.config,
            r.budget,
            r.wall,
            r.spp,
            r.mse.sqrt(),
            r.mse,
            r.rel_mse,
            r.paths_per_s,
            r.lookups_per_path,
            r.null_per_real
        );
    }
    crate::write_whole(path, s.as_bytes())
}

/// The markdown report: one row per configuration with its error at the
/// largest budget and its efficiency against the global-majorant baseline
/// (geometric mean over budgets of MSE_base x t_base / (MSE x t)), then
/// the ceiling any majorant structure has on this scene (`ceiling.rs`).
fn report(args: &ErrorArgs, rows: &[Row], w: u32, h: u32, collision: CollisionCost) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Run time against error: {}\n",
        args.scene.file.display()
    );
    let _ = writeln!(
        s,
        "{w}x{h}, budgets {:?} s, {} threads. Efficiency = 1 / (MSE x time), relative to `{BASELINE}` (Mitsuba 3's scheme) at the same budget, geometric mean over budgets.\n",
        args.budgets,
        rayon::current_num_threads()
    );
    let _ = writeln!(s, "| configuration | spp at {0} s | RMSE at {0} s | relMSE at {0} s | MSE x paths/pixel | paths/s | lookups/path | null/real | efficiency vs baseline |", args.budgets.last().copied().unwrap_or(0.0));
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    let mut names: Vec<&str> = Vec::new();
    for r in rows {
        if !names.contains(&r.config.as_str()) {
            names.push(&r.config);
        }
    }
    for name in names {
        let mine: Vec<&Row> = rows.iter().filter(|r| r.config == name).collect();
        let base: Vec<&Row> = rows.iter().filter(|r| r.config == BASELINE).collect();
        let mut log_sum = 0f64;
        let mut n = 0;
        for (m, b) in mine.iter().zip(&base) {
            if m.mse > 0.0 && b.mse > 0.0 {
                log_sum += ((b.mse * b.wall) / (m.mse * m.wall)).ln();
                n += 1;
            }
        }
        let eff = if n > 0 {
            (log_sum / n as f64).exp()
        } else {
            f64::NAN
        };
        let last = mine.last().unwrap();
        let _ = writeln!(
            s,
            "| {name} | {} | {:.5} | {:.5} | {:.4} | {:.0} | {:.1} | {:.2} | {:.2}x |",
            last.spp,
            last.mse.sqrt(),
            last.rel_mse,
            last.mse * last.spp as f64,
            last.paths_per_s,
            last.lookups_per_path,
            last.null_per_real,
            eff
        );
    }
    let _ = writeln!(s, "\nThe biased ray marchers' error flattens at their bias as the budget grows; the unbiased estimators keep falling as 1/sqrt(time).\n");
    let _ = writeln!(s, "![error against time](error_vs_time.png)\n");
    ceiling::write(&mut s, rows, BASELINE, collision);
    s
}
