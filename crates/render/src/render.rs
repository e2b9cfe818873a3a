//! The render loop: tiles over rayon, sample passes, time budget, progress.

use std::time::{Duration, Instant};

use rayon::prelude::*;

use crate::adaptive::{Adaptive, Selection};
use crate::compositing::Layers;
use crate::film::{AovImage, Film, Halves, Image, Tile};
use crate::majorant_choice;
use crate::path_setup::{light_sampling_stat, path_tracer, shadow_grid, ShadowGrid};
use crate::pixel_sampler::PixelSampler;
use crate::progress::Progress;
use crate::scene::{fitted_tile_size, Budget, Crop, RenderSettings, Scene};
use crate::shutter_lights::OverShutter;
use crate::stats::RenderStats;
use cirrus_kernel::integrator::{
    CameraSampler, IntegratorKind, LightGrid, RayMarcher, TwoPassMarcher,
};
use cirrus_kernel::light::Lights;
use cirrus_kernel::medium::{GlobalMedia, Media};
use cirrus_kernel::sampling::{SampleStream, SamplerKind};
use cirrus_kernel::Camera;
use cirrus_kernel::{Counters, MajorantMode};

/// A finished render.
pub struct Rendered {
    /// The rendered pixels: the whole image, or the crop window.
    pub image: Image,
    pub stats: RenderStats,
    /// Where `image` sits in the camera's full image.
    pub window: Window,
    /// The AOV passes over the same pixels, if the settings asked for them.
    pub aovs: Option<AovImage>,
    /// The two halves of the image's samples, if the settings asked for
    /// them (a denoiser's error is measured with them).
    pub halves: Option<Halves>,
    /// What a denoiser made of the image, once one has replaced its RGB.
    pub denoised: Option<Denoised>,
    /// Light groups, Cryptomatte coverage and deep samples, if kept.
    pub layers: Option<Layers>,
}

/// The layers a denoiser leaves beside the image it replaced: the noisy
/// RGB, the plain denoised RGB, and per pixel the weight the final image
/// gives the noisy one (`final = w * noisy + (1 - w) * denoised`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Denoised {
    pub noisy: Vec<[f32; 3]>,
    pub plain: Vec<[f32; 3]>,
    pub noisy_weight: Vec<f32>,
}

/// Placement of a rendered window in the full image (an EXR data window
/// inside its display window).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Window {
    pub x0: u32,
    pub y0: u32,
    pub full_width: u32,
    pub full_height: u32,
}

/// The majorant structure a CPU render of `scene` with `settings` walks:
/// `auto` resolved by the same probe [`render`] runs, so another backend
/// walks what the CPU would.
pub fn majorant_mode<M: Media>(scene: &Scene<M>, settings: &RenderSettings) -> MajorantMode {
    let shadows = shadow_grid(&scene.media, &scene.lights, settings);
    let lights = &scene.lights;
    majorant_choice::choose(
        &scene.media,
        &scene.camera,
        lights,
        settings,
        shadows.as_ref(),
    )
    .0
}

/// Renders `scene` with `settings` on the ambient rayon pool (install a
/// `ThreadPool` around the call to choose the thread count).
///
/// Pixel `(x, y)`'s sample `s` draws all its numbers from
/// `SampleStream::new(sampler, seed, y * width + x, s)`, each pixel
/// accumulates its samples in order, and adaptive sampling decides on the
/// pixel's own samples alone, so the image is bit-identical for any
/// thread count and a crop is bit-identical to the same pixels of the
/// full image.
pub fn render<M: Media>(scene: &Scene<M>, settings: &RenderSettings) -> Rendered {
    let Scene {
        media,
        camera,
        lights,
    } = scene;
    let start = Instant::now();
    // Built before the majorant probe, whose paths should choose their
    // lights as the render's will (the grid holds no reference to the
    // media, so either structure takes it).
    let shadows = shadow_grid(media, lights, settings);
    let (mode, probe) = majorant_choice::choose(media, camera, lights, settings, shadows.as_ref());
    let mut r = match mode {
        MajorantMode::Global => render_with(
            &GlobalMedia::new(media),
            camera,
            lights,
            settings,
            shadows.as_ref(),
            start,
        ),
        _ => render_with(media, camera, lights, settings, shadows.as_ref(), start),
    };
    r.stats.majorant = match settings.majorant {
        MajorantMode::Auto => format!("auto: {}", mode.name()),
        _ => mode.name().into(),
    };
    r.stats.majorant_probe = probe.map(|[local, global]| [local.cost(), global.cost()]);
    r
}

fn render_with<M: Media>(
    medium: &M,
    camera: &Camera,
    lights: &Lights,
    settings: &RenderSettings,
    shadows: Option<&ShadowGrid>,
    start: Instant,
) -> Rendered {
    let mut counters = Counters::default();
    let out = integrate(
        medium,
        camera,
        lights,
        settings,
        shadows,
        start,
        &mut counters,
    );
    let wall_seconds = start.elapsed().as_secs_f64();
    let samples = &out.image.samples;
    let stats = RenderStats {
        device: "cpu".into(),
        integrator: settings.integrator.name().into(),
        transmittance: settings.transmittance.name().into(),
        majorant: settings.majorant.name().into(),
        width: out.image.width,
        height: out.image.height,
        spp: out.image.spp,
        wall_seconds,
        setup_seconds: out.setup_seconds,
        counters,
        rays_per_second: counters.paths as f64 / wall_seconds.max(1e-9),
        light_sampling: out.light_sampling,
        sunward: match settings.integrator {
            IntegratorKind::Path => settings.sunward.name().into(),
            _ => String::new(),
        },
        spp_mean: samples.iter().map(|&n| f64::from(n)).sum::<f64>() / samples.len().max(1) as f64,
        spp_min: samples.iter().copied().min().unwrap_or(0),
        spp_max: samples.iter().copied().max().unwrap_or(0),
        ..Default::default()
    };
    let crop = crop_of(settings, camera);
    Rendered {
        image: out.image,
        stats,
        window: Window {
            x0: crop.x0,
            y0: crop.y0,
            full_width: camera.width(),
            full_height: camera.height(),
        },
        aovs: out.aovs,
        halves: out.halves,
        denoised: None,
        layers: out.layers,
    }
}

/// What the sample passes resolve to.
struct Resolved {
    image: Image,
    aovs: Option<AovImage>,
    layers: Option<Layers>,
    halves: Option<Halves>,
}

/// What the integrator's passes made, with what its setup reports.
struct Integrated {
    image: Image,
    aovs: Option<AovImage>,
    layers: Option<Layers>,
    halves: Option<Halves>,
    /// Seconds from the render's start to its first sample pass (shadow
    /// grids).
    setup_seconds: f64,
    light_sampling: String,
}

/// Sets up the chosen integrator over `medium` and runs its passes.
fn integrate<M: Media>(
    medium: &M,
    camera: &Camera,
    lights: &Lights,
    settings: &RenderSettings,
    shadows: Option<&ShadowGrid>,
    start: Instant,
    counters: &mut Counters,
) -> Integrated {
    let lights = lights.clone();
    let done = |r: Resolved, setup_seconds: f64| Integrated {
        image: r.image,
        aovs: r.aovs,
        layers: r.layers,
        halves: r.halves,
        setup_seconds,
        light_sampling: String::new(),
    };
    match settings.integrator {
        IntegratorKind::Path => {
            let tracer = path_tracer(medium, &lights, settings, shadows);
            let light_sampling = light_sampling_stat(settings, &tracer, shadows);
            let setup = start.elapsed().as_secs_f64();
            let resolved = match lights.over_shutter() {
                None => run(&tracer, camera, settings, start, counters),
                Some(shutter) => {
                    let make = |l: &Lights| path_tracer(medium, l, settings, shadows);
                    let s = OverShutter::new(shutter, make);
                    run(&s, camera, settings, start, counters)
                }
            };
            Integrated {
                light_sampling,
                ..done(resolved, setup)
            }
        }
        IntegratorKind::RayMarch => {
            let marcher = |l: &Lights| {
                RayMarcher::new(medium, l.clone(), settings.step_voxels)
                    .with_shadow_step(settings.shadow_step())
            };
            let resolved = match lights.over_shutter() {
                None => run(&marcher(&lights), camera, settings, start, counters),
                Some(shutter) => {
                    let s = OverShutter::new(shutter, marcher);
                    run(&s, camera, settings, start, counters)
                }
            };
            done(resolved, 0.0)
        }
        IntegratorKind::RayMarch2Pass => {
            let grid = LightGrid::build(
                medium,
                &lights,
                settings.shadow_step(),
                &settings.light_grid,
                settings.seed,
                counters,
            );
            let setup = start.elapsed().as_secs_f64();
            let s = TwoPassMarcher::new(medium, lights, &grid, settings.step_voxels);
            done(run(&s, camera, settings, start, counters), setup)
        }
    }
}

/// The window to render: the settings' crop clamped to the image, or all.
pub(crate) fn crop_of(settings: &RenderSettings, camera: &Camera) -> Crop {
    let (w, h) = (camera.width(), camera.height());
    match settings.crop {
        Some(c) => {
            let (x1, y1) = (c.x1.min(w), c.y1.min(h));
            Crop {
                x0: c.x0.min(x1.saturating_sub(1)),
                y0: c.y0.min(y1.saturating_sub(1)),
                x1: x1.max(1),
                y1: y1.max(1),
            }
        }
        None => Crop {
            x0: 0,
            y0: 0,
            x1: w,
            y1: h,
        },
    }
}

/// Runs sample passes until the budget is spent and resolves the film
/// (and its AOVs).
fn run<S: CameraSampler>(
    sampler: &S,
    camera: &Camera,
    settings: &RenderSettings,
    start: Instant,
    counters: &mut Counters,
) -> Resolved {
    let crop = crop_of(settings, camera);
    let (w, h) = (crop.x1 - crop.x0, crop.y1 - crop.y0);
    let tile_size = fitted_tile_size(settings.tile_size, w, h, rayon::current_num_threads());
    let mut film = Film::new(
        (crop.x0, crop.y0, w, h),
        tile_size,
        (settings.aovs, settings.halves),
        &settings.compositing,
    );
    let progress = Progress::new(settings, film.width, film.height);
    let passes = Passes {
        sampler,
        pixels: PixelSampler::new(camera, settings),
        kind: settings.sampler,
        seed: settings.seed,
        progress: &progress,
    };
    let spp = match (settings.budget, settings.adaptive) {
        (Budget::Spp(n), None) => {
            let n = n.max(1);
            *counters += passes.run(&mut film, Plan::Uniform { s0: 0, s1: n }).0;
            n
        }
        (Budget::Spp(n), Some(rule)) => {
            let n = n.max(1);
            let plan = Plan::Adaptive {
                rule,
                selection: None,
                count: n,
                max: n,
            };
            *counters += passes.run(&mut film, plan).0;
            max_count(&film)
        }
        (Budget::Time(seconds), None) => passes.timed_uniform(&mut film, seconds, start, counters),
        (Budget::Time(seconds), Some(rule)) => {
            passes.timed_adaptive(&mut film, rule, seconds, start, counters)
        }
    };
    progress.finish();
    Resolved {
        image: film.resolve(spp, counters),
        aovs: film.resolve_aovs(),
        layers: film.resolve_layers(),
        halves: film.resolve_halves(),
    }
}

/// The most samples any pixel of `film` has.
fn max_count(film: &Film) -> u32 {
    let counts = film.tiles.iter().flat_map(|t| t.pixels.iter());
    counts.map(|p| p.count()).max().unwrap_or(0)
}

/// Which samples one pass takes of each pixel.
#[derive(Clone, Copy)]
enum Plan {
    /// Samples `s0..s1` of every pixel.
    Uniform { s0: u32, s1: u32 },
    /// Up to `count` more samples of each pixel not stopped (and taken by
    /// `selection`, if any), never beyond `max` in all; a pixel stops at
    /// the first checkpoint where `rule` says it has converged.
    Adaptive {
        rule: Adaptive,
        selection: Option<Selection>,
        count: u32,
        max: u32,
    },
}

/// Samples of one pixel between looks at the cancellation flag: one
/// relaxed atomic load per 64 paths costs nothing measurable, and at 100k
/// spp a stop comes within a pixel's 64 samples instead of a tile's 25M.
const CANCEL_CHECK: u32 = 64;

/// What every pass of one render shares.
struct Passes<'a, S> {
    sampler: &'a S,
    pixels: PixelSampler<'a>,
    kind: SamplerKind,
    seed: u64,
    progress: &'a Progress,
}

impl<S: CameraSampler> Passes<'_, S> {
    /// Progressive uniform passes until `seconds` of wall time since
    /// `start` are spent; returns the samples per pixel reached.
    fn timed_uniform(
        &self,
        film: &mut Film,
        seconds: f64,
        start: Instant,
        counters: &mut Counters,
    ) -> u32 {
        let budget = Duration::from_secs_f64(seconds.max(0.0));
        let loop_start = Instant::now();
        let mut spp = 0u32;
        let mut size = 1u32;
        while size > 0 && !self.progress.cancelled() {
            let plan = Plan::Uniform {
                s0: spp,
                s1: spp + size,
            };
            *counters += self.run(film, plan).0;
            spp += size;
            self.progress.set_spp(spp);
            // Next pass: as many samples as the measured rate says fit in
            // the remaining time, at most twice the last pass so one
            // noisy estimate cannot overshoot the budget badly.
            let per_spp = loop_start.elapsed().as_secs_f64() / spp as f64;
            let remaining = budget.saturating_sub(start.elapsed()).as_secs_f64();
            let fit = (remaining / per_spp.max(1e-9)).floor().min(u32::MAX as f64) as u32;
            size = fit.min(size.saturating_mul(2));
        }
        spp
    }

    /// Adaptive passes, each to the pixels of highest error, until
    /// `seconds` are spent or every pixel is below the threshold; returns
    /// the most samples any pixel took.
    fn timed_adaptive(
        &self,
        film: &mut Film,
        rule: Adaptive,
        seconds: f64,
        start: Instant,
        counters: &mut Counters,
    ) -> u32 {
        let budget = Duration::from_secs_f64(seconds.max(0.0));
        let mut size = 1u32;
        while size > 0 && !self.progress.cancelled() {
            let pass_start = Instant::now();
            let (selection, pixels) = Selection::next(film, &rule);
            if pixels == 0 {
                break; // every pixel is below the threshold
            }
            let plan = Plan::Adaptive {
                rule,
                selection: Some(selection),
                count: size,
                max: u32::MAX,
            };
            let (c, taken) = self.run(film, plan);
            *counters += c;
            self.progress.set_spp(max_count(film));
            // As the uniform loop, with the cost per sample of the last
            // pass alone: passes move from cheap sky pixels to costly
            // cloud pixels, so the running average would overshoot.
            // The next pass takes `size` samples of about as many
            // pixels as this one.
            let per_sample = pass_start.elapsed().as_secs_f64() / taken.max(1) as f64;
            let remaining = budget.saturating_sub(start.elapsed()).as_secs_f64();
            let fit = remaining / (per_sample * pixels as f64).max(1e-9);
            size = (fit.floor().min(u32::MAX as f64) as u32).min(size.saturating_mul(2));
        }
        max_count(film)
    }

    /// One pass over the film, tiles in parallel; returns the work
    /// counters and the number of samples taken.
    fn run(&self, film: &mut Film, plan: Plan) -> (Counters, u64) {
        film.tiles
            .par_iter_mut()
            // One job a tile: rayon runs a split's leaf to its end on one
            // thread, and idle threads can take only work not yet started,
            // so leaves of several tiles (a cloud's costly middle among
            // them) ended renders with threads idle.
            .with_max_len(1)
            .map(|tile| {
                let mut c = Counters::default();
                if self.progress.cancelled() {
                    return (c, 0);
                }
                let mut taken = 0u64;
                for ty in 0..tile.h {
                    for tx in 0..tile.w {
                        taken += self.pixel(tile, tx, ty, plan, &mut c);
                    }
                }
                let per_pixel = match plan {
                    Plan::Uniform { s0, s1 } => s1 - s0,
                    Plan::Adaptive { count, .. } => count,
                };
                self.progress
                    .tile_done(u64::from(tile.w * tile.h) * u64::from(per_pixel));
                (c, taken)
            })
            .reduce(|| (Counters::default(), 0), |a, b| (a.0 + b.0, a.1 + b.1))
    }

    /// The plan's samples of the tile's pixel `(tx, ty)`; returns how many.
    fn pixel(&self, tile: &mut Tile, tx: u32, ty: u32, plan: Plan, c: &mut Counters) -> u64 {
        let i = (ty * tile.w + tx) as usize;
        let (s0, s1, rule) = match plan {
            Plan::Uniform { s0, s1 } => (s0, s1, None),
            Plan::Adaptive {
                rule,
                selection,
                count,
                max,
            } => {
                let (pixel, stopped) = (&tile.pixels[i], tile.stopped[i]);
                if stopped || selection.is_some_and(|s| !s.takes(pixel, stopped)) {
                    return 0;
                }
                // Samples are added in order, so the count is the next index.
                let n = pixel.count();
                (n, n.saturating_add(count).min(max), Some(rule))
            }
        };
        // Numbers are keyed by the pixel's index in the full image, so a
        // crop renders exactly the full render's values for its pixels.
        let (x, y) = (tile.x0 + tx, tile.y0 + ty);
        let camera = self.pixels.camera();
        let index = u64::from(y) * u64::from(camera.width()) + u64::from(x);
        for s in s0..s1 {
            let mut draws = SampleStream::new(self.kind, self.seed, index, s);
            let ray = self.pixels.ray(x, y, &mut draws);
            let sample = self.sampler.sample_stream(ray, &mut draws, c);
            tile.add(tx, ty, sample, ray.dir.dot(camera.forward()), c);
            if rule.is_some_and(|r| r.is_checkpoint(s + 1) && r.converged(&tile.pixels[i])) {
                tile.stopped[i] = true;
                return u64::from(s + 1 - s0);
            }
            // A pixel may take many samples in one pass (a sample budget
            // is one pass): look at the flag every CANCEL_CHECK samples too,
            // so a stop never waits for a whole tile at high spp. A
            // cancelled image is discarded, so its partial pixels are fine.
            if (s - s0) % CANCEL_CHECK == CANCEL_CHECK - 1 && self.progress.cancelled() {
                return u64::from(s + 1 - s0);
            }
        }
        u64::from(s1 - s0)
    }
}
