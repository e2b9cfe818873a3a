//! The cirrus renderer: physically based images of sparse density fields
//! (OpenVDB clouds), plus the biased baselines they are measured against.
//!
//! How the parts fit:
//!
//! - [`medium`] defines [`DensityField`], the one interface to a volume: point
//!   lookups and, along a ray, front-to-back [`MajorantSegment`]s bounding
//!   the density ([`MajorantSegment`] and the box type [`Bounds3`] are
//!   `cirrus-bricks`' own). [`BrickField`] places a brick volume in render
//!   space; with the `testing` feature the test fields live here too
//!   (`ConstantBox`, `GridField` with its DDA-walked `MajorantGrid`). A
//!   [`Medium`] adds density scale, albedo, a [`Phase`] function and
//!   [`Emission`]; [`GlobalMedia`] puts one global majorant over any media
//!   (Mitsuba's way).
//! - [`tracking`] turns segments into events: delta-tracked free flights and
//!   ratio, residual-ratio and track-length transmittance, each with a
//!   collision cap and Russian roulette, written once over a [`Spectrum`]
//!   (`f32` for grey media, `Vec3` for chromatic ones).
//! - [`integrator`] turns a camera ray into a [`Sample`]: the unbiased
//!   [`PathTracer`], the single-scattering [`RayMarcher`], and the two-pass
//!   [`TwoPassMarcher`] over a cached [`LightGrid`].
//! - [`render()`] runs an integrator over a [`Scene`] (media, camera,
//!   lights) on tiles on rayon into a film of
//!   per-pixel means and variances, for a sample count or a time budget,
//!   and returns the [`Image`] with [`RenderStats`] (and AOVs, and where a
//!   crop window sits). [`image_io`] writes EXR and PNG files atomically;
//!   [`exr_layers`] writes AOV layers and crop data windows and merges tiles.
//! - [`Media`] is what trackers and integrators walk: [`Volumes`], one
//!   medium or several under a top-level BVH whose extinction and majorant
//!   segments add where they overlap, each with its own albedo, phase and
//!   emission ([`blackbody`] for temperature grids).
//! - [`Camera`], [`light`] (sun and environment, constant or an
//!   importance-sampled [`EnvMap`] over a [`distribution`]) and the counter-based
//!   [`Rng`] in [`sampling`] are the supporting pieces. The RNG is keyed by
//!   (seed, pixel, sample), which makes images independent of thread count;
//!   so are the Owen-scrambled Sobol points ([`sobol`]) a [`SampleStream`]
//!   takes its first path vertices' draws from, and [`adaptive`] sampling
//!   stops each pixel on its own samples.
//!
//! Coordinates are render space: world space minus an offset the caller
//! picks so that f32 stays precise; lengths keep world units.

#[macro_use]
mod settings_enum;

pub mod adaptive;
pub mod blackbody;
pub mod camera;
pub mod camera_motion;
pub mod compositing;
pub mod control;
pub mod distribution;
pub mod env_map;
pub mod error;
pub mod exr_layers;
mod exr_read;
pub mod film;
pub mod image_io;
pub mod integrator;
pub mod light;
pub mod majorant_choice;
pub mod medium;
mod path_setup;
pub mod phase;
mod pixel_sampler;
pub mod ray;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod shutter;
pub mod sobol;
pub mod spectrum;
pub mod stats;
pub mod tracking;
pub mod transform_motion;
pub mod volumes;

pub use adaptive::Adaptive;
pub use blackbody::Blackbody;
pub use camera::Camera;
pub use camera_motion::{CameraMotion, CameraPose};
pub use compositing::{Compositing, DepthHoldout, Layers};
pub use control::RenderControl;
pub use env_map::EnvMap;
pub use error::{Error, Result};
pub use film::{AovImage, Halves, Image};
pub use integrator::{
    AovSample, CameraSampler, DistanceSampling, IntegratorKind, LightGrid, LightGridSettings,
    LightSampling, PathTracer, RayMarcher, Sample, Sunward, TwoPassMarcher,
};
pub use light::{
    AreaLight, AreaShape, Environment, Light, LightKind, Lights, SphereLight, Spot, Sun,
};
pub use medium::{
    Bounds3, BrickField, DensityField, Emission, Extinction, GlobalMedia, Interaction,
    MajorantSegment, Media, Medium, MediumError, Velocity, VelocityUnit,
};
#[cfg(feature = "testing")]
pub use medium::{ConstantBox, GridField, MajorantGrid};
pub use phase::{HenyeyGreenstein, Phase};
pub use ray::Ray;
pub use render::{render, Denoised, Rendered, Window};
pub use sampling::{Rng, SampleStream, SamplerKind};
pub use scene::{
    Budget, Crop, MajorantMode, RenderSettings, Scene, DEFAULT_SPP, DEFAULT_STEP_VOXELS,
};
pub use shutter::Shutter;
pub use spectrum::Spectrum;
pub use stats::{Counters, RenderStats};
pub use tracking::TransmittanceEstimator;
pub use volumes::Volumes;
