//! The path tracer on a GPU: `cirrus-kernel`'s unbiased volume path
//! tracing (delta tracking over the majorant hierarchy, shadow rays by
//! residual ratio, ratio or track-length estimation, next-event
//! estimation with MIS, every phase function, chromatic media by spectral
//! tracking, Russian roulette)
//! as one WGSL compute kernel run through `wgpu` on Vulkan, for the scenes
//! it can render exactly, and a refusal naming everything else.
//!
//! How the parts fit:
//!
//! - `support.rs`: what the kernel renders ([`unsupported`] names the
//!   rest: other integrators and lights, emitting media, u8 bricks,
//!   motion, several volumes, AOVs and compositing
//!   layers, adaptive sampling, denoising), and where it reaches the same
//!   expectation by other estimators than the settings name
//!   ([`substitutions`]: random numbers, every light at each vertex, no
//!   equi-angular sampling toward sphere lights, no sunward
//!   scattering).
//! - `flat.rs`: the prepared scene `cirrus-scene` makes for every render
//!   (the [`PreparedScene`]) as flat arrays ([`FlatScene`]): the brick
//!   map, the atlas as u32 words, the constant bricks, the bounds pyramid
//!   and the field's cell partition (the CPU's hierarchy walk), lights as
//!   tagged records and one block of parameters (transform, camera,
//!   medium, window, seed, majorants and shadow rays' estimator).
//! - `device.rs`: the adapter ([`open`]; the `device` setting that
//!   chooses it is `cirrus_scene::Device`) and [`GpuError`].
//! - `kernel.rs` and `shaders/`: the megakernel, one WGSL file a stage
//!   (`lookup`, `walk`, `spectral`, `delta`, `ratio`, `phase`,
//!   `table_phase`, `lights`, `sphere_light`, `area_light`, `path`), each
//!   citing the CPU code it mirrors; the scene uploaded once, each pixel's
//!   path and running moments kept on the device by the one invocation that
//!   owns it, a window whose paths exceed a binding rendered band by band.
//! - [`render`] reads the moments back into the host's film
//!   ([`cirrus_render::PassFilm`]), so the image resolves and writes
//!   (EXR, PNG) exactly as a CPU render's does.
//!
//! Same seed and settings give the same image on the same device: each
//! sample's numbers are keyed by (seed, pixel, sample), and no sum depends
//! on the order invocations run in.

mod device;
mod flat;
mod kernel;
mod support;

use std::time::Instant;

use cirrus_render::{
    Budget, MajorantMode, PassFilm, PixelMoments, RenderSettings, RenderStats, Rendered,
};

pub use device::{open, Gpu, GpuError, INSTALL_HINT};
pub use flat::{FlatScene, LightRecord, Params, WalkChoice};
pub use kernel::{source, window_bands, PixelSlot, STAGES};
pub use support::{substitutions, unsupported, PreparedScene};

/// Renders `scene` with `settings` on `gpu`, or says why not: what the
/// kernel does not render is refused by name before anything is uploaded.
pub fn render(
    gpu: &Gpu,
    scene: &PreparedScene,
    settings: &RenderSettings,
) -> Result<Rendered, GpuError> {
    settings
        .validate()
        .map_err(|e| GpuError::Device(e.to_string()))?;
    let refused = unsupported(scene, settings);
    if !refused.is_empty() {
        return Err(GpuError::Unsupported(refused));
    }
    let mut film = PassFilm::new(&scene.camera, settings);
    let start = Instant::now();
    let walk = walk_choice(scene, settings);
    let flat = flatten(scene, settings, &film, walk);
    let mut kernel = kernel::Kernel::new(gpu, &flat)?;
    let setup_seconds = start.elapsed().as_secs_f64();
    let spp = match settings.budget {
        Budget::Spp(n) => {
            run_to(&mut kernel, n.max(1))?;
            n.max(1)
        }
        Budget::Time(seconds) => {
            // One more sample of every pixel at a time, until the time is
            // spent (at least one).
            let mut n = 0;
            while n == 0 || start.elapsed().as_secs_f64() < seconds {
                n += 1;
                run_to(&mut kernel, n)?;
            }
            n
        }
    };
    let slots = kernel.read_film()?;
    let moments: Vec<PixelMoments> = slots
        .iter()
        .map(|p| PixelMoments {
            n: p.n,
            mean: p.mean,
            m2: p.m2,
        })
        .collect();
    film.add(&moments, spp);
    let mut stats = RenderStats {
        integrator: settings.integrator.name().into(),
        transmittance: walk.transmittance.name().into(),
        majorant: match settings.majorant {
            MajorantMode::Auto => format!("auto: {}", walk.majorant.name()),
            _ => walk.majorant.name().into(),
        },
        light_sampling: "all".into(),
        sunward: "off".into(),
        setup_seconds,
        ..Default::default()
    };
    stats.counters.paths = slots.iter().map(|p| u64::from(p.n)).sum();
    stats.counters.nonfinite_samples = slots.iter().map(|p| u64::from(p.nonfinite)).sum();
    // Paths the device cut short end where they were, as capped ones do.
    stats.counters.collision_cap_hits = slots.iter().map(|p| u64::from(p.cut)).sum();
    stats.counters.real_collisions = slots.iter().map(|p| u64::from(p.reals)).sum();
    stats.counters.null_collisions = slots.iter().map(|p| u64::from(p.nulls)).sum();
    stats.counters.shadow_collisions = slots.iter().map(|p| u64::from(p.shadows)).sum();
    Ok(film.finish(stats))
}

/// The majorants and shadow rays' estimator of `settings`, as a CPU
/// render takes them: `auto` majorants resolved by the CPU's own probe.
fn walk_choice(scene: &PreparedScene, settings: &RenderSettings) -> WalkChoice {
    WalkChoice {
        majorant: cirrus_render::majorant_mode(scene, settings),
        transmittance: settings.transmittance,
    }
}

/// Most scattering events a dispatch advances a pixel's paths by; the
/// kernel stops earlier once it has run `ITERATION_BUDGET` loop
/// iterations (`common.wgsl`), which keeps a dispatch short on a GPU and within
/// lavapipe's 65535 loop iterations an invocation (a path cut there is
/// detected and counted).
const EVENTS_PER_DISPATCH: u32 = 4096;

/// Dispatches queued between checks of whether every pixel is done.
const DISPATCHES_PER_CHECK: u32 = 8;

/// Dispatches until every pixel has `target` samples, band after band
/// of the window where its paths exceed a binding.
fn run_to(kernel: &mut kernel::Kernel, target: u32) -> Result<(), GpuError> {
    for band in 0..kernel.bands() {
        kernel.enter_band(band)?;
        loop {
            for _ in 0..DISPATCHES_PER_CHECK {
                kernel.dispatch(target, EVENTS_PER_DISPATCH);
            }
            if kernel.pending()? == 0 {
                break;
            }
        }
        kernel.leave_band()?;
    }
    Ok(())
}

/// The flat form of `scene` for `film`'s window and `settings`' seed and
/// depth (the caller has checked it is supported).
fn flatten(
    scene: &PreparedScene,
    settings: &RenderSettings,
    film: &PassFilm,
    walk: WalkChoice,
) -> FlatScene {
    let medium = &scene.media.instances()[0];
    let field = medium.field.still_field();
    // The field's own cells, as the CPU walks them; the finest where the
    // field was made without a refinement rule (`BrickVolume::segments`).
    let finest;
    let partition = match field.partition() {
        Some(p) => p,
        None => {
            finest = field.volume().partition(0.0, f32::INFINITY);
            &finest
        }
    };
    let lights = scene.lights.clone().pruned();
    let lights: Vec<_> = lights.iter().cloned().collect();
    let mut flat = FlatScene::new(
        medium,
        field.volume(),
        partition,
        |o, d| field.local_ray(o, d),
        &scene.camera,
        &lights,
        walk,
    );
    let w = film.window();
    let camera = &scene.camera;
    flat.params.image = [camera.width(), camera.height(), w.x0, w.y0];
    flat.params.window = [w.x1 - w.x0, w.y1 - w.y0, 0, 0];
    let depth = settings.max_depth.unwrap_or(flat::UNLIMITED_DEPTH);
    flat.params.seed = [settings.seed as u32, (settings.seed >> 32) as u32, depth, 0];
    flat
}
