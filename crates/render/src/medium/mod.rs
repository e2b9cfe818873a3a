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
pub use field::{Bounds3, DensityField, Lattice, MajorantSegment};
#[cfg(feature = "testing")]
pub use grid_field::GridField;
#[cfg(feature = "testing")]
pub use majorant_grid::{DdaSegments, MajorantGrid};
pub use media::{GlobalMedia, Interaction, Media, Scaled};
pub use motion::{Velocity, VelocityUnit};

use glam::Vec3;

use crate::phase::Phase;

/// A participating medium: extinction
/// `sigma_t,c(p) = extinction_tint_c * density_scale * density(p)` per RGB
/// channel `c`, `sigma_s = albedo * sigma_t` per channel, and a phase
/// function.
///
/// `density_scale` is the largest channel's extinction per unit density,
/// so the field's majorants scaled by it bound every channel; the tint is
/// each channel's share of it, in [0, 1]. A grey medium (tint 1, 1, 1)
/// samples free flights and transmittance as scalars; a coloured albedo
/// then only tints the path throughput. A chromatic one takes the spectral
/// trackers ([`crate::tracking::spectral`]).
#[derive(Clone, Debug)]
pub struct Medium<F> {
    pub field: F,
    /// Converts field density to the largest channel's extinction, in
    /// 1 / render-space units.
    pub density_scale: f32,
    /// Each channel's extinction relative to `density_scale`, in [0, 1].
    pub extinction_tint: Vec3,
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
            extinction_tint: Vec3::ONE,
            albedo,
            phase: Phase::hg(g),
        }
    }

    pub fn with_phase(self, phase: Phase) -> Self {
        Self { phase, ..self }
    }

    /// Sets extinction per channel: `density_scale` times `tint`, whose
    /// largest component must be 1 ([`Extinction::split`] gives both).
    pub fn with_extinction_tint(self, extinction_tint: Vec3) -> Self {
        Self {
            extinction_tint,
            ..self
        }
    }

    /// Extinction coefficient at `p` (the largest channel's).
    #[inline]
    pub fn sigma_t(&self, p: Vec3) -> f32 {
        self.density_scale * self.field.density(p)
    }
}

/// Extinction per unit density and RGB channel, split into what the
/// trackers need: the largest channel's scale (what majorants are scaled
/// by) and each channel's share of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extinction {
    pub scale: f32,
    /// In [0, 1], largest component 1; `Vec3::ONE` for grey media.
    pub tint: Vec3,
}

impl Extinction {
    /// Splits a per-channel extinction scale (finite and >= 0 each). Equal
    /// channels give exactly `(scale, ONE)`, so grey media stay grey bit
    /// for bit.
    pub fn split(rgb: Vec3) -> Self {
        let scale = rgb.max_element();
        if rgb.x == rgb.y && rgb.y == rgb.z || scale <= 0.0 {
            return Self {
                scale,
                tint: Vec3::ONE,
            };
        }
        Self {
            scale,
            tint: (rgb / scale).min(Vec3::ONE),
        }
    }

    pub fn is_grey(&self) -> bool {
        self.tint == Vec3::ONE
    }
}
