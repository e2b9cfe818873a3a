//! Participating media: a density field and the optical parameters that turn
//! it into extinction, scattering and a phase function.
//!
//! - `field` defines [`DensityField`], the interface the trackers walk.
//! - `constant_box`, `grid_field` (+ `majorant_grid`) are the fields this
//!   crate owns (tests and the fixed-grid baseline); `brick_field` adapts
//!   the brick volumes of `cirrus-bricks`, placed in render space.
//! - `global` collapses any field to one global majorant (Mitsuba-style).
//! - `media` defines [`Media`], what the trackers and integrators walk: a
//!   lone [`Medium`] or several volume instances, in extinction units.

mod brick_field;
mod constant_box;
mod field;
mod global;
mod grid_field;
mod majorant_grid;
mod media;

pub use brick_field::{BrickField, BrickSegments};
pub use constant_box::ConstantBox;
pub use field::{DensityField, MajorantSegment};
pub use global::GlobalMajorant;
pub use grid_field::GridField;
pub use majorant_grid::{DdaSegments, MajorantGrid};
pub use media::{GlobalMedia, Interaction, Media, Scaled};

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

    /// The same medium seen through the global majorant.
    pub fn with_global_majorant(&self) -> Medium<GlobalMajorant<&F>> {
        Medium {
            field: GlobalMajorant::new(&self.field),
            density_scale: self.density_scale,
            albedo: self.albedo,
            phase: self.phase.clone(),
        }
    }

    /// A medium borrowing this one's field (so integrators are written once
    /// for `Medium<&F>`-like views and owned media alike).
    pub fn by_ref(&self) -> Medium<&F> {
        Medium {
            field: &self.field,
            density_scale: self.density_scale,
            albedo: self.albedo,
            phase: self.phase.clone(),
        }
    }
}
