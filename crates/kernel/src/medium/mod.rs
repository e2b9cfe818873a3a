//! Participating media: a density field and the optical parameters that turn
//! it into extinction, scattering and a phase function.
//!
//! - `field` defines [`DensityField`], the interface the trackers walk.
//! - `constant_box`, `grid_field` (+ `majorant_grid`) are test fields with
//!   known answers (feature `testing`); `brick_field` adapts the brick
//!   volumes of `cirrus-bricks`, placed in render space.
//! - `global` is the one segment of a global majorant (Mitsuba-style),
//!   which [`GlobalMedia`] puts over any media.
//! - `media` defines [`Media`], what the trackers and integrators walk, in
//!   extinction units ([`Volumes`](crate::Volumes) is the one
//!   implementation a scene renders; [`GlobalMedia`] wraps any).
//! - `emission` is what a medium emits: blackbody or an emission grid.
//! - `motion` moves a brick field with a velocity grid (motion blur).

mod brick_field;
#[cfg(feature = "testing")]
mod constant_box;
mod emission;
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
pub use emission::Emission;
pub use field::{Bounds3, DensityField, Lattice, MajorantSegment};
#[cfg(feature = "testing")]
pub use grid_field::GridField;
#[cfg(feature = "testing")]
pub use majorant_grid::{DdaSegments, MajorantGrid};
pub use media::{GlobalMedia, Interaction, Media, Scaled};
pub use motion::{Velocity, VelocityUnit};

use glam::Vec3;

use crate::phase::Phase;

/// A participating medium: a density field placed in render space and what
/// turns it into light transport. Extinction is
/// `sigma_t,c(p) = extinction_tint_c * density_scale * density(p)` per RGB
/// channel `c`, `sigma_s = albedo * sigma_t` per channel, scattering follows
/// the phase function, and an optional [`Emission`] adds the source term.
///
/// `density_scale` is the largest channel's extinction per unit density,
/// so the field's majorants scaled by it bound every channel; the tint is
/// each channel's share of it, in [0, 1]. A grey medium (tint 1, 1, 1)
/// samples free flights and transmittance as scalars; a coloured albedo
/// then only tints the path throughput. A chromatic one is tracked per
/// channel ([`crate::spectrum`]).
///
/// What the renderer walks is [`Media`]: one medium or several overlapping
/// ones are [`Volumes`](crate::Volumes) (`Volumes::from(medium)`).
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
    pub emission: Option<Emission<F>>,
    /// A matte: lights and shadows the others, never seen by the camera.
    pub holdout: bool,
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
            emission: None,
            holdout: false,
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

    pub fn with_emission(self, emission: Emission<F>) -> Self {
        Self {
            emission: Some(emission),
            ..self
        }
    }

    /// Extinction coefficient at `p` at shutter time `time` (the largest
    /// channel's).
    #[inline]
    pub fn sigma_t(&self, p: Vec3, time: f32) -> f32 {
        self.density_scale * self.field.density_at(p, time)
    }

    /// Checks the medium's parameters.
    pub fn validate(&self) -> Result<(), MediumError> {
        if !(self.density_scale.is_finite() && self.density_scale >= 0.0) {
            return Err(MediumError::DensityScale(self.density_scale));
        }
        let a = self.albedo;
        if !a.is_finite() || a.min_element() < 0.0 || a.max_element() > 1.0 {
            return Err(MediumError::Albedo(a));
        }
        Ok(())
    }
}

/// A medium parameter out of range.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MediumError {
    #[error("density scale must be finite and >= 0, got {0}")]
    DensityScale(f32),
    #[error("albedo must lie in [0, 1], got {0}")]
    Albedo(Vec3),
}

impl From<MediumError> for crate::error::Error {
    fn from(e: MediumError) -> Self {
        Self::Invalid(e.to_string())
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
