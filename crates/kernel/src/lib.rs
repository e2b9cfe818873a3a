//! What a light path through a sparse volume is made of: media, trackers,
//! phase functions, lights, the camera and the integrators over them, as
//! plain data and functions. No files, images, progress or settings live
//! here: `cirrus-render` runs these over tiles into a film and writes it.
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
//! - [`Media`] is what trackers and integrators walk: [`Volumes`], one
//!   medium or several under a top-level BVH whose extinction and majorant
//!   segments add where they overlap, each with its own albedo, phase and
//!   emission ([`blackbody`] for temperature grids).
//! - [`tracking`] turns segments into events: delta-tracked free flights and
//!   ratio, residual-ratio and track-length transmittance, each with a
//!   collision cap and Russian roulette, written once over a [`Spectrum`]
//!   (`f32` for grey media, `Vec3` for chromatic ones).
//! - [`light`]: the scene's [`Lights`] as a list (distant, dome, sphere and
//!   area lights), each tagged with its light group.
//! - [`integrator`] turns a camera ray into a [`Sample`]: the unbiased
//!   [`PathTracer`], the single-scattering [`RayMarcher`], and the two-pass
//!   [`TwoPassMarcher`] over a cached [`LightGrid`].
//! - [`Camera`] (with its motion over a [`Shutter`]) makes the rays; the
//!   counter-based [`Rng`] in [`sampling`] is keyed by (seed, pixel,
//!   sample), which makes images independent of thread count; so are the
//!   Owen-scrambled Sobol points ([`sobol`]) a [`SampleStream`] takes its
//!   first path vertices' draws from. [`Counters`] count what was done.
//!
//! Coordinates are render space: world space minus an offset the caller
//! picks so that f32 stays precise; lengths keep world units.

#[macro_use]
mod settings_enum;

pub mod blackbody;
mod camera;
pub mod camera_motion;
mod counters;
mod distribution;
mod env_map;
mod error;
pub mod integrator;
pub mod light;
pub mod medium;
pub mod phase;
mod ray;
pub mod sampling;
mod shutter;
pub mod sobol;
pub mod spectrum;
pub mod tracking;
pub mod transform_motion;
pub mod volumes;

pub use blackbody::Blackbody;
pub use camera::Camera;
pub use camera_motion::{CameraMotion, CameraPose};
pub use counters::Counters;
pub use env_map::EnvMap;
pub use error::{Error, Result};
pub use integrator::{
    AovSample, CameraSampler, DistanceSampling, IntegratorKind, LightGrid, LightGridSettings,
    LightSampling, PathTracer, RayMarcher, Sample, Sunward, TwoPassMarcher,
};
pub use light::{
    AreaLight, AreaShape, Environment, Light, LightKind, Lights, SphereLight, Spot, Sun,
    MAX_LIGHT_EXTENT, MAX_LIGHT_VALUE,
};
pub use medium::{
    Bounds3, BrickField, DensityField, Emission, Extinction, GlobalMedia, Interaction,
    MajorantSegment, Media, Medium, MediumError, Velocity, VelocityUnit,
};
#[cfg(feature = "testing")]
pub use medium::{ConstantBox, GridField, MajorantGrid};
pub use phase::{HenyeyGreenstein, Phase};
pub use ray::Ray;
pub use sampling::{Rng, SampleStream, SamplerKind};
pub use shutter::Shutter;
pub use spectrum::Spectrum;
pub use tracking::{MajorantMode, TransmittanceEstimator};
pub use volumes::Volumes;
