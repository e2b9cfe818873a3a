//! What the caller fills in: the scene (medium, camera, lights) and the
//! render settings.

use std::sync::Arc;

use cirrus_kernel::{
    Camera, DistanceSampling, Error, IntegratorKind, LightGridSettings, LightSampling, Lights,
    MajorantMode, Result, SamplerKind, Shutter, Sunward, TransmittanceEstimator,
};

use crate::adaptive::Adaptive;
use crate::compositing::Compositing;
use crate::control::RenderControl;

/// What is rendered, all in render space: the media (a lone medium or
/// several, as [`Volumes`](crate::Volumes)), a camera and lights at
/// infinity.
pub struct Scene<M> {
    pub media: M,
    pub camera: Camera,
    pub lights: Lights,
}

/// How long to render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Budget {
    /// Exactly this many samples per pixel (at most, with adaptive
    /// sampling).
    Spp(u32),
    /// Progressive passes until this many seconds of wall time (setup
    /// included) are spent; at least one sample per pixel is always taken
    /// and every pixel has the same count. The count reached is reported.
    /// With adaptive sampling, each pass goes to the pixels of highest
    /// error instead, and the render ends early once all are below the
    /// threshold.
    Time(f64),
}

/// Samples per pixel when no budget is given.
pub const DEFAULT_SPP: u32 = 64;

/// The seed when none is given.
pub const DEFAULT_SEED: u64 = 0;

/// The ray marchers' step in voxels when none is given.
pub const DEFAULT_STEP_VOXELS: f32 = 0.5;

/// Tile edge in pixels by default: small enough that the last tiles of a
/// render (sky tiles are cheap, cloud tiles costly) finish together. On
/// two threads 8-pixel tiles rendered the default cloud 9% faster than
/// 16-pixel ones and the sky-lit cloud 4% (BENCHMARKS.md), at the same
/// speed on one thread; 4-pixel tiles cost 1-3% in overhead.
pub const DEFAULT_TILE_SIZE: u32 = 8;

/// Tiles a render wants per thread: with 16, a list schedule of the thick
/// cloud's measured tile times on 16 threads comes within 3% of perfect,
/// against 15% lost with 4 (128x128 in 16-pixel tiles).
pub const TILES_PER_THREAD: u32 = 16;

/// The smallest edge [`RenderSettings::tile_size`] is halved to.
pub const MIN_TILE_SIZE: u32 = 4;

/// The tile edge for a `width` x `height` window on `threads` threads:
/// `largest`, halved while the window has fewer than [`TILES_PER_THREAD`]
/// tiles a thread and the edge stays at least [`MIN_TILE_SIZE`].
pub fn fitted_tile_size(largest: u32, width: u32, height: u32, threads: usize) -> u32 {
    let tiles = |edge: u32| u64::from(width.div_ceil(edge)) * u64::from(height.div_ceil(edge));
    let wanted = u64::from(TILES_PER_THREAD) * threads.max(1) as u64;
    let mut edge = largest.max(1);
    while tiles(edge) < wanted && edge / 2 >= MIN_TILE_SIZE {
        edge /= 2;
    }
    edge
}

/// Everything about how to render, independent of the scene.
///
/// Its [`Default`] is the renderer's one set of defaults: each settings
/// enum's own `Default`, [`DEFAULT_SPP`], [`DEFAULT_SEED`],
/// [`DEFAULT_STEP_VOXELS`] and [`Shutter::INSTANT`]; the
/// scene files and the command line declare theirs from these.
#[derive(Clone, Debug)]
pub struct RenderSettings {
    pub integrator: IntegratorKind,
    pub transmittance: TransmittanceEstimator,
    pub majorant: MajorantMode,
    pub budget: Budget,
    /// Same seed, same image, whatever the thread count.
    pub seed: u64,
    /// Where the path tracer's numbers come from (Sobol by default).
    pub sampler: SamplerKind,
    /// Per-pixel stopping on the pixel's own error; `None` gives every
    /// pixel the whole budget.
    pub adaptive: Option<Adaptive>,
    /// Scattering events per path (path tracer): 0 = environment through
    /// the volume only, 1 = single scattering, `None` = unlimited.
    pub max_depth: Option<u32>,
    /// Ray-march step in voxels (ray marchers and the light grid).
    pub step_voxels: f32,
    /// The ray marchers' shadow-ray step in voxels (OpenVDB `vdb_render`'s
    /// `-shadowstep`; the light grid's marches are shadow rays too);
    /// `None`: the step.
    pub shadow_step_voxels: Option<f32>,
    pub light_grid: LightGridSettings,
    /// Largest tile edge in pixels: tiles are the threads' units of work,
    /// and a render with fewer than [`TILES_PER_THREAD`] of them a thread
    /// halves the edge (down to [`MIN_TILE_SIZE`], or this size where
    /// smaller) so its last tiles do not leave threads idle. Images do not
    /// depend on it.
    pub tile_size: u32,
    /// Show progress on stderr: a bar on a terminal, else a plain line
    /// every few seconds (`progress.rs`).
    pub progress: bool,
    /// Render only this window of the camera's image (render farms); its
    /// pixels are bit-identical to the same pixels of a full render.
    pub crop: Option<Crop>,
    /// Keep the AOV passes (albedo, depth, emission, direct, samples).
    pub aovs: bool,
    /// Keep the two halves of each pixel's samples beside the image
    /// ([`Halves`](crate::film::Halves)), for a denoiser's error estimate.
    pub halves: bool,
    /// Progress and cancellation from another thread (bindings, servers).
    pub control: Option<Arc<RenderControl>>,
    /// Each camera sample's time is drawn over this interval (frames);
    /// moving media must have been built for the same shutter, so their
    /// majorants bound every time drawn.
    pub shutter: Shutter,
    /// Light groups, holdout depth, Cryptomatte and deep samples
    /// ([`crate::compositing`]); the default keeps none.
    pub compositing: Compositing,
    /// Whether next-event estimation samples every light at each vertex,
    /// or one ([`LightSampling`]).
    pub light_sampling: LightSampling,
    /// Where the path tracer also scatters toward the sun ([`Sunward`]).
    pub sunward: Sunward,
    /// How the path tracer samples where light scatters along a ray
    /// ([`DistanceSampling`]).
    pub distance_sampling: DistanceSampling,
}

/// A pixel window `[x0, x1) x [y0, y1)` of the camera's image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crop {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl Crop {
    /// Checks the window is non-empty and inside a `width x height` image.
    pub fn validate(&self, width: u32, height: u32) -> Result<()> {
        if self.x0 >= self.x1 || self.y0 >= self.y1 || self.x1 > width || self.y1 > height {
            return Err(Error::invalid(format!(
                "crop {},{},{},{} must be a non-empty window x0 < x1 <= {width}, y0 < y1 <= {height}",
                self.x0, self.y0, self.x1, self.y1
            )));
        }
        Ok(())
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            integrator: IntegratorKind::default(),
            transmittance: TransmittanceEstimator::default(),
            majorant: MajorantMode::default(),
            budget: Budget::Spp(DEFAULT_SPP),
            seed: DEFAULT_SEED,
            sampler: SamplerKind::default(),
            adaptive: None,
            max_depth: None,
            step_voxels: DEFAULT_STEP_VOXELS,
            shadow_step_voxels: None,
            light_grid: LightGridSettings::default(),
            tile_size: DEFAULT_TILE_SIZE,
            progress: true,
            crop: None,
            aovs: false,
            halves: false,
            control: None,
            shutter: Shutter::INSTANT,
            compositing: Compositing::default(),
            light_sampling: LightSampling::default(),
            sunward: Sunward::default(),
            distance_sampling: DistanceSampling::default(),
        }
    }
}

impl RenderSettings {
    /// Checks values the renderer would otherwise have to clamp silently.
    /// The shadow-ray march step in voxels.
    pub fn shadow_step(&self) -> f32 {
        self.shadow_step_voxels.unwrap_or(self.step_voxels)
    }

    pub fn validate(&self) -> Result<()> {
        match self.budget {
            Budget::Spp(0) => return Err(Error::invalid("spp must be at least 1")),
            Budget::Time(s) if !(s.is_finite() && s > 0.0) => {
                return Err(Error::invalid(format!(
                    "time budget must be a positive number of seconds, got {s}"
                )))
            }
            _ => {}
        }
        if let Some(s) = self
            .shadow_step_voxels
            .filter(|s| !(s.is_finite() && *s > 0.0))
        {
            return Err(Error::invalid(format!(
                "shadow step must be a positive number of voxels, got {s}"
            )));
        }
        self.shutter.validate()?;
        if !(self.step_voxels.is_finite() && self.step_voxels > 0.0) {
            return Err(Error::invalid(format!(
                "step must be a positive number of voxels, got {}",
                self.step_voxels
            )));
        }
        let g = &self.light_grid;
        if !(g.cell_voxels.is_finite() && g.cell_voxels > 0.0) || g.env_directions == 0 {
            return Err(Error::invalid(
                "light grid needs a positive cell size and at least one direction",
            ));
        }
        if self.tile_size == 0 {
            return Err(Error::invalid("tile size must be at least 1"));
        }
        if let Some(a) = &self.adaptive {
            a.validate()?;
        }
        self.compositing.validate()?;
        Ok(())
    }
}
