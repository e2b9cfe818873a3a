//! Participating media: a density field and the optical parameters that turn
//! it into extinction, scattering and a phase function.
//!
//! - `field` defines [`DensityField`], the interface the trackers walk.
//! - `constant_box`, `grid_field` (+ `majorant_grid`) are test fields with
//!   known answers (feature `testing`); `brick_field` adapts the brick
//!   volumes of `cirrus-bricks`, placed in render space.
//! - `global` is the one segment of a global majorant (Mitsuba-style),
//!   which [`GlobalMedia`] puts over any media.
//! - `media` defines [`Media`], what the trackers and integrators walk: a
//!   lone [`Medium`] or several volume instances, in extinction units.
//! - `motion` moves a brick field with a velocity grid (motion blur).

mod brick_field;
#[cfg(feature = "testing")]
mod constant_box;
mod field;
mod global;
#[cfg(feature = "testing")]
mod grid_field;
#[cfg(feature = "testing")]
mod majorant_grid;
mod media;
mod motion;

pub use brick_field::BrickField;
#[cfg(feature = "testing")]
pub use constant_box::ConstantBox;
pub use field::{Bounds3, DensityField, MajorantSegment};
#[cfg(feature = "testing")]
pub use grid_field::GridField;
#[cfg(feature = "testing")]
pub use majorant_grid::{DdaSegments, MajorantGrid};
pub use media::{GlobalMedia, Interaction, Media, Scaled};
pub use motion::{Velocity, VelocityUnit};

use glam::Vec3;

use crate::phase::Phase;

/// A grey participating medium: `sigma_t(p) = density_scale * density(p)`,
/// `sigma_s = albedo * sigma_t` per colour channel, and a phase function.
///
/// Extinction is grey, so free-flight sampling and transmittance are scalar;
/// a coloured albedo only tints the path throughput.
#[derive(Clone, Debug)]
pub struct Medium<F> {
    pub field: F,
    /// Converts field density to extinction in 1 / render-space units.
    pub density_scale: f32,
    /// Single-scattering albedo `sigma_s / sigma_t` per RGB channel, in [0, 1].
    pub albedo: Vec3,
    pub phase: Phase,
}

impl<F: DensityField> Medium<F> {
    /// A medium with the Henyey-Greenstein phase function of asymmetry `g`
    /// ([`Phase::hg`]); [`Medium::with_phase`] sets any other.
    pub fn new(field: F, density_scale: f32, albedo: Vec3, g: f32) -> Self {
        Self {
            field,
            density_scale,
            albedo,
            phase: Phase::hg(g),
        }
    }

    pub fn with_phase(self, phase: Phase) -> Self {
        Self { phase, ..self }
    }

    /// Extinction coefficient at `p`.
    #[inline]
    pub fn sigma_t(&self, p: Vec3) -> f32 {
        self.density_scale * self.field.density(p)
    }
}
