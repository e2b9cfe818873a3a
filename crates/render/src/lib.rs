//! The cirrus renderer's host: it runs the kernel's integrators
//! (`cirrus-kernel`: media, trackers, lights, integrators) over a
//! [`Scene`] on tiles on rayon into a film, and writes what it made.
//!
//! How the parts fit:
//!
//! - [`render()`] runs an integrator over a [`Scene`] (media, camera,
//!   lights) for a sample count or a time budget ([`RenderSettings`]), into
//!   a film of per-pixel means and variances, and returns the [`Image`]
//!   with [`RenderStats`] (and AOVs, halves for a denoiser, and where a
//!   crop window sits). [`adaptive`] sampling stops each pixel on its own
//!   samples; [`RenderControl`] reports progress and cancels from another
//!   thread.
//! - [`image_io`] writes EXR and PNG files atomically; [`exr_layers`]
//!   writes AOV layers and crop data windows and merges tiles;
//!   [`read_env_map`] reads an HDR sky.
//! - [`compositing`]: light groups, holdouts, deep samples and Cryptomatte,
//!   as compositors read them.
//! - [`majorant_choice`] probes a scene to choose its majorants.
//! - [`PassFilm`] takes whole passes rendered elsewhere (the GPU backend)
//!   as per-pixel moments into the same film.
//!
//! The kernel is [`kernel`]; the types a render's caller builds a scene
//! from are re-exported here.

pub mod adaptive;
pub mod compositing;
mod control;
pub mod exr_layers;
mod exr_read;
mod film;
pub mod image_io;
pub mod majorant_choice;
mod pass_film;
mod path_setup;
mod pixel_sampler;
mod progress;
mod render;
mod scene;
mod shutter_lights;
mod stats;

pub use cirrus_kernel as kernel;

pub use adaptive::Adaptive;
pub use compositing::{Compositing, DepthHoldout, Layers};
pub use control::RenderControl;
pub use exr_read::read_env_map;
pub use film::{AovImage, Halves, Image};
pub use pass_film::{PassFilm, PixelMoments};
pub use render::{majorant_mode, render, Denoised, Rendered, Window};
pub use scene::{
    fitted_tile_size, Budget, Crop, RenderSettings, Scene, DEFAULT_SEED, DEFAULT_SPP,
    DEFAULT_STEP_VOXELS, DEFAULT_TILE_SIZE, MIN_TILE_SIZE, TILES_PER_THREAD,
};
pub use stats::{CameraReport, RenderStats};

pub use cirrus_kernel::{
    AreaLight, AreaShape, Blackbody, Bounds3, BrickField, Camera, CameraMotion, CameraPose,
    Counters, DensityField, DistanceSampling, Emission, EnvMap, Environment, Error, Extinction,
    GlobalMedia, HenyeyGreenstein, IntegratorKind, Interaction, Light, LightGridSettings,
    LightKind, LightSampling, Lights, MajorantMode, MajorantSegment, Media, Medium, MediumError,
    Phase, Result, SamplerKind, Shutter, SphereLight, Spot, Sun, Sunward, TransmittanceEstimator,
    Velocity, VelocityUnit, Volumes, MAX_LIGHT_EXTENT, MAX_LIGHT_VALUE,
};
#[cfg(feature = "testing")]
pub use cirrus_kernel::{ConstantBox, GridField, MajorantGrid};
