//! The render loop: tiles over rayon, sample passes, time budget, progress.

use std::io::IsTerminal;
use std::sync::Arc;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

use crate::camera::Camera;
use crate::control::RenderControl;
use crate::film::{AovImage, Film, Image};
use crate::integrator::{
    CameraSampler, IntegratorKind, LightGrid, PathTracer, RayMarcher, TwoPassMarcher,
};
use crate::light::Lights;
use crate::medium::{DensityField, GlobalMedia, Media};
use crate::sampling::Rng;
use crate::scene::{Budget, Crop, MajorantMode, RenderSettings, Scene};
use crate::stats::{Counters, RenderStats};

/// A finished render.
pub struct Rendered {
    /// The rendered pixels: the whole image, or the crop window.
    pub image: Image,
    pub stats: RenderStats,
    /// Where `image` sits in the camera's full image.
    pub window: Window,
    /// The AOV passes over the same pixels, if the settings asked for them.
    pub aovs: Option<AovImage>,
    /// The image's RGB before a denoiser replaced it (written as the
    /// `noisy.R/G/B` layer).
    pub noisy: Option<Vec<[f32; 3]>>,
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

/// Renders `scene` with `settings` on the ambient rayon pool (install a
/// `ThreadPool` around the call to choose the thread count).
///
/// Pixel `(x, y)`'s sample `s` draws all its random numbers from
/// `Rng::new(seed, y * width + x, s)`, and each pixel accumulates its
/// samples in order, so the image is bit-identical for any thread count.
pub fn render<F: DensityField>(scene: &Scene<F>, settings: &RenderSettings) -> Rendered {
    render_media(&scene.medium, &scene.camera, &scene.lights, settings)
}

/// [`render`] for any [`Media`]: a lone medium or several volume
/// instances ([`Volumes`](crate::volumes::Volumes)).
pub fn render_media<M: Media>(
    media: &M,
    camera: &Camera,
    lights: &Lights,
    settings: &RenderSettings,
) -> Rendered {
    let start = Instant::now();
    match settings.majorant {
        MajorantMode::Hierarchy => render_with(media, camera, lights, settings, start),
        MajorantMode::Global => {
            render_with(&GlobalMedia::new(media), camera, lights, settings, start)
        }
    }
}

fn render_with<M: Media>(
    medium: &M,
    camera: &Camera,
    lights: &Lights,
    settings: &RenderSettings,
    start: Instant,
) -> Rendered {
    let mut counters = Counters::default();
    let lights = lights.clone();
    let (image, aovs, setup_seconds) = match settings.integrator {
        IntegratorKind::Path => {
            let s = PathTracer::new(medium, lights, settings.transmittance, settings.max_depth);
            let (image, aovs) = run(&s, camera, settings, start, &mut counters);
            (image, aovs, 0.0)
        }
        IntegratorKind::RayMarch => {
            let s = RayMarcher::new(medium, lights, settings.step_voxels);
            let (image, aovs) = run(&s, camera, settings, start, &mut counters);
            (image, aovs, 0.0)
        }
        IntegratorKind::RayMarch2Pass => {
            let grid = LightGrid::build(
                medium,
                &lights,
                settings.step_voxels,
                &settings.light_grid,
                settings.seed,
                &mut counters,
            );
            let setup = start.elapsed().as_secs_f64();
            let s = TwoPassMarcher::new(medium, lights, &grid, settings.step_voxels);
            let (image, aovs) = run(&s, camera, settings, start, &mut counters);
            (image, aovs, setup)
        }
    };
    let wall_seconds = start.elapsed().as_secs_f64();
    let stats = RenderStats {
        integrator: settings.integrator.name().into(),
        transmittance: settings.transmittance.name().into(),
        majorant: settings.majorant.name().into(),
        width: image.width,
        height: image.height,
        spp: image.spp,
        wall_seconds,
        setup_seconds,
        counters,
        rays_per_second: counters.paths as f64 / wall_seconds.max(1e-9),
        ..Default::default()
    };
    let crop = crop_of(settings, camera);
    Rendered {
        image,
        stats,
        window: Window {
            x0: crop.x0,
            y0: crop.y0,
            full_width: camera.width(),
            full_height: camera.height(),
        },
        aovs,
        noisy: None,
    }
}

/// The window to render: the settings' crop clamped to the image, or all.
fn crop_of(settings: &RenderSettings, camera: &Camera) -> Crop {
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
) -> (Image, Option<AovImage>) {
    let crop = crop_of(settings, camera);
    let mut film = Film::new(
        crop.x0,
        crop.y0,
        crop.x1 - crop.x0,
        crop.y1 - crop.y0,
        settings.tile_size,
        settings.aovs,
    );
    let progress = Progress::new(settings, film.width, film.height);
    let mut spp = 0u32;
    match settings.budget {
        Budget::Spp(n) => {
            *counters += pass(
                &mut film,
                sampler,
                camera,
                settings.seed,
                0,
                n.max(1),
                &progress,
            );
            spp = n.max(1);
        }
        Budget::Time(seconds) => {
            let budget = Duration::from_secs_f64(seconds.max(0.0));
            let loop_start = Instant::now();
            let mut size = 1u32;
            while size > 0 && !progress.cancelled() {
                *counters += pass(
                    &mut film,
                    sampler,
                    camera,
                    settings.seed,
                    spp,
                    spp + size,
                    &progress,
                );
                spp += size;
                progress.set_spp(spp);
                // Next pass: as many samples as the measured rate says fit in
                // the remaining time, at most twice the last pass so one
                // noisy estimate cannot overshoot the budget badly.
                let per_spp = loop_start.elapsed().as_secs_f64() / spp as f64;
                let remaining = budget.saturating_sub(start.elapsed()).as_secs_f64();
                let fit = (remaining / per_spp.max(1e-9)).floor().min(u32::MAX as f64) as u32;
                size = fit.min(size.saturating_mul(2));
            }
        }
    }
    progress.finish();
    let image = film.resolve(spp, counters);
    (image, film.resolve_aovs())
}

/// One pass: samples `s0..s1` for every pixel, tiles in parallel.
fn pass<S: CameraSampler>(
    film: &mut Film,
    sampler: &S,
    camera: &Camera,
    seed: u64,
    s0: u32,
    s1: u32,
    progress: &Progress,
) -> Counters {
    // Random streams are keyed by the pixel's index in the full image, so
    // a crop renders exactly the full render's values for its pixels.
    let width = camera.width();
    film.tiles
        .par_iter_mut()
        .map(|tile| {
            let mut c = Counters::default();
            if progress.cancelled() {
                return c;
            }
            for ty in 0..tile.h {
                for tx in 0..tile.w {
                    let (x, y) = (tile.x0 + tx, tile.y0 + ty);
                    let pixel = u64::from(y) * u64::from(width) + u64::from(x);
                    for s in s0..s1 {
                        let mut rng = Rng::new(seed, pixel, u64::from(s));
                        let (u, v) = (rng.uniform(), rng.uniform());
                        let ray = camera.ray(x as f32 + u, y as f32 + v);
                        let sample = sampler.sample(ray, &mut rng, &mut c);
                        tile.add(tx, ty, sample, &mut c);
                    }
                }
            }
            progress.tile_done(u64::from(tile.w * tile.h) * u64::from(s1 - s0));
            c
        })
        .reduce(Counters::default, |a, b| a + b)
}

/// A progress bar with ETA on stderr, or nothing when stderr is not a
/// terminal or progress is off. Updated once per tile, never per sample.
struct Progress {
    bar: Option<ProgressBar>,
    control: Option<Arc<RenderControl>>,
    /// With a time budget the bar measures milliseconds, not samples.
    timed: Option<(Instant, u64)>,
}

impl Progress {
    fn new(settings: &RenderSettings, width: u32, height: u32) -> Self {
        let (len, timed) = match settings.budget {
            Budget::Spp(n) => {
                let samples = u64::from(width) * u64::from(height) * u64::from(n.max(1));
                (samples, None)
            }
            Budget::Time(s) => {
                let ms = (s * 1000.0).max(1.0) as u64;
                (ms, Some((Instant::now(), ms)))
            }
        };
        let control = settings.control.clone();
        if let Some(c) = &control {
            c.start(len);
        }
        if !settings.progress || !std::io::stderr().is_terminal() {
            return Self {
                bar: None,
                control,
                timed,
            };
        }
        let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
        let style = ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] [{wide_bar}] {percent:>3}% ETA {eta} {msg}",
        )
        .expect("valid template");
        bar.set_style(style);
        Self {
            bar: Some(bar),
            control,
            timed,
        }
    }

    fn cancelled(&self) -> bool {
        self.control.as_ref().is_some_and(|c| c.is_cancelled())
    }

    fn tile_done(&self, samples: u64) {
        let elapsed_ms = |(t0, ms): (Instant, u64)| (t0.elapsed().as_millis() as u64).min(ms);
        if let Some(c) = &self.control {
            match self.timed {
                None => c.add(samples),
                Some(t) => c.set(elapsed_ms(t)),
            }
        }
        let Some(bar) = &self.bar else { return };
        match self.timed {
            None => bar.inc(samples),
            Some(t) => bar.set_position(elapsed_ms(t)),
        }
    }

    fn set_spp(&self, spp: u32) {
        if let Some(bar) = &self.bar {
            bar.set_message(format!("{spp} spp"));
        }
    }

    fn finish(&self) {
        if let (Some(c), Some((_, ms))) = (&self.control, self.timed) {
            c.set(ms);
        }
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}
