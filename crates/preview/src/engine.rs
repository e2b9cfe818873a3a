//! The render thread: decides the next pass from the shared view, renders
//! it, folds it into the accumulation and publishes the frame.
//!
//! After a change the first pass is a quick low-resolution one (sized
//! from the measured paths per second to take about 40 ms), so the page
//! answers at once; then full-resolution passes accumulate, each about a
//! quarter of a second, until `max_spp`. A change cancels a running
//! full-resolution pass; a preview pass finishes (it is short), so while
//! the user drags frames keep arriving at the pace previews complete, and
//! at most the latest view waits behind the running pass. Without a page
//! connected, rendering stops once the last request is `idle` old.

use std::collections::HashMap;
use std::sync::Arc;
use std::time::Instant;

use cirrus_render::RenderControl;
use cirrus_scene::{ErrorKind, Overrides};
use serde_json::json;

use crate::accumulate::Accumulation;
use crate::frame::{display_rgb, encode_png};
use crate::shared::{Running, Shared, Snapshot, State};
use crate::source::Renderer;

/// Wall time a preview pass aims for.
const PREVIEW_SECONDS: f64 = 0.04;
/// Wall time a full-resolution pass aims for: frequent frames, little
/// per-pass overhead.
const PASS_SECONDS: f64 = 0.25;
/// Most samples per pixel in one pass.
const MAX_PASS_SPP: u32 = 64;
/// Paths per second assumed before any pass was timed.
const GUESS_RATE: f64 = 250_000.0;

enum Job {
    Quit,
    Redisplay { exposure: f32, denoise: bool },
    Pass(Box<Pass>),
}

struct Pass {
    /// What is rendered, with resolution, spp and seed.
    overrides: Overrides,
    /// The accumulation key (the view's overrides at full resolution).
    key: Overrides,
    preview: bool,
    control: Arc<RenderControl>,
    version: u64,
    exposure: f32,
    denoise: bool,
}

#[derive(Default)]
struct Engine {
    acc: Option<Accumulation>,
    /// The key whose preview pass has been shown.
    preview_key: Option<Overrides>,
    /// A key whose render failed: not retried until the view changes.
    failed: Option<Overrides>,
    /// Measured paths per second, per integrator and device.
    rates: HashMap<(&'static str, &'static str), f64>,
}

/// Runs until [`Shared::quit`].
pub fn run(renderer: &mut dyn Renderer, shared: &Shared) {
    let mut engine = Engine::default();
    loop {
        let job = {
            let mut st = shared.lock();
            loop {
                match engine.decide(&mut st, shared) {
                    Some(job) => break job,
                    None => st = shared.wait_work(st),
                }
            }
        };
        match job {
            Job::Quit => return,
            Job::Redisplay { exposure, denoise } => engine.display(shared, None, exposure, denoise),
            Job::Pass(p) => engine.pass(renderer, shared, *p),
        }
    }
}

impl Engine {
    /// The next job, or `None` to wait. Registers a pass as running.
    fn decide(&mut self, st: &mut State, shared: &Shared) -> Option<Job> {
        let info = &shared.info;
        if st.quit {
            return Some(Job::Quit);
        }
        let res = st.view.resolution(info.base_res);
        let key = st.view.render_overrides(&info.lighting, res);
        let same = self.acc.as_ref().is_some_and(|a| a.key == key);
        if st.redisplay {
            st.redisplay = false;
            if same {
                return Some(Job::Redisplay {
                    exposure: st.view.exposure,
                    denoise: st.view.denoise,
                });
            }
        }
        let active = st.clients > 0 || st.last_activity.elapsed() < info.idle;
        if !active || self.failed.as_ref() == Some(&key) {
            return None;
        }
        let (overrides, preview) = match &self.acc {
            Some(a) if same => {
                if a.spp >= info.max_spp {
                    return None;
                }
                let per_spp = a.seconds / f64::from(a.spp.max(1));
                let fit = (PASS_SECONDS / per_spp.max(1e-9)).floor().min(1e6) as u32;
                let n = fit
                    .clamp(1, a.spp.clamp(1, MAX_PASS_SPP))
                    .min(info.max_spp - a.spp);
                (with_samples(&key, res, n, u64::from(a.passes)), false)
            }
            _ => match self.preview_res(&key, res) {
                Some(small) if self.preview_key.as_ref() != Some(&key) => {
                    (with_samples(&key, small, 1, 0), true)
                }
                _ => (with_samples(&key, res, 1, 0), false),
            },
        };
        let control = Arc::new(RenderControl::new());
        st.running = Some(Running {
            control: control.clone(),
            key: key.clone(),
            preview,
        });
        Some(Job::Pass(Box::new(Pass {
            overrides,
            key,
            preview,
            control,
            version: st.version,
            exposure: st.view.exposure,
            denoise: st.view.denoise,
        })))
    }

    /// A resolution whose 1-spp pass takes about [`PREVIEW_SECONDS`], or
    /// `None` when the full resolution is about as quick.
    fn preview_res(&self, key: &Overrides, (w, h): (u32, u32)) -> Option<(u32, u32)> {
        let rate = self
            .rates
            .get(&rate_key(key))
            .copied()
            .unwrap_or(GUESS_RATE);
        let target = rate * PREVIEW_SECONDS;
        let full = f64::from(w) * f64::from(h);
        if full <= 1.5 * target {
            return None;
        }
        let s = (target / full).sqrt().clamp(0.125, 1.0);
        let side = |x: u32| ((f64::from(x) * s).round() as u32).max(1);
        Some((side(w), side(h)))
    }

    fn pass(&mut self, renderer: &mut dyn Renderer, shared: &Shared, p: Pass) {
        let start = Instant::now();
        let result = renderer.render(&p.overrides, p.control.clone());
        let seconds = start.elapsed().as_secs_f64();
        shared.lock().running = None;
        let r = match result {
            Ok(_) | Err(_) if p.control.is_cancelled() => return,
            Ok(r) => r,
            Err(e) if e.kind() == ErrorKind::Cancelled => return,
            Err(e) => return self.fail(shared, p.key, e.to_string()),
        };
        let rate = r.stats.counters.paths as f64 / seconds.max(1e-9);
        let old = self.rates.entry(rate_key(&p.key)).or_insert(rate);
        *old = 0.5 * (*old + rate);
        let (w, h) = p.overrides.res.unwrap_or((r.image.width, r.image.height));
        if (r.image.width, r.image.height) != (w, h) {
            let msg = format!(
                "the scene rendered {}x{} pixels, not {w}x{h} (an [output] crop?)",
                r.image.width, r.image.height
            );
            return self.fail(shared, p.key, msg);
        }
        if p.preview {
            self.preview_key = Some(p.key.clone());
            let mut one = Accumulation::new(p.key.clone(), w, h);
            one.add(&r);
            let meta = meta(
                &one,
                p.version,
                true,
                p.exposure,
                false,
                shared.info.max_spp,
            );
            match encode_png(&display_rgb(&one, false).0, w, h, p.exposure) {
                Ok(png) => shared.publish(meta, Some(Arc::new(png))),
                Err(e) => shared.publish(error(e.to_string()), None),
            }
            return;
        }
        if !self.acc.as_ref().is_some_and(|a| a.key == p.key) {
            self.acc = Some(Accumulation::new(p.key.clone(), w, h));
        }
        if let Some(a) = &mut self.acc {
            a.add(&r);
        }
        self.display(shared, Some(&p), p.exposure, p.denoise);
    }

    /// Publishes the accumulation as a frame and keeps it for Save.
    fn display(&mut self, shared: &Shared, p: Option<&Pass>, exposure: f32, denoise: bool) {
        let Some(a) = &self.acc else { return };
        let (rgb, denoised) = display_rgb(a, denoise);
        let png = match encode_png(&rgb, a.width, a.height, exposure) {
            Ok(png) => Arc::new(png),
            Err(e) => return shared.publish(error(e.to_string()), None),
        };
        let version = p.map_or_else(|| shared.lock().version, |p| p.version);
        let mut m = meta(a, version, false, exposure, denoised, shared.info.max_spp);
        if p.is_none() {
            m["redisplay"] = true.into();
        }
        let mut overrides = a.key.clone();
        overrides.spp = Some(a.spp);
        overrides.seed = Some(0);
        overrides.exposure = Some(exposure);
        overrides.denoise = Some(denoised);
        let snapshot = Snapshot {
            image: a.image(),
            png: png.clone(),
            overrides,
        };
        shared.lock().snapshot = Some(Arc::new(snapshot));
        shared.publish(m, Some(png));
    }

    fn fail(&mut self, shared: &Shared, key: Overrides, message: String) {
        self.failed = Some(key);
        shared.publish(error(message), None);
    }
}

/// `key` rendered at `res` with `spp` samples and `seed`.
fn with_samples(key: &Overrides, res: (u32, u32), spp: u32, seed: u64) -> Overrides {
    Overrides {
        res: Some(res),
        spp: Some(spp),
        seed: Some(seed),
        ..key.clone()
    }
}

/// What a pass's speed depends on most: its integrator and its device.
fn rate_key(key: &Overrides) -> (&'static str, &'static str) {
    (integrator(key), key.device.unwrap_or_default().name())
}

fn integrator(key: &Overrides) -> &'static str {
    key.integrator.map_or("path", |i| i.name())
}

/// A frame's readout. `version`: of the view the pass started from.
fn meta(
    a: &Accumulation,
    version: u64,
    preview: bool,
    exposure: f32,
    denoised: bool,
    max_spp: u32,
) -> serde_json::Value {
    let (tw, th) = a.key.res.unwrap_or((a.width, a.height));
    json!({
        "type": "frame",
        "version": version,
        "preview": preview,
        "width": a.width,
        "height": a.height,
        // A preview is not part of the accumulation: it counts no samples.
        "spp": if preview { 0 } else { a.spp },
        "passes": a.passes,
        // The full resolution (a preview is smaller).
        "target": [tw, th],
        "max_spp": max_spp,
        "paths_per_second": a.paths_per_second(),
        "seconds": a.seconds,
        "integrator": integrator(&a.key),
        // Where the last pass ran ("cpu", or "gpu: " and the adapter).
        "device": a.device,
        "exposure": exposure,
        "denoised": denoised,
    })
}

fn error(message: String) -> serde_json::Value {
    json!({"type": "error", "message": message})
}
